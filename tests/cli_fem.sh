#!/usr/bin/env bash
# Pure finite-element cases through the command line: the cantilever by dynamic relaxation on
# 2 ranks and by the static KSP solve on 1 rank agree (1e-4) and match beam theory within the
# Hex8 bending error; the static run writes one snapshot per hold (one step per hold), also
# across a restart; the clamp reaction balances the load; a bad node set is a clean error;
# a run stopped by SIGTERM and restarted ends at the same answer, its fe.xdmf listing every snapshot.
# Usage: cli_fem.sh FDEM_BINARY SOURCE_DIR
source "$2/tests/support/cli_common.sh" "$@"
CASE="$SRC/cases/fem/cantilever.yaml"
$MPIRUN -n 2 "$FDEM" run "$CASE" --out "$tmp/dr" -q >"$tmp/dr.log" 2>&1 || { cat "$tmp/dr.log"; fail "relaxation run"; }
$MPIRUN -n 1 "$FDEM" run "$CASE" --out "$tmp/st" -q --set fem.solver=static >"$tmp/st.log" 2>&1 || { cat "$tmp/st.log"; fail "static run"; }
$PY - "$tmp/dr" "$tmp/st" <<'PYEOF' || fail "results"
import sys, csv, glob, h5py, numpy as np
from fe_out import tip
def reaction(d):
    rows = list(csv.DictReader(open(d + "/reactions.csv")))
    return float(rows[-1]["beam_xmin_rz"])
wd, ws = tip(sys.argv[1]), tip(sys.argv[2])
E, nu, L, b, h, P = 2e11, 0.3, 1.0, 0.1, 0.1, 1000.0
I = b * h**3 / 12; G = E / (2 * (1 + nu))
beam = P * L**3 / (3 * E * I) + P * L / (5 / 6 * G * b * h)
print("tip deflection: relaxation %.6e m, static %.6e m, beam theory %.6e m" % (-wd, -ws, beam))
print("relaxation vs static: %.2e; static / beam theory: %.4f" % (abs(wd - ws) / abs(ws), -ws / beam))
assert abs(wd - ws) / abs(ws) < 1e-4, "relaxation and static solve differ"
assert 0.9 < -ws / beam < 1.0, "static solution not within 10 % below beam theory"
for d in sys.argv[1:]:
    rz = reaction(d)
    print("clamp reaction rz %.9g N (load 1000 N)" % rz)
    assert abs(rz - P) < 1e-3 * P, "reaction does not balance the load"
PYEOF
# Static runs count one step per hold (hold k ends at step k, time k): the cantilever's two
# holds (load factors 0.5, 1) leave three distinct snapshots, fe.xdmf lists each once in order,
# fe_history.csv steps increase, and the snapshot of hold 1 is half that of hold 2 (linear). A
# static run that stopped after hold 1 (its checkpoint) and is restarted on 2 ranks ends the same.
$MPIRUN -n 1 "$FDEM" run "$CASE" --out "$tmp/st1" -q --set fem.solver=static --set 'fem.load_steps=[0.5]' \
  >"$tmp/st1.log" 2>&1 || { cat "$tmp/st1.log"; fail "static run, first hold only"; }
$MPIRUN -n 2 "$FDEM" run "$CASE" --out "$tmp/st1" -q --set fem.solver=static --restart "$tmp/st1/fe_checkpoint.h5" \
  >"$tmp/st1re.log" 2>&1 || { cat "$tmp/st1re.log"; fail "static restart"; }
$PY - "$tmp/st" "$tmp/st1" <<'PYEOF' || fail "static run steps"
import sys, os, re, csv, glob, h5py, numpy as np
from fe_out import tip_of, displacement, ksp_bounds, agree_within_ksp
def check(d):
    files = sorted(glob.glob(d + "/fe_[0-9]*.h5"))
    steps = [int(re.fullmatch(r"fe_([0-9]+)\.h5", os.path.basename(f)).group(1)) for f in files]
    x = open(d + "/fe.xdmf").read()
    listed = [int(s) for s in re.findall(r'<Grid Name="step_([0-9]+)"', x)]
    times = [float(t) for t in re.findall(r'<Time Value="([^"]+)"', x)]
    hist = list(csv.DictReader(open(d + "/fe_history.csv")))
    hs = [int(float(r["step"])) for r in hist]
    rs = [int(float(r["step"])) for r in csv.DictReader(open(d + "/reactions.csv"))]
    print("%s: files %s, fe.xdmf steps %s times %s, fe_history steps %s" % (d, steps, listed, times, hs))
    assert steps == [0, 1, 2], "snapshot files %s, expected the start + one per hold (steps 0, 1, 2)" % steps
    assert listed == steps, "fe.xdmf lists %s, expected %s" % (listed, steps)
    assert times == [0.0, 1.0, 2.0], "fe.xdmf times %s" % times
    for f in files:
        assert "%s:/nodes/coordinates" % os.path.basename(f) in x, f + " not referenced by fe.xdmf"
    assert hs == [1, 2] and all(a < b for a, b in zip(hs, hs[1:])), "fe_history.csv steps %s" % hs
    assert [int(float(r["hold"])) for r in hist] == [0, 1] and rs == hs, "holds / reaction steps"
    t = [tip_of(f) for f in files]
    assert [s for _, _, s, _ in t] == steps and [tm for _, _, _, tm in t] == times, "snapshot attributes"
    assert t[0][0] == 0 and t[0][1] == 0, "the initial snapshot is not the undeformed state"
    # Linear elasticity: hold 1 (factor 0.5) is half of hold 2, within what the two solves guarantee.
    bounds = ksp_bounds(d)
    agree_within_ksp(2 * displacement(files[1]), displacement(files[2]), bounds[0] + bounds[1],
                     d + ": 2 x hold 1 vs hold 2")
    for r, (_, um, _, _) in zip(hist, t[1:]):
        assert abs(float(r["max_displacement"]) - um) < 1e-12 * um, "fe_history max_displacement vs snapshot"
    return files[2], bounds[1]
# The run stopped after hold 1 and restarted on 2 ranks solves hold 2 with another preconditioner
# (GAMG on 2 ranks) from another initial guess: not the same bits, but within the KSP guarantees.
(fs, bs), (fr, br) = check(sys.argv[1]), check(sys.argv[2])
print("static tip, hold 2: %.9e m; stopped after hold 1 + restarted: %.9e m" % (-tip_of(fs)[0], -tip_of(fr)[0]))
agree_within_ksp(displacement(fr), displacement(fs), bs + br, "restarted static run vs uninterrupted")
PYEOF
# ParaView files: the XDMF lists the snapshots (start + one per hold) as a hexahedral mesh.
n=$(grep -c 'fe_[0-9]*\.h5:/nodes/coordinates' "$tmp/dr/fe.xdmf")
[ "$n" -eq 3 ] || fail "fe.xdmf lists $n snapshots, expected 3"
grep -q 'TopologyType="Hexahedron"' "$tmp/dr/fe.xdmf" || fail "fe.xdmf has no hexahedral topology"
grep -q '"element_updates_per_second"' "$tmp/dr/run.json" || fail "run.json lacks element_updates_per_second"
# run.json's fe_partition: one entry per rank, the owned elements add up to the mesh's, every rank
# owns nodes and reports its peak memory.
$PY - "$tmp/dr/run.json" "$tmp/dr/structures.json" <<'PYEOF' || fail "run.json fe_partition"
import sys, json
j = json.load(open(sys.argv[1]))
rk = j["fe_partition"]["ranks"]
n = sum(m["elements"] for m in json.load(open(sys.argv[2]))["meshes"])
assert len(rk) == j["ranks"] == 2, rk
assert sum(r["elements"] for r in rk) == n, (rk, n)
assert all(r["nodes"] > 0 and r["elements"] > 0 and r["peak_rss_mb"] > 10 for r in rk), rk
print("fe_partition: elements %s of %d" % ([r["elements"] for r in rk], n))
PYEOF
# Stopped by SIGTERM inside a hold, the run writes fe_checkpoint.h5; --restart on 1 rank finishes
# it, ending at the uninterrupted run's answer to the last bit: the holds run a fixed number of
# steps (tolerance never met, max_steps 15000), the interrupted hold continues its step count
# (the checkpoint's hold_start) and the explicit solver gives the same bits on any number of ranks.
FIXED=(--set fem.tolerance=1e-30 --set fem.max_steps=15000)
$MPIRUN -n 2 "$FDEM" run "$CASE" --out "$tmp/ref" -q "${FIXED[@]}" >"$tmp/ref.log" 2>&1 \
  || { cat "$tmp/ref.log"; fail "fixed-step reference run"; }
$MPIRUN -n 2 "$FDEM" run "$CASE" --out "$tmp/sig" -q "${FIXED[@]}" \
  >"$tmp/sig.log" 2>&1 &
pid=$!
for i in $(seq 1 300); do grep -q . "$tmp/sig/run.json" 2>/dev/null && break; sleep 0.1; done
sleep 1
# the ranks themselves: mpirun would forward the signal and kill the ranks after a 1 s grace,
# which a loaded machine can exceed before the checkpoint is written
kill -TERM $(ps -o pid= --ppid $pid); wait $pid; code=$?
[ $code -ne 0 ] || fail "FE run stopped by a signal exited with 0"
[ -f "$tmp/sig/fe_checkpoint.h5" ] || { cat "$tmp/sig.log"; fail "no FE checkpoint after SIGTERM"; }
grep -q '"status": "interrupted"' "$tmp/sig/run.json" || fail "run.json does not say interrupted"
$MPIRUN -n 1 "$FDEM" run "$CASE" --out "$tmp/sig" -q "${FIXED[@]}" --restart "$tmp/sig/fe_checkpoint.h5" \
  >"$tmp/re.log" 2>&1 || { cat "$tmp/re.log"; fail "FE restart failed"; }
$PY - "$tmp/ref" "$tmp/sig" <<'PYEOF' || fail "restarted FE run differs"
import sys, glob, h5py, numpy as np
from fe_out import tip
import csv
a, b = tip(sys.argv[1]), tip(sys.argv[2])
print("tip deflection uninterrupted %.17e, interrupted + restarted %.17e (rel. diff %.2e)" % (a, b, abs(a - b) / abs(a)))
ends = [[int(float(r["step"])) for r in csv.DictReader(open(d + "/fe_history.csv"))] for d in sys.argv[1:3]]
print("hold ends: uninterrupted %s, interrupted + restarted %s" % tuple(ends))
assert ends[0] == [15000, 30000] and ends[1] == ends[0], "the interrupted hold did not keep its step count"
assert a == b, "the restarted run does not end at the uninterrupted run's answer to the last bit"
PYEOF
n=$(wc -l < "$tmp/sig/fe_history.csv")
[ "$n" -eq 3 ] || fail "fe_history.csv has $n lines after the restart, expected header + 2 holds"
# fe.xdmf continues across the restart: like the uninterrupted run's it lists the start and the
# end of both holds, plus the snapshot at the signal (the checkpoint's step); each step once, in
# order, and exactly the fe_*.h5 files in the directory.
$PY - "$tmp/ref" "$tmp/sig" <<'PYEOF' || fail "fe.xdmf after the restart"
import sys, os, re, csv, glob
from fe_out import listed, files, hold_ends
a, b = listed(sys.argv[1]), listed(sys.argv[2])
print("fe.xdmf steps: uninterrupted %s, interrupted + restarted %s (files %s)" % (a, b, files(sys.argv[2])))
assert a == [0] + hold_ends(sys.argv[1]), a
assert b == sorted(set(b)), "fe.xdmf lists a step twice or out of order: %s" % b
assert b == files(sys.argv[2]), "fe.xdmf does not list the fe_*.h5 files of the directory"
# plus the signal's step, inside hold 1 or 2 (the signal comes about 1 s into the run; none when
# it came at the last step of hold 1: that hold then ends and the run stops after it)
extra = sorted(set(b) - set(a))
assert set(a) <= set(b) and len(extra) <= 1 and len(b) == len(a) + len(extra), b
assert all(0 < e < a[-1] for e in extra), b
assert hold_ends(sys.argv[2]) == a[1:], hold_ends(sys.argv[2])
PYEOF
# Shells: the pressurised pipe (static solve, 2 ranks) expands uniformly by cos(pi/64) p R^2/(E t).
$MPIRUN -n 2 "$FDEM" run "$SRC/cases/fem/pipe_pressure.yaml" --out "$tmp/pipe" -q >"$tmp/pipe.log" 2>&1 \
  || { cat "$tmp/pipe.log"; fail "pipe run"; }
$PY - "$tmp/pipe" <<'PYEOF' || fail "pipe expansion"
import sys, glob, h5py, numpy as np
f = sorted(glob.glob(sys.argv[1] + "/fe_[0-9]*.h5"))[-1]
with h5py.File(f, "r") as h:
    x = h["nodes/coordinates"][:]; u = h["nodes/displacement"][:]
r = np.hypot(x[:, 0], x[:, 1]); ur = (u[:, 0] * x[:, 0] + u[:, 1] * x[:, 1]) / r
ratio = ur / (10e3 * 0.075**2 / (450e6 * 0.004))
print("pipe: u_r / (p R^2 / E t) from %.6f to %.6f (cos(pi/64) = %.6f)" % (ratio.min(), ratio.max(), np.cos(np.pi / 64)))
assert abs(ratio.min() - np.cos(np.pi / 64)) < 1e-4 and abs(ratio.max() - np.cos(np.pi / 64)) < 1e-4
PYEOF
# The same pipe along y (cylinder axis: y, centred at x 0.4 as the buried pipe): ring node 0 on
# top (z = R), node 16 at x = +R; the same expansion.
sed -e 's/divisions: \[64, 4\]}/divisions: [64, 4], axis: y}/' -e 's/base: \[0, 0, 0\]/base: [0.4, 0, 0]/' \
    -e '/^  restraints:/,/^  loads:/{/^  restraints:/!{/^  loads:/!d}}' "$SRC/cases/fem/pipe_pressure.yaml" >"$tmp/pipe_y.yaml"
sed -i 's/^  restraints:/  restraints:\
    - {mesh: pipe, node_set: start, fixed: [y]}\
    - {mesh: pipe, region: {min: [0.399, -1, 0.07], max: [0.401, 1, 0.08]}, fixed: [x]}\
    - {mesh: pipe, region: {min: [0.47, -1, -0.001], max: [0.48, 1, 0.001]}, fixed: [z]}\
    - {mesh: pipe, region: {min: [0.399, -1, -0.08], max: [0.401, 1, -0.07]}, fixed: [x]}/' "$tmp/pipe_y.yaml"
$MPIRUN -n 2 "$FDEM" run "$tmp/pipe_y.yaml" --out "$tmp/pipe_y" -q >"$tmp/pipe_y.log" 2>&1 \
  || { cat "$tmp/pipe_y.yaml" "$tmp/pipe_y.log"; fail "pipe along y"; }
$PY - "$tmp/pipe_y" <<'PYEOF' || fail "pipe along y"
import sys, glob, h5py, numpy as np
f = sorted(glob.glob(sys.argv[1] + "/fe_[0-9]*.h5"))[-1]
with h5py.File(f, "r") as h:
    x = h["nodes/coordinates"][:]; u = h["nodes/displacement"][:]
dx, dz = x[:, 0] - 0.4, x[:, 2]
r = np.hypot(dx, dz); ur = (u[:, 0] * dx + u[:, 2] * dz) / r
ratio = ur / (10e3 * 0.075**2 / (450e6 * 0.004))
print("pipe along y: u_r / (p R^2 / E t) from %.6f to %.6f; node 0 at %s, node 16 at %s" % (ratio.min(), ratio.max(), x[0], x[16]))
assert abs(ratio.min() - np.cos(np.pi / 64)) < 1e-4 and abs(ratio.max() - np.cos(np.pi / 64)) < 1e-4
assert np.allclose(x[0], [0.4, 0, 0.075], atol=1e-15) and np.allclose(x[16], [0.475, 0, 0], atol=1e-15)
assert x[:, 1].min() == 0 and abs(x[:, 1].max() - 0.1) < 1e-15  # along +y from the base
PYEOF
# fem.ties: two blocks tied at their common face make one laterally restrained column: top
# settlement p H / M (exact for Hex8), the tied nodes' rows repeat the nodes they became; a tie
# that joins nothing exits 2 with one message.
$MPIRUN -n 2 "$FDEM" run "$SRC/cases/fem/tied_blocks.yaml" --out "$tmp/tied" >"$tmp/tied.log" 2>&1 \
  || { cat "$tmp/tied.log"; fail "tied blocks"; }
grep -q "tied upper:zmin -> lower: 4 nodes" "$tmp/tied.log" || { cat "$tmp/tied.log"; fail "tied blocks: no tie line"; }
$PY - "$tmp/tied" <<'PYEOF' || fail "tied blocks"
import sys, glob, h5py, numpy as np
with h5py.File(sorted(glob.glob(sys.argv[1] + "/fe_[0-9]*.h5"))[-1], "r") as h:
    x = h["nodes/coordinates"][:]; u = h["nodes/displacement"][:]; sig = h["elements/stress"][:]
E, nu, p = 20e6, 0.3, 1e5
# the static answer's element stresses (before 2026-12-03 a static run wrote zeros): sigma_zz = -p,
# sigma_xx = sigma_yy = nu / (1 - nu) sigma_zz
print("tied blocks: element stress zz %.6f..%.6f kPa, xx %.6f kPa (K0 p = %.6f)" % (sig[:, 2].min() / 1e3, sig[:, 2].max() / 1e3,
      sig[:, 0].mean() / 1e3, -nu / (1 - nu) * p / 1e3))
assert len(sig) == 4 and np.abs(sig[:, 2] / -p - 1).max() < 1e-9
assert np.abs(sig[:, :2] / (-nu / (1 - nu) * p) - 1).max() < 1e-9
M = E * (1 - nu) / ((1 + nu) * (1 - 2 * nu))
top, mid = np.abs(x[:, 2] - 0.2) < 1e-12, np.abs(x[:, 2] - 0.1) < 1e-12
print("tied blocks: top settlement %.9e m (p H / M = %.9e), the common face's 8 rows %.9e (%.9e)"
      % (u[top, 2].mean(), -p * 0.2 / M, u[mid, 2].mean(), -p * 0.1 / M))
assert top.sum() == 4 and mid.sum() == 8
assert np.abs(u[top, 2] / (-p * 0.2 / M) - 1).max() < 1e-9
assert np.abs(u[mid, 2] / (-p * 0.1 / M) - 1).max() < 1e-9
PYEOF
$MPIRUN -n 2 "$FDEM" run "$SRC/cases/fem/tied_blocks.yaml" --out "$tmp/tied_bad" --set fem.ties.0.node_set=zmax >"$tmp/o" 2>"$tmp/e"
code=$?
[ $code -eq 2 ] && [ "$(grep -c "fem.ties: mesh 'upper' to 'lower': no node of node set 'zmax' lies within 1e-09 m" "$tmp/e")" -eq 1 ] && [ ! -e "$tmp/tied_bad" ] \
  || { cat "$tmp/e"; fail "a tie that joins nothing: exit $code"; }
# A restraint on a node set the mesh does not have: exit 2, message once, no output.
$MPIRUN -n 2 "$FDEM" run "$CASE" --out "$tmp/bad" --set 'fem.restraints.0.node_set=front' >"$tmp/o" 2>"$tmp/e"
code=$?
[ $code -eq 2 ] || { cat "$tmp/e"; fail "bad node set: exit $code"; }
n=$(grep -c "has no node set 'front'" "$tmp/e")
[ "$n" -eq 1 ] || { cat "$tmp/e"; fail "bad node set message printed $n times"; }
[ -e "$tmp/bad" ] && fail "output directory created for a bad case"
# A signal during a static run (100 holds) stops it after the current hold -- a static solve is
# not interrupted inside: non-zero exit, status interrupted, the checkpoint of the last finished
# hold; --restart on 1 rank finishes the remaining holds: every hold once in fe_history.csv and
# fe.xdmf, the final tip deflection that of the 2-hold static run (same final load, linear).
LS=$($PY -c "print('[' + ','.join(str((k + 1) / 100) for k in range(100)) + ']')")
$MPIRUN -n 2 "$FDEM" run "$CASE" --out "$tmp/ssig" --set fem.solver=static --set "fem.load_steps=$LS" \
  >"$tmp/ssig.log" 2>&1 &
pid=$!
for i in $(seq 1 2400); do grep -q "^hold 2/100" "$tmp/ssig.log" && break; sleep 0.01; done  # progress lines: flushed
kill -TERM $(ps -o pid= --ppid $pid); wait $pid; code=$?  # (the ranks, as above)
[ $code -ne 0 ] || { cat "$tmp/ssig.log"; fail "static run stopped by SIGTERM exited with 0 (finished all holds?)"; }
grep -q '"status": "interrupted"' "$tmp/ssig/run.json" || fail "static run.json does not say interrupted"
grep -q "signal 15 after hold" "$tmp/ssig.log" || { cat "$tmp/ssig.log"; fail "static run: no stop message"; }
$MPIRUN -n 1 "$FDEM" run "$CASE" --out "$tmp/ssig" -q --set fem.solver=static --set "fem.load_steps=$LS" \
  --restart "$tmp/ssig/fe_checkpoint.h5" >"$tmp/ssre.log" 2>&1 || { cat "$tmp/ssre.log"; fail "static restart after a signal"; }
$PY - "$tmp/st" "$tmp/ssig" <<'PYEOF' || fail "static run stopped by a signal and restarted"
import sys, re, csv, glob, h5py, numpy as np
from fe_out import tip
rows = list(csv.DictReader(open(sys.argv[2] + "/fe_history.csv")))
steps = [int(float(r["step"])) for r in rows]; holds = [int(float(r["hold"])) for r in rows]
x = open(sys.argv[2] + "/fe.xdmf").read()
listed = [int(s) for s in re.findall(r'Name="step_([0-9]+)"', x)]
a, b = tip(sys.argv[1]), tip(sys.argv[2])
print("static run stopped by SIGTERM and restarted: %d history rows, %d snapshots listed, tip %.9e vs %.9e (rel. diff %.1e)"
      % (len(rows), len(listed), b, a, abs(a - b) / abs(a)))
assert steps == list(range(1, 101)) and holds == list(range(100)), (steps, holds)
assert listed == list(range(101)), listed
assert abs(a - b) < 1e-8 * abs(a)
PYEOF
echo "FE command-line checks passed"
