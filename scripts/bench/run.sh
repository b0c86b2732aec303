#!/usr/bin/env bash
# Runs every benchmark: the C programs built from scripts/bench/bench_*.c
# (passed in BENCH_BIN) and the Lua scenes scripts/bench/*.lua run by the
# interpreter. Each prints `name: value unit` lines.
set -euo pipefail
cd "$(dirname "$0")/../.."
echo "# outcrop benchmarks on $(nproc) cores, $(date -u +%Y-%m-%dT%H:%MZ)"
for b in $BENCH_BIN; do
  echo "## $(basename "$b")"
  "$b"
done

# Start-up of the interpreter: the median wall time of 20 runs of a
# one-line script, without images (OpenImageIO is loaded on first use,
# lib/io/oiio_load.c) and with one tiny PNG written.
# The peer: stock lua5.4 loading the module (the embedders' route) and
# printing, timed the same way.
startup_ms() {
  local script=$1 dir times=() t0 t1
  dir=$(mktemp -d)
  for _ in $(seq 20); do
    t0=$(date +%s%N)
    if [ "$script" = stock ]; then
      lua5.4 -e "package.cpath = '$(dirname "$OUTCROP")/?.so;' .. package.cpath
        require 'outcrop' print(1)" >/dev/null
    else
      "$OUTCROP" run "$script" --out "$dir" >/dev/null
    fi
    t1=$(date +%s%N)
    times+=($(( (t1 - t0) / 1000 )))
  done
  rm -rf "$dir"
  printf '%s\n' "${times[@]}" | sort -n |
    awk '{ v[NR] = $1 } END { printf "%.1f", (v[10] + v[11]) / 2 / 1000 }'
}
echo "## start-up"
tmp=$(mktemp -d)
echo 'print(1)' >"$tmp/print.lua"
echo 'assert(outcrop.render(outcrop.point{center = {0, 0, 0}, radius = 1}, {size = {8, 8}}):write("tiny.png"))' >"$tmp/png.lua"
echo "runtime.startup_ms: $(startup_ms "$tmp/print.lua") ms"
echo "runtime.startup_ms_with_image: $(startup_ms "$tmp/png.lua") ms"
echo "runtime.startup_ms_stock_lua_require: $(startup_ms stock) ms"
rm -rf "$tmp"

shopt -s nullglob
for s in scripts/bench/*.lua; do
  echo "## $(basename "$s")"
  "$OUTCROP" run "$s" --out "$(mktemp -d)"
done
