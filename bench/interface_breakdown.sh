#!/bin/bash
# Where the interface stage's time goes (docs/performance.md, "Coupled FE-DE step"): one coupled run
# of the production build, read from its run.json. The coupler times each stage of its sub-cycle
# with the production timers (ScopedTimer; names from CouplerTimings::stages(),
# src/coupling/coupler.hpp), slowest rank:
#   coupling_candidates  candidate grid and lists (at neighbour rebuilds)
#   coupling_scan        extrapolation of the surface, quick rejection, closest points
#   coupling_select      face/edge/vertex selection, merging, history carry-over
#   coupling_law         contact law, particle forces, contact records (measurements)
#   coupling_distribute  fixed-point vertex (nodal force distribution) and surface-group sums
#   coupling_contacts    all of the above (the engine's interface_contacts stage is compute() alone)
#   coupling_reduce, coupling_fe, coupling_scatter: the FE update.
# Usage: bash bench/interface_breakdown.sh [RANKS (1)] [CASE [fdem run arguments ...]]
#   default case: cases/geogrid_pullout/ci.yaml --set packing.settle.max_steps=3000 --set time.steps=10000
# Builds nothing: build/fdem (or $FDEM) must exist (make build).
set -euo pipefail
cd "$(dirname "$0")/.."
np=${1:-1}
shift || true
if [ $# -eq 0 ]; then
  set -- cases/geogrid_pullout/ci.yaml --set packing.settle.max_steps=3000 --set time.steps=10000
fi
FDEM=${FDEM:-build/fdem}
[ -x "$FDEM" ] || { echo "interface_breakdown.sh: $FDEM not found; run 'make build' first" >&2; exit 2; }
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
bash scripts/mpirun.sh -n "$np" "$FDEM" run "$@" --out "$out/run" -q >"$out/log" 2>&1 || {
  cat "$out/log" >&2
  exit 1
}
/usr/bin/python3 - "$out/run/run.json" "$*" "$np" <<'PYEOF'
import json, sys
r = json.load(open(sys.argv[1]))
t = r["timings"]
steps = max(1, r["steps"] - r.get("start_step", 0))
print("interface stages of `fdem run %s` on %s rank(s), %d steps (slowest rank):" % (sys.argv[2], sys.argv[3], steps))
parts = [("candidate grid and lists", "coupling_candidates"),
         ("scan (extrapolation, plane tests, closest points)", "coupling_scan"),
         ("face/edge/vertex selection, merging, history", "coupling_select"),
         ("contact law, particle forces, contact records", "coupling_law"),
         ("nodal (vertex) and surface-group sums", "coupling_distribute")]
total = t.get("coupling_contacts", 0.0)
for name, key in parts + [("whole contact stage", "coupling_contacts")]:
    s = t.get(key, 0.0)
    print("  %-52s %9.3f s  %8.4f ms/step  %5.1f %%" % (name, s, 1e3 * s / steps, 100 * s / total if total else 0))
rest = total - sum(t.get(k, 0.0) for _, k in parts)
print("  %-52s %9.3f s" % ("(timer overhead and rounding)", rest))
for key in ("coupling_reduce", "coupling_fe", "coupling_scatter"):
    print("  %-52s %9.3f s  %8.4f ms/step" % (key, t.get(key, 0.0), 1e3 * t.get(key, 0.0) / steps))
PYEOF
