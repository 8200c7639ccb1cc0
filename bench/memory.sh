#!/usr/bin/env bash
# Memory per rank (docs/performance.md#memory-per-rank): a bed of N generated grains (default
# 1 000 000; bench/memory.yaml's cloud, the box scaled to N) on 1, 2 and 4 ranks (oversubscribed
# is fine: memory does not need the cores): start-up (generation), 20 steps and a checkpoint, then
# a restart from that checkpoint and 20 steps more; and the same start with the cloud generated
# in shares (`placement: cells`: no rank builds the whole cloud), and the same cloud read from a
# sphere text file (each rank parses its byte range of the file). Each rank's peak resident memory comes from
# run.json ("decomposition" -> "peak_rss_mb", getrusage). Issue 20's aim: at 4 ranks, <= 30 % of
# the 1-rank figure.
#   bash bench/memory.sh [N]          output: bench/results/memory.txt
set -euo pipefail
cd "$(dirname "$0")/.."
N=${1:-1000000}
FDEM=${FDEM:-build/fdem}
PY=/usr/bin/python3
MPIRUN="bash scripts/mpirun.sh"
[ -x "$FDEM" ] || { echo "memory.sh: $FDEM not found; run 'make build' first" >&2; exit 2; }
W=bench/work/memory
rm -rf "$W"; mkdir -p "$W" bench/results
# porosity 0.85, d 4-6 mm (mean volume 6.81e-8 m^3): N grains fill a cube of side (N v / 0.15)^(1/3)
# (a solid fraction random addition reaches in generation cells too, docs/case-format.md#generate)
SIDE=$($PY -c "print('%.4f' % (($N * 6.807e-8 / 0.15) ** (1 / 3)))")
box="{min: [0, 0, 0], max: [$SIDE, $SIDE, $SIDE]}"
for np in 1 2 4; do
  $MPIRUN -n "$np" "$FDEM" run bench/memory.yaml --out "$W/n$np" -q --set "domain=$box" \
    --set "particles.0.generate.box=$box" \
    --set "particles.0.generate.count=$N" --set time.steps=20 >/dev/null
  cp "$W/n$np/run.json" "$W/n$np/run_start.json"
  if [ "$np" = 1 ]; then  # the cloud as a sphere file: "id x y z r" from the first checkpoint
    $PY - "$W/n1/checkpoint.h5" "$W/spheres.txt" <<'PYEOF'
import sys, h5py, numpy as np
with h5py.File(sys.argv[1], "r") as f:
    p = f["particles"]
    x, r, i = p["x"][...], p["r"][...], p["id"][...]
o = np.argsort(i)
with open(sys.argv[2], "w") as out:
    out.write("# id x y z r\n")
    for k in o:
        out.write("%d %.17g %.17g %.17g %.17g\n" % (i[k], x[k, 0], x[k, 1], x[k, 2], r[k]))
PYEOF
  fi
  $MPIRUN -n "$np" "$FDEM" run bench/memory.yaml --out "$W/f$np" -q --set "domain=$box" \
    --set "particles=[{file: {path: $PWD/$W/spheres.txt, material: grain}}]" --set time.steps=20 >/dev/null
  $MPIRUN -n "$np" "$FDEM" run bench/memory.yaml --out "$W/c$np" -q --set "domain=$box" \
    --set "particles.0.generate.box=$box" --set particles.0.generate.placement=cells \
    --set "particles.0.generate.count=$N" --set time.steps=20 >/dev/null
  $MPIRUN -n "$np" "$FDEM" run bench/memory.yaml --out "$W/n$np" -q --set "domain=$box" \
    --set "particles.0.generate.box=$box" \
    --set "particles.0.generate.count=$N" --set time.steps=40 --restart "$W/n$np/checkpoint.h5" >/dev/null
done
$PY - "$W" "$N" <<'PYEOF' | tee bench/results/memory.txt
import json, sys
w, n = sys.argv[1], int(sys.argv[2])
print("# bench/memory.sh: %d generated grains; peak resident memory per rank (MB, getrusage)" % n)
print("%5s %26s %26s %26s %26s" % ("ranks", "start + 20 steps + ckpt", "cells start + 20 + ckpt", "restart + 20 steps",
                                   "sphere file + 20 + ckpt"))
base = {}
def peak(path):
    r = json.load(open(path))["decomposition"]["ranks"]
    return max(q["peak_rss_mb"] for q in r), sum(q["peak_rss_mb"] for q in r) / len(r)
for p in (1, 2, 4):
    row = []
    for k, f in enumerate(("n%d/run_start.json", "c%d/run.json", "n%d/run.json", "f%d/run.json")):
        mx, mean = peak("%s/%s" % (w, f % p))
        base.setdefault(k, mx)
        row.append("%.0f (mean %.0f) %3.0f%%" % (mx, mean, 100 * mx / base[k]))
    print("%5d %26s %26s %26s %26s" % (p, row[0], row[1], row[2], row[3]))
print("(per column: the busiest rank's peak, the mean over the ranks, and the peak against 1 rank)")
PYEOF
