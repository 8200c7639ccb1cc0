#!/usr/bin/env bash
# Coupled FE-DE cases through the command line (particles + fem + coupling):
# cases/coupling/sphere_on_plate.yaml on 1 and 2 ranks -- the final interface force equals the
# sphere's weight (1e-6), 1 and 2 ranks agree (1e-6) on it and on the plate's largest
# displacement, particle and FE XDMF files share one output directory, run.json has the
# coupling record; measurements (measure.csv, roses.csv) with the interface contact in the
# Love-Weber stress; SIGTERM writes the checkpoint (DEM + FE state) and exits 143; `fdem check` of the coupled
# cases; bad coupled input exits 2 with file, line and message; restarts continue the run; a
# dense bed on a coarse plate settles with the automatic sub-cycle (many contacts on one node).
# Usage: cli_coupled.sh FDEM_BINARY SOURCE_DIR
source "$2/tests/support/cli_common.sh" "$@"
CASE="$SRC/cases/coupling/sphere_on_plate.yaml"
$MPIRUN -n 1 "$FDEM" run "$CASE" --out "$tmp/np1" -q >"$tmp/np1.log" 2>&1 || { cat "$tmp/np1.log"; fail "1-rank run"; }
$MPIRUN -n 2 "$FDEM" run "$CASE" --out "$tmp/np2" >"$tmp/np2.log" 2>&1 || { cat "$tmp/np2.log"; fail "2-rank run"; }
grep -q "dt clamped to the FE stable step" "$tmp/np2.log" || { cat "$tmp/np2.log"; fail "start-up lines do not say the DEM step was clamped"; }
$PY - "$tmp/np1" "$tmp/np2" <<'PYEOF' || fail "results"
import sys, csv, json, math
def last(d):
    rows = list(csv.DictReader(open(d + "/interface.csv")))
    return float(rows[-1]["fz"]), float(rows[-1]["max_fe_displacement"]), int(rows[-1]["step"])
m = 2650 * 4 / 3 * math.pi * 0.01**3
W = m * 9.81
(f1, u1, s1), (f2, u2, s2) = last(sys.argv[1]), last(sys.argv[2])
print("final interface Fz: 1 rank %.10g N, 2 ranks %.10g N; weight m g %.10g N" % (f1, f2, W))
print("  |Fz| vs m g: %.2e (1 rank), %.2e (2 ranks); 1 vs 2 ranks: Fz %.2e, max plate displacement %.2e (%.6e m)"
      % (abs(-f1 - W) / W, abs(-f2 - W) / W, abs(f1 - f2) / W, abs(u1 - u2) / u1, u2))
assert s1 == s2 == 3000
assert abs(-f1 - W) < 1e-9 * W and abs(-f2 - W) < 1e-9 * W, "interface force is not the sphere's weight"
assert abs(f1 - f2) < 1e-9 * W, "1 and 2 ranks differ in the interface force"
assert u1 > 0 and abs(u1 - u2) < 1e-9 * u1, "1 and 2 ranks differ in the plate displacement"
info = json.load(open(sys.argv[2] + "/run.json"))
assert info["status"] == "finished"
c = info["coupling"]
assert c["subcycle"] == 1 and c["dt_dem_clamped"] == 1 and abs(c["dt_fe"] - c["dt_dem"]) < 1e-15
for k in ("coupling_contacts", "coupling_reduce", "coupling_fe", "coupling_scatter", "fe_update"):
    assert k in info["timings"], k
PYEOF
for f in particles.xdmf fe.xdmf history.csv interface.csv reactions.csv checkpoint.h5; do
  [ -s "$tmp/np2/$f" ] || fail "output $f missing"
done
h5ls "$tmp/np2/checkpoint.h5/fe" >/dev/null 2>&1 || fail "checkpoint.h5 has no FE state (group /fe)"
n=$(grep -c 'fe_[0-9]*\.h5:/nodes/coordinates' "$tmp/np2/fe.xdmf")
m=$(grep -c 'particles_[0-9]*\.h5' "$tmp/np2/particles.xdmf")
[ "$n" -eq 4 ] || fail "fe.xdmf lists $n snapshots, expected 4 (steps 0, 1000, 2000, 3000)"
[ "$m" -ge 4 ] || fail "particles.xdmf lists $m references, expected snapshots at the same 4 steps"
# Measurements in a coupled run (the case's `measure` section): a box around the sphere; the
# interface contact counts like a wall contact, so at rest the Love-Weber sigma_zz of the box is
# the sphere's lever times its weight over the box volume, (r - delta/2) m g / V, and the
# porosity is exact, 1 - (4/3 pi r^3) / V.
cp "$CASE" "$tmp/meas.yaml"
cat >>"$tmp/meas.yaml" <<'YEOF'
measure:
  every: 1000
  boxes: [{name: sphere, min: [0.08, 0.08, 0.005], max: [0.12, 0.12, 0.035]}]
  roses: [{plane: xz, bins: 12}]
YEOF
$MPIRUN -n 2 "$FDEM" run "$tmp/meas.yaml" --out "$tmp/meas" -q >"$tmp/meas.log" 2>&1 || { cat "$tmp/meas.log"; fail "coupled run with measure"; }
$PY - "$tmp/meas" <<'PYEOF' || fail "coupled measurements"
import sys, csv, math
rows = list(csv.DictReader(open(sys.argv[1] + "/measure.csv")))
assert [int(r["step"]) for r in rows] == [0, 1000, 2000, 3000], [r["step"] for r in rows]
r = rows[-1]
m = 2650 * 4 / 3 * math.pi * 0.01**3
V = 0.04 * 0.04 * 0.03
szz = float(r["szz"]); expect = 0.01 * m * 9.81 / V
phi = 1 - 4 / 3 * math.pi * 0.01**3 / V
print("coupled measure: box around the sphere: szz %.6g Pa (r m g / V = %.6g Pa, %.1e), sxx %.2g Pa, porosity %.12f "
      "(exact %.12f), particles %s" % (szz, expect, szz / expect - 1, float(r["sxx"]), float(r["porosity"]), phi, r["particles"]))
assert abs(szz / expect - 1) < 1e-3, "szz"
assert abs(float(r["sxx"])) < 1e-6 * expect and abs(float(r["syy"])) < 1e-6 * expect
assert abs(float(r["porosity"]) - phi) < 1e-12
assert float(r["particles"]) == 1 and float(r["Z"]) == 0
assert float(rows[0]["szz"]) == 0.0  # step 0: the sphere does not touch the plate yet
roses = list(csv.DictReader(open(sys.argv[1] + "/roses.csv")))
assert len(roses) == 4 * 12 and sum(float(x["count"]) for x in roses) == 0  # no particle pair
PYEOF
# SIGTERM: both checkpoints, run.json says interrupted; exit 128 + 15 (checked on a singleton
# run: mpirun reports its own code for a signalled job).
# Two named surfaces (the top face, then the rest of the plate's surface: faces are not counted
# twice): per-surface columns in interface.csv; the top carries the sphere, the rest nothing.
$MPIRUN -n 2 "$FDEM" run "$CASE" --out "$tmp/grp" -q \
  --set 'coupling.surfaces=[{mesh: plate, face_set: zmax, name: top}, {mesh: plate, name: rest}]' >/dev/null 2>&1 \
  || fail "run with two surfaces"
$PY - "$tmp/grp" <<'PYEOF' || fail "per-surface interface forces"
import sys, csv, math
r = list(csv.DictReader(open(sys.argv[1] + "/interface.csv")))[-1]
W = 2650 * 4 / 3 * math.pi * 0.01**3 * 9.81
assert abs(-float(r["top_fz"]) - W) < 1e-9 * W and float(r["rest_fz"]) == 0.0, r
assert abs(float(r["top_fz"]) + float(r["rest_fz"]) - float(r["fz"])) < 1e-12 * W
print("surfaces: top %.10g N, rest %g N, total %.10g N" % (float(r["top_fz"]), float(r["rest_fz"]), float(r["fz"])))
PYEOF
# Rigid, then released; two holds, each ended by the combined DEM + FE convergence check.
$MPIRUN -n 2 "$FDEM" run "$CASE" --out "$tmp/holds" --set coupling.rigid_steps=500 --set 'fem.load_steps=[1,2]' \
  --set coupling.tolerance=1e-4 >"$tmp/holds.log" 2>&1 || { cat "$tmp/holds.log"; fail "holds run"; }
grep -q "step 500: structure released" "$tmp/holds.log" || { cat "$tmp/holds.log"; fail "no release line at step 500"; }
$PY - "$tmp/holds" "$tmp/holds.log" <<'PYEOF' || fail "rigid then release / combined convergence"
import sys, csv, math, re
rows = list(csv.DictReader(open(sys.argv[1] + "/interface.csv")))
W = 2650 * 4 / 3 * math.pi * 0.01**3 * 9.81
assert all(float(r["max_fe_displacement"]) == 0.0 for r in rows if int(r["step"]) <= 500), "plate moved while rigid"
assert float(rows[-1]["max_fe_displacement"]) > 1e-7, "plate did not deflect after the release"
assert max(int(r["hold"]) for r in rows) == 1, "expected two holds (0 and 1)"
last = int(rows[-1]["step"])
assert last < 3000, "holds did not end by convergence before time.steps (%d)" % last
assert abs(-float(rows[-1]["fz"]) - W) < 1e-4 * W
# the hold lines (not the progress lines, printed mid-hold when the machine is slow)
ends = list(re.finditer(r"(?m)^hold [0-9]+/[0-9]+: .*unbalanced DEM ([0-9.e+-]+) FE ([0-9.e+-]+)", open(sys.argv[2]).read()))
assert len(ends) == 2, "expected two hold lines, got %d" % len(ends)
for m in ends:
    assert float(m.group(1)) < 1e-4 and float(m.group(2)) < 1e-4, m.group(0)
print("rigid to step 500, released; 2 holds converged by step %d; Fz = m g to %.1e" % (last, abs(-float(rows[-1]["fz"]) / W - 1)))
PYEOF
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
"$FDEM" run "$CASE" --out "$tmp/sig" -q --set time.steps=100000000 >"$tmp/sig.log" 2>&1 &
pid=$!
for i in $(seq 1 300); do grep -q . "$tmp/sig/run.json" 2>/dev/null && break; sleep 0.1; done
sleep 1
kill -TERM $pid; wait $pid; code=$?
[ $code -eq 143 ] || { cat "$tmp/sig.log"; fail "coupled run stopped by SIGTERM exited with $code, expected 143"; }
[ -f "$tmp/sig/checkpoint.h5" ] && h5ls "$tmp/sig/checkpoint.h5/fe" >/dev/null 2>&1 || fail "no DEM + FE checkpoint after SIGTERM"
grep -q '"status": "interrupted"' "$tmp/sig/run.json" || fail "run.json does not say interrupted"
# Restarts: from the SIGTERM checkpoint (exit 0); 700 steps on 2 ranks, then restarted on 1 rank
# to 3000 steps, against the uninterrupted 1-rank run; checkpoint.h5 alone (FE state in /fe) restarts.
$MPIRUN -n 1 "$FDEM" run "$CASE" --out "$tmp/sig" -q --restart "$tmp/sig/checkpoint.h5" \
  --set time.steps=$(( $(sed -n 's/.*"steps": \([0-9]*\).*/\1/p' "$tmp/sig/run.json" | head -1) + 200 )) \
  >"$tmp/e" 2>&1 || { cat "$tmp/e"; fail "restart from the SIGTERM checkpoint"; }
$MPIRUN -n 2 "$FDEM" run "$CASE" --out "$tmp/re" -q --set time.steps=700 >/dev/null 2>&1 || fail "700-step run"
mkdir "$tmp/ck700" && cp "$tmp/re/checkpoint.h5" "$tmp/ck700/"
$MPIRUN -n 1 "$FDEM" run "$CASE" --out "$tmp/re" -q --restart "$tmp/re/checkpoint.h5" >"$tmp/e" 2>&1 \
  || { cat "$tmp/e"; fail "restart at step 700"; }
$PY - "$tmp/np1" "$tmp/re" <<'PYEOF' || fail "restarted coupled run"
import sys, csv
def rows(d):
    return {int(r["step"]): r for r in csv.DictReader(open(d + "/interface.csv"))}
a, b = rows(sys.argv[1]), rows(sys.argv[2])
assert sorted(a) == sorted(b), "restarted interface.csv has other steps than the uninterrupted one"
# reactions.csv: the same steps, none twice (rows written after the checkpoint are dropped)
ra = [int(float(r["step"])) for r in csv.DictReader(open(sys.argv[1] + "/reactions.csv"))]
rb = [int(float(r["step"])) for r in csv.DictReader(open(sys.argv[2] + "/reactions.csv"))]
assert rb == ra, "restarted reactions.csv: steps %s... vs %s..." % (rb[:12], ra[:12])
for k in (1000, 3000):
    fa, fb = float(a[k]["fz"]), float(b[k]["fz"])
    ua, ub = float(a[k]["max_fe_displacement"]), float(b[k]["max_fe_displacement"])
    print("step %d: Fz %.10g vs %.10g (%.1e), max displacement %.10g vs %.10g (%.1e)"
          % (k, fa, fb, abs(fb / fa - 1), ua, ub, abs(ub / ua - 1)))
    tol = 1e-9
    assert abs(fb / fa - 1) < tol and abs(ub / ua - 1) < tol, k
PYEOF
# The FE time series continues across the restart: fe.xdmf lists the uninterrupted run's
# snapshot steps (0, 1000, 2000, 3000) plus the 700-step run's last (700), each once. Restarted
# again from the step-700 checkpoint, now to step 1500, in a copy of that directory: the files of
# steps 2000 and 3000 written after the checkpoint are on disk but must not be listed.
cp -r "$tmp/re" "$tmp/re2"
$MPIRUN -n 1 "$FDEM" run "$CASE" --out "$tmp/re2" -q --restart "$tmp/ck700/checkpoint.h5" --set time.steps=1500 \
  >"$tmp/e" 2>&1 || { cat "$tmp/e"; fail "second restart at step 700"; }
$PY - "$tmp/np1" "$tmp/re" "$tmp/re2" <<'PYEOF' || fail "fe.xdmf after the restart"
import sys, os, re, glob
from fe_out import listed, files
a, b, c = (listed(d) for d in sys.argv[1:])
print("fe.xdmf steps: uninterrupted %s; stopped at 700 and restarted %s; again, to 1500 %s (files %s)"
      % (a, b, c, files(sys.argv[3])))
assert a == [0, 1000, 2000, 3000], a
assert b == sorted(set(b)) and c == sorted(set(c)), "fe.xdmf lists a step twice or out of order"
assert b == sorted(a + [700]) == files(sys.argv[2]), "restarted fe.xdmf: %s" % b
assert c == [0, 700, 1000, 1500], "fe.xdmf of the run restarted to 1500: %s" % c
assert files(sys.argv[3]) == [0, 700, 1000, 1500, 2000, 3000]
PYEOF
# (a checkpoint without the FE state: tests/cli_kill_restart.sh)
# Many contacts on one node: a dense bed of small grains on a plate of 2 x 2 bricks. The FE
# stable step bounds the free node's contact stiffness by a dense grain layer over its share of
# the surface (0.01 m^2 / (2 sqrt 3 r^2) = 115.5 contacts of 5e4 N/m), which gives n = 2; the
# plate settles and carries the bed (weight 21.78 N, less what the side walls carry by friction).
# Failed before: with the one-contact bound n was 7 and the interface force swung between -0.1
# and -63 N to the end.
$MPIRUN -n 2 "$FDEM" run "$SRC/cases/coupling/bed_on_coarse_plate.yaml" --out "$tmp/bed" -q >"$tmp/bed.log" 2>&1 \
  || { cat "$tmp/bed.log"; fail "bed on a coarse plate"; }
$PY - "$tmp/bed" <<'PYEOF' || fail "bed on a coarse plate: stable step or settling"
import sys, csv, json, math
d = sys.argv[1]
c = json.load(open(d + "/run.json"))["coupling"]
k1 = 1e7 * 0.005                                # normal_stiffness(E, r, E, r) = E r
kn = k1 * 0.01 / (2 * math.sqrt(3) * 0.005**2)  # the free top node's share: a quarter of each of 4 quads
print("k per contact %.6g N/m, node bound %.6g N/m (expected %.6g), subcycle %d, dt_fe %.4g s, stable %.4g s"
      % (c["k_interface"], c["k_interface_node"], kn, c["subcycle"], c["dt_fe"], c["dt_fe_stable"]))
assert abs(c["k_interface"] - k1) < 1e-9 * k1 and abs(c["k_interface_node"] - kn) < 1e-9 * kn
assert c["subcycle"] == 2 and c["dt_fe"] <= c["dt_fe_stable"]
W = 1600 * 2650 * 4 / 3 * math.pi * 0.005**3 * 9.81
fz = [-float(r["fz"]) for r in csv.DictReader(open(d + "/interface.csv"))]
tail = fz[-6:]
print("interface force over the last 2 500 steps %.4f .. %.4f N, bed weight %.4f N" % (min(tail), max(tail), W))
assert max(tail) - min(tail) < 0.005 * W, "the plate has not settled"
assert 0.9 * W < min(tail) and max(tail) <= W, "the plate does not carry the bed"
PYEOF
# fdem check of the coupled cases.
for f in "$SRC"/cases/coupling/*.yaml; do
  $MPIRUN -n 2 "$FDEM" check "$f" >"$tmp/o" 2>"$tmp/e" || { cat "$tmp/e"; fail "check $f"; }
  grep -q "interface .* triangles" "$tmp/o" || { cat "$tmp/o"; fail "check $f prints no interface line"; }
done
# Bad coupled input: exit 2, "FILE:LINE: error: WHAT" once, no output directory.
for f in "$SRC"/cases/bad/coupling_*.yaml; do
  expected=$(head -1 "$f" | sed -n 's/^# expected error: //p')
  loc=${expected%%: *}; what=${expected#*: }
  $MPIRUN -n 2 "$FDEM" run "$f" --out "$tmp/bad" >/dev/null 2>"$tmp/e"; c=$?
  k=$(grep -F -- "$loc: error: " "$tmp/e" | grep -cF -- "$what")
  [ $c -eq 2 ] && [ "$k" -eq 1 ] && [ ! -e "$tmp/bad" ] || { cat "$tmp/e"; fail "$f: exit $c, message x$k: $expected"; }
  echo "ok   $(basename "$f"): $expected"
done
# coupling without fem / without particles: errors naming the key.
cat >"$tmp/nofem.yaml" <<'YEOF'
domain: {min: [0, 0, 0], max: [0.2, 0.2, 0.1]}
time: {steps: 10}
materials: [{name: grain, young: 1.0e7, density: 2650}]
particles: [{inline: {material: grain, spheres: [[0.1, 0.1, 0.05, 0.01]]}}]
coupling: {material: grain, surfaces: [{mesh: plate}]}
YEOF
"$FDEM" check "$tmp/nofem.yaml" >/dev/null 2>"$tmp/e"; c=$?
[ $c -eq 2 ] && grep -q "nofem.yaml:[0-9]*: error: coupling: needs finite elements" "$tmp/e" || { cat "$tmp/e"; fail "coupling without fem: exit $c"; }
"$FDEM" check "$SRC/cases/fem/cantilever.yaml" --set coupling.material=x >/dev/null 2>"$tmp/e"; c=$?
[ $c -eq 2 ] && grep -q "coupling: only for cases with particles" "$tmp/e" || { cat "$tmp/e"; fail "coupling without particles: exit $c"; }
echo "coupled command-line checks passed"
