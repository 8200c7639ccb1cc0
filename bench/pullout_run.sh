#!/usr/bin/env bash
# Geogrid pullout benchmark (docs/performance.md, "Geogrid pullout"): the same coupled run on 1
# and 2 ranks -- the CI variant (cases/geogrid_pullout/ci.yaml) from one packed specimen, STEPS DEM
# steps (consolidation at 49 kPa and the first pull steps). The runs are bitwise identical on 1
# and 2 ranks, so the wall times compare the same work. Prints wall time, particle-steps/s,
# element updates/s, parallel efficiency and the time per stage of each run (run.json), and
# writes them to bench/results/pullout_ci.txt.
#   bash bench/pullout_run.sh [STEPS]            (default 30000)
# Preparation (not measured, cached in bench/work/pullout_ci_pack/): the packing, on 2 ranks.
# Builds nothing: build/fdem must exist (make build).
set -euo pipefail
cd "$(dirname "$0")/.."
STEPS=${1:-30000}
FDEM=build/fdem
MPIRUN="bash $PWD/scripts/mpirun.sh"
CASE=cases/geogrid_pullout/ci.yaml
WORK=${BENCH_WORK:-bench/work}
[ -x "$FDEM" ] || { echo "pullout_run.sh: $FDEM not found; run 'make build' first" >&2; exit 2; }
mkdir -p "$WORK" bench/results
SPEC=$WORK/pullout_ci_pack/specimen.h5
if [ ! -f "$SPEC" ]; then
  echo "== packing the CI specimen (2 ranks, not measured)"
  $MPIRUN -n 2 "$FDEM" run "$CASE" --set time.steps=1 --out "$WORK/pullout_ci_pack" -q
fi
for np in 1 2; do
  echo "== $np rank(s): $STEPS steps from the specimen"
  rm -rf "$WORK/pullout_ci_np$np"
  $MPIRUN -n "$np" "$FDEM" run "$CASE" --specimen "$SPEC" --set time.steps="$STEPS" \
    --set output.snapshot_every=1000000 --set measure.every=1000000 --out "$WORK/pullout_ci_np$np" -q
done
/usr/bin/python3 - "$WORK" "$STEPS" <<'PYEOF' | tee bench/results/pullout_ci.txt
import json, sys, os, platform
work, steps = sys.argv[1], int(sys.argv[2])
r = {np: json.load(open(os.path.join(work, "pullout_ci_np%d" % np, "run.json"))) for np in (1, 2)}
cpu = "unknown"
for line in open("/proc/cpuinfo"):
    if line.startswith("model name"):
        cpu = line.split(":", 1)[1].strip()
        break
print("geogrid pullout CI, %d DEM steps from the packed specimen; %s, %d cores" % (steps, cpu, os.cpu_count()))
print("particles %d, FE elements (SS-1 section) %s, subcycle %s" % (
    r[1]["particles"]["final"], "136", int(r[1].get("coupling", {}).get("subcycle", 0))))
print("%-6s %10s %16s %16s %8s" % ("ranks", "wall (s)", "particle-steps/s", "element upd./s", "eff."))
for np in (1, 2):
    eff = r[1]["wall_time_s"] / (np * r[np]["wall_time_s"])
    print("%-6d %10.2f %16.3e %16.3e %7.0f%%" % (np, r[np]["wall_time_s"], r[np]["particle_steps_per_second"],
                                                r[np]["element_updates_per_second"], 100 * eff))
print("time per stage (s, slowest rank) and per DEM step (ms):")
names = list(r[1]["timings"].keys())
for k in names:
    a, b = r[1]["timings"][k], r[2]["timings"].get(k, 0.0)
    print("  %-20s %9.2f %7.3f ms   %9.2f %7.3f ms" % (k, a, 1e3 * a / steps, b, 1e3 * b / steps))
PYEOF
