#!/usr/bin/env bash
# Load holds on walls (docs/case-format.md#holds) end to end: cases/lab/plate_load_ci.yaml, a
# strip footing on ~1 500 grains loaded to 5, 10, 20 and 40 kPa in four held increments.
#  - 2 ranks: four rows in holds.csv, each converged, the footing's stress within the tolerance
#    (1 %) of its target, the settlement growing with the load; at every hold's end the floor
#    carries the footing's load plus the grains' weight (vertical equilibrium, frictionless side
#    walls: within 1 %).
#  - 1 rank: holds.csv byte for byte the 2-rank one (the holds end at the same steps: the checks
#    are rank-independent).
#  - a run cut inside hold 3 (time.steps) and restarted from its checkpoint: holds.csv byte for
#    byte the uninterrupted one's (the checkpoint carries the hold and its start).
#  - holds.stop: the run ends once the footing has moved 28.5 mm, in hold 3, with a last row
#    `converged 0` at a settlement >= 28.5 mm.
#  - a coupled run (cases/coupling/footing_on_plate_ci.yaml, a footing over a clamped FE plate):
#    holds converged at their targets; the floor and the clamps carry the footing plus the
#    weight (1 %); cut in hold 2 on 2 ranks, restarted on 1: the same holds.csv.
# Usage (ctest): cli_wall_holds.sh FDEM_BINARY SOURCE_DIR
source "$2/tests/support/cli_common.sh" "$@"
CASE="$SRC/cases/lab/plate_load_ci.yaml"
$MPIRUN -n 2 "$FDEM" run "$CASE" --out "$tmp/a" >"$tmp/a.log" 2>&1 || { tail -30 "$tmp/a.log"; fail "2-rank run"; }
grep "^hold" "$tmp/a.log"
mass=$("$FDEM" check "$CASE" | sed -n 's/.*total mass \([0-9.e+-]*\) kg.*/\1/p')
[ -n "$mass" ] || fail "fdem check does not give the particles' total mass"
$PY - "$tmp/a" "$mass" <<'PYEOF' || fail "holds / equilibrium"
import csv, sys
d, mass = sys.argv[1], float(sys.argv[2])
h = list(csv.DictReader(open(d + "/holds.csv")))
assert [int(r["hold"]) for r in h] == [1, 2, 3, 4], h
targets = [5000, 10000, 20000, 40000]
walls = {int(float(r["step"])): r for r in csv.DictReader(open(d + "/walls.csv"))}
W = mass * 9.81
prev = -1.0
for r, t in zip(h, targets):
    s, st, u = int(r["step"]), float(r["footing_stress"]), float(r["footing_settlement"])
    assert r["converged"] == "1" and float(r["footing_target"]) == t, r
    assert abs(st - t) / t < 0.01, (st, t)
    assert u > prev, (u, prev)
    prev = u
    w = walls[s]
    floor, footing = -float(w["floor_fz"]), float(w["footing_fz"])
    print("hold %s: step %d, footing %.1f Pa (target %d), settlement %.3f mm; floor %.4f N = footing %.4f N + "
          "weight %.4f N (ratio %.5f)" % (r["hold"], s, st, t, 1e3 * u, floor, footing, W, floor / (footing + W)))
    assert abs(floor / (footing + W) - 1) < 0.01
PYEOF

$MPIRUN -n 1 "$FDEM" run "$CASE" --out "$tmp/b" -q >"$tmp/b.log" 2>&1 || { tail -30 "$tmp/b.log"; fail "1-rank run"; }
cmp "$tmp/a/holds.csv" "$tmp/b/holds.csv" || { cat "$tmp/b/holds.csv"; fail "holds.csv differs between 1 and 2 ranks"; }

# cut inside hold 3 and restarted
cut=$($PY -c "import csv; h=list(csv.DictReader(open('$tmp/a/holds.csv'))); print(int(h[1]['step']) + 1000)")
$MPIRUN -n 2 "$FDEM" run "$CASE" --out "$tmp/c" -q --set time.steps=$cut >"$tmp/c.log" 2>&1 || { tail -30 "$tmp/c.log"; fail "cut run"; }
[ "$(wc -l <"$tmp/c/holds.csv")" = 3 ] || fail "the cut run has not ended in hold 3"
$MPIRUN -n 2 "$FDEM" run "$CASE" --out "$tmp/c" -q --restart "$tmp/c/checkpoint.h5" >"$tmp/c2.log" 2>&1 ||
  { tail -30 "$tmp/c2.log"; fail "restart"; }
cmp "$tmp/a/holds.csv" "$tmp/c/holds.csv" || { cat "$tmp/c/holds.csv"; fail "the restarted run's holds.csv differs"; }

# a stop on the footing's settlement
$MPIRUN -n 2 "$FDEM" run "$CASE" --out "$tmp/d" --set "holds.stop={wall: footing, displacement: 0.0285}" \
  >"$tmp/d.log" 2>&1 || { tail -30 "$tmp/d.log"; fail "stop run"; }
grep -q "holds.stop: 0.0285 m) in hold 3" "$tmp/d.log" || { cat "$tmp/d.log"; fail "no stop in hold 3"; }
$PY - "$tmp/d/holds.csv" <<'PYEOF' || fail "the stop's row"
import csv, sys
h = list(csv.DictReader(open(sys.argv[1])))
assert len(h) == 3 and h[-1]["hold"] == "3" and h[-1]["converged"] == "0", h
assert float(h[-1]["footing_settlement"]) >= 0.0285, h[-1]
PYEOF

# A coupled run (cases/coupling/footing_on_plate_ci.yaml): a footing on soil over a clamped plate
# (FE), holds at 1, 2 and 4 kPa on 2 ranks. Each converged, the footing at its target; at each
# hold's end the floor and the plate's clamps together carry the footing's load plus the grains'
# weight. A run cut 1 000 steps into hold 2 and restarted on 1 rank ends with the same holds.csv.
COUPLED="$SRC/cases/coupling/footing_on_plate_ci.yaml"
$MPIRUN -n 2 "$FDEM" run "$COUPLED" --out "$tmp/e" >"$tmp/e.log" 2>&1 || { tail -30 "$tmp/e.log"; fail "coupled run"; }
grep "^hold .* at step" "$tmp/e.log"
$PY - "$tmp/e" <<'PYEOF' || fail "coupled holds / equilibrium"
import csv, math, sys
d = sys.argv[1]
def by_step(f):
    return {int(float(r["step"])): r for r in csv.DictReader(open(d + "/" + f))}
walls, reac = by_step("walls.csv"), by_step("reactions.csv")
W = 0.0
for line in open(d + "/specimen.txt"):
    if not line.startswith("#") and line.strip():
        r = float(line.split()[4])
        W += 2650 * 4 / 3 * math.pi * r ** 3 * 9.81
h = list(csv.DictReader(open(d + "/holds.csv")))
assert [r["hold"] for r in h] == ["1", "2", "3"], h
for r, t in zip(h, [1000, 2000, 4000]):
    s = int(r["step"])
    assert r["converged"] == "1" and abs(float(r["footing_stress"]) - t) / t < 0.01, r
    floor, footing = -float(walls[s]["bottom_fz"]), float(walls[s]["footing_fz"])
    clamps = float(reac[s]["plate_xmin_rz"]) + float(reac[s]["plate_xmax_rz"])
    ratio = (floor + clamps) / (footing + W)
    print("hold %s: footing %.1f Pa, settlement %.3f mm; floor %.4f N + clamps %.4f N = footing %.4f N + weight "
          "%.4f N (ratio %.5f)" % (r["hold"], float(r["footing_stress"]), 1e3 * float(r["footing_settlement"]), floor,
                                   clamps, footing, W, ratio))
    assert abs(ratio - 1) < 0.01
PYEOF
cut=$($PY -c "import csv; h=list(csv.DictReader(open('$tmp/e/holds.csv'))); print(int(h[0]['step']) + 1000)")
$MPIRUN -n 2 "$FDEM" run "$COUPLED" --out "$tmp/f" -q --set time.steps=$cut >"$tmp/f.log" 2>&1 || { tail -30 "$tmp/f.log"; fail "cut coupled run"; }
$MPIRUN -n 1 "$FDEM" run "$COUPLED" --out "$tmp/f" -q --restart "$tmp/f/checkpoint.h5" >"$tmp/f2.log" 2>&1 ||
  { tail -30 "$tmp/f2.log"; fail "coupled restart"; }
cmp "$tmp/e/holds.csv" "$tmp/f/holds.csv" || { cat "$tmp/f/holds.csv"; fail "the restarted coupled run's holds.csv differs"; }
echo "load holds on walls: passed"
