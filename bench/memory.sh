#!/usr/bin/env bash
# Memory per rank (docs/performance.md#memory-per-rank): a bed of N generated grains (default
# 1 000 000; bench/memory.yaml's cloud, the box scaled to N) on 1, 2 and 4 ranks (oversubscribed
# is fine: memory does not need the cores): start-up (generation), 20 steps and a checkpoint, then
# a restart from that checkpoint and 20 steps more; and the same start with the cloud generated
# in shares (`placement: cells`: no rank builds the whole cloud), and the same cloud read from a
# sphere text file (each rank parses its byte range of the file), and N grains packed in two
# layers (bench/memory_pack.yaml: a few settling steps per layer, then 20 steps of the case; the
# packer holds each rank's share between its engines). Each rank's peak resident memory comes from
# run.json ("decomposition" -> "peak_rss_mb", getrusage). Issue 20's aim: at 4 ranks, <= 30 % of
# the 1-rank figure.
#   bash bench/memory.sh [N]          output: bench/results/memory.txt
#   bash bench/memory.sh N cells      the cells start only (a 10 M bed in minutes):
#                                     bench/results/memory_cells_N.txt
#   bash bench/memory.sh N pack       the packing only: bench/results/memory_pack_N.txt
set -euo pipefail
cd "$(dirname "$0")/.."
N=${1:-1000000}
WAYS=${2:-all}
case "$WAYS" in all|cells|pack) ;; *) echo "memory.sh: second argument: all, cells or pack, not '$WAYS'" >&2; exit 2 ;; esac
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
# the packing: N grains fill a cube of side (N v / 0.6)^(1/3) at porosity 0.4; the domain is
# 2.6 sides high (the second layer's cloud falls from above the first's, which has barely settled)
PSIDE=$($PY -c "print('%.4f' % (($N * 6.807e-8 / 0.6) ** (1 / 3)))")
pack_sets=(--set "domain={min: [-0.005, -0.005, -0.005], max: [$($PY -c "print($PSIDE + 0.005)"), $($PY -c "print($PSIDE + 0.005)"), $($PY -c "print(2.6 * $PSIDE)")]}"
           --set "packing.box={min: [0, 0, 0], max: [$PSIDE, $PSIDE, $PSIDE]}" --set "walls.2.point=[$PSIDE, 0, 0]"
           --set "walls.4.point=[0, $PSIDE, 0]")
# the layers' clouds in generation cells (packing.placement; PACK_PLACEMENT=sequential for the
# other, PACK_PLACEMENT= for the case's default)
PACK_PLACEMENT=${PACK_PLACEMENT-cells}
[ -n "$PACK_PLACEMENT" ] && pack_sets+=(--set "packing.placement=$PACK_PLACEMENT")
for np in 1 2 4; do
  if [ "$WAYS" = pack ] || [ "$WAYS" = all ]; then
    $MPIRUN -n "$np" "$FDEM" run bench/memory_pack.yaml --out "$W/p$np" -q "${pack_sets[@]}" >/dev/null
    [ "$WAYS" = pack ] && continue
  fi
  if [ "$WAYS" = cells ]; then
    $MPIRUN -n "$np" "$FDEM" run bench/memory.yaml --out "$W/c$np" -q --set "domain=$box" \
      --set "particles.0.generate.box=$box" --set particles.0.generate.placement=cells \
      --set "particles.0.generate.count=$N" --set time.steps=20 >/dev/null
    continue
  fi
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
# The memory every rank has before any grain (MPI, PETSc, HDF5, the program): a 1 000-grain run.
$MPIRUN -n 1 "$FDEM" run bench/memory.yaml --out "$W/base" -q --set time.steps=20 \
  --set particles.0.generate.count=1000 --set particles.0.generate.box="{min: [0, 0, 0], max: [0.08, 0.08, 0.08]}" >/dev/null
RESULT=bench/results/memory.txt
[ "$WAYS" = cells ] && RESULT=bench/results/memory_cells_$N.txt
[ "$WAYS" = pack ] && RESULT=bench/results/memory_pack_$N.txt
PACK_PLACEMENT=$PACK_PLACEMENT $PY - "$W" "$N" "$WAYS" <<'PYEOF' | tee "$RESULT"
import json, sys
w, n, ways = sys.argv[1], int(sys.argv[2]), sys.argv[3]
def peak(path):
    r = json.load(open(path))["decomposition"]["ranks"]
    return max(q["peak_rss_mb"] for q in r), sum(q["peak_rss_mb"] for q in r) / len(r)
base_mb = peak(w + "/base/run.json")[0]
cols = [("start + 20 steps + ckpt", "n%d/run_start.json"), ("cells start + 20 + ckpt", "c%d/run.json"),
        ("restart + 20 steps", "n%d/run.json"), ("sphere file + 20 + ckpt", "f%d/run.json"),
        ("packing 2 layers + 20", "p%d/run.json")]
if ways == "pack":
    print("# packing.placement: %s" % (__import__("os").environ.get("PACK_PLACEMENT", "cells") or "the default"))
if ways == "cells":
    cols = cols[1:2]
if ways == "pack":
    cols = cols[4:5]
print("# bench/memory.sh: %d generated grains; peak resident memory per rank (MB, getrusage)" % n)
print("%5s" % "ranks" + "".join(" %26s" % c[0] for c in cols))
one = {}
for p in (1, 2, 4):
    row = []
    for k, (_, f) in enumerate(cols):
        mx, mean = peak("%s/%s" % (w, f % p))
        one.setdefault(k, mx)
        row.append("%.0f (mean %.0f) %3.0f%%" % (mx, mean, 100 * mx / one[k]))
    print("%5d" % p + "".join(" %26s" % r for r in row))
print("(per column: the busiest rank's peak, the mean over the ranks, and the peak against 1 rank)")
print("base (a 1 000-grain run on 1 rank): %.1f MB per rank" % base_mb)
for k, (name, f) in enumerate(cols):
    mx4 = peak("%s/%s" % (w, f % 4))[0]
    print("%s: above the base, 4 ranks %.0f MB against 1 rank %.0f MB: %.0f %%; %.0f bytes per grain on 1 rank"
          % (name, mx4 - base_mb, one[k] - base_mb, 100 * (mx4 - base_mb) / (one[k] - base_mb), (one[k] - base_mb) * 1048576 / n))
PYEOF
