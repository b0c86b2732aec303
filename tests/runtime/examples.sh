#!/bin/bash
# examples.sh — the examples whose result is a promise of the README,
# checked as they run (each in its own output folder):
#
#   OUTCROP=/abs/path/to/outcrop bash tests/runtime/examples.sh
#
# sea-arch: examples/sea_cliffs.lua at its own cell (0.8), picture left
# out (--set render=false): its mesh is one closed component (specks of a
# few vertices dropped) with a through-hole, genus >= 1 (topology.lua).

set -u

if [ -z "${OUTCROP:-}" ] || [ ! -x "$OUTCROP" ]; then
  echo "examples.sh: set OUTCROP to the outcrop binary" >&2
  exit 2
fi
HERE=$(cd "$(dirname "$0")" && pwd)
ROOT=$(cd "$HERE/../.." && pwd)
T=$(mktemp -d "${TMPDIR:-/tmp}/outcrop-ex.XXXXXX") || exit 2
trap 'rm -rf "$T"' EXIT
. "$HERE/tally.sh"

name=sea-arch
why=
mkdir -p "$T/$name"
if ! "$OUTCROP" run "$HERE/topology.lua" "$ROOT/examples/sea_cliffs.lua" 1 \
  --set render=false --out "$T/$name" >"$T/out" 2>"$T/err"; then
  because "$(grep -m1 -E 'outcrop:|assert' "$T/err" || echo "exit status $?")"
fi
grep -qE 'ERROR: (Address|Leak)Sanitizer|runtime error:' "$T/err" &&
  because "sanitizer report"
grep -q '^topology: 1 component' "$T/out" || because "no single component reported"
tally "$T/out" "$T/err"
grep "^topology" "$T/out" | sed "s/^/     /"

echo "example tests: $npass passed, $nfail failed"
[ "$nfail" -eq 0 ]
