#!/usr/bin/env bash
# Runs that explode or go non-finite stop loudly (docs/user-guide.md "Runs that diverge"):
#  - a DEM run with dt 3x the critical step: exit 3, the message names the step, the particle(s)
#    and "time step too large", printed once; run.json "diverged" with that message; the
#    checkpoint written before the blow-up is kept and restarts (exit 0, at its step);
#  - particles leaving the domain all at once: exit 3 naming the share lost;
#  - a grain moving more than half its radius per step: exit 3 naming it and its travel;
#  - coincident input particles: an input error (exit 2) naming the ids and the sphere file's line;
#  - an FE run (relaxation, and static) with a 1e9 N load after a normal first hold: exit 3
#    naming the hold, step, node and element; the first hold's fe_checkpoint.h5 restarts;
#  - a static solve without restraints: exit 2 naming fem.restraints, before any output;
#  - a normal run still finishes (exit 0, run.json "finished") with the checks active.
# Usage: cli_health.sh FDEM_BINARY SOURCE_DIR
source "$2/tests/support/cli_common.sh" "$@"

# status DIR: run.json's status; message DIR: its message
status() { $PY -c 'import json,sys; print(json.load(open(sys.argv[1] + "/run.json"))["status"])' "$1"; }
message() { $PY -c 'import json,sys; print(json.load(open(sys.argv[1] + "/run.json")).get("message", ""))' "$1"; }
# once FILE TEXT: TEXT occurs on exactly one line of FILE
once() { [ "$(grep -cF -- "$2" "$1")" -eq 1 ]; }

# 1. dt 3x the critical step (settle demo: critical 6.65e-5 s for its smallest grain, r 2 mm).
CASE="$SRC/cases/demo/settle.yaml"
$MPIRUN -n 2 "$FDEM" run "$CASE" --out "$tmp/dt" -q --set time.dt=2.0e-4 --set time.steps=4000 \
  --set output.checkpoint_every=50 >"$tmp/dt.out" 2>"$tmp/dt.err"
code=$?
[ $code -eq 3 ] || { cat "$tmp/dt.err"; fail "dt 3x critical: exit code $code, want 3"; }
once "$tmp/dt.err" "fdem: error: the run diverged at step " || { cat "$tmp/dt.err"; fail "dt 3x critical: message not printed once"; }
# (whichever check passes its limit first: an overlap beyond 1 r, or a grain moving more than
# half its radius or turning more than 0.5 rad per step)
grep -qE "step [0-9]+: (particles [0-9]+ and [0-9]+ overlap by .* of the smaller radius \(limit 1\)|particle [0-9]+ moves [0-9.e+-]+ of its radius and turns [0-9.e+-]+ rad per step \(limits 0.5 and 0.5\))" "$tmp/dt.err" ||
  { cat "$tmp/dt.err"; fail "dt 3x critical: no step / particle ids / overlap or travel in the message"; }
grep -qF "likely cause: time step too large: dt = 0.0002 s, critical 6.6" "$tmp/dt.err" ||
  { cat "$tmp/dt.err"; fail "dt 3x critical: likely cause not named"; }
[ "$(status "$tmp/dt")" = diverged ] || fail "dt 3x critical: run.json status $(status "$tmp/dt"), want diverged"
message "$tmp/dt" | grep -qF "time step too large" || fail "dt 3x critical: run.json message"
step=$(sed -n 's/.*diverged at step \([0-9]*\):.*/\1/p' "$tmp/dt.err")
ck=$(( (step - 1) / 50 * 50 ))
echo "dt 3x critical: diverged at step $step; last checkpoint at step $ck"
[ "$ck" -gt 0 ] || fail "dt 3x critical: diverged before the first checkpoint (step $step)"
# The checkpoint is the one of step $ck (before the blow-up) and restarts: 0 more steps -> exit 0.
$MPIRUN -n 2 "$FDEM" run "$CASE" --out "$tmp/dt" -q --set time.dt=2.0e-4 --set time.steps=$ck \
  --restart "$tmp/dt/checkpoint.h5" >"$tmp/dt2.out" 2>"$tmp/dt2.err" ||
  { cat "$tmp/dt2.err"; fail "restart from the checkpoint kept before the blow-up"; }
[ "$(status "$tmp/dt")" = finished ] || fail "restart from the kept checkpoint: run.json $(status "$tmp/dt")"
$PY - "$tmp/dt/run.json" "$ck" <<'PYEOF' || fail "restart from the kept checkpoint: wrong step"
import json, sys
r = json.load(open(sys.argv[1]))
assert r["start_step"] == int(sys.argv[2]) and r["steps"] == int(sys.argv[2]), (r["start_step"], r["steps"])
PYEOF

# 2. Particles leaving the domain at once: 20 spheres shot upwards at 200 m/s.
for i in $(seq 1 20); do echo "$i $(( i % 5 )).0e-2 $(( i / 5 )).0e-2 0.01 0.004"; done >"$tmp/row.txt"
cat >"$tmp/eject.yaml" <<EOF
name: eject
domain: {min: [-0.01, -0.01, -0.01], max: [0.06, 0.06, 0.1]}
time: {dt: 1.0e-6, steps: 2000}
materials:
  - {name: sand, young: 1.0e8, density: 2640}
particles:
  - file: {path: row.txt, material: sand, velocity: [0, 0, 200]}
output: {checkpoint_every: 100}
EOF
$MPIRUN -n 2 "$FDEM" run "$tmp/eject.yaml" --out "$tmp/ej" -q >"$tmp/ej.out" 2>"$tmp/ej.err"
code=$?
[ $code -eq 3 ] || { cat "$tmp/ej.err"; fail "ejected particles: exit code $code, want 3"; }
once "$tmp/ej.err" "20 of 20 particles (100.0 %) left the domain at once" ||
  { cat "$tmp/ej.err"; fail "ejected particles: share lost not named once"; }
[ "$(status "$tmp/ej")" = diverged ] || fail "ejected particles: run.json $(status "$tmp/ej")"

# 2b. Kinetic energy beyond what the step resolves: one grain (r 1 mm) flying at 600 m/s with
# dt 1e-6 s travels 0.6 of its radius per step, with nothing to overlap: exit 3 naming it.
cat >"$tmp/fast.yaml" <<EOF
name: fast
domain: {min: [-0.01, -0.01, -0.01], max: [2.0, 0.01, 0.01]}
gravity: [0, 0, 0]
time: {dt: 1.0e-6, steps: 1000}
materials:
  - {name: sand, young: 1.0e8, density: 2640}
particles:
  - inline: {material: sand, velocity: [600, 0, 0], spheres: [[0, 0, 0, 0.001]]}
EOF
$MPIRUN -n 2 "$FDEM" run "$tmp/fast.yaml" --out "$tmp/fast" -q >"$tmp/fast.out" 2>"$tmp/fast.err"
code=$?
[ $code -eq 3 ] || { cat "$tmp/fast.err"; fail "fast grain: exit code $code, want 3"; }
once "$tmp/fast.err" "fdem: error: the run diverged at step " || { cat "$tmp/fast.err"; fail "fast grain: message not printed once"; }
grep -qE "step [0-9]+: particle [0-9]+ moves 0.6 of its radius and turns 0 rad per step \(limits 0.5 and 0.5\): its kinetic energy grew beyond what the time step resolves" "$tmp/fast.err" ||
  { cat "$tmp/fast.err"; fail "fast grain: the message does not name the particle and its travel per step"; }
[ "$(status "$tmp/fast")" = diverged ] || fail "fast grain: run.json status $(status "$tmp/fast"), want diverged"
# ... and at 400 m/s (0.4 r per step) it flies through (exit 0)
$MPIRUN -n 2 "$FDEM" run "$tmp/fast.yaml" --out "$tmp/slow" -q --set 'particles.0.inline.velocity=[400, 0, 0]' \
  >"$tmp/slow.out" 2>"$tmp/slow.err" || { cat "$tmp/slow.err"; fail "grain at 0.4 r per step: not finished"; }

# 3. Coincident particles in a sphere file: an input error naming both ids and the file's line.
printf '# id x y z r\n1 0.01 0.01 0.01 0.004\n2 0.03 0.01 0.01 0.004\n\n3 0.01 0.01 0.01 0.004\n' >"$tmp/dup.txt"
sed -e 's/row.txt/dup.txt/' -e 's/velocity: \[0, 0, 200\]/velocity: [0, 0, 0]/' "$tmp/eject.yaml" >"$tmp/dup.yaml"
$MPIRUN -n 2 "$FDEM" run "$tmp/dup.yaml" --out "$tmp/dup" -q >"$tmp/dup.out" 2>"$tmp/dup.err"
code=$?
[ $code -eq 2 ] || { cat "$tmp/dup.err"; fail "coincident particles: exit code $code, want 2"; }
once "$tmp/dup.err" "dup.txt:5: error: particles 1 and 3 overlap by 0.008 m = 2 of the smaller radius (limit 0.5)" ||
  { cat "$tmp/dup.err"; fail "coincident particles: message"; }
[ ! -e "$tmp/dup" ] || fail "coincident particles: output directory created"

# 4. FE: a first hold at 1000 N, then 1e9 N at the cantilever's tip (load factor 1e6, the top of its range).
FE="$SRC/cases/fem/cantilever.yaml"
for solver in relaxation static; do
  d="$tmp/fe_$solver"
  $MPIRUN -n 2 "$FDEM" run "$FE" --out "$d" -q --set fem.solver=$solver --set 'fem.load_steps=[1.0, 1.0e6]' \
    >"$d.out" 2>"$d.err"
  code=$?
  [ $code -eq 3 ] || { cat "$d.err"; fail "FE $solver, 1e9 N: exit code $code, want 3"; }
  once "$d.err" "fdem: error: the FE run diverged in hold 2 (load factor 1e+06), step " ||
    { cat "$d.err"; fail "FE $solver: hold and step not named once"; }
  grep -qE "the displacement of node [0-9]+ \(element [0-9]+\) is .* m, more than the size of the mesh" "$d.err" ||
    { cat "$d.err"; fail "FE $solver: node / element not named"; }
  [ "$(status "$d")" = diverged ] || fail "FE $solver: run.json $(status "$d")"
  # fe_checkpoint.h5 is the one of hold 1: restarting with that single hold has nothing to do.
  $MPIRUN -n 2 "$FDEM" run "$FE" --out "$d" -q --set fem.solver=$solver --set 'fem.load_steps=[1.0]' \
    --restart "$d/fe_checkpoint.h5" >"$d.2.out" 2>"$d.2.err" || { cat "$d.2.err"; fail "FE $solver: restart from hold 1"; }
  [ "$(status "$d")" = finished ] || fail "FE $solver: restart: run.json $(status "$d")"
  echo "FE $solver: $(grep -o 'hold 2 (load factor 1e+06), step [0-9]*' "$d.err")"
done

# 5. A static solve without restraints: the model's rigid-body motion, an input error (exit 2).
grep -v -e 'restraints:' -e 'node_set: xmin, fixed' "$FE" >"$tmp/free.yaml"
$MPIRUN -n 2 "$FDEM" run "$tmp/free.yaml" --out "$tmp/free" -q --set fem.solver=static >"$tmp/free.out" 2>"$tmp/free.err"
code=$?
[ $code -eq 2 ] || { cat "$tmp/free.err"; fail "unrestrained static solve: exit code $code, want 2"; }
once "$tmp/free.err" "--set fem.solver=static: error: fem.solver: static needs restraints (fem.restraints or fem.displacements)" ||
  { cat "$tmp/free.err"; fail "unrestrained static solve: message"; }
[ ! -e "$tmp/free/run.json" ] || fail "unrestrained static solve: run.json written ($(status "$tmp/free"))"
$MPIRUN -n 2 "$FDEM" check "$tmp/free.yaml" --set fem.solver=static >/dev/null 2>"$tmp/free.err"
[ $? -eq 2 ] || fail "fdem check of an unrestrained static case: exit code, want 2"

# 6. A normal run still finishes with the checks active.
$MPIRUN -n 2 "$FDEM" run "$SRC/cases/examples/sphere_file.yaml" --out "$tmp/ok" -q >"$tmp/ok.out" 2>"$tmp/ok.err" ||
  { cat "$tmp/ok.err"; fail "sphere_file.yaml"; }
[ "$(status "$tmp/ok")" = finished ] || fail "sphere_file.yaml: run.json $(status "$tmp/ok")"
[ ! -s "$tmp/ok.err" ] || { cat "$tmp/ok.err"; fail "sphere_file.yaml: stderr not empty"; }
echo "all run-health checks passed"
