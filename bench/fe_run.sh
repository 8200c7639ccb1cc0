#!/usr/bin/env bash
# FE benchmark: element updates per second of the explicit solver on 1 and 2 ranks for a
# geogrid-sized mesh (the SS-1 grid of cases/fem/geogrid_tension.yaml, 1580 Hex8) and a
# 200 000-element block (bench/fe_block.yaml). Fixed step counts (the tolerance is never met).
# Usage: bash bench/fe_run.sh [GRID_STEPS] [BLOCK_STEPS]
set -euo pipefail
cd "$(dirname "$0")/.."
FDEM=${FDEM:-build/fdem}
[ -x "$FDEM" ] || { echo "fe_run.sh: $FDEM not found; run 'make build' first" >&2; exit 2; }
GS=${1:-4000}; BS=${2:-200}
PY=/usr/bin/python3
OUT=bench/work/fe; mkdir -p "$OUT"
run() {  # name ranks case steps extra...
  local name=$1 np=$2 case=$3 steps=$4; shift 4
  bash scripts/mpirun.sh -n "$np" "$FDEM" run "$case" --out "$OUT/${name}_n$np" -q \
    --set fem.tolerance=1e-30 --set fem.max_steps="$steps" --set fem.check_every="$steps" "$@" >/dev/null
  $PY - "$OUT/${name}_n$np/run.json" "$name" "$np" "$steps" <<'PYEOF'
import json, sys
j = json.load(open(sys.argv[1])); name, np, steps = sys.argv[2], int(sys.argv[3]), int(sys.argv[4])
fe = j["timings"]["fe_steps"]
print("%-8s %d rank(s): %6d steps, FE time %7.2f s, %.3e element updates/s, %.3f ms per step"
      % (name, np, j["steps"], fe, j["element_updates_per_second"], 1e3 * fe / max(j["steps"], 1)))
PYEOF
}
echo "== FE benchmark (element updates per second = elements x steps / FE solver time)"
for np in 1 2; do
  run grid "$np" cases/fem/geogrid_tension.yaml "$GS" --set 'fem.displacement_steps=[1]'
done
for np in 1 2; do
  run block "$np" bench/fe_block.yaml "$BS"
done
