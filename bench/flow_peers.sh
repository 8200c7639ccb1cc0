#!/usr/bin/env bash
# Flowing-bed benchmark against the peers: fdem, LAMMPS and LIGGGHTS on 1 and 2 ranks from the
# same loose cloud thrown into an open box (bench/flow.yaml: ~29 000 grains, d 4-6 mm, 1 m/s
# downwards, 20 000 steps: neighbour-list rebuilds, migration between ranks, contacts forming).
# The dense, settled bed is `make bench` (bench/run.sh); this is its flowing counterpart
# (docs/performance.md#the-flowing-bed-against-the-peers).
#   bash bench/flow_peers.sh [STEPS]      (default 20000)
# 1. (not measured) fdem generates the cloud of bench/flow.yaml; its first snapshot becomes a
#    sphere file (scripts/h5_to_spheres.py) and a LAMMPS/LIGGGHTS data file
#    (bench/spheres_to_liggghts.py).
# 2. (measured, one after the other) fdem (bench/flow.yaml reading that sphere file, every grain
#    at 1 m/s down), LAMMPS (bench/in.flow.lammps) and LIGGGHTS (bench/in.flow), 1 and 2 ranks.
#    fdem's time is its wall_time_s (set-up and the final files included), the peers' their
#    'Loop time'. The cloud collapses onto the floor: fdem moves its cut planes with the grains
#    (src/partition), LAMMPS balances with `fix balance`, LIGGGHTS (which has none) is not cut
#    along gravity (`processors * * 1`). A missing peer binary is skipped with a message ($LAMMPS, $LIGGGHTS: other
#    binaries; Debian packages lammps, liggghts).
# Output: bench/results/flow_peers.txt and flow_peers.json. Builds nothing (make build).
set -euo pipefail
cd "$(dirname "$0")/.."
STEPS=${1:-20000}
FDEM=${FDEM:-build/fdem}
PY=/usr/bin/python3
MPIRUN="bash $PWD/scripts/mpirun.sh"
LAMMPS=${LAMMPS:-lmp}
LIGGGHTS=${LIGGGHTS:-liggghts}
[ -x "$FDEM" ] || { echo "flow_peers.sh: $FDEM not found; run 'make build' first" >&2; exit 2; }
W=bench/work/flow
rm -rf "$W"; mkdir -p "$W" bench/results

echo "== the cloud (bench/flow.yaml's generation; not measured)"
$MPIRUN -n 1 "$FDEM" run bench/flow.yaml --out "$W/gen" -q --set time.steps=1 > /dev/null
$PY scripts/h5_to_spheres.py "$W/gen/particles_00000000.h5" "$W/flow_spheres.txt"
$PY bench/spheres_to_liggghts.py "$W/flow_spheres.txt" "$W/flow.data" \
  --box -0.002 0.202 -0.002 0.202 -0.002 0.302 --density 2640
echo "   $(grep -vc '^#' "$W/flow_spheres.txt") grains"

for P in 1 2; do
  echo "== fdem, $P rank(s), $STEPS steps"
  $MPIRUN -n "$P" "$FDEM" run bench/flow.yaml --out "$W/fdem_n$P" -q --set time.steps="$STEPS" \
    --set "particles=[{file: {path: $PWD/$W/flow_spheres.txt, material: grain, velocity: [0, 0, -1.0]}}]" > /dev/null
done
run_peer() {  # NAME BINARY INPUT LOGPREFIX
  local name=$1 bin=$2 input=$3 log=$4
  if ! command -v "$bin" > /dev/null 2>&1; then
    echo "== SKIPPING $name: binary '$bin' not found"
    return 0
  fi
  for P in 1 2; do
    echo "== $name, $P rank(s), $STEPS steps"
    ( cd "$W" && $MPIRUN -n "$P" "$bin" -in "$OLDPWD/$input" -echo none -log none \
        -var datafile flow.data -var steps "$STEPS" ) > "$W/${log}_n$P.log" 2>&1 ||
      { tail -n 30 "$W/${log}_n$P.log" >&2; exit 1; }
  done
}
run_peer LAMMPS "$LAMMPS" bench/in.flow.lammps lammps
run_peer LIGGGHTS "$LIGGGHTS" bench/in.flow liggghts

$PY - "$W" <<'PYEOF' | tee bench/results/flow_peers.txt
import json, os, sys
sys.path.insert(0, "bench")
from report import fdem_result, peer_result, cpu_info
w = sys.argv[1]
model, cores = cpu_info()
rows = {}
for p in (1, 2):
    rows[("fdem", p)] = fdem_result(os.path.join(w, "fdem_n%d" % p), p)
    for code, log in (("LAMMPS", "lammps"), ("LIGGGHTS", "liggghts")):
        r = peer_result(os.path.join(w, "%s_n%d.log" % (log, p)), p, code)
        if r and "error" not in r:
            rows[(code, p)] = r
print("# bench/flow_peers.sh: a cloud thrown into an open box (bench/flow.yaml), %s, %d cores" % (model, cores))
print("%-9s %5s %8s %7s %10s %14s %14s %8s %22s" % ("code", "ranks", "grains", "steps", "time (s)", "particle-st/s",
                                                   "per core", "eff.", "fdem / faster peer"))
out = []
for (code, p), r in sorted(rows.items(), key=lambda kv: (kv[0][0] != "fdem", kv[0][0], kv[0][1])):
    per_core = r["particle_steps_per_second"] / p
    one = rows.get((code, 1))
    eff = "" if p == 1 or not one else "%.1f %%" % (100 * r["particle_steps_per_second"] / (p * one["particle_steps_per_second"]))
    ratio = ""
    if code == "fdem":
        peers = [rows[(c, p)]["particle_steps_per_second"] for c in ("LAMMPS", "LIGGGHTS") if (c, p) in rows]
        if peers:
            ratio = "%.2f" % (r["particle_steps_per_second"] / max(peers))
    print("%-9s %5d %8d %7d %10.2f %14.4g %14.4g %8s %22s" % (code, p, r["particles"], r["steps"], r["wall_time_s"],
                                                          r["particle_steps_per_second"], per_core, eff, ratio))
    out.append(dict(r, per_core=per_core))
json.dump({"cpu": model, "cores": cores, "runs": out}, open("bench/results/flow_peers.json", "w"), indent=1)
PYEOF
