#!/usr/bin/env bash
# The direct shear calibration (thesis ch. 3.5; docs/cases/direct_shear.md) in reduced form:
# cases/lab/direct_shear_packed_ci.yaml (~2 800 grains of d 2.5-4 mm, 2 ranks) packed the thesis's
# way (one frictionless, shaken layer, struck off at 25 mm, friction restored) and sheared at the
# thesis's three normal stresses from that one specimen (--specimen). Checks:
#  - the specimen: packing.json's interior porosity in 0.34-0.42 and no grain lost in any run;
#  - the pair frictions the thesis states (run.json's pair table): sand-rough (floor and top
#    plate) 1.0 = 45 deg from `interactions`, sand-smooth (the box's sides) 0, sand-sand 0.6745;
#    the floor's and the plate's mobilised |F_x|/F_z never above that 1.0 (walls.csv);
#  - the servo: sigma_n within 5 % of its target at every lab.csv row while shearing and its
#    mean within 3 % (it runs ~2.5 % high at 13.6 kPa: the plate rises with the dilating specimen and the
#    servo lags a little at this CI shear rate; the full-size case at half the rate: docs/cases/direct_shear.md);
#  - the peak: tau peaks between 1.0 and 4.5 mm of shear displacement (the thesis's curves end at
#    4.5 mm), peaks rise with sigma_n while the peak ratio tau/sigma_n falls (dilatancy is
#    suppressed by stress), the specimen dilates and softens after the peak (the mean tau of the
#    last tenth below 85 % of the peak: a dense, frictionlessly packed sand);
#  - direct_shear_report.py reproduces the peaks and writes its tables and figures.
# ~1.5 min on an idle 2-core machine.
# Usage: cli_lab_direct_shear.sh FDEM_BINARY SOURCE_DIR
set -u
FDEM=$1; SRC=$2
MPIRUN="bash $SRC/scripts/mpirun.sh"
PY=/usr/bin/python3
CASE="$SRC/cases/lab/direct_shear_packed_ci.yaml"
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }
t0=$(date +%s)
spec=()
for s in 13600 27300 40900; do
  $MPIRUN -n 2 "$FDEM" run "$CASE" --out "$tmp/ds_$s" -q "${spec[@]}" \
    --set walls.9.motion.0.servo.stress=$s --set walls.9.motion.1.servo.stress=$s >"$tmp/ds_$s.log" 2>&1 \
    || { cat "$tmp/ds_$s.log"; fail "direct shear at $s Pa"; }
  spec=(--specimen "$tmp/ds_13600/specimen.h5")
done
echo "packing + direct shear at 3 normal stresses on 2 ranks: $(( $(date +%s) - t0 )) s"
$PY - "$tmp" <<'PYEOF' || fail "direct shear checks"
import sys, csv, json
d = sys.argv[1]
pk = json.load(open("%s/ds_13600/packing.json" % d))
n0, grains = pk["interior"]["porosity"], pk["particles"]
print("specimen: %d grains, interior porosity %.4f" % (grains, n0))
assert 0.34 <= n0 <= 0.42, "interior porosity %.4f outside 0.34..0.42" % n0
peaks = []
for s0 in (13600, 27300, 40900):
    run = "%s/ds_%d" % (d, s0)
    pairs = {tuple(sorted(p["materials"])): p for p in json.load(open(run + "/run.json"))["pairs"]}
    assert abs(pairs[("rough", "sand")]["friction"] - 1.0) < 1e-12, pairs[("rough", "sand")]
    assert pairs[("rough", "sand")]["friction_from"] == "interactions"
    assert pairs[("sand", "smooth")]["friction"] == 0 and abs(pairs[("sand", "sand")]["friction"] - 0.6745) < 1e-12
    hist = list(csv.DictReader(open(run + "/history.csv")))
    assert all(int(float(h["particles"])) == grains for h in hist), "grains lost at %d Pa" % s0
    walls = list(csv.DictReader(open(run + "/walls.csv")))
    for w in ("floor", "top"):
        mob = max(abs(float(r[w + "_fx"])) / abs(float(r[w + "_fz"])) for r in walls if abs(float(r[w + "_fz"])) > 0)
        assert mob <= 1.0 + 1e-9, "%s mobilises |Fx|/Fz %.3f > its friction 1.0" % (w, mob)
    rows = list(csv.DictReader(open(run + "/lab.csv")))
    sh = [r for r in rows if float(r["shear_displacement"]) > 1e-9]  # (before shearing: round-off, ~1e-19 m)
    assert len(sh) > 20, "no shearing rows"
    worst = max(abs(float(r["sigma_n"]) / s0 - 1) for r in sh)
    sn = sum(float(r["sigma_n"]) for r in sh) / len(sh)
    u = [1e3 * float(r["shear_displacement"]) for r in sh]
    tau = [float(r["tau"]) for r in sh]
    dil = [float(r["normal_displacement"]) - float(sh[0]["normal_displacement"]) for r in sh]
    k = max(range(len(tau)), key=lambda i: tau[i])
    tail = tau[-max(1, len(tau) // 10):]
    res = sum(tail) / len(tail)
    print("sigma_n %5.1f kPa: rows within %.3f, mean %+.3f; peak tau %.2f kPa (tau/sigma_n %.3f) at %.2f mm; "
          "residual %.2f kPa (%.2f of the peak); dilation %.2f mm" % (s0 / 1e3, worst, sn / s0 - 1, tau[k] / 1e3,
          tau[k] / sn, u[k], res / 1e3, res / tau[k], 1e3 * max(dil)))
    assert worst < 0.05, "sigma_n off by %.3f at a row (%d Pa)" % (worst, s0)
    assert abs(sn / s0 - 1) < 0.03, "mean sigma_n off by %.3f (%d Pa)" % (sn / s0 - 1, s0)
    assert 1.0 <= u[k] <= 4.5, "peak at %.2f mm, expected 1.0 .. 4.5 mm" % u[k]
    assert res < 0.85 * tau[k], "no softening after the peak (%.2f of it)" % (res / tau[k])
    assert max(dil) > 0, "the specimen does not dilate"
    peaks.append((sn, tau[k]))
assert peaks[0][1] < peaks[1][1] < peaks[2][1], "peaks do not rise with sigma_n"
r = [t / s for s, t in peaks]
assert r[0] > r[1] > r[2], "the peak ratio tau/sigma_n does not fall with sigma_n: %s" % r
PYEOF
$PY "$SRC/scripts/direct_shear_report.py" "$tmp/ds_13600" "$tmp/ds_27300" "$tmp/ds_40900" --figures "$tmp/fig" \
  >"$tmp/report.log" 2>&1 || { cat "$tmp/report.log"; fail "direct_shear_report.py"; }
for f in direct_shear.csv fits.csv curves.png envelope.png; do
  [ -s "$tmp/fig/$f" ] || fail "the report wrote no $f"
done
grep -q "^target: peaks within 4.5 mm .* met" "$tmp/report.log" || { cat "$tmp/report.log"; fail "report: peak target"; }
# the runs from ds_13600's specimen (--specimen) carry its grains and porosity (via run.json "specimen")
$PY - "$tmp" <<'PYEOF' || fail "report: the specimen runs' porosity"
import sys, csv, json
d = sys.argv[1]
pk = json.load(open("%s/ds_13600/packing.json" % d))
rows = list(csv.DictReader(open("%s/fig/direct_shear.csv" % d)))
assert len(rows) == 3, rows
for r in rows:
    assert abs(float(r["porosity"]) - pk["interior"]["porosity"]) < 1e-9 and int(float(r["grains"])) == pk["particles"], r
PYEOF
echo "direct shear checks passed"
