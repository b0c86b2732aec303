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
shopt -s nullglob
for s in scripts/bench/*.lua; do
  echo "## $(basename "$s")"
  "$OUTCROP" run "$s" --out "$(mktemp -d)"
done
