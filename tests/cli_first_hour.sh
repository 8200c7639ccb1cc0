#!/usr/bin/env bash
# A user's first hour (docs/quickstart.md), through the real command line:
#  - the quick start's two cases are the ones docs/quickstart.md prints, byte for byte;
#  - settle_box on 2 ranks stops by time.stop_unbalanced once the bed is at rest: the kinetic
#    energy per grain at the stop below time.stop_kinetic_ratio (1e-3) x m g d, computed here from
#    the first snapshot's masses and diameters; the container's five faces carry the grains' weight
#    (sum of their fz = -W within 1 %: static equilibrium, the side walls' friction included);
#    1 and 2 ranks give the same history.csv byte for byte;
#  - the thin cloud that asked for the guard (500 grains over a 0.1 m box): without the guard
#    (stop_kinetic_ratio 0) it stops at the first history row below the ratio with a contact, in
#    free fall (kinetic energy above the guard); with it, later, at rest;
#  - plate_box: each of the four holds converges with the plate's pressure within 1 % of its
#    target and the settlement growing with the load;
#  - `fdem check` of numbers that look like other units (density 2.65, friction 30, young 5000) and of
#    a wall outside the domain: exit 0, each warning printed once on 2 ranks;
#  - scripts/plot_run.py draws the settled box (a PNG, exit 0) and refuses a directory that is
#    not a run (exit 2); scripts/summary.py prints the plate's four holds, one line each.
# (Grains inside a box wall, behind a flipped plane: cases/bad/wall_*.yaml, cli_errors.)
# Usage: cli_first_hour.sh FDEM_BINARY SOURCE_DIR
source "$2/tests/support/cli_common.sh" "$@"
QS="$SRC/cases/quickstart"

# 1. The cases the quick start shows are the shipped ones.
$PY - "$SRC/docs/quickstart.md" "$QS/settle_box.yaml" "$QS/plate_box.yaml" <<'PYEOF' || fail "docs/quickstart.md and cases/quickstart differ"
import re, sys
doc = open(sys.argv[1]).read()
blocks = re.findall(r"```yaml\n(.*?)```", doc, re.S)
for path in sys.argv[2:]:
    text = open(path).read()
    name = path.rsplit("/", 1)[1]
    hit = [b for b in blocks if b.startswith("# Quick start") and b == text]
    assert hit, f"{name}: no ```yaml block of docs/quickstart.md is this file byte for byte"
PYEOF

# 2. Settling: stops at rest, not in free fall; the faces carry the weight; 1 vs 2 ranks.
$MPIRUN -n 2 "$FDEM" run "$QS/settle_box.yaml" --out "$tmp/s2" >"$tmp/s2.log" 2>&1 || { cat "$tmp/s2.log"; fail "settle_box (2 ranks)"; }
grep -q "kinetic energy .* m g d below 1.000e-03 at step" "$tmp/s2.log" || { cat "$tmp/s2.log"; fail "no stop message with the kinetic guard"; }
"$FDEM" run "$QS/settle_box.yaml" --out "$tmp/s1" -q >"$tmp/s1.log" 2>&1 || { cat "$tmp/s1.log"; fail "settle_box (1 rank)"; }
cmp -s "$tmp/s1/history.csv" "$tmp/s2/history.csv" || fail "history.csv differs between 1 and 2 ranks"
$PY - "$tmp/s2" <<'PYEOF' || fail "settling stop"
import csv, sys
from grains import weights
run = sys.argv[1]
mgd, W = weights(run, 2650)
last = list(csv.DictReader(open(f"{run}/history.csv")))[-1]
ke = float(last["kinetic_energy"]) / float(last["particles"])
assert float(last["unbalanced"]) < 0.01 and ke < 1e-3 * mgd, (last, ke / mgd)
walls = list(csv.DictReader(open(f"{run}/walls.csv")))[-1]
fz = sum(float(v) for k, v in walls.items() if k.endswith("_fz"))
faces = sorted(k[:-3] for k in walls if k.endswith("_fz"))
assert faces == ["box_xmax", "box_xmin", "box_ymax", "box_ymin", "box_zmin"], faces
assert abs(fz + W) < 0.01 * W, (fz, W)
print(f"settle_box: stops at step {last['step']} (kinetic {ke / mgd:.2e} m g d); faces {fz:.4f} N, weight {W:.4f} N")
PYEOF
# The cloud of the issue that asked for the guard: 500 grains, thinly spread over a wider box. Its
# unbalanced ratio drops below 0.01 at the first impacts, long before the bed forms.
sed -e 's/max: \[0.05, 0.05, 0.2\]/max: [0.1, 0.1, 0.2]/g' -e 's/max: \[0.047, 0.047, 0.19\]/max: [0.09, 0.09, 0.15]/' \
  -e 's/min: \[0.003, 0.003, 0.003\]/min: [0.01, 0.01, 0.01]/' -e 's/count: 1000/count: 500/' "$QS/settle_box.yaml" >"$tmp/cloud.yaml"
for k in guarded unguarded; do
  set_k=(); [ $k = unguarded ] && set_k=(--set time.stop_kinetic_ratio=0)
  $MPIRUN -n 2 "$FDEM" run "$tmp/cloud.yaml" --out "$tmp/c_$k" -q "${set_k[@]}" >"$tmp/c_$k.log" 2>&1 ||
    { cat "$tmp/c_$k.log"; fail "cloud ($k)"; }
done
$PY - "$tmp/c_guarded" "$tmp/c_unguarded" <<'PYEOF' || fail "the kinetic guard"
import csv, sys
from grains import weights
run, unguarded = sys.argv[1], sys.argv[2]
mgd, _ = weights(run, 2650)
hist = list(csv.DictReader(open(f"{run}/history.csv")))
last = hist[-1]
ke = float(last["kinetic_energy"]) / float(last["particles"])
assert float(last["unbalanced"]) < 0.01 and ke < 1e-3 * mgd, (last, ke / mgd)
# without the guard: the first row below the ratio with a contact, still falling
first = next(h for h in hist if float(h["unbalanced"]) < 0.01 and float(h["contacts"]) > 0)
stop0 = list(csv.DictReader(open(f"{unguarded}/history.csv")))[-1]
assert stop0["step"] == first["step"], (stop0["step"], first["step"])
assert int(stop0["step"]) < int(last["step"]), (stop0["step"], last["step"])
ke0 = float(stop0["kinetic_energy"]) / float(stop0["particles"])
assert ke0 > 1e-3 * mgd, ke0 / mgd
print(f"cloud: stops at step {last['step']} ({ke / mgd:.2e} m g d); without the guard at {stop0['step']} "
      f"({ke0 / mgd:.2e} m g d, {stop0['contacts']} contacts)")
PYEOF

# 3. The plate load test: four holds, each converged at its pressure, settlement growing.
$MPIRUN -n 2 "$FDEM" run "$QS/plate_box.yaml" --out "$tmp/p" -q >"$tmp/p.log" 2>&1 || { cat "$tmp/p.log"; fail "plate_box"; }
$PY - "$tmp/p/holds.csv" <<'PYEOF' || fail "plate_box holds"
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
assert [r["hold"] for r in rows] == ["1", "2", "3", "4"], rows
s = [float(r["plate_settlement"]) for r in rows]
for r in rows:
    assert r["converged"] == "1", r
    assert abs(float(r["plate_stress"]) / float(r["plate_target"]) - 1) < 0.01, r
assert all(b > a for a, b in zip(s, s[1:])), s
print("plate_box: settlement since hold 1 (mm):", [round((x - s[0]) * 1e3, 3) for x in s])
PYEOF

# 4. Numbers in other units, a wall off the domain: warnings, once each, exit 0.
sed -e 's/density: 2650, friction: 0.5/density: 2.65, friction: 30/' -e 's/young: 5.0e6, density: 7850/young: 5000, density: 7850/' \
  -e '/name: box, type: container/a\  - {name: shelf, type: box, material: steel, min: [0.1, 0, 0], max: [0.2, 0.05, 0.01]}' \
  "$QS/settle_box.yaml" >"$tmp/units.yaml"
$MPIRUN -n 2 "$FDEM" check "$tmp/units.yaml" >"$tmp/u.out" 2>"$tmp/u.err"; c=$?
[ $c -eq 0 ] || { cat "$tmp/u.err"; fail "check with unit warnings: exit $c"; }
for w in "density 2.65 kg/m^3 is lighter than any grain: g/cm^3?" "friction 30 is steeper than 63 deg: degrees?" \
         "young 5000 Pa is softer than a sponge: MPa?" "wall 'shelf' lies wholly outside the domain"; do
  n=$(grep -cF -- "$w" "$tmp/u.err")
  [ "$n" -eq 1 ] || { cat "$tmp/u.err"; fail "warning '$w' printed $n times, want once"; }
done
# the shipped quick start warns of nothing
"$FDEM" check "$QS/settle_box.yaml" >/dev/null 2>"$tmp/q.err" && [ ! -s "$tmp/q.err" ] || { cat "$tmp/q.err"; fail "settle_box warns"; }

# 5. A picture of any run.
$PY "$SRC/scripts/plot_run.py" "$tmp/s2" --out "$tmp/s2.png" >"$tmp/plot.log" 2>&1 || { cat "$tmp/plot.log"; fail "plot_run.py"; }
[ -s "$tmp/s2.png" ] || fail "plot_run.py wrote no PNG"
mkdir -p "$tmp/empty"
$PY "$SRC/scripts/plot_run.py" "$tmp/empty" >/dev/null 2>&1; c=$?
[ $c -eq 2 ] || fail "plot_run.py of a directory that is no run: exit $c, want 2"
# and a summary of any run in text: the plate's holds, one line each
$PY "$SRC/scripts/summary.py" "$tmp/p" >"$tmp/sum.txt" 2>&1 || { cat "$tmp/sum.txt"; fail "summary.py"; }
n=$(grep -c "^  hold [1-4] step .*, converged, .*plate .* Pa, settlement" "$tmp/sum.txt")
[ "$n" -eq 4 ] || { cat "$tmp/sum.txt"; fail "summary.py: $n hold lines, want 4"; }
echo "cli_first_hour: ok"
