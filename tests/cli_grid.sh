#!/usr/bin/env bash
# The process grid (`decomposition.grid`, docs/case-format.md#decomposition): the settle demo
# (3 000 grains poured into a box under gravity, 3 000 steps: rebuilds, migration, rebalancing)
# on 2 ranks cut along x, along z and by `auto`, and on 3 ranks along y, ends with the same
# particles bit for bit (id, position, velocity, angular velocity, force), and run.json names the grid asked for; `auto` does not
# cut across gravity (the box is tallest along z, which the smallest cut area alone would cut).
# A grid whose product is not the rank count, or not a list of three counts, is refused with
# the file and line (exit 2); one with slabs thinner than the ghost layer is refused too (exit 2,
# naming the --set that gave it, printed once).
# Usage: cli_grid.sh FDEM_BINARY SOURCE_DIR
source "$2/tests/support/cli_common.sh" "$@"
CASE="$SRC/cases/demo/settle.yaml"
SETS="--set time.steps=3000 --set output.snapshot_every=3000"
run() {  # NAME RANKS GRID
  $MPIRUN -n "$2" "$FDEM" run "$CASE" --out "$tmp/$1" -q $SETS ${3:+--set decomposition.grid=$3} >"$tmp/$1.log" 2>&1 \
    || { cat "$tmp/$1.log"; fail "run $1 ($2 ranks, grid ${3:-auto}) failed"; }
}
run x2 2 "[2,1,1]"
run z2 2 "[1,1,2]"
run auto2 2
run y3 3 "[1,3,1]"
$PY - "$tmp" <<'PYEOF' || fail "the grids give different results"
import json, sys, h5py, numpy as np
t = sys.argv[1]
want = {"x2": [2, 1, 1], "z2": [1, 1, 2], "y3": [1, 3, 1]}
for name, g in want.items():
    got = json.load(open(f"{t}/{name}/run.json"))["decomposition"]["grid"]
    assert got == g, (name, got, g)
auto = json.load(open(f"{t}/auto2/run.json"))["decomposition"]["grid"]
assert auto[2] == 1 and auto[0] * auto[1] == 2, ("auto cuts across gravity", auto)
def load(name):
    with h5py.File(f"{t}/{name}/particles_00003000.h5", "r") as f:
        ids = f["id"][:]
        o = np.argsort(ids)
        return {k: f[k][:][o] for k in ("id", "position", "velocity", "angular_velocity", "force")}
ref = load("x2")
for name in ("z2", "auto2", "y3"):
    got = load(name)
    for k in ref:
        assert got[k].shape == ref[k].shape and np.array_equal(got[k], ref[k]), (name, k)
print(len(ref["id"]), "particles identical bit for bit on grids", list(want.values()), "and auto", auto)
PYEOF
# Refused: the product is not the rank count (the file and line of the key), not three counts,
# slabs thinner than the ghost layer.
cat >"$tmp/bad.yaml" <<EOF2
$(sed '/^name:/d' "$CASE")
name: bad_grid
decomposition:
  grid: [1, 1, 3]
EOF2
line=$(grep -n "grid: \[1, 1, 3\]" "$tmp/bad.yaml" | cut -d: -f1)
$MPIRUN -n 2 "$FDEM" run "$tmp/bad.yaml" --out "$tmp/bad" -q >"$tmp/bad.log" 2>&1; code=$?
[ $code -eq 2 ] || { cat "$tmp/bad.log"; fail "a grid of 3 on 2 ranks: exit $code, expected 2"; }
grep -q "bad.yaml:$line: error: decomposition.grid \[1, 1, 3\] has 3 subdomains but the run has 2 rank" "$tmp/bad.log" \
  || { cat "$tmp/bad.log"; fail "no file:line message for a grid of 3 on 2 ranks"; }
[ "$(grep -c 'error:' "$tmp/bad.log")" -eq 1 ] || { cat "$tmp/bad.log"; fail "the error is not printed once"; }
$MPIRUN -n 1 "$FDEM" check "$CASE" --set "decomposition.grid=[2,1]" >"$tmp/bad2.log" 2>&1; code=$?
[ $code -eq 2 ] && grep -q "decomposition.grid: expected 'auto' or \[px, py, pz\]" "$tmp/bad2.log" \
  || { cat "$tmp/bad2.log"; fail "a grid of two counts: exit $code"; }
$MPIRUN -n 2 "$FDEM" run "$CASE" --out "$tmp/thin" -q $SETS --set "decomposition.grid=[1,1,2]" \
  --set neighbor.skin=0.15 --set time.steps=1 >"$tmp/thin.log" 2>&1; code=$?
[ $code -eq 2 ] && [ "$(grep -c 'error:' "$tmp/thin.log")" -eq 1 ] \
  && grep -q "^--set decomposition.grid=\[1,1,2\]: error: .* 0.105 m wide along z, less than the ghost-layer width" "$tmp/thin.log" \
  || { cat "$tmp/thin.log"; fail "slabs thinner than the ghost layer: exit $code"; }
echo "grids: same results; bad grids refused"
