#!/usr/bin/env bash
# Does fdem's speed depend on how the input numbers its grains? (docs/performance.md#order-keys)
#   bash bench/id_order.sh [STEPS]        (default 300; needs bench/work/spheres_100000.txt: make bench)
# A 1 M-grain bed: ten tiles (5 x 2) of the dense benchmark's settled 100 000-grain bed, once with
# the tiles' ids (scattered in space within each tile, as the random generation left them) and
# once with all ids shuffled (a random permutation, seed 1); each run STEPS steps on 1 rank
# (pinned to CPU 0 with taskset when available), no output in between. Prints each run's wall time
# and its particle-contact stage (run.json timings). fdem orders grains and contact pairs by order
# keys that follow space (src/dem/particles.hpp, order_key), so the two should agree; before the
# keys (ordered by id) the shuffled bed's contact stage took 2.8-3.4 times the tiled one's.
# $FDEM: the binary (default build/fdem); $FDEM_BASE: a second binary run on the same files.
set -euo pipefail
cd "$(dirname "$0")/.."
STEPS=${1:-300}
FDEM=${FDEM:-build/fdem}
PY=/usr/bin/python3
W=bench/work/id_order
SRC=bench/work/spheres_100000.txt
[ -s "$SRC" ] || { echo "id_order.sh: $SRC missing: run make bench (bench/run.sh) first" >&2; exit 2; }
[ -x "$FDEM" ] || { echo "id_order.sh: $FDEM not found: make build" >&2; exit 2; }
mkdir -p "$W"
if [[ ! -s $W/tiled.txt || $W/tiled.txt -ot $SRC ]]; then
  $PY - "$SRC" "$W" <<'EOF'
import sys
import numpy as np
src, w = sys.argv[1], sys.argv[2]
a = np.loadtxt(src)
n = len(a)
tiles = []
for ty in range(2):
    for tx in range(5):
        b = a.copy()
        b[:, 0] += (5 * ty + tx) * n
        b[:, 1] += 0.1002 * tx
        b[:, 2] += 0.1002 * ty
        tiles.append(b)
t = np.vstack(tiles)
ids = t[:, 0].astype(np.int64)
for name, col in (("tiled", ids), ("shuffled", np.random.default_rng(1).permutation(len(t)))):
    with open("%s/%s.txt" % (w, name), "w") as f:
        f.write("# 10 tiles of %s, ids %s: id x y z r\n" % (src, name))
        for i, row in zip(col, t):
            f.write("%d %.17g %.17g %.17g %.17g\n" % (i, row[1], row[2], row[3], row[4]))
EOF
fi
PIN=()
command -v taskset > /dev/null && PIN=(taskset -c 0)
for bin in "$FDEM" ${FDEM_BASE:+"$FDEM_BASE"}; do
  for name in tiled shuffled; do
    out=$W/run_$(basename "$bin")_$name
    rm -rf "$out"
    "${PIN[@]}" "$bin" run bench/dense.yaml --out "$out" -q \
      --set "particles.0.file.path=$(realpath "$W/$name.txt")" \
      --set "domain.max=[0.503, 0.2022, 0.085012]" --set "walls.2.point=[0.5012, 0, 0]" \
      --set "walls.4.point=[0, 0.2002, 0]" --set time.steps=$STEPS
    $PY - "$out/run.json" "$bin" "$name" <<'EOF'
import json, sys
j = json.load(open(sys.argv[1]))
print("%-24s ids %-8s  %d grains, %d steps: wall %.1f s, particle contacts %.1f s"
      % (sys.argv[2], sys.argv[3], j["particles"]["initial"], j["steps"], j["wall_time_s"],
         j["timings"]["particle_contacts"]))
EOF
  done
done
