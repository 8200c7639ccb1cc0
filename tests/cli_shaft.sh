#!/usr/bin/env bash
# The shaft active earth pressure test in its CI form (thesis ch. 3; cases/shaft/ci.yaml, written
# by scripts/shaft_case.py ci; docs/cases/shaft.md): a coarse quarter model (L 0.25 m, H 0.30 m,
# ~3 000 grains d 12.5-25 mm rained in 3 layers around the shaft), the three 30-degree segments
# held (at rest), then moved 0.5 mm towards the axis in one held step.
#  - 2 ranks: two holds, converged, every segment exactly at its target (1e-12 m);
#  - the lateral pressure drops at every depth: the segments' inward force in each third of the
#    height (two 0.05 m bands) at 0.5 mm below its at-rest value, and in total below 60 %;
#  - equilibrium at both holds' ends: the walls' forces (floor, symmetry planes, outer walls and
#    the segments) add up to the grains' weight (vertical, 1 %) and to zero horizontally (1 % of it);
#  - the grains never enter the shaft (packing.exclude): no grain centre within a of the axis;
#  - the report (scripts/shaft_report.py) runs on it and writes its CSVs and figures; shaft.csv's
#    pressures per band give each third's p/p0 as the walls' forces do;
#  - the analytical solutions (scripts/shaft_theory.py --check): their limits (Rankine near the
#    surface, Coulomb for a plane wall, Prater's zero at h/a about 9);
#  - the contact network rebuilt from the snapshots (scripts/shaft_network.py) equals the run's own
#    /force_network: the same pairs, every normal force within K_N |v_rel| dt (the step between the
#    snapshot and the measurement) + 1e-6 of the largest;
#  - without the segments (an empty keep-out cylinder) grains roll into it while packing: the
#    packer warns once, naming the cylinder and the line; with them, no warning;
#  - 1 rank: holds.csv byte for byte the 2-rank one (packing and holds are rank-independent).
# Usage (ctest): cli_shaft.sh FDEM_BINARY SOURCE_DIR
source "$2/tests/support/cli_common.sh" "$@"
CASE="$SRC/cases/shaft/ci.yaml"
$PY "$SRC/scripts/shaft_case.py" ci | cmp - "$CASE" || fail "cases/shaft/ci.yaml is not what scripts/shaft_case.py ci writes"
$MPIRUN -n 2 "$FDEM" run "$CASE" --out "$tmp/a" "${ref_seed[@]}" >"$tmp/a.log" 2>&1 || { tail -30 "$tmp/a.log"; fail "2-rank run"; }
grep "^hold" "$tmp/a.log"
! grep -q "inside packing.exclude" "$tmp/a.log" || fail "grains inside the shaft at the end of packing"
$PY - "$tmp/a" <<'PYEOF' || fail "shaft holds / pressure / equilibrium"
import csv, math, sys
d = sys.argv[1]
h = list(csv.DictReader(open(d + "/holds.csv")))
assert [r["hold"] for r in h] == ["1", "2"], h
walls = {int(float(r["step"])): r for r in csv.DictReader(open(d + "/walls.csv"))}
W, inside = 0.0, 0
for line in open(d + "/specimen.txt"):
    if line.startswith("#") or not line.strip():
        continue
    _, x, y, z, r = map(float, line.split())
    W += 2650 * 4 / 3 * math.pi * r ** 3 * 9.81
    inside += math.hypot(x, y) < 0.075
assert inside == 0, "%d grain centres inside the shaft" % inside
names = ["bottom", "sym_x", "sym_y", "outer_x", "outer_y", "seg1", "seg2", "seg3"]
axes = {k: (-math.cos(math.radians(t)), -math.sin(math.radians(t)), 0.0) for k, t in ((1, 15), (2, 45), (3, 75))}
thirds = []
for r, t in zip(h, [0.0, 0.0005]):
    assert r["converged"] == "1", r
    for k in (1, 2, 3):
        assert abs(float(r["seg%d_displacement" % k]) - t) <= 1e-12, r
    w = walls[int(r["step"])]
    F = [sum(float(w[n + "_f" + c]) for n in names) for c in "xyz"]
    print("hold %s: walls' force sum (%.4f, %.4f, %.4f) N, grains' weight %.4f N: vertical ratio %.5f"
          % (r["hold"], F[0], F[1], F[2], W, -F[2] / W))
    assert abs(-F[2] / W - 1) < 0.01 and abs(F[0]) < 0.01 * W and abs(F[1]) < 0.01 * W
    band = lambda b: sum(sum(float(w["seg%d_b%d_f%s" % (k, b, c)]) * axes[k][i] for i, c in enumerate("xyz"))
                         for k in (1, 2, 3))
    thirds.append([band(1) + band(2), band(3) + band(4), band(5) + band(6)])
    print("  inward force on the shaft, bottom / middle / top third: %s N" % " / ".join("%.3f" % f for f in thirds[-1]))
for j in range(3):
    assert 0 < thirds[1][j] < thirds[0][j], thirds
assert sum(thirds[1]) < 0.6 * sum(thirds[0]), thirds
print("p / p0 (all depths): %.3f" % (sum(thirds[1]) / sum(thirds[0])))
# the case page's headline numbers (docs/cases/shaft.md): the at-rest force and p / p0 per third
import json
numbers = {"p_over_p0": sum(thirds[1]) / sum(thirds[0])}
for j, name in enumerate(("bottom", "middle", "top")):
    numbers["p0_%s_N" % name] = thirds[0][j]
    numbers["p_over_p0_%s" % name] = thirds[1][j] / thirds[0][j]
json.dump(numbers, open(d + "/numbers.json", "w"), indent=1)
PYEOF
reference_check shaft_ci "$tmp/a/numbers.json"
# the report (scripts/shaft_report.py) on the run: its tables, CSVs and figures
$PY "$SRC/scripts/shaft_report.py" "$tmp/a" --figures "$tmp/fig" >"$tmp/report.log" 2>&1 ||
  { cat "$tmp/report.log"; fail "scripts/shaft_report.py"; }
grep -q "the bands add up to the segments' force" "$tmp/report.log" || { cat "$tmp/report.log"; fail "report: no consistency line"; }
for f in "$tmp/a/shaft.csv" "$tmp/a/shaft_depths.csv" "$tmp/fig/pressure_ratio.png" "$tmp/fig/p0_depth.png"; do
  [ -s "$f" ] || fail "report: $f not written"
done
# shaft.csv's pressures per band are the segments' inward forces over their areas (the three
# segments alike, R dtheta h): each third's sum of p_mean h, hold 2 over hold 1, is the test's own
# p/p0 of that third from walls.csv (the CSV's 6 digits: 1e-4)
$PY - "$tmp/a" <<'PYEOF' || fail "report: shaft.csv against walls.csv"
import csv, json, sys
d = sys.argv[1]
num = json.load(open(d + "/numbers.json"))
rows = list(csv.DictReader(open(d + "/shaft.csv")))
holds = sorted({int(r["hold"]) for r in rows})
assert holds == [1, 2], holds
F = {(int(r["hold"]), int(r["band"])): float(r["p_mean"]) * float(r["h"]) for r in rows}
assert sorted({b for h, b in F}) == [1, 2, 3, 4, 5, 6], sorted(F)
for j, name in enumerate(("bottom", "middle", "top")):
    b = (2 * j + 1, 2 * j + 2)
    ratio = sum(F[(2, k)] for k in b) / sum(F[(1, k)] for k in b)
    print("shaft.csv: p/p0 of the %s third %.5f, from walls.csv %.5f" % (name, ratio, num["p_over_p0_" + name]))
    assert abs(ratio / num["p_over_p0_" + name] - 1) < 1e-4, (name, ratio, num["p_over_p0_" + name])
PYEOF
$PY "$SRC/scripts/shaft_theory.py" --check || fail "scripts/shaft_theory.py --check"
$PY "$SRC/scripts/shaft_network.py" "$tmp/a" --s-mm 0.5 --check-network 1e-6 --figure "$tmp/fig/network.png" ||
  fail "scripts/shaft_network.py: the rebuilt contact network"
[ -s "$tmp/fig/network.png" ] || fail "scripts/shaft_network.py: no figure"
# an empty keep-out cylinder (no segments): grains roll in; the packer says so, once, on rank 0
$PY - "$CASE" "$tmp/hole.yaml" <<'PYEOF' || fail "writing the case without segments"
import sys, yaml
c = yaml.safe_load(open(sys.argv[1]))
c["walls"] = [w for w in c["walls"] if not w["name"].startswith("seg")]
c["materials"] = [m for m in c["materials"] if m["name"] != "shaft"]
for k in ("holds", "measure", "time"):
    c.pop(k, None)
yaml.safe_dump(c, open(sys.argv[2], "w"), sort_keys=False)
PYEOF
$MPIRUN -n 2 "$FDEM" run "$tmp/hole.yaml" --out "$tmp/hole" -q >"$tmp/hole.log" 2>&1 || { tail -20 "$tmp/hole.log"; fail "packing without the segments"; }
[ "$(grep -c "grain centre(s) inside packing.exclude\[0\] (radius 0.075 m)" "$tmp/hole.log")" = 1 ] ||
  { cat "$tmp/hole.log"; fail "no (or more than one) warning about grains inside the empty keep-out cylinder"; }
$MPIRUN -n 1 "$FDEM" run "$CASE" --out "$tmp/b" -q "${ref_seed[@]}" >"$tmp/b.log" 2>&1 || { tail -30 "$tmp/b.log"; fail "1-rank run"; }
cmp "$tmp/a/holds.csv" "$tmp/b/holds.csv" || { cat "$tmp/a/holds.csv" "$tmp/b/holds.csv"; fail "holds.csv differs between 1 and 2 ranks"; }
echo "shaft (CI form): passed"
