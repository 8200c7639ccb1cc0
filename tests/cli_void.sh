#!/usr/bin/env bash
# Geogrid-reinforced fill over a void, CI size (cases/void/ci_n1.yaml, thesis ch. 6; 2 ranks):
#  * packing.structures: the formation joins from the start, the grid after layer 1 (grains
#    overlapping it removed then); packing.surcharge: ~5 kPa of dense grains on the struck-off fill;
#  * hold 1 (the grid released) ends in equilibrium: the interface carries the grains' weight;
#  * fem.remove in a coupled run: at hold 2 the void's elements go, the interface loses their
#    faces and gains the void's walls (2344 -> 2328 triangles), grains fall into the void and none
#    ever gets inside the remaining formation; the grid sags;
#  * the scripts/void_case.py output is the shipped case file;
#  * the removal and what follows are rank-independent: 1 and 3 ranks from the same specimen give
#    the same interface.csv and particles, bit for bit;
#  * scripts/void_report.py: its self-checks and figures, and hold 2's time history (particle and
#    FE snapshots) ending at the final state's surface and grid settlement.
# Usage (ctest): cli_void.sh FDEM_BINARY SOURCE_DIR
source "$2/tests/support/cli_common.sh" "$@"
CASE="$SRC/cases/void/ci_n1.yaml"
for v in ci slice full; do
  for n in n0 n1; do
    $PY "$SRC/scripts/void_case.py" $v $n | cmp -s - "$SRC/cases/void/${v}_$n.yaml" ||
      fail "cases/void/${v}_$n.yaml is not what scripts/void_case.py $v $n writes"
  done
done
$MPIRUN -n 2 "$FDEM" run "$CASE" --out "$tmp/o" "${ref_seed[@]}" >"$tmp/log" 2>&1 || { tail -30 "$tmp/log"; fail "run"; }
grep -q "structure 'formation' inserted (216 interface triangles" "$tmp/log" || { cat "$tmp/log"; fail "formation"; }
grep -q "hold 2: elements removed; interface triangles 2344 -> 2328" "$tmp/log" || { cat "$tmp/log"; fail "removal line"; }
$PY - "$tmp/o" "$tmp/log" <<'PYEOF' || fail "void CI run"
import sys, json, csv, re, glob
import numpy as np, h5py, yaml
d, log = sys.argv[1], open(sys.argv[2]).read()
j = json.load(open(d + "/packing.json"))
parts = j["structure"]["parts"]
assert [(p["mesh"], p["inserted_after_layer"], p["triangles"]) for p in parts] == \
    [("formation", 0, 216), ("grid", 1, 2128)], parts
m = re.search(r"structure 'grid' inserted \(2128 interface triangles as a rigid wall\); (\d+) grains", log)
assert m and int(m.group(1)) > 0, "the grid removed no grains when it joined"
case = yaml.safe_load(open(d + "/case.yaml"))
rho = {mm["name"]: mm["density"] for mm in case["materials"]}
names = [mm["name"] for mm in case["materials"]]
# the surcharge: ~5 kPa (rho_s chosen for 0.05 m at porosity 0.36), its grains on top of the soil
s = j["surcharge"]
assert abs(s["pressure"] - 5000) < 0.1 * 5000, s
A = 0.3 * 0.0592

def grains(step):
    with h5py.File("%s/particles_%08d.h5" % (d, step), "r") as f:
        return f["position"][()], f["radius"][()], f["material"][()], f["id"][()]

steps = sorted(int(p[-11:-3]) for p in glob.glob(d + "/particles_*.h5"))
x, r, mat, ids = grains(steps[0])
sur = mat == names.index("surcharge")
W_sur = float(np.sum(4 / 3 * np.pi * r[sur] ** 3) * rho["surcharge"] * 9.81)
assert abs(W_sur / A - s["pressure"]) < 1e-6 * s["pressure"], (W_sur / A, s["pressure"])
# (in the levelled surface's hollows, but not below them: no centre 1.5 largest diameters under the
# strike-off. The struck-off surface has pits: with the (key, id) contact order the lowest one is a
# 7 mm grain at 0.1852 m, 1.04 d_max down, resting on two soil grains centred at 0.177 and 0.1845 m)
assert sur.sum() == s["grains"] and x[sur, 2].min() > 0.2 - 1.5 * 0.0142, ("surcharge grains inside the soil", x[sur, 2].min())
W = float(sum(np.sum(4 / 3 * np.pi * r[mat == k] ** 3) * rho[n] * 9.81 for k, n in enumerate(names)))
# the interface rows: hold 1 ends in equilibrium with the interface carrying the weight (walls frictionless)
rows = list(csv.DictReader(open(d + "/interface.csv")))
end1 = [rw for rw in rows if int(float(rw["hold"])) == 0][-1]
fz = -float(end1["fz"])
print("grains %d, weight %.3f N (surcharge %.3f N = %.0f Pa); interface at the end of hold 1: %.3f N (%.2f %%)"
      % (len(r), W, W_sur, W_sur / A, fz, 100 * (fz / W - 1)))
assert abs(fz / W - 1) < 0.02, "hold 1: the interface does not carry the grains' weight"
# coupling.grain_resultant: the grains' resultant ratio |sum(f + m g)| / sum(m g) ended hold 1 below 0.01; the side
# walls are frictionless (their forces horizontal), so its vertical part is the interface's misfit to the weight
h1 = list(csv.DictReader(open(d + "/holds.csv")))[0]
gr = float(h1["grain_resultant"])
print("hold 1: grain_resultant %.3e, |interface / weight - 1| %.3e" % (gr, abs(fz / W - 1)))
assert int(h1["step"]) == int(float(end1["step"])) and h1["converged"] == "1", (h1, end1["step"])
assert gr < 0.01 and abs(fz / W - 1) <= gr * (1 + 1e-9) + 1e-12, (gr, fz / W - 1)
# the void x 0.1 .. 0.2, z -0.1 .. 0: no grain centre inside the remaining formation at any snapshot;
# grains in the void at the end
for st in steps:
    x, r, mat, ids = grains(st)
    solid = (x[:, 2] < 0) & ~((x[:, 0] > 0.1) & (x[:, 0] < 0.2) & (x[:, 2] > -0.1))
    assert not solid.any(), "step %d: %d grain centres inside the formation" % (st, solid.sum())
x, r, mat, ids = grains(steps[-1])
inside = (x[:, 2] < 0).sum()
print("grain centres in the void at the end (step %d): %d, the lowest at z %.4f m" % (steps[-1], inside, x[:, 2].min()))
assert inside > 20
# the grid over the void sags after the removal
def grid_down(step):
    with h5py.File("%s/fe_%08d.h5" % (d, step), "r") as f:
        X, U = f["nodes/coordinates"][()], f["nodes/displacement"][()]
    g = X[:, 2] > 0.05
    over = g & (X[:, 0] > 0.1) & (X[:, 0] < 0.2)
    return -U[over, 2].mean()
h1 = int(float(end1["step"]))
u1, u2 = grid_down(h1), grid_down(int(float(rows[-1]["step"])))
print("grid over the void: down %.3f mm at the end of hold 1, %.3f mm at the end" % (1e3 * u1, 1e3 * u2))
assert u2 > 2 * u1 and u2 - u1 > 5e-5, "the grid did not sag over the void"
PYEOF

# Rank independence across the removal: from the same specimen, holds cut short (hold 1 ends 2000
# steps after the release, hold 2 runs 2000 steps), on 1 and 3 ranks.
sets=(--specimen "$tmp/o/specimen.h5" --set fem.max_steps=2000 --set output.snapshot_every=1000)
"$FDEM" run "$CASE" --out "$tmp/r1" "${sets[@]}" >"$tmp/l1" 2>&1 || { tail -20 "$tmp/l1"; fail "1 rank"; }
$MPIRUN -n 3 --oversubscribe "$FDEM" run "$CASE" --out "$tmp/r3" "${sets[@]}" >"$tmp/l3" 2>&1 ||
  { tail -20 "$tmp/l3"; fail "3 ranks"; }
grep -q "interface triangles 2344 -> 2328" "$tmp/l1" || fail "1 rank: no removal"
cmp "$tmp/r1/interface.csv" "$tmp/r3/interface.csv" || fail "interface.csv differs between 1 and 3 ranks"
cmp "$tmp/r1/history.csv" "$tmp/r3/history.csv" || fail "history.csv differs between 1 and 3 ranks"
$PY - "$tmp/r1" "$tmp/r3" <<'PYEOF' || fail "particles differ between 1 and 3 ranks"
import sys, glob, h5py, numpy as np
a, b = sys.argv[1:]
last = sorted(glob.glob(a + "/particles_*.h5"))[-1].split("/")[-1]
def load(p):
    with h5py.File(p, "r") as f:
        o = np.argsort(f["id"][()])
        return f["position"][()][o], f["velocity"][()][o]
xa, va = load(a + "/" + last)
xb, vb = load(b + "/" + last)
assert np.array_equal(xa, xb) and np.array_equal(va, vb), np.abs(xa - xb).max()
print("1 and 3 ranks: %s identical (%d grains)" % (last, len(xa)))
PYEOF
# scripts/void_report.py on the full run (every section, its self-checks, the figures) and on the
# 1-rank run, whose particle and FE snapshots inside hold 2 give section 7's time history: its last
# row is the final state, so its surface and grid settlement are sections 4's and 6's.
$PY "$SRC/scripts/void_report.py" "$tmp/o" --check --csv "$tmp/o.csv" --figures "$tmp/fig" >"$tmp/rep_o" 2>&1 ||
  { cat "$tmp/rep_o"; fail "void_report.py --check on the run"; }
for f in porosity displacement stress roses grid; do
  [ -s "$tmp/fig/void_$f.png" ] || fail "void_report.py wrote no void_$f.png"
done
# the case page's headline numbers (docs/cases/void.md, the CI variant's table) against the reference
$PY "$SRC/tests/support/reference.py" pick "$tmp/o.csv" "$tmp/numbers.json" rest_minus_fz_over_weight \
  hold2_steps=final_steps surface_max_settlement_mm void_grains por_max_above_rel_pct fabric_horizontal_final \
  fabric_vertical_final grid_max_settlement_since_rest_mm grid_T_void_kN_m grid_T_max_kN_m || fail "the void's numbers"
reference_check void_ci_n1 "$tmp/numbers.json"
$PY "$SRC/scripts/void_report.py" "$tmp/r1" --check --csv "$tmp/r1.csv" --figures "$tmp/fig1" >"$tmp/rep_r1" 2>&1 ||
  { cat "$tmp/rep_r1"; fail "void_report.py --check on the 1-rank run"; }
[ -s "$tmp/fig1/void_history.png" ] || fail "void_report.py wrote no void_history.png"
$PY - "$tmp/r1.csv" "$tmp/r1/interface.csv" <<'PYEOF' || { cat "$tmp/rep_r1"; fail "void_report.py: hold 2's time history"; }
import csv, sys
r = list(csv.DictReader(open(sys.argv[1])))[0]
ic = list(csv.DictReader(open(sys.argv[2])))
f = lambda k: float(r[k])
rest = [q for q in ic if int(float(q["hold"])) == 0][-1]
assert int(r["history_snapshots"]) >= 2 and int(r["history_last_step"]) == int(float(ic[-1]["step"])), r
t = float(ic[-1]["time"]) - float(rest["time"])   # (the CSV's 6 digits)
assert t > 0 and abs(f("history_last_t_s") / t - 1) < 1e-5, (r["history_last_t_s"], t)
for a, b in (("history_last_surface_mm", "surface_max_settlement_mm"),
             ("history_last_grid_sag_mm", "grid_max_settlement_since_rest_mm"),
             ("history_last_grid_T_void_kN_m", "grid_T_void_kN_m")):
    assert abs(f(a) - f(b)) <= 1e-6 * max(1.0, abs(f(b))), (a, f(a), b, f(b))
assert f("history_last_grid_sag_mm") > 0, r["history_last_grid_sag_mm"]
print("void_report: %s snapshots in hold 2; at the end (t %.4f s after the removal) grid %.4f mm, surface %.4f mm"
      % (r["history_snapshots"], f("history_last_t_s"), f("history_last_grid_sag_mm"), f("history_last_surface_mm")))
PYEOF
echo "cli_void: ok"
