#!/usr/bin/env bash
# The pullout validation slice, reduced (cases/geogrid_pullout/slice_ci.yaml: the slice's
# cross-section with a short grid; docs/cases/geogrid_pullout.md): packing with the grid inserted,
# consolidation at 49 kPa and one 2.5 mm pull step on 2 ranks. Asserts that the slice's pieces
# work together: the grid's transverse ribs run on to the symmetry walls and bear there, their
# cut ends are held at u_y = 0 (the restraints' y reactions balance the soil's y force on the
# grid), the clamp force equals F_f + F_bt within 2 %, the pull is resisted (force > 0, growing
# from the consolidation hold), sigma_v is held within 5 % (by each of the top plate's two
# segments), no grain is lost, and run.json
# records the interface pair with the thesis's tan phi 0.95.
# Usage (ctest): cli_pullout_slice.sh FDEM_BINARY SOURCE_DIR
source "$2/tests/support/cli_common.sh" "$@"
CASE="$SRC/cases/geogrid_pullout/slice_ci.yaml"
$MPIRUN -n 2 "$FDEM" run "$CASE" --out "$tmp/a" >"$tmp/log_a" 2>&1 || { tail -30 "$tmp/log_a"; fail "slice run"; }
$PY "$SRC/scripts/pullout_report.py" "$tmp/a" >"$tmp/report_a" 2>&1 || { cat "$tmp/report_a"; fail "pullout_report.py"; }
$PY - "$tmp/a" "$SRC" <<'PYEOF' || { cat "$tmp/report_a"; fail "slice checks"; }
import csv, json, sys
d = sys.argv[1]
R = {int(r["hold"]): r for r in csv.DictReader(open(d + "/pullout.csv"))}
assert sorted(R) == [0, 1], sorted(R)
f = lambda r, k: float(r[k])
p = R[1]
ratio = (f(p, "F_f_N") + f(p, "F_bt_N")) / f(p, "clamp_force_N")
print("pull hold: u %.2f mm, clamp %.2f N, F_f %.2f N, F_bt %.2f N, (F_f + F_bt)/clamp %.4f, sigma_v %.2f kPa"
      % (f(p, "clamp_displacement_mm"), f(p, "clamp_force_N"), f(p, "F_f_N"), f(p, "F_bt_N"), ratio, f(p, "sigma_v_kPa")))
assert abs(f(p, "clamp_displacement_mm") - 2.5) < 1e-6, p["clamp_displacement_mm"]
assert abs(ratio - 1) < 0.02, ratio
assert f(p, "clamp_force_N") > 0 and f(p, "clamp_force_N") > abs(f(R[0], "clamp_force_N")), (p["clamp_force_N"], R[0]["clamp_force_N"])
assert f(p, "F_f_N") > 0 and f(p, "F_bt_N") > 0, (p["F_f_N"], p["F_bt_N"])
for h, r in R.items():
    assert abs(f(r, "sigma_v_kPa") / 49.0 - 1) < 0.05, (h, r["sigma_v_kPa"])
# the top plate is in two segments (walls top_1, top_2), each its own servo: each holds sigma_v
# within 5 % at every hold end, each on its own part of the surface
W = {int(r["step"]): r for r in csv.DictReader(open(d + "/walls.csv"))}
for h, r in R.items():
    w = W[int(r["step"])]
    for k in (1, 2):
        assert abs(float(w["top_%d_stress" % k]) / 49000.0 - 1) < 0.05, (h, k, w["top_%d_stress" % k])
    print("hold %d end: segments at z %+.3f / %+.3f mm, %.2f / %.2f kPa" % (h, 1e3 * float(w["top_1_uz"]),
          1e3 * float(w["top_2_uz"]), float(w["top_1_stress"]) / 1e3, float(w["top_2_stress"]) / 1e3))
# the symmetry restraints carry the grid's y loads: at the end of each hold the y reactions of the
# two side restraints balance the soil's y force on the grid (and the clamp's) -- the grid's y
# equilibrium -- and both sides are loaded
rows = list(csv.DictReader(open(d + "/reactions.csv")))
last = rows[-1]
ry = {c: float(last[c]) for c in last if c.endswith("_ry")}
assert "grid_ymin_ry" in ry and "grid_ymax_ry" in ry, sorted(last)
iface = {int(r["step"]): r for r in csv.DictReader(open(d + "/interface.csv"))}
fy = float(iface[int(last["step"])]["fy"])
resid = fy + sum(ry.values())
print("y at the last hold end: soil on grid %.4f N, reactions %s, sum %.2e N" % (fy, ry, resid))
assert ry["grid_ymin_ry"] != 0 and ry["grid_ymax_ry"] != 0, ry
assert abs(resid) <= 0.02 * f(p, "clamp_force_N"), resid
# pair table in run.json
j = json.load(open(d + "/run.json"))
pairs = {(q["materials"][0], q["materials"][1]): q for q in j["pairs"]}
q = pairs[("sand", "grid")]
assert abs(q["friction"] - 0.95) < 1e-12 and q["friction_from"] == "interactions" and q["touch"] == "grain-interface", q
# no grain lost
removed = [l for l in open(d + "/removed.csv") if l.strip() and not l.startswith("step")]
assert not removed, removed[:3]
n0 = json.load(open(d + "/packing.json"))["particles"]
assert all(int(r["particles"]) == n0 for r in csv.DictReader(open(d + "/history.csv"))), "particle count changed"
print("ok: %d grains" % n0)
# case.yaml is the case as run; structures.json the grid's layout as generated
sys.path.insert(0, sys.argv[2] + "/scripts")
from fdem_common import load_case
ran, case = load_case(d + "/case.yaml"), load_case(sys.argv[2] + "/cases/geogrid_pullout/slice_ci.yaml")
def contains(a, b, path="case"):
    """every key and value of b is in a (a may add defaults)"""
    if isinstance(b, dict):
        assert isinstance(a, dict), path
        for k, v in b.items():
            assert k in a, "%s.%s missing from case.yaml" % (path, k)
            contains(a[k], v, path + "." + k)
    elif isinstance(b, list):
        assert isinstance(a, list) and len(a) == len(b), path
        for i, (x, y) in enumerate(zip(a, b)):
            contains(x, y, "%s[%d]" % (path, i))
    else:
        assert a == b, "%s: %r in case.yaml, %r in the case file" % (path, a, b)
contains(ran, case)  # no --set given: the case file, plus its defaults
assert ran["damping"] == 0.2 and ran["time"]["dt"] == "auto" and ran["materials"][0]["poisson"] == 0.25, "defaults not filled in"
g = case["fem"]["meshes"][0]["geogrid"]
m = json.load(open(d + "/structures.json"))["meshes"]
assert len(m) == 1 and m[0]["name"] == "grid", m
gi = m[0]["geogrid"]
tx, ly = gi["transverse_x"], gi["longitudinal_y"]
assert len(tx) == g["transverse_ribs"] and len(ly) == g["longitudinal_ribs"], gi
assert abs(tx[0] - (g["origin"][0] + g["clamp_length"] + g["clamp_gap"])) < 1e-12, tx
assert all(abs((b - a) - gi["pitch_x"]) < 1e-12 for a, b in zip(tx, tx[1:])), tx
assert abs(gi["pitch_x"] - gi["aperture_x"] - g["rib_width"]) < 1e-12, gi
assert abs(ly[0] - (g["origin"][1] + g["side_overhang"])) < 1e-12 and abs(ly[1] - ly[0] - gi["pitch_y"]) < 1e-12, ly
assert abs(m[0]["max"][0] - m[0]["min"][0] - g["length"]) < 1e-12, m[0]
print("ok: case.yaml as run; structures.json: ribs at x", ", ".join("%.4f" % x for x in tx))
PYEOF
echo "PASS"
