#!/usr/bin/env bash
# compare_revisions.sh — proves that a change keeps outputs and speed: builds
# an earlier commit (OLD) and the working tree (or the commit NEW) side by
# side and, in one run,
#
#   1. runs every example scene (examples/*.lua), the golden-image scenes
#      (scripts/compare/golden.lua) and the benchmarks' meshes, image and
#      query values (scripts/bench, kept through OUTCROP_BENCH_OUT) with
#      both builds, and compares every output file byte for byte (sha256):
#      one line `same|DIFFERENT|ONLY-OLD|ONLY-NEW path` per file, a total
#      (an example OLD does not have runs with the new build only, its
#      files listed as NEW-EXAMPLE and not compared);
#   2. times the benchmarks of both builds interleaved (old, new, old,
#      new… so that machine drift falls on both alike), ROUNDS rounds (3),
#      and prints the median of each figure as `name: old new ratio`, the
#      ratio being new/old for rates and old/new for times: above 1 means
#      the new build is faster, either way; then the same for the best
#      round of each side, and the load average (figures taken on a
#      loaded machine vary far more than the 3 % a restructuring aims at).
#
#   scripts/compare_revisions.sh OLD [NEW]      (or make compare-revisions OLD=rev)
#
# Exit status: 0 when every output is the same and every run succeeded,
# 1 when an output differs or is missing on one side, 2 on a failed build
# or run.
#
# Both builds run the same inputs: the examples, golden scenes and benchmark
# sources of NEW (or of the working tree). The benchmark sources are built
# against each build's library; names that NEW has renamed from oc_hf_* to
# oc_heightfield_* are renamed back for an OLD that has only the old names,
# and an OLD whose library cannot build NEW's benchmarks is timed with its
# own (then no benchmark outputs are compared). Options kept small so that
# a run takes about 15 minutes on 2 cores: the examples at their defaults
# except sea_cliffs without its picture (--set render=false); bench_mesh's
# speedup and spheres1000 parts, bench_render's HD image, bench_eval's
# BVH queries (without its brute-force check).
# OMP_NUM_THREADS=2 throughout (the benchmarks set their own threads).
# Builds and outputs go to a temporary folder (KEEP=1 keeps it); the
# working tree is built in its own build/release as `make` does.
# OUTPUTS=0 skips the outputs (a timing run alone, when the outputs were
# compared before on the same revisions).
set -uo pipefail

if [ $# -lt 1 ] || [ $# -gt 2 ]; then
  echo "usage: scripts/compare_revisions.sh OLD [NEW]" >&2
  exit 2
fi
ROOT=$(cd "$(dirname "$0")/.." && pwd)
OLD=$1
NEW=${2:-}
ROUNDS=${ROUNDS:-3}
JOBS=${JOBS:-2}
export OMP_NUM_THREADS=2
T=$(mktemp -d "${TMPDIR:-/tmp}/outcrop-cmp.XXXXXX") || exit 2
[ "${KEEP:-0}" = 1 ] && echo "# keeping $T" || trap 'rm -rf "$T"' EXIT

die() { echo "compare_revisions: $*" >&2; exit 2; }
log() { echo "# $*"; }

# ---- the two trees -------------------------------------------------------
unpack() { # rev dir
  mkdir -p "$2" && git -C "$ROOT" archive --format=tar "$1" | tar -x -C "$2" ||
    die "cannot unpack $1"
}
oldrev=$(git -C "$ROOT" rev-parse --short "$OLD^{commit}") || die "no commit $OLD"
unpack "$oldrev" "$T/old"
if [ -n "$NEW" ]; then
  newrev=$(git -C "$ROOT" rev-parse --short "$NEW^{commit}") || die "no commit $NEW"
  unpack "$newrev" "$T/new"
  NEWT=$T/new
else
  newrev="working tree ($(git -C "$ROOT" rev-parse --short HEAD)$(
    git -C "$ROOT" diff --quiet HEAD 2>/dev/null || echo '+changes'))"
  NEWT=$ROOT
fi
log "old: $oldrev; new: $newrev; $(nproc) cores; $ROUNDS rounds"

BENCHES="bench_eval bench_mesh bench_render"
# Each tree gets NEW's benchmark sources (OLD's own are kept in bench.own).
cp -r "$T/old/scripts/bench" "$T/old/scripts/bench.own"
cp "$NEWT"/scripts/bench/*.c "$NEWT"/scripts/bench/*.h "$T/old/scripts/bench/"
# Names NEW uses that OLD's headers have only under the oc_hf_ (OC_HF_)
# prefix: renamed back in OLD's copy.
for n in $(grep -ohE '\b(oc_heightfield|OC_HEIGHTFIELD)_[A-Za-z0-9_]+' "$T"/old/scripts/bench/*.[ch] | sort -u); do
  case $n in
  oc_*) short=oc_hf_${n#oc_heightfield_} ;;
  *) short=OC_HF_${n#OC_HEIGHTFIELD_} ;;
  esac
  if ! grep -rqw "$n" "$T/old/lib" --include='*.h' && grep -rqw "$short" "$T/old/lib" --include='*.h'; then
    sed -i "s/\b$n\b/$short/g" "$T"/old/scripts/bench/*.[ch]
  fi
done

build() { # tree label
  local bins="" b
  for b in $BENCHES; do bins="$bins build/release/bench/$b"; done
  log "building $2 (make -j$JOBS all + benchmarks)"
  if ! make -C "$1" -j"$JOBS" all >"$T/build-$2.log" 2>&1; then
    tail -20 "$T/build-$2.log" >&2
    die "the $2 build failed ($T/build-$2.log)"
  fi
  if ! make -C "$1" -j"$JOBS" $bins >>"$T/build-$2.log" 2>&1; then
    [ "$2" = old ] || { tail -20 "$T/build-$2.log" >&2; die "the new benchmarks failed to build"; }
    log "old: NEW's benchmarks do not build against it; timing its own, no benchmark outputs compared"
    rm -rf "$1/scripts/bench" && mv "$1/scripts/bench.own" "$1/scripts/bench"
    touch "$T/old-own-bench"
    make -C "$1" -j"$JOBS" $bins >>"$T/build-$2.log" 2>&1 || die "the old benchmarks failed to build"
  fi
}
build "$T/old" old
build "$NEWT" new
bin() { [ "$1" = old ] && echo "$T/old/build/release" || echo "$NEWT/build/release"; }

# ---- outputs -------------------------------------------------------------
failed=0
run_scene() { # side name script [options]
  local side=$1 name=$2 script=$3 out="$T/out/$1/$2" log="$T/logs/$1.${2//\//_}.log"
  shift 3
  mkdir -p "$out" "$T/logs"
  if ! (cd "$NEWT" && "$(bin "$side")/outcrop" run "$script" "$@" --out "$out" \
        >"$log" 2>&1); then
    echo "FAILED ($side) $name: $(tail -1 "$log")"
    failed=1
  fi
}
OUTPUTS=${OUTPUTS:-1}
[ "$OUTPUTS" = 1 ] && log "outputs: examples, golden scenes"
[ "$OUTPUTS" = 1 ] && for e in "$NEWT"/examples/*.lua; do
  name=$(basename "$e" .lua)
  opts=()
  [ "$name" = sea_cliffs ] && opts=(--set render=false)
  sides="old new"
  # an example OLD does not have may use what OLD lacks: new build only
  if [ ! -e "$T/old/examples/$name.lua" ]; then
    sides=new
    echo "examples/$name" >>"$T/new-examples"
  fi
  for side in $sides; do run_scene "$side" "examples/$name" "examples/$name.lua" "${opts[@]}"; done
done
[ "$OUTPUTS" = 1 ] && for side in old new; do run_scene "$side" golden scripts/compare/golden.lua; done

# ---- benchmarks, interleaved --------------------------------------------
only() { # bench -> its parts
  case $1 in
  bench_mesh) echo speedup,spheres1000 ;;
  bench_render) echo hd ;;
  bench_eval) echo qps ;;
  *) echo "" ;;
  esac
}
mkdir -p "$T/logs"
for r in $(seq "$ROUNDS"); do
  log "benchmarks, round $r of $ROUNDS"
  for b in $BENCHES; do
    for side in old new; do
      keep=
      if [ "$OUTPUTS" = 1 ] && [ "$r" = 1 ] && ! { [ "$side" = old ] && [ -e "$T/old-own-bench" ]; }; then
        keep="$T/out/$side/bench/$b" && mkdir -p "$keep"
      fi
      if ! OUTCROP_BENCH_OUT=$keep OUTCROP_BENCH_ONLY=$(only "$b") \
           "$(bin "$side")/bench/$b" >"$T/logs/bench.$side.$r.$b.txt" 2>&1; then
        echo "FAILED ($side) $b round $r: $(tail -1 "$T/logs/bench.$side.$r.$b.txt")"
        failed=1
      fi
    done
  done
done

# ---- the comparison --------------------------------------------------------
mkdir -p "$T/out/old" "$T/out/new"
echo "== outputs (sha256, old against new)"
(cd "$T/out/old" && find . -type f | sort) >"$T/files.old"
(cd "$T/out/new" && find . -type f | sort) >"$T/files.new"
nsame=0 ndiff=0 nnew=0
touch "$T/new-examples"
while read -r f; do
  f=${f#./}
  if grep -qxF "$(dirname "$f")" "$T/new-examples"; then
    echo "NEW-EXAMPLE $f"; nnew=$((nnew + 1))
  elif [ ! -e "$T/out/old/$f" ]; then
    echo "ONLY-NEW $f"; ndiff=$((ndiff + 1))
  elif [ ! -e "$T/out/new/$f" ]; then
    echo "ONLY-OLD $f"; ndiff=$((ndiff + 1))
  elif [ "$(sha256sum <"$T/out/old/$f")" = "$(sha256sum <"$T/out/new/$f")" ]; then
    echo "same $f"; nsame=$((nsame + 1))
  else
    echo "DIFFERENT $f"; ndiff=$((ndiff + 1))
  fi
done < <(sort -u "$T/files.old" "$T/files.new")
echo "outputs: $nsame same, $ndiff different, $nnew of examples OLD has not (not compared)"

# Figures: the median of the rounds of each side. The times of the speedup
# come from its '# cell 0.5 m' line (full grid, surface bounds + direct).
figure() { # side bench name -> values, one a line
  local f
  for f in "$T"/logs/bench."$1".*."$2".txt; do
    case $3 in
    full_grid_seconds)
      sed -nE 's/^# cell 0\.5 m.*full grid ([0-9.]+) s.*/\1/p' "$f" ;;
    bounds_seconds)
      sed -nE 's/^# cell 0\.5 m.*direct extraction ([0-9.]+) s.*/\1/p' "$f" ;;
    *) sed -nE "s/^$3: ([0-9.e+-]+) .*/\1/p" "$f" ;;
    esac
  done
}
median() { sort -g | awk '{ v[NR] = $1 } END { if (NR) print (NR % 2 ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2) }'; }
best() { # rate|time: the highest rate or the lowest time
  if [ "$1" = rate ]; then sort -g | tail -1; else sort -g | head -1; fi
}
SPECS="bench_eval:eval.qps_2t:rate bench_mesh:mesh.bounds_speedup:rate
  bench_mesh:full_grid_seconds:time bench_mesh:bounds_seconds:time
  bench_mesh:mesh.spheres1000_seconds_2t:time bench_render:render.hd_seconds_2t:time"
figures() { # median|best
  local spec b name kind o n label
  for spec in $SPECS; do
    IFS=: read -r b name kind <<<"$spec"
    if [ "$1" = median ]; then
      o=$(figure old "$b" "$name" | median)
      n=$(figure new "$b" "$name" | median)
    else
      o=$(figure old "$b" "$name" | best "$kind")
      n=$(figure new "$b" "$name" | best "$kind")
    fi
    label=$name
    case $name in *_seconds) [ "${name#mesh.}" = "$name" ] && label="mesh.bounds_speedup.$name" ;; esac
    if [ -z "$o" ] || [ -z "$n" ]; then
      echo "$label: ${o:-?} ${n:-?} ?"
      continue
    fi
    awk -v l="$label" -v o="$o" -v n="$n" -v k="$kind" \
      'BEGIN { r = k == "rate" ? n / o : o / n; printf "%s: %.4g %.4g %.3f\n", l, o, n, r }'
  done
}
echo "== benchmarks (median of $ROUNDS interleaved rounds; ratio new/old for"
echo "   rates, old/new for times: > 1 means the new build is faster)"
figures median
# The best round of each side is less sensitive to other work on the
# machine than the median (a loaded machine only ever slows a run).
echo "== the same, best round of each side"
figures best
echo "# load average at the end: $(cut -d' ' -f1-3 /proc/loadavg)"

if [ "$failed" != 0 ]; then
  echo "compare_revisions: a build or run failed (see above)"
  exit 2
fi
[ "$ndiff" -eq 0 ] || exit 1
exit 0
