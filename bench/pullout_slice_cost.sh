#!/usr/bin/env bash
# The validation slice's coupled step against the pure-DEM step of the same grains
# (docs/performance.md, "Geogrid pullout: validation slice"): STEPS steps on 2 ranks of
#   A: cases/geogrid_pullout/slice.yaml from its packed specimen (the grid coupled, FE every
#      2 DEM steps; the consolidation hold), and
#   B: bench/pullout_slice_dem.yaml: the same grains from specimen.txt, no grid,
# then prints both rates, the ratio and A's time per stage (run.json).
#   bash bench/pullout_slice_cost.sh OUT_DIR_OF_A_SLICE_RUN [STEPS]   (default 5000)
# The slice run's directory must hold specimen.h5 and specimen.txt (make validate writes them).
set -euo pipefail
cd "$(dirname "$0")/.."
SPEC=${1:?usage: pullout_slice_cost.sh SLICE_OUT_DIR [STEPS]}
STEPS=${2:-5000}
FDEM=build/fdem
MPIRUN="bash $PWD/scripts/mpirun.sh"
WORK=${BENCH_WORK:-bench/work}
mkdir -p "$WORK" bench/results
SPEC=$(cd "$SPEC" && pwd)
rm -rf "$WORK/slice_coupled" "$WORK/slice_dem"
$MPIRUN -n 2 "$FDEM" run cases/geogrid_pullout/slice.yaml --specimen "$SPEC/specimen.h5" --set time.steps="$STEPS" \
  --set output.snapshot_every=1000000 --set measure.every=1000000 --out "$WORK/slice_coupled" -q
$MPIRUN -n 2 "$FDEM" run bench/pullout_slice_dem.yaml --set particles.0.file.path="$SPEC/specimen.txt" \
  --set time.steps="$STEPS" --out "$WORK/slice_dem" -q
/usr/bin/python3 - "$WORK" <<'PYEOF' | tee bench/results/pullout_slice_cost.txt
import json, sys, os
w = sys.argv[1]
a = json.load(open(os.path.join(w, "slice_coupled", "run.json")))
b = json.load(open(os.path.join(w, "slice_dem", "run.json")))
cpu = next((l.split(":", 1)[1].strip() for l in open("/proc/cpuinfo") if l.startswith("model name")), "?")
print("validation slice, %d steps on %d ranks; %s, %d cores" % (a["steps"], a["ranks"], cpu, os.cpu_count()))
for name, r in (("coupled (grid + FE)", a), ("pure DEM (same grains)", b)):
    print("  %-24s %7d grains  %8.2f s  %.3e particle-steps/s  %.3f ms/step"
          % (name, r["particles"]["initial"], r["wall_time_s"], r["particle_steps_per_second"],
             1e3 * r["wall_time_s"] / r["steps"]))
print("  coupled / pure-DEM step: %.2f" % ((a["wall_time_s"] / a["steps"]) / (b["wall_time_s"] / b["steps"])))
print("  coupled run, time per stage (s, slowest rank): " + ", ".join("%s %.2f" % kv for kv in a["timings"].items()))
print("  pure DEM, time per stage (s, slowest rank): " + ", ".join("%s %.2f" % kv for kv in b["timings"].items()))
PYEOF
