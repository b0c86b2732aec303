#!/bin/bash
# examples.sh — the examples whose result is a promise of the README,
# checked as they run (each in its own output folder):
#
#   OUTCROP=/abs/path/to/outcrop bash tests/runtime/examples.sh
#
# sea-arch: examples/sea_cliffs.lua at its own cell (0.8), picture left
# out (--set render=false): its mesh is one closed component (specks of a
# few vertices dropped) with a through-hole, genus >= 1 (topology.lua).
#
# coast-arch: examples/elev_coast.lua the same way (the arch of a tree).
#
# elev-*: the elevation-tree examples at 96 x 54 (--set size=96), run
# with one thread and with two: the same PNG bytes both times; the dunes
# leave the peak's elevation as it was and raise the desert floor; the
# thirty instances share the patch (37 nodes, not 182); the lake's level
# is below the land around it; a younger crater's floor is its own; the
# LoD render takes fewer tree calls per pixel than the full-detail one
# on the same march (slope bounds: the LoD view source has no model).
# EXAMPLES_THREADS="2" (the sanitizer pass) runs them once, on two
# threads: the release pass has compared the thread counts.
#
# diffusion-*: two feature-curve examples the same way (below).

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

# coast-arch: examples/elev_coast.lua (an elevation tree implicitized and
# eroded by the sea) at its own cell, picture left out: one closed
# component with a through-hole under the neck.
name=coast-arch
why=
mkdir -p "$T/$name"
if ! "$OUTCROP" run "$HERE/topology.lua" "$ROOT/examples/elev_coast.lua" 1 \
  --set render=false --out "$T/$name" >"$T/out" 2>"$T/err"; then
  because "$(grep -m1 -E 'outcrop:|assert' "$T/err" || echo "exit status $?")"
fi
grep -qE 'ERROR: (Address|Leak)Sanitizer|runtime error:' "$T/err" &&
  because "sanitizer report"
grep -q '^topology: 1 component' "$T/out" || because "no single component reported"
tally "$T/out" "$T/err"
grep "^topology" "$T/out" | sed "s/^/     /"

# Runs example $1 at 96 pixels into $T/$2/N on one thread and on two
# (EXAMPLES_THREADS), stdout in $T/out1 (and out2): the same PNG bytes.
run_96() {
  local ex=$1 name=$2 n threads=${EXAMPLES_THREADS:-1 2}
  mkdir -p "$T/$name/1" "$T/$name/2"
  for n in $threads; do
    "$OUTCROP" run "$ROOT/examples/$ex.lua" --set size=96 --threads $n \
      --out "$T/$name/$n" >"$T/out$n" 2>"$T/err" ||
      because "$(grep -m1 -E 'outcrop:|assert' "$T/err" || echo "exit status $?")"
  done
  [ "$threads" = "1 2" ] || cp "$T/$name/$threads/$ex.png" "$T/$name/1/$ex.png" 2>/dev/null
  [ "$threads" = "1 2" ] || cp "$T/out$threads" "$T/out1"
  if [ -f "$T/$name/1/$ex.png" ] && [ -f "$T/$name/2/$ex.png" ]; then
    cmp -s "$T/$name/1/$ex.png" "$T/$name/2/$ex.png" ||
      because "$ex.png differs between --threads 1 and 2"
  else
    because "no $ex.png written"
  fi
}

for ex in elev_river elev_dunes elev_instances elev_road elev_coast elev_lake \
  elev_craters elev_multiscale elev_lod; do
  name=elev-${ex#elev_}
  why=
  run_96 "$ex" "$name"
  case $ex in
  elev_dunes)
    # desert floor A m -> B m with dunes; peak C m -> D m: B > A, D = C
    awk '/desert floor/ { ok = ($7 > $4 + 1 && $12 == $15) } END { exit !ok }' \
      FS='[ ]+' "$T/out1" || because "the dunes did not keep to the low ground"
    ;;
  elev_instances)
    grep -q '30 instances: 37 nodes, 5 primitives' "$T/out1" ||
      because "the instances do not share the patch"
    ;;
  elev_lake)
    # water level A m; the land around it B to C m: A < B
    awk '/water level/ { ok = ($4 + 0 < $13 + 0) } END { exit !ok }' \
      FS='[ ]+' "$T/out1" || because "the lake's level is not below the land around it"
    ;;
  elev_lod)
    # with LoD: A tree calls per pixel; full detail: B (both on
    # first-order models): A < B
    awk '/with LoD:/ { a = $4 } /full detail:/ { b = $4 }
      END { exit !(a + 0 > 0 && a + 0 < b + 0) }' FS='[ ]+' "$T/out1" ||
      because "the LoD render does not take fewer tree calls"
    ;;
  elev_craters)
    # a younger crater over an older rim: floor F = its level L - depth D
    awk '/cuts the rim/ { d = $18 - ($24 - $27); ok = (d < 0.11 && d > -0.11) }
      END { exit !ok }' FS='[ ]+' "$T/out1" ||
      because "the younger crater's floor is not its own"
    ;;
  esac
  tally "$T/out1" "$T/err"
done

# diffusion-*: the feature-curve examples (Hnaidi et al. 2010) with a
# 96-pixel render, on one thread and on two: the same PNG bytes; the
# ridges meet (their flanks conflict) and the island reaches its rim.
for ex in diffusion_ridges diffusion_island; do
  name=diffusion-${ex#diffusion_}
  why=
  run_96 "$ex" "$name"
  case $ex in
  diffusion_ridges)
    # N steps, A strict, B slope and C conflicting samples: C > 0
    awk '/conflicting/ { ok = ($9 + 0 > 0) } END { exit !ok }' FS='[ ]+' \
      "$T/out1" || because "the ridges' flanks did not meet"
    ;;
  diffusion_island)
    # 9 curves, N steps, LO..HI m: the rim's 440..460 m (plus noise)
    awk '/curves/ { split($6, r, "[.][.]"); ok = (r[2] + 0 >= 440) }
      END { exit !ok }' FS='[ ]+' "$T/out1" || because "the island is too low"
    ;;
  esac
  tally "$T/out1" "$T/err"
done

echo "example tests: $npass passed, $nfail failed"
[ "$nfail" -eq 0 ]
