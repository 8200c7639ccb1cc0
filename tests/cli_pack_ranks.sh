#!/usr/bin/env bash
# Packing does not depend on the number of ranks: a 2-layer variant of
# cases/specimens/pack_layers_ci.yaml on 1 and on 2 ranks writes the same specimen, bit for bit
# (the DEM is bitwise deterministic across rank counts, tests/mpi_determinism.cpp, the packing
# builds every engine from the ranks' shares, which the engine orders by key, and the porosity
# criterion that ends the frictionless layers sums in integers), and the same report numbers; both layers end by the
# porosity criterion at the same step. Also: a packing over a `placement: cells` cloud gives the
# same specimen on 1 and 2 ranks; radius expansion (cases/specimens/pack_expansion_ci.yaml) runs.
# Usage: cli_pack_ranks.sh FDEM_BINARY SOURCE_DIR
source "$2/tests/support/cli_common.sh" "$@"
CASE="$SRC/cases/specimens/pack_layers_ci.yaml"
SETS="--set packing.layers=2 --set packing.box.max=[0.05,0.05,0.03] --set packing.final_steps=500"
for n in 1 2; do
  $MPIRUN -n $n "$FDEM" run "$CASE" --out "$tmp/r$n" -q $SETS --set packing.save="$tmp/s$n.txt" >"$tmp/r$n.log" 2>&1 \
    || { cat "$tmp/r$n.log"; fail "packing on $n rank(s) failed"; }
done
cmp "$tmp/s1.txt" "$tmp/s2.txt" || fail "the specimens packed on 1 and 2 ranks differ"
$PY - "$tmp/r1/packing.json" "$tmp/r2/packing.json" <<'PYEOF' || fail "reports differ"
import json, sys
a, b = (json.load(open(p)) for p in sys.argv[1:3])
for k in ("particles", "contacts", "steps"):
    assert a[k] == b[k], (k, a[k], b[k])
for la, lb in zip(a["layers"], b["layers"]):
    assert la["ended_by"] == "porosity" and la["ended_by"] == lb["ended_by"], (la, lb)
    assert la["steps"] == lb["steps"] and la["bulk_porosity"] == lb["bulk_porosity"], (la, lb)
print("layers end by", [l["ended_by"] for l in a["layers"]], "at", [l["steps"] for l in a["layers"]], "steps on 1 and 2 ranks")
for k in ("porosity", "coordination", "k0"):
    assert abs(a["interior"][k] - b["interior"][k]) <= 1e-9 * max(1, abs(a["interior"][k])), (k, a["interior"][k], b["interior"][k])
print("1 vs 2 ranks: identical specimens;", a["particles"], "particles, porosity", a["interior"]["porosity"])
PYEOF
# A `placement: cells` cloud under a packed layer: the packing starts from the ranks' blocks of
# cells as shares (before 2026-12-05 it was handed each rank's block as if whole and stopped with
# "particle count changed in migration"); the specimen is the same on 1 and 2 ranks.
cat >"$tmp/cells.yaml" <<'EOF2'
name: pack_over_cells
domain: {min: [-0.005, -0.005, -0.005], max: [0.055, 0.055, 0.22]}
time: {safety: 0.3, steps: 1}
damping: 0.2
materials:
  - {name: sand, young: 5.0e6, density: 2650, kt_kn: 0.25, friction: 0.5}
  - {name: smooth, young: 5.0e6, density: 7850, friction: 0.0}
particles:
  - generate: {material: sand, box: {min: [0, 0, 0], max: [0.05, 0.05, 0.03]}, porosity: 0.85, seed: 3,
               placement: cells, size: {distribution: uniform, min: 0.003, max: 0.005}}
walls:
  - {name: bottom, type: plane, material: smooth, point: [0, 0, 0], normal: [0, 0, 1]}
  - {name: xmin, type: plane, material: smooth, point: [0, 0, 0], normal: [1, 0, 0]}
  - {name: xmax, type: plane, material: smooth, point: [0.05, 0, 0], normal: [-1, 0, 0]}
  - {name: ymin, type: plane, material: smooth, point: [0, 0, 0], normal: [0, 1, 0]}
  - {name: ymax, type: plane, material: smooth, point: [0, 0.05, 0], normal: [0, -1, 0]}
packing:
  material: sand
  box: {min: [0, 0, 0], max: [0.05, 0.05, 0.085]}
  layers: 1
  porosity: 0.37
  size: {distribution: uniform, min: 0.003, max: 0.005}
  seed: 70
  cloud_fraction: 0.25
  settle: {unbalanced: 0.05, max_steps: 20000, check_every: 200}
EOF2
for n in 1 2; do
  $MPIRUN -n $n "$FDEM" run "$tmp/cells.yaml" --out "$tmp/c$n" -q --set packing.save="$tmp/c$n.txt" >"$tmp/c$n.log" 2>&1 \
    || { cat "$tmp/c$n.log"; fail "packing over a cells cloud on $n rank(s) failed"; }
done
cmp "$tmp/c1.txt" "$tmp/c2.txt" || fail "the specimens packed over a cells cloud on 1 and 2 ranks differ"
[ "$(grep -vc '^#' "$tmp/c1.txt")" -gt 3000 ] || fail "packing over a cells cloud: too few grains in the specimen"
$MPIRUN -n 2 "$FDEM" run "$SRC/cases/specimens/pack_expansion_ci.yaml" --out "$tmp/exp" >"$tmp/exp.log" 2>&1 \
  || { cat "$tmp/exp.log"; fail "radius expansion failed"; }
grep "interior " "$tmp/exp.log"
$PY -c "import json;d=json.load(open('$tmp/exp/packing.json'));n=d['interior']['porosity'];assert 0.3<n<0.45,n" || fail "expansion porosity"
echo "ok"
