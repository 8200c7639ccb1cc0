#!/usr/bin/env bash
# Scaling benchmark (make bench-scaling; docs/performance.md#scaling-out):
#  1. the ghost layer and the traffic per rank on 1, 2, 3, 4, 6 and 8 ranks (oversubscribed: the
#     counts do not depend on the cores) for a static cloud in a cube (bench/ghosts.yaml, side
#     SIDE m), against the model of bench/scaling_report.py, and that model extrapolated to a
#     10 M-grain bed on 64-1024 ranks;
#  2. strong and weak scaling on 1 and 2 ranks of this machine for a cloud falling into a box
#     (bench/flow.yaml: rebuilds, migration): the same cloud on 1 and 2 ranks (strong), and the
#     box and the cloud doubled along x on 2 ranks (weak: the same grains per rank).
# The dense bed (fdem against LIGGGHTS) is `make bench`, the coupled step bench/coupled_run.sh.
#   bash bench/scaling.sh [SIDE]     (default 0.3 m: ~80 000 grains in part 1)
# Output: bench/results/scaling.txt, scaling.json, scaling.png. Builds nothing (make build).
set -euo pipefail
cd "$(dirname "$0")/.."
SIDE=${1:-0.3}
FDEM=${FDEM:-build/fdem}
PY=/usr/bin/python3
MPIRUN="bash scripts/mpirun.sh"
[ -x "$FDEM" ] || { echo "scaling.sh: $FDEM not found; run 'make build' first" >&2; exit 2; }
W=bench/work/scaling
rm -rf "$W"; mkdir -p "$W" bench/results
box="{min: [0, 0, 0], max: [$SIDE, $SIDE, $SIDE]}"
dirs=()
for np in 1 2 3 4 6 8; do
  $MPIRUN -n "$np" "$FDEM" run bench/ghosts.yaml --out "$W/ghosts_n$np" -q --set "domain=$box" \
    --set "particles.0.generate.box=$box" >/dev/null
  dirs+=("$W/ghosts_n$np")
done
{
  echo "# bench/scaling.sh $SIDE, $(date -u +%Y-%m-%d), $(nproc) cores: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs)"
  echo
  echo "## 1. Ghosts and traffic per rank"
  $PY bench/scaling_report.py "${dirs[@]}" --json bench/results/scaling.json --png bench/results/scaling.png
  echo
  echo "## 2. Strong and weak scaling, a cloud falling into a box (bench/flow.yaml)"
  printf "%-8s %5s %9s %8s %12s %14s %8s\n" run ranks grains rebuilds "wall (s)" "particle-st/s" "eff."
  run_flow() {  # name ranks extra-set...
    local name=$1 np=$2; shift 2
    $MPIRUN -n "$np" "$FDEM" run bench/flow.yaml --out "$W/$name" -q "$@" >/dev/null
  }
  run_flow strong1 1
  run_flow strong2 2
  run_flow weak2 2 --set "domain={min: [-0.002, -0.002, -0.002], max: [0.402, 0.202, 0.302]}" \
    --set "particles.0.generate.box={min: [0, 0, 0.05], max: [0.4, 0.2, 0.3]}" --set 'walls.2.point=[0.4, 0, 0]'
  $PY - "$W" <<'PYEOF'
import json, sys
w = sys.argv[1]
j = {n: json.load(open("%s/%s/run.json" % (w, n))) for n in ("strong1", "strong2", "weak2")}
t1 = j["strong1"]["wall_time_s"]
for n, ref in (("strong1", None), ("strong2", "strong"), ("weak2", "weak")):
    r = j[n]
    eff = "" if ref is None else "%.0f %%" % (100 * (t1 / (2 * r["wall_time_s"]) if ref == "strong" else
                                                    t1 / r["wall_time_s"] * r["particles"]["final"] / (2 * j["strong1"]["particles"]["final"])))
    print("%-8s %5d %9d %8d %12.2f %14.3e %8s" % (n, r["ranks"], r["particles"]["final"], r["neighbour_rebuilds"],
                                                 r["wall_time_s"], r["particle_steps_per_second"], eff))
PYEOF
} | tee bench/results/scaling.txt
