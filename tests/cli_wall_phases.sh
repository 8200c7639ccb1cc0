#!/usr/bin/env bash
# Motion phases that start on a condition (walls.motion.after; docs/case-format.md#phases-that-start-on-a-condition):
# the quick start's settling box with a plate above it, `motion: [fixed, {after: {unbalanced: 0.01},
# velocity: [0, 0, -0.5]}]`.
#  - the plate starts at the first history row where the unbalanced-force ratio is below 0.01 with
#    a contact and the kinetic energy per grain below 1e-3 m g d (found here from history.csv and
#    the first snapshot's grains): before it its displacement is 0, after it -0.5 m/s x the time
#    since (a velocity wall: to round-off);
#  - a box listed before the plate, `{after: {stage: down}}` with the plate's phase named `down`,
#    starts at the same step (its displacement equals the plate's on every row);
#  - `after: {time: 0.099}` starts it at the first history row 0.099 s or more into the run (step
#    5 000, dt 1.99963e-5 s), `{steps: 5000}` at step 5 000;
#  - 1 and 2 ranks give the same walls.csv byte for byte, and so do runs stopped before and after
#    the start and restarted from their checkpoints (the start is in the checkpoint).
# Usage: cli_wall_phases.sh FDEM_BINARY SOURCE_DIR
source "$2/tests/support/cli_common.sh" "$@"
sed -e 's/^name: settle_box/name: plate_after/' -e 's/steps: 100000 .*/steps: 20000/' -e '/stop_unbalanced/d' \
  -e '/name: box, type: container/a\  - {name: marker, type: box, material: steel, min: [0.04, 0.04, 0.195], max: [0.045, 0.045, 0.199],\n     motion: [fixed, {after: {stage: down}, velocity: [0, 0, -0.5]}]}\n  - {name: plate, type: box, material: steel, min: [0.015, 0.015, 0.192], max: [0.035, 0.035, 0.197],\n     motion: [fixed, {name: down, after: {unbalanced: 0.01}, velocity: [0, 0, -0.5]}]}' \
  "$SRC/cases/quickstart/settle_box.yaml" >"$tmp/case.yaml"
run() { local out=$1; shift; "$@" run "$tmp/case.yaml" --out "$tmp/$out" -q "${EXTRA[@]}" >"$tmp/$out.log" 2>&1 ||
  { cat "$tmp/$out.log"; fail "run $out"; }; }
EXTRA=(); run one "$FDEM"
EXTRA=(); run two $MPIRUN -n 2 "$FDEM"
cmp -s "$tmp/one/walls.csv" "$tmp/two/walls.csv" || fail "walls.csv differs between 1 and 2 ranks"
for n in 10000 18000; do  # stopped before and after the plate starts, then restarted
  EXTRA=(--set time.steps=$n); run "r$n" $MPIRUN -n 2 "$FDEM"
  EXTRA=(--restart "$tmp/r$n/checkpoint.h5"); run "r$n" $MPIRUN -n 2 "$FDEM"
  cmp -s "$tmp/one/walls.csv" "$tmp/r$n/walls.csv" || fail "restarted at step $n: walls.csv differs"
done
$PY - "$tmp/one" <<'PYEOF' || fail "the plate's start"
import csv, sys
from grains import weights
run = sys.argv[1]
mgd, _ = weights(run, 2650)
hist = list(csv.DictReader(open(f"{run}/history.csv")))
start = next(int(h["step"]) for h in hist if float(h["unbalanced"]) < 0.01 and float(h["contacts"]) > 0
             and float(h["kinetic_energy"]) / float(h["particles"]) < 1e-3 * mgd)
walls = list(csv.DictReader(open(f"{run}/walls.csv")))
t0 = next(float(w["time"]) for w in walls if int(w["step"]) == start)
moved = 0
for w in walls:
    uz, t = float(w["plate_uz"]), float(w["time"])
    if int(w["step"]) <= start:
        assert uz == 0.0, (w["step"], uz)
    else:
        assert abs(uz + 0.5 * (t - t0)) < 1e-12, (w["step"], uz, -0.5 * (t - t0))
        moved += 1
assert moved >= 5, moved
# the marker (listed before the plate) starts with the plate's phase `down`: the same step
assert all(w["marker_uz"] == w["plate_uz"] for w in walls), "the marker did not start with the plate"
print(f"plate starts at step {start} (t {t0:.5f} s); {moved} rows after it at -0.5 m/s")
PYEOF
grep -q "wall 'plate': motion phase 2 starts at step" "$tmp/two.log" && fail "-q printed the phase line"
# a time and a step count from the run's start
EXTRA=(--set 'walls[plate].motion.1={name: down, after: {time: 0.099}, velocity: [0, 0, -0.5]}' --set time.steps=6000)
run time $MPIRUN -n 2 "$FDEM"
EXTRA=(--set 'walls[plate].motion.1={name: down, after: {steps: 5000}, velocity: [0, 0, -0.5]}' --set time.steps=6000)
run steps "$FDEM"
$PY - "$tmp/time/walls.csv" "$tmp/steps/walls.csv" <<'PYEOF' || fail "after: time / steps"
import csv, sys
for path in sys.argv[1:]:
    rows = list(csv.DictReader(open(path)))
    first = next(int(w["step"]) for w in rows if float(w["plate_uz"]) != 0.0)
    assert first == 5200, (path, first)  # the first row after the start at step 5 000 (rows every 200)
print("after: {time: 0.099} and {steps: 5000}: the plate moves from step 5000 (first row 5200)")
PYEOF
echo "cli_wall_phases: ok"
