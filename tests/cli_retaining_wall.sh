#!/usr/bin/env bash
# Displacement holds and force bands on walls (docs/case-format.md#holds, #force-bands) end to end:
# cases/lab/retaining_wall_ci.yaml, ~1 500 grains settled behind a wall that then moves away from
# them by 0.25, 0.5, 1 and 2 mm in held steps (the active earth pressure protocol of the thesis's
# shaft, ch. 3, in miniature).
#  - 2 ranks: five rows in holds.csv, each converged, the wall exactly at its target (within
#    1e-12 m); its horizontal force falls below the at-rest one at every moved hold (at rest ->
#    active), the last one at most 70 % of it, and from 0.5 mm on stays on the active plateau
#    (within 25 % of its mean: with ~1 500 grains each converged hold is one realization of the
#    slumped wedge, and the plateau is not monotone: 0.0563, 0.0634, 0.0536 N at 0.5, 1, 2 mm
#    with the (key, id) contact order, 0.0664, 0.0571, 0.0508 N with the id order); the force bands
#    (five depth bands covering the wall) add up to the wall's force (exact sums: 1e-12); the floor
#    carries the grains' weight (frictionless walls: 1 %).
#  - 1 rank: holds.csv and walls.csv byte for byte the 2-rank ones.
#  - a run cut while the wall moves in hold 3 and restarted from its checkpoint: holds.csv byte for
#    byte the uninterrupted one's (the move continues from where it was).
# Usage (ctest): cli_retaining_wall.sh FDEM_BINARY SOURCE_DIR
source "$2/tests/support/cli_common.sh" "$@"
CASE="$SRC/cases/lab/retaining_wall_ci.yaml"
$MPIRUN -n 2 "$FDEM" run "$CASE" --out "$tmp/a" >"$tmp/a.log" 2>&1 || { tail -30 "$tmp/a.log"; fail "2-rank run"; }
grep "^hold" "$tmp/a.log"
mass=$("$FDEM" check "$CASE" | sed -n 's/.*total mass \([0-9.e+-]*\) kg.*/\1/p')
[ -n "$mass" ] || fail "fdem check does not give the particles' total mass"
$PY - "$tmp/a" "$mass" <<'PYEOF' || fail "displacement holds / bands / equilibrium"
import csv, sys
d, mass = sys.argv[1], float(sys.argv[2])
h = list(csv.DictReader(open(d + "/holds.csv")))
assert [int(r["hold"]) for r in h] == [1, 2, 3, 4, 5], h
targets = [0, 0.00025, 0.0005, 0.001, 0.002]
walls = {int(float(r["step"])): r for r in csv.DictReader(open(d + "/walls.csv"))}
W = mass * 9.81
forces = []
for r, t in zip(h, targets):
    s, f, u = int(r["step"]), float(r["xmax_force"]), float(r["xmax_displacement"])
    assert r["converged"] == "1" and float(r["xmax_target"]) == t, r
    assert abs(u - t) <= 1e-12, (u, t)
    w = walls[s]
    assert abs(float(w["xmax_fx"]) - f) <= 1e-12 * f, (w["xmax_fx"], f)
    bands = [float(w["xmax_b%d_fx" % k]) for k in range(1, 6)]
    assert abs(sum(bands) - f) <= 1e-12 * f, (bands, f)
    floor = -float(w["floor_fz"])
    print("hold %s: step %d, wall at %.3f mm, force %.5f N (bands %s, sum %.5f N); floor %.4f N / weight %.4f N = %.5f"
          % (r["hold"], s, 1e3 * u, f, " ".join("%.4f" % b for b in bands), sum(bands), floor, W, floor / W))
    assert abs(floor / W - 1) < 0.01
    forces.append(f)
assert all(f < forces[0] for f in forces[1:]), forces
assert forces[-1] < 0.7 * forces[0], forces
plateau = forces[2:]
mean = sum(plateau) / len(plateau)
assert all(abs(f / mean - 1) < 0.25 for f in plateau), forces
PYEOF

$MPIRUN -n 1 "$FDEM" run "$CASE" --out "$tmp/b" -q >"$tmp/b.log" 2>&1 || { tail -30 "$tmp/b.log"; fail "1-rank run"; }
cmp "$tmp/a/holds.csv" "$tmp/b/holds.csv" || { cat "$tmp/b/holds.csv"; fail "holds.csv differs between 1 and 2 ranks"; }
cmp "$tmp/a/walls.csv" "$tmp/b/walls.csv" || fail "walls.csv differs between 1 and 2 ranks"

# cut while the wall moves in hold 3 (0.25 mm at 0.02 m/s: ~2 800 steps), restarted
cut=$($PY -c "import csv; h=list(csv.DictReader(open('$tmp/a/holds.csv'))); print(int(h[1]['step']) + 1000)")
$MPIRUN -n 2 "$FDEM" run "$CASE" --out "$tmp/c" -q --set time.steps=$cut \
  >"$tmp/c.log" 2>&1 || { tail -30 "$tmp/c.log"; fail "cut run"; }
[ "$(wc -l <"$tmp/c/holds.csv")" = 3 ] || fail "the cut run has not ended in hold 3"
$MPIRUN -n 2 "$FDEM" run "$CASE" --out "$tmp/c" -q --restart "$tmp/c/checkpoint.h5" >"$tmp/c2.log" 2>&1 ||
  { tail -30 "$tmp/c2.log"; fail "restart"; }
cmp "$tmp/a/holds.csv" "$tmp/c/holds.csv" || { cat "$tmp/c/holds.csv"; fail "the restarted run's holds.csv differs"; }
echo "displacement holds and force bands: passed"
