#!/usr/bin/env bash
# Coupled FE-DE step cost split (docs/performance.md, "Coupled FE-DE step"): the SS-1 geogrid in
# 88 032 spheres, STEPS timed DEM steps on 1 and 2 ranks; raw output to
# bench/results/coupled_split_np{1,2}.txt.
#   bash bench/coupled_run.sh [STEPS] [MASS_SCALE]      (defaults 1000, 1e4)
# Builds nothing: build/bench_coupled_split must exist (make build).
set -euo pipefail
cd "$(dirname "$0")/.."
STEPS=${1:-1000}
SCALE=${2:-1e4}
BIN=build/bench_coupled_split
[ -x "$BIN" ] || { echo "coupled_run.sh: $BIN not found; run 'make build' first" >&2; exit 2; }
mkdir -p bench/results
for np in 1 2; do
  bash scripts/mpirun.sh -n "$np" "$BIN" "$STEPS" "$SCALE" | tee "bench/results/coupled_split_np$np.txt"
done
