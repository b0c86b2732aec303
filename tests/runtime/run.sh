#!/bin/bash
# run.sh — integration tests of the `outcrop` interpreter: command line,
# exit statuses, error reports, parameters, seed, sandbox, Ctrl-C, threads,
# --list-params, provenance by either front end.
#
#   OUTCROP=/abs/path/to/outcrop bash tests/runtime/run.sh
#
# Prints "ok NAME" or "FAIL NAME: reasons" (with the case's stderr) for
# every case and exits 1 if any failed. Each case runs in its own folder
# under a temporary directory that is removed at the end. A sanitizer
# report on stderr fails the case whatever the exit status.

set -u

if [ -z "${OUTCROP:-}" ] || [ ! -x "$OUTCROP" ]; then
  echo "run.sh: set OUTCROP to the outcrop binary" >&2
  exit 2
fi
HERE=$(cd "$(dirname "$0")" && pwd)
S=$HERE/scenes
T=$(mktemp -d "${TMPDIR:-/tmp}/outcrop-rt.XXXXXX") || exit 2
trap 'rm -rf "$T"' EXIT
OUT=$T/stdout
ERR=$T/stderr
. "$HERE/tally.sh"

# begin NAME: a fresh folder $W, the current folder of the runs that follow
begin() {
  name=$1
  W=$T/cases/$1
  mkdir -p "$W"
  why=
}


sanitizer_check() {
  if grep -qE 'ERROR: (Address|Leak)Sanitizer|runtime error:' "$ERR"; then
    because "sanitizer report"
  fi
}

# run ARGS...: outcrop ARGS in $W, stdin empty; sets rc
run() {
  (cd "$W" && exec "$OUTCROP" "$@") >"$OUT" 2>"$ERR" </dev/null
  rc=$?
  sanitizer_check
}

# run_in DIR ARGS...: the same from another current folder
run_in() {
  local dir=$1
  shift
  (cd "$dir" && exec "$OUTCROP" "$@") >"$OUT" 2>"$ERR" </dev/null
  rc=$?
  sanitizer_check
}

status_is() { [ "$rc" -eq "$1" ] || because "exit status $rc, expected $1"; }
out_has() { grep -qF -- "$1" "$OUT" || because "stdout lacks '$1'"; }
out_lacks() { ! grep -qF -- "$1" "$OUT" || because "stdout has '$1'"; }
err_has() { grep -qF -- "$1" "$ERR" || because "stderr lacks '$1'"; }
err_starts() {
  [ "$(head -c ${#1} "$ERR")" = "$1" ] || because "stderr does not start with '$1'"
}
file_has() {
  [ -f "$1" ] && grep -qF -- "$2" "$1" || because "$1 missing or lacks '$2'"
}
no_file() { [ ! -e "$1" ] || because "$1 exists"; }

end() { tally "$ERR"; }

# ---- command line --------------------------------------------------------

begin help
run --help
status_is 0; out_has "usage: outcrop"; out_has "--unsafe"
end

begin version
run --version
status_is 0; out_has "outcrop 0.1.0"; out_has "Lua 5.4"
end

begin no-arguments
run
status_is 2; err_has "no scene given"
end

begin run-without-scene
run run --seed 3
status_is 2; err_has "no scene given"
end

begin unknown-option
run --frobnicate "$S/hello.lua"
status_is 2; err_has "unknown option '--frobnicate'"; out_lacks "module"
end

begin missing-scene
run "$W/missing.lua" --out "$W/newout"
status_is 2; err_has "cannot open"; err_has "missing.lua"
no_file "$W/newout" # nothing is created for a command that fails
end

begin scene-is-a-folder
run "$W"
status_is 2; err_has "cannot read"
end

begin option-without-value
run "$S/hello.lua" --seed
status_is 2; err_has "option '--seed' needs a value"
end

begin bad-seed
for v in -1 1.5 abc "" " 3" 9223372036854775808; do
  run --seed "$v" "$S/hello.lua"
  [ "$rc" -eq 2 ] || because "--seed '$v' gave status $rc"
done
err_has "--seed expects"
end

begin bad-threads
for v in 0 -2 two 1025 ""; do
  run --threads "$v" "$S/hello.lua"
  [ "$rc" -eq 2 ] || because "--threads '$v' gave status $rc"
done
err_has "--threads expects"
end

begin set-without-equals
run --set novalue "$S/hello.lua"
status_is 2; err_has "NAME=VALUE"
run --set =value "$S/hello.lua"
status_is 2
end

begin out-not-creatable
: >"$W/file"
run "$S/hello.lua" --out "$W/file/sub"
status_is 2; err_has "cannot create output folder"
end

begin out-created
run "$S/write.lua" --out "$W/a/b/c" rel.txt
status_is 0; file_has "$W/a/b/c/rel.txt" written
end

# ---- running, arguments, errors --------------------------------------------

begin plain-equals-run
run "$S/hello.lua" x y
status_is 0
cp "$OUT" "$W/plain"
run run "$S/hello.lua" x y
status_is 0
cmp -s "$OUT" "$W/plain" || because "outputs differ"
out_has "module	table	true"; out_has "args	2	x	y"
end

begin script-args
run "$S/hello.lua" one --seed 4 -- --two
status_is 0; out_has "arg0	$S/hello.lua"; out_has "args	2	one	--two"
end

begin stdin-scene
(cd "$W" && echo 'print("from stdin", ...)' | "$OUTCROP" - a) >"$OUT" 2>"$ERR"
rc=$?
sanitizer_check
status_is 0; out_has "from stdin	a"
end

begin script-error
run_in "$HERE" scenes/error.lua --out "$W"
status_is 1
err_starts "outcrop: scenes/error.lua:5: attempt to index a nil value"
err_has "traceback"; err_has "scenes/error.lua:9:"; err_has "scenes/error.lua:13:"
end

begin syntax-error
run "$S/syntax.lua"
status_is 1; err_starts "outcrop: $S/syntax.lua:3:"
end

begin error-object
run "$S/errobj.lua"
status_is 1; err_has "(error object is a table value)"
run "$S/errobj.lua" tostring
status_is 1; err_has "outcrop: custom error object"
end

begin os-exit
run "$S/exit.lua" 3
status_is 3; out_lacks "not reached"
run "$S/exit.lua"
status_is 0; out_lacks "not reached"
run "$S/exit.lua" 4 co
status_is 4; out_lacks "not reached"
end

begin coroutines
run "$S/coroutine.lua"
status_is 0; out_has "coroutines ok"
run --unsafe "$S/coroutine.lua"
status_is 0; out_has "coroutines ok"
end

# ---- parameters and seed -----------------------------------------------------

begin params
run "$S/params.lua" --set a=3 --set b=hello --set c=true --set d=x=y
status_is 0; out_has "params	3	hello	true"; out_has "d	x=y"
end

begin params-before-scene
run run --set=a=3 --set b=hello --set c=false --set c=true "$S/params.lua"
status_is 0; out_has "params	3	hello	true"; out_has "d	nil"
end

begin seed
run "$S/seed.lua"
status_is 0; out_has "seed	1	integer"
run "$S/seed.lua" --seed 42
status_is 0; out_has "seed	42	integer"
run --seed=7 "$S/seed.lua"
status_is 0; out_has "seed	7	integer"
run run --seed 9223372036854775807 "$S/seed.lua"
status_is 0; out_has "seed	9223372036854775807	integer"
end

begin threads
run --threads 1 "$S/threads.lua" --seed 3
status_is 0
cp "$OUT" "$W/one"
run "$S/threads.lua" --threads=2 --seed 3
status_is 0; out_has "threads"
cmp -s "$OUT" "$W/one" || because "outputs differ between 1 and 2 threads"
end

# ---- sandbox -----------------------------------------------------------------

begin sandbox-library
run "$S/sandbox.lua"
status_is 0; out_has "sandbox ok"
end

begin sandbox-require
run "$S/require.lua"
status_is 0; out_has "C module refused"
if lua5.4 -e 'require "lfs"' 2>/dev/null; then
  run --unsafe "$S/require.lua"
  status_is 0; out_has "C module loaded"
fi
end

begin write-relative-into-out
run "$S/write.lua" rel.txt --out "$W/o"
status_is 0; file_has "$W/o/rel.txt" written; no_file "$W/rel.txt"
end

begin write-default-out-is-cwd
run "$S/write.lua" rel.txt
status_is 0; file_has "$W/rel.txt" written
end

begin write-relative-out
run "$S/write.lua" --out o/p rel.txt
status_is 0; file_has "$W/o/p/rel.txt" written
end

begin write-subfolder
run "$S/write.lua" sub/dir/x.txt --out "$W/o"
status_is 0; file_has "$W/o/sub/dir/x.txt" written
end

begin write-absolute-inside
run "$S/write.lua" "$W/o/abs.txt" --out "$W/o"
status_is 0; file_has "$W/o/abs.txt" written
end

begin write-absolute-outside-denied
run "$S/write.lua" "$W/outside.txt" --out "$W/o"
status_is 1; err_has "io.open"; err_has "outside.txt"; no_file "$W/outside.txt"
run "$S/write.lua" "$W/outside.txt" a --out "$W/o"
status_is 1; no_file "$W/outside.txt"
end

begin update-outside-denied
echo original >"$W/existing.txt"
run "$S/write.lua" "$W/existing.txt" r+ --out "$W/o"
status_is 1
file_has "$W/existing.txt" original
end

begin escape-denied
run "$S/write.lua" ../escape.txt --out "$W/o"
status_is 1; err_has "io.open"; no_file "$W/escape.txt"
end

begin symlink-escape-denied
mkdir -p "$W/o" "$W/elsewhere"
ln -s "$W/elsewhere" "$W/o/link"
run "$S/write.lua" link/x.txt --out "$W/o"
status_is 1; no_file "$W/elsewhere/x.txt"
end

begin read-absolute-allowed
echo hello-input >"$T/input.txt"
run "$S/read.lua" "$T/input.txt" --out "$W/o"
status_is 0; out_has "read	hello-input"
end

begin read-relative-from-cwd
echo in-cwd >"$W/input.txt"
mkdir -p "$W/o"
echo in-out >"$W/o/input.txt"
run "$S/read.lua" input.txt --out "$W/o"
status_is 0; out_has "read	in-cwd"
end

begin io-output
run "$S/output.lua" x.txt --out "$W/o"
status_is 0; file_has "$W/o/x.txt" output
run "$S/output.lua" "$W/out.txt" --out "$W/o"
status_is 1; err_has "io.output"; no_file "$W/out.txt"
end

begin remove-rename
mkdir -p "$W/o"
echo a >"$W/o/a.txt"
echo b >"$W/o/b.txt"
echo keep >"$W/keep.txt"
run "$S/remove.lua" remove a.txt --out "$W/o"
status_is 0; no_file "$W/o/a.txt"
run "$S/remove.lua" rename b.txt c.txt --out "$W/o"
status_is 0; file_has "$W/o/c.txt" b
run "$S/remove.lua" remove "$W/keep.txt" --out "$W/o"
status_is 1; err_has "os.remove"; file_has "$W/keep.txt" keep
run "$S/remove.lua" rename c.txt ../moved.txt --out "$W/o"
status_is 1; err_has "os.rename"; no_file "$W/moved.txt"; file_has "$W/o/c.txt" b
run "$S/remove.lua" rename "$W/keep.txt" d.txt --out "$W/o"
status_is 1; file_has "$W/keep.txt" keep
end

# a precompiled scene is Lua bytecode, which can be crafted to break out
# of the VM: refused as a file and on standard input
begin bytecode-scene
printf 'print("bytecode ran")\n' >"$W/scene.lua"
luac5.4 -o "$W/scene.luac" "$W/scene.lua"
run "$W/scene.luac"
status_is 2; err_has "binary chunk"; err_has "--unsafe"; out_lacks "bytecode ran"
(cd "$W" && exec "$OUTCROP" - <"$W/scene.luac") >"$OUT" 2>"$ERR"
rc=$?
sanitizer_check
status_is 2; err_has "binary chunk"; out_lacks "bytecode ran"
run --unsafe "$W/scene.luac"
status_is 0; out_has "bytecode ran"
end

# a closed standard output is not reused by the first file opened: print
# fails (and the status says so) instead of writing into that file
begin closed-stdout
(cd "$W" && exec "$OUTCROP" "$S/closedout.lua") >&- 2>"$ERR" </dev/null
rc=$?
sanitizer_check
status_is 1; err_has "writing standard output"
[ "$(cat "$W/out.txt")" = written ] || because "out.txt holds '$(cat "$W/out.txt")'"
end

begin unsafe
run "$S/unsafe.lua" --out "$W/o"
status_is 1
run "$S/unsafe.lua" --unsafe --out "$W/o"
status_is 0; out_has "unsafe ok"; file_has "$W/unsafe.txt" unsafe
no_file "$W/o/unsafe.txt"
run --unsafe "$S/write.lua" "$W/anywhere.txt" --out "$W/o"
status_is 0; file_has "$W/anywhere.txt" written
end

# ---- Ctrl-C ----------------------------------------------------------------

# Bash starts background jobs with SIGINT ignored, and outcrop (rightly)
# keeps an ignored SIGINT ignored: restore the default for the child.
if env --default-signal=INT,HUP,TERM true 2>/dev/null; then
  DEFSIG=(env --default-signal=INT,HUP,TERM)
else
  DEFSIG=()
  set -m # with job control, background jobs keep default signals
fi

# stop_with SIG SCENE [HOW] [OPTIONS...]: runs SCENE HOW, sends SIG half a
# second after it wrote started.txt, and waits for the end (10 s at most);
# sets rc
stop_with() {
  local sig=$1 scene=$2 how=${3:-}
  shift 3 2>/dev/null || shift $#
  (cd "$W" && exec "${DEFSIG[@]}" "$OUTCROP" "$S/$scene" --out "$W/o" $how "$@") \
    >"$OUT" 2>"$ERR" </dev/null &
  pid=$!
  for _ in $(seq 200); do # up to 20 s for a slow (sanitized) start
    [ -e "$W/o/started.txt" ] && break
    sleep 0.1
  done
  sleep 0.5
  kill -"$sig" "$pid" 2>/dev/null
  for _ in $(seq 100); do
    kill -0 "$pid" 2>/dev/null || break
    sleep 0.1
  done
  if kill -0 "$pid" 2>/dev/null; then
    because "still running 10 s after SIG$sig"
    kill -KILL "$pid" 2>/dev/null
  fi
  wait "$pid"
  rc=$?
  sanitizer_check
  [ -e "$W/o/started.txt" ] || because "the scene never started"
}

# ctrl_c SCENE [HOW]: Ctrl-C, and checks that it stopped cleanly (status
# 130, "interrupted", nothing after the interruption)
ctrl_c() {
  stop_with INT "$@"
  status_is 130; err_has "outcrop: interrupted"; no_file "$W/o/after.txt"
}

# only_started: nothing but started.txt in the output folder (no output,
# no temporary)
only_started() {
  [ -z "$(ls -A "$W/o" | grep -v '^started.txt$')" ] ||
    because "files left in the output folder: $(ls -A "$W/o")"
}

# interrupt NAME [HOW]: Ctrl-C half a second into loop.lua HOW
interrupt() {
  begin "$1"
  ctrl_c loop.lua "${2:-}"
  no_file "$W/o/mesh.ply"
  end
}

interrupt interrupt
interrupt interrupt-coroutine-wrap wrap
interrupt interrupt-coroutine-resume resume
interrupt interrupt-coroutine-nested nested
interrupt interrupt-polygonize mesh
interrupt interrupt-coroutine-close close
interrupt interrupt-wrap-close wrap-close
interrupt interrupt-xpcall-handler xpcall
interrupt interrupt-finalizer finalizer

# SIGTERM and SIGHUP stop the scene as Ctrl-C does, with 128 + signal
begin sigterm-polygonize
stop_with TERM loop.lua mesh
status_is 143; err_has "outcrop: terminated"; only_started
end

begin sigterm-lua-loop
stop_with TERM loop.lua finalizer
status_is 143; err_has "outcrop: terminated"; only_started
end

begin sighup
stop_with HUP loop.lua xpcall
status_is 129; err_has "outcrop: hangup"; only_started
end

# print to a closed pipe: stock Lua dies of SIGPIPE, outcrop stops cleanly
begin sigpipe
mkdir -p "$W/o"
(cd "$W" && exec "$OUTCROP" "$S/loop.lua" print --out "$W/o") 2>"$ERR" \
  </dev/null | head -n 1 >"$OUT"
rc=${PIPESTATUS[0]}
sanitizer_check
status_is 141; err_has "outcrop: broken pipe"; out_has "line"
no_file "$W/o/after.txt"
end

# ---- resource limits ---------------------------------------------------------

begin help-limits
run --help
out_has "--max-memory SIZE"; out_has "--timeout SECONDS"; out_has "124"
end

begin bad-limits
for v in "" 0.5 -1M 12Q M 1e3 99999999999T; do
  run --max-memory "$v" "$S/hello.lua"
  [ "$rc" -eq 2 ] || because "--max-memory '$v' gave status $rc"
done
err_has "--max-memory expects"
for v in "" -1 abc 1e400 nan inf; do
  run --timeout "$v" "$S/hello.lua"
  [ "$rc" -eq 2 ] || because "--timeout '$v' gave status $rc"
done
err_has "--timeout expects"
end

begin max-memory-lua
run --max-memory 64M "$S/grow.lua"
status_is 1; err_has "not enough memory (--max-memory 64 MiB reached)"
out_lacks "not reached"
end

begin max-memory-engine
run --max-memory=256M "$S/grow.lua" engine
status_is 1; err_has "(--max-memory 256 MiB reached)"
err_has "outcrop.heightfield.fbm"; out_lacks "heightfield made"
run --max-memory 256M "$S/grow.lua" engine 512 --threads 2
status_is 1; out_has "heightfield made	512	512"; out_lacks "not reached"
err_has "grow.lua:13: not reached on purpose"
end

begin max-memory-none
run --max-memory 0 "$S/hello.lua" x
status_is 0; out_has "args	1	x"
for v in none 1G 512MiB 65536k 2gb; do
  run --max-memory "$v" "$S/hello.lua"
  [ "$rc" -eq 0 ] || because "--max-memory '$v' gave status $rc"
done
end

begin timeout-lua-loop
started=$SECONDS
run --timeout 1 "$S/loop.lua" --out "$W/o"
status_is 124; err_has "outcrop: timeout (--timeout 1 s)"
[ $((SECONDS - started)) -le 8 ] || because "took $((SECONDS - started)) s"
no_file "$W/o/after.txt"
end

begin timeout-engine
started=$SECONDS
run --timeout=1.5 "$S/loop.lua" mesh --out "$W/o"
status_is 124; err_has "outcrop: timeout (--timeout 1.5 s)"
[ $((SECONDS - started)) -le 8 ] || because "took $((SECONDS - started)) s"
only_started
end

# stuck in C, where no hook runs: ended GRACE (10 s) after the timeout
begin timeout-stuck-in-c
started=$SECONDS
run --timeout 0.5 "$S/loop.lua" c --out "$W/o"
status_is 124; err_has "outcrop: timeout (--timeout 0.5 s), still running 10 s later: killed"
[ $((SECONDS - started)) -le 15 ] || because "took $((SECONDS - started)) s"
end

begin timeout-finalizer
run --timeout 1 "$S/loop.lua" finalizer --out "$W/o"
status_is 124; no_file "$W/o/after.txt"
end

begin timeout-not-reached
run --timeout 30 "$S/hello.lua"
status_is 0
end

# ---- rendering -------------------------------------------------

# interrupt_render NAME [HOW]: Ctrl-C half a second into render_loop.lua HOW
interrupt_render() {
  begin "$1"
  ctrl_c render_loop.lua "${2:-}"
  no_file "$W/o/render.png"
  only_started
  end
}

interrupt_render interrupt-render
interrupt_render interrupt-render-function function

# meta_has FILE KEY VALUE: the image's metadata, read by OpenImageIO
meta_has() {
  oiiotool --info -v "$1" 2>/dev/null | grep -qF -- "$2: \"$3\"" ||
    because "$1 lacks metadata $2 = \"$3\""
}

begin render-provenance
run "$S/render_meta.lua" --set b=two --set a=1 --seed 7 --out "$W/o" r.png
status_is 0
meta_has "$W/o/r.png" outcrop:scene "$S/render_meta.lua"
meta_has "$W/o/r.png" outcrop:params "a=1 b=two"
meta_has "$W/o/r.png" outcrop:seed 7
meta_has "$W/o/r.png" outcrop:version 0.1.0
run "$S/render_meta.lua" --out "$W/o" r.exr
status_is 0
meta_has "$W/o/r.exr" outcrop:seed 1
meta_has "$W/o/r.exr" outcrop:params "(none)"
oiiotool --info -v "$W/o/r.exr" 2>/dev/null | grep -q "channel list: .*P\.z" ||
  because "r.exr lacks the AOV channels"
end

begin render-threads
run --threads 1 "$S/render_meta.lua" --out "$W/o" one.exr
status_is 0
run --threads 2 "$S/render_meta.lua" --out "$W/o" two.exr
status_is 0
cmp -s "$W/o/one.exr" "$W/o/two.exr" || because "1 and 2 threads give different EXR files"
run --threads 1 "$S/render_meta.lua" --out "$W/o" one.png
run --threads 2 "$S/render_meta.lua" --out "$W/o" two.png
cmp -s "$W/o/one.png" "$W/o/two.png" || because "1 and 2 threads give different PNG files"
end

# ---- parameters: typos, --list-params, provenance by both front ends ------

begin set-typo
run "$S/steps.lua" --set stpes=6 --out "$W/o"
status_is 2
err_has "outcrop: --set stpes: no outcrop.param reads it (did you mean 'steps'?)"
out_has "steps	4	0.8	plain	false" # the scene ran with the default
run "$S/steps.lua" --set zzzzzz=1 --set steps=5 --set quik=true --out "$W/o"
status_is 2
err_has "--set quik: no outcrop.param reads it (did you mean 'quick'?)"
err_has "--set zzzzzz: no outcrop.param reads it"
grep -q "zzzzzz.*did you mean" "$ERR" && because "a far name got a suggestion"
grep -q "steps: no" "$ERR" && because "steps was read"
# a name read only at the very end of the scene counts
run "$S/steps.lua" --set late=1 --set steps=5 --out "$W/o"
status_is 0; out_has "steps	5	0.8	plain	false"
end

begin list-params
mkdir -p "$W/tmp"
(cd "$W" && TMPDIR="$W/tmp" exec "$OUTCROP" run "$S/steps.lua" --list-params \
  --set steps=9 --out "$W/never") >"$OUT" 2>"$ERR" </dev/null
rc=$?
sanitizer_check
status_is 0
printf 'steps\t4\tinteger\ncell\t0.8\tnumber\nname\tplain\tstring\nquick\tfalse\tboolean\nlate\tnil\tnil\n' >"$W/want"
cmp -s "$OUT" "$W/want" || because "the list differs from $(cat "$W/want")"
out_lacks "steps	9" # the scene's own prints are discarded
no_file "$W/never"; no_file "$W/steps.txt"; no_file "$W/sub"
[ -z "$(ls -A "$W/tmp")" ] || because "the temporary output folder was left: $(ls -A "$W/tmp")"
run "$S/steps.lua" --list-params --unsafe
status_is 2; err_has "cannot be combined with --unsafe"
# a typo is still an error after the list
run "$S/steps.lua" --list-params --set stpes=1
status_is 2; err_has "did you mean 'steps'?"; out_has "steps	4	integer"
end

# The module next to the binary, for stock lua5.4 (a sanitized module
# needs its runtime preloaded, as the Makefile's check-asan does).
MODDIR=$(dirname "$OUTCROP")
stock_lua() {
  local pre=
  if ldd "$MODDIR/outcrop.so" 2>/dev/null | grep -q libasan; then
    pre="$(gcc -print-file-name=libasan.so):$(gcc -print-file-name=libubsan.so)"
  fi
  (cd "$W" && ASAN_OPTIONS=detect_leaks=0 LD_PRELOAD=$pre exec lua5.4 "$@") \
    >"$OUT" 2>"$ERR" </dev/null
  rc=$?
  sanitizer_check
}

begin routes-same-provenance
cp "$HERE/../fixtures/heightmap16.png" "$W/in.png"
cp "$S/routes.lua" "$W/routes.lua"
mkdir -p "$W/o2"
run routes.lua in.png --seed 7 --set steps=6 --out "$W/o1"
status_is 0; out_has "routes	6	24"
stock_lua -e "package.cpath = '$MODDIR/?.so;' .. package.cpath
  require('outcrop').configure{seed = 7, params = {steps = '6'}, out = 'o2'}" \
  routes.lua in.png
status_is 0; out_has "routes	6	24"
for f in bumps.png slice.png render.exr; do
  cmp -s "$W/o1/$f" "$W/o2/$f" || because "$f differs between the two routes"
done
scene_sha=$(sha256sum "$W/routes.lua" | cut -c1-64)
in_sha=$(sha256sum "$W/in.png" | cut -c1-64)
for f in o1/slice.png o2/slice.png o1/render.exr o2/bumps.png; do
  meta_has "$W/$f" outcrop:seed 7
  meta_has "$W/$f" outcrop:params "size=24 steps=6"
  meta_has "$W/$f" outcrop:scene routes.lua
  meta_has "$W/$f" outcrop:scene_sha256 "$scene_sha"
done
meta_has "$W/o1/slice.png" outcrop:inputs "in.png=$in_sha"
meta_has "$W/o2/render.exr" outcrop:inputs "in.png=$in_sha"
# bumps.png was written before the load
meta_has "$W/o1/bumps.png" outcrop:inputs "(none)"
end

begin stdin-scene-hash
printf 'assert(outcrop.slice(outcrop.point{center = {0, 0, 0}, radius = 1},\n  {size = {2, 2}}):write("s.png"))\n' >"$W/s.lua"
(cd "$W" && "$OUTCROP" - --out "$W/o" <"$W/s.lua") >"$OUT" 2>"$ERR"
rc=$?
status_is 0
meta_has "$W/o/s.png" outcrop:scene -
meta_has "$W/o/s.png" outcrop:scene_sha256 "$(sha256sum "$W/s.lua" | cut -c1-64)"
# a first line starting with '#' is skipped but hashed
printf '#!/usr/bin/env outcrop\n' | cat - "$W/s.lua" >"$W/shebang.lua"
run shebang.lua --out "$W/o"
status_is 0
meta_has "$W/o/s.png" outcrop:scene_sha256 "$(sha256sum "$W/shebang.lua" | cut -c1-64)"
end

begin configure-in-scene
# a scene configuring itself: the seed it asks for unless --seed says
# otherwise, and then it is an error
printf 'outcrop.configure{seed = 5, params = {steps = 2}}\nprint("seed", outcrop.seed, outcrop.param("steps", 4))\n' >"$W/c.lua"
run c.lua
status_is 0; out_has "seed	5	2"
run c.lua --seed 5 --set steps=2
status_is 0; out_has "seed	5	2"
run c.lua --seed 6
status_is 1; err_has "outcrop.configure: 'seed' is already configured as 6 (got 5)"
printf 'outcrop.configure{out = "."}\n' >"$W/out.lua"
run out.lua
status_is 1; err_has "'out' cannot be set in the sandbox"
run out.lua --unsafe --out "$W/elsewhere"
status_is 1; err_has "'out' is already configured as"
end

# ---- start-up: OpenImageIO is loaded on the first image read or write ------

# (the scene prints the shared objects mapped into the process)
begin image-library-lazy
cat >"$W/maps.lua" <<'LUA'
local oc = require "outcrop"
local function mapped()
  local f = assert(io.open("/proc/self/maps"))
  local s = f:read("a"); f:close()
  return s:find("libOpenImageIO", 1, true) ~= nil
end
print("before " .. tostring(mapped()))
oc.polygonize(oc.point{center = {0, 0, 0}, radius = 1}, {cell = 0.5}):write("m.obj")
print("mesh " .. tostring(mapped()))
assert(oc.render(oc.point{center = {0, 0, 0}, radius = 1}, {size = {4, 4}}):write("r.png"))
print("image " .. tostring(mapped()))
LUA
run "$W/maps.lua" --out "$W/o"
status_is 0
out_has "before false"
out_has "mesh false"
out_has "image true"
end

# A copy of the interpreter without liboutcrop_oiio.so beside it: scripts
# without images run; an image write is an ordinary error naming the cause.
begin image-library-missing
mkdir -p "$W/lone"
cp "$OUTCROP" "$W/lone/outcrop"
echo 'print(1 + 1)' >"$W/p.lua"
echo 'local oc = require "outcrop"
assert(oc.render(oc.point{center = {0, 0, 0}, radius = 1}, {size = {4, 4}}):write("r.png"))' >"$W/w.lua"
(cd "$W" && exec "$W/lone/outcrop" p.lua) >"$OUT" 2>"$ERR" </dev/null
rc=$?
status_is 0
out_has 2
(cd "$W" && LD_LIBRARY_PATH= exec "$W/lone/outcrop" w.lua --out o) >"$OUT" 2>"$ERR" </dev/null
rc=$?
status_is 1
err_has "image support unavailable: "
err_has "liboutcrop_oiio.so"
[ ! -e "$W/o/r.png" ] || because "r.png was written"
end

set +m

echo "runtime tests: $npass passed, $nfail failed"
[ "$nfail" -eq 0 ]
