#!/bin/bash
# outpaths.sh — the sandbox's output paths under attack: folders renamed
# or swapped for symbolic links by a Lua callback between the check and
# the write, symbolic links on the way (even ones pointing inside), and
# leaf links. Nothing may land outside --out; refusals are clean errors.
#
#   OUTCROP=/abs/path/to/outcrop bash tests/runtime/outpaths.sh
#
# Prints "ok NAME" or "FAIL NAME: reasons" and exits 1 if any failed.

set -u

if [ -z "${OUTCROP:-}" ] || [ ! -x "$OUTCROP" ]; then
  echo "outpaths.sh: set OUTCROP to the outcrop binary" >&2
  exit 2
fi
S=$(cd "$(dirname "$0")" && pwd)/scenes
T=$(mktemp -d "${TMPDIR:-/tmp}/outcrop-op.XXXXXX") || exit 2
trap 'rm -rf "$T"' EXIT
. "$(dirname "$0")/tally.sh"

# begin NAME: a fresh case folder $W with an output folder $W/o, a folder
# $W/elsewhere outside it, $W/o/trap, a link from inside to elsewhere, and
# two folders that look alike: $W/o/a/sub (a folder) and $W/o/x/sub (a
# link to elsewhere), so that renaming x to a, folders only, turns the
# checked path a/sub/... into one that leads out.
begin() {
  name=$1 why=
  W=$T/$1
  mkdir -p "$W/o/sub" "$W/o/a/sub" "$W/o/x" "$W/elsewhere"
  ln -s "$W/elsewhere" "$W/o/trap"
  ln -s "$W/elsewhere" "$W/o/x/sub"
}
# swap ARGS...: the swap.lua scene with --out $W/o
swap() {
  (cd "$W" && exec "$OUTCROP" "$S/swap.lua" --out "$W/o" "$@") \
    >"$T/stdout" 2>"$T/stderr" </dev/null
  rc=$?
  if grep -qE 'ERROR: (Address|Leak)Sanitizer|runtime error:' "$T/stderr"; then
    because "sanitizer report"
  fi
}
status_is() { [ "$rc" -eq "$1" ] || because "exit status $rc, expected $1"; }
says() { cat "$T/stdout" "$T/stderr" | grep -qF -- "$1" || because "no '$1'"; }
nothing_outside() {
  [ -z "$(ls -A "$W/elsewhere")" ] || because "written outside: $(ls -A "$W/elsewhere")"
  [ -z "$(find "$W" -maxdepth 1 -type f)" ] || because "written in the case folder"
}
no_temporaries() {
  [ -z "$(find "$W/o" -name '.*.tmp-*')" ] || because "temporary left"
}
end() { tally "$T/stdout" "$T/stderr"; }

# The colour callback swaps the checked folder for a link leading out.
for k in ply obj glb; do
  begin "callback-swaps-folder-for-link-$k"
  swap mesh a/sub/m.$k a old x a
  status_is 1; says "symbolic link"; says "outside the output folder"
  nothing_outside; no_temporaries
  end
done

# The callback moves the folder away: the write goes where the path says
# now, inside.
begin callback-moves-folder-away
swap mesh sub/m.ply sub gone
status_is 0; says "wrote sub/m.ply"
[ -f "$W/o/sub/m.ply" ] || because "no $W/o/sub/m.ply"
nothing_outside; no_temporaries
end

# the extension each kind of writer takes
ext() { case $1 in mesh) echo ply ;; file) echo txt ;; *) echo png ;; esac; }

# Links on the way are refused, also ones that lead back inside.
for kind in mesh image hf file; do
  begin "link-on-the-way-$kind"
  ln -s "$W/o/sub" "$W/o/inside"
  swap $kind trap/x.$(ext $kind)
  status_is 1; says "'trap' is a symbolic link"
  swap $kind inside/deeper/x.$(ext $kind)
  status_is 1; says "'inside' is a symbolic link"
  [ ! -e "$W/o/sub/deeper" ] || because "folder created through a link"
  nothing_outside; no_temporaries
  end
done

# A link in place of the file itself is refused.
begin leaf-link
ln -s "$W/elsewhere/target.png" "$W/o/file.png"
swap image file.png
status_is 1; says "it is a symbolic link"
nothing_outside
end

# The scene renames the link over a folder before io.open and os.remove.
begin rename-then-open
swap file a/sub/x.txt a old x a
status_is 1; says "symbolic link"; nothing_outside
end

# Plain writes still work, folders are created, absolute paths inside too.
for kind in mesh image hf file; do
  begin "plain-$kind"
  e=$(ext $kind)
  swap $kind new/deeper/x.$e
  status_is 0; says "wrote new/deeper/x.$e"
  [ -f "$W/o/new/deeper/x.$e" ] || because "no file"
  swap $kind "$W/o/abs.$e"
  status_is 0; [ -f "$W/o/abs.$e" ] || because "no absolute file"
  nothing_outside; no_temporaries
  end
done

# A full disk: every writer reports nil, "<path>: No space left on
# device" and leaves neither the file nor its temporary (needs root for
# the tmpfs); a file of io.open is the script's own, not atomic, and its
# close reports the error.
for kind in mesh image hf file; do
  begin "disk-full-$kind"
  if [ "$(id -u)" != 0 ] || ! mount -t tmpfs -o size=64k octest "$W/o/sub" 2>/dev/null; then
    echo "skip $name (a tmpfs needs root)"
    continue
  fi
  dd if=/dev/zero of="$W/o/sub/fill" bs=4k 2>/dev/null
  swap $kind sub/x.$(ext $kind)
  status_is 0; says "No space left on device"
  if [ $kind != file ]; then
    says "failed sub/x.$(ext $kind): sub/x.$(ext $kind): No space left on device"
    [ "$(ls -A "$W/o/sub")" = fill ] || because "left: $(ls -A "$W/o/sub")"
  fi
  umount "$W/o/sub"
  end
done

echo "output path tests: $npass passed, $nfail failed"
[ "$nfail" -eq 0 ]
