#!/bin/bash
# readme_snippets.sh — every ```lua block of README.md runs as written:
#
#   OUTCROP=/abs/path/to/outcrop bash tests/runtime/readme_snippets.sh [README]
#
# Each block runs in a fresh folder under the interpreter (`outcrop run
# block.lua --out .`, sandboxed), and a block whose first line is
# `local oc = require "outcrop"` runs once more under stock lua5.4 with
# the module beside the interpreter (outcrop.so) on LUA_CPATH. A block
# names the files it reads in a comment, `-- fixtures: NAME ...`: each
# NAME of tests/fixtures is copied into the folder both as NAME and as
# tests/fixtures/NAME (so a path written for the repository's root works
# too); `NEW=NAME` copies it as NEW. A block opened by ```lua no-run is a
# deliberate fragment and is skipped (listed at the end). A block passes
# when it exits 0 within 120 s with no sanitizer report.

set -u

if [ -z "${OUTCROP:-}" ] || [ ! -x "$OUTCROP" ]; then
  echo "readme_snippets.sh: set OUTCROP to the outcrop binary" >&2
  exit 2
fi
HERE=$(cd "$(dirname "$0")" && pwd)
ROOT=$(cd "$HERE/../.." && pwd)
README=${1:-$ROOT/README.md}
MODDIR=$(cd "$(dirname "$OUTCROP")" && pwd)
T=$(mktemp -d "${TMPDIR:-/tmp}/outcrop-readme.XXXXXX") || exit 2
trap 'rm -rf "$T"' EXIT
. "$HERE/tally.sh"

# A sanitized module needs the sanitizer runtimes loaded before lua5.4.
PRELOAD=
if ldd "$MODDIR/outcrop.so" 2>/dev/null | grep -q libasan; then
  PRELOAD="$(gcc -print-file-name=libasan.so):$(gcc -print-file-name=libubsan.so)"
fi

# The blocks: $T/blocks/LINE.lua (LINE: of the opening fence), and
# $T/skipped listing the no-run ones.
mkdir -p "$T/blocks"
awk -v dir="$T/blocks" -v skipped="$T/skipped" '
  /^```lua([ \t].*)?$/ && !inb {
    inb = 1; start = NR; norun = ($0 ~ /no-run/)
    if (norun) print start > skipped
    out = dir "/" sprintf("%05d", start) ".lua"; next
  }
  /^```[ \t]*$/ && inb { inb = 0; close(out); next }
  inb && !norun { print > out }
' "$README"
touch "$T/skipped"

# fixtures FILE DIR: copies the fixtures FILE names into DIR
fixtures() {
  local spec dst src
  for spec in $(sed -n 's/^.*-- fixtures:\(.*\)$/\1/p' "$1"); do
    case $spec in
      *=*) dst=${spec%%=*}; src=${spec#*=} ;;
      *) dst=$spec; src=$spec ;;
    esac
    if [ ! -f "$ROOT/tests/fixtures/$src" ]; then
      because "fixture $src is not in tests/fixtures"
      continue
    fi
    mkdir -p "$2/tests/fixtures"
    cp "$ROOT/tests/fixtures/$src" "$2/$dst"
    cp "$ROOT/tests/fixtures/$src" "$2/tests/fixtures/$dst"
  done
}

# check HOW STATUS: the case's verdict on the run just made
check() {
  [ "$2" -eq 0 ] || because "$1: exit status $2"
  if grep -qE 'ERROR: (Address|Leak)Sanitizer|runtime error:' "$W/err"; then
    because "$1: sanitizer report"
  fi
}

for f in "$T"/blocks/*.lua; do
  [ -e "$f" ] || continue
  line=$((10#$(basename "$f" .lua)))
  name="README.md:$line"
  why=
  W=$T/run/$line
  mkdir -p "$W/interp"
  fixtures "$f" "$W/interp"
  cp "$f" "$W/block.lua"
  (cd "$W/interp" && timeout 120 "$OUTCROP" run "$W/block.lua" --out . \
    >"$W/out" 2>"$W/err")
  check interpreter $?
  case $(grep -m1 -v '^[[:space:]]*$' "$f") in
  'local oc = require "outcrop"'*)
    mkdir -p "$W/stock"
    fixtures "$f" "$W/stock"
    (cd "$W/stock" && LUA_CPATH="$MODDIR/?.so;;" LD_PRELOAD="$PRELOAD" \
      ASAN_OPTIONS=detect_leaks=0 timeout 120 lua5.4 "$W/block.lua" \
      >>"$W/out" 2>>"$W/err")
    check lua5.4 $?
    ;;
  *) because "does not start with 'local oc = require \"outcrop\"' (stock lua5.4 cannot run it)" ;;
  esac
  tally "$W/err"
done

while read -r line; do
  echo "skip README.md:$line (no-run)"
done <"$T/skipped"
echo "README snippets: $npass passed, $nfail failed"
[ "$nfail" -eq 0 ]
