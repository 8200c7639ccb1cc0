#!/usr/bin/env bash
# Crash safety of checkpoints (docs/user-guide.md#checkpoints-and-restarts), on 2 ranks:
# - a particle run and a coupled run (tests/data/particles_escape.yaml, coupled_escape.yaml: grains
#   thrown sideways leave the domain and are removed while the run goes on) killed with SIGKILL
#   while writing a checkpoint (FDEM_TEST_DIE_IN_CHECKPOINT: the process _exit()s halfway through
#   the file) and at several moments after the first checkpoint exists: --restart ends bitwise
#   equal (ids, positions, velocities; FE displacements) to the uninterrupted run;
# - a coupled run stopped by SIGTERM restarts bitwise, with the same particle count, and a coupled
#   run ending inside a sub-cycle keeps the checkpoint of the sub-cycle's start;
# - corrupted (64 bytes overwritten inside a dataset), truncated, foreign, newer-version and
#   non-HDF5 checkpoints, and a corrupted specimen, are refused: exit 2, one message naming the
#   file and what is wrong.
# Usage: cli_kill_restart.sh FDEM_BINARY SOURCE_DIR
source "$2/tests/support/cli_common.sh" "$@"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
PCASE="$SRC/tests/data/particles_escape.yaml"
CCASE="$SRC/tests/data/coupled_escape.yaml"
REF_STEPS=3000

# bitwise DIR_A DIR_B STEP: the particle snapshots (and FE snapshots if any) of STEP are equal.
bitwise() {
  $PY - "$1" "$2" "$3" <<'PYEOF'
import sys, os, h5py, numpy as np
a, b, s = sys.argv[1], sys.argv[2], int(sys.argv[3])
def parts(d):
    with h5py.File("%s/particles_%08d.h5" % (d, s), "r") as h:
        i = np.argsort(h["id"][:])
        return h["id"][:][i], h["position"][:][i], h["velocity"][:][i]
ia, xa, va = parts(a); ib, xb, vb = parts(b)
assert len(ia) == len(ib), "step %d: %d vs %d particles" % (s, len(ia), len(ib))
assert (ia == ib).all(), "step %d: different particle sets" % s
dx = np.abs(xa - xb).max() if len(ia) else 0.0
assert dx == 0.0 and (va == vb).all(), "step %d: positions differ by up to %.3e m" % (s, dx)
msg = "step %d: %d particles bitwise equal" % (s, len(ia))
fa = "%s/fe_%08d.h5" % (a, s)
if os.path.exists(fa):
    from fe_out import displacement
    ua, ub = displacement(fa), displacement("%s/fe_%08d.h5" % (b, s))
    assert (ua == ub).all(), "step %d: FE displacements differ by up to %.3e m" % (s, np.abs(ua - ub).max())
    msg += ", FE displacements bitwise equal (max %.3e m)" % np.abs(ua).max()
print(msg)
PYEOF
}
ck_step() { $PY -c "import h5py,sys; print(int(h5py.File(sys.argv[1],'r').attrs['step']))" "$1"; }
# Runs that are killed or signalled are given far more steps than they can make before the signal
# (the whole 3000-step reference takes 0.5 s on an idle machine), so the signal never comes after
# the end; the step they reached depends on the machine's speed, so the uninterrupted reference
# for a later step is run when needed: reference CASE KIND STEP prints a directory holding it.
LONG=1000000
reference() {
  if [ "$3" -le $REF_STEPS ]; then echo "$tmp/$2-ref"; return; fi
  local r="$tmp/$2-ref$3"
  [ -d "$r" ] || $MPIRUN -n 2 "$FDEM" run "$1" --out "$r" -q --set time.steps=$3 --set output.snapshot_every=100 \
    >"$tmp/ref.log" 2>&1 || { cat "$tmp/ref.log" >&2; fail "$2: reference run to step $3"; }
  echo "$r"
}

for kind in particles coupled; do
  if [ $kind = particles ]; then CASE=$PCASE; else CASE=$CCASE; fi
  ref="$tmp/$kind-ref"
  $MPIRUN -n 2 "$FDEM" run "$CASE" --out "$ref" -q --set time.steps=$REF_STEPS --set output.snapshot_every=100 \
    >"$tmp/ref.log" 2>&1 || { cat "$tmp/ref.log"; fail "$kind: reference run"; }
  removed=$(($(wc -l <"$ref/removed.csv") - 1))
  [ "$removed" -gt 20 ] || fail "$kind: only $removed particles left the domain in the reference run"

  # 1. Killed while writing its 3rd checkpoint (steps 100, 200, 300): checkpoint.h5 is the one of
  # step 200, the half-written file is only checkpoint.h5.tmp; the restart ends bitwise equal.
  d="$tmp/$kind-die"
  FDEM_TEST_DIE_IN_CHECKPOINT=3 $MPIRUN -n 2 "$FDEM" run "$CASE" --out "$d" -q --set time.steps=$REF_STEPS \
    --set output.checkpoint_every=100 --set output.snapshot_every=100 >"$tmp/die.log" 2>&1 && fail "$kind: run did not die"
  [ -f "$d/checkpoint.h5.tmp" ] || { cat "$tmp/die.log"; fail "$kind: no half-written checkpoint.h5.tmp"; }
  s=$(ck_step "$d/checkpoint.h5")
  [ "$s" -eq 200 ] || fail "$kind: after dying in the 3rd checkpoint checkpoint.h5 is of step $s, expected 200"
  $MPIRUN -n 2 "$FDEM" run "$CASE" --out "$d" -q --restart "$d/checkpoint.h5" --set time.steps=900 \
    --set output.snapshot_every=100 >"$tmp/re.log" 2>&1 || { cat "$tmp/re.log"; fail "$kind: restart after dying mid-checkpoint"; }
  echo -n "$kind, killed inside the checkpoint of step 300, restarted from 200: "
  bitwise "$ref" "$d" 900 || fail "$kind: restart after dying mid-checkpoint differs"

  # 2. SIGKILL of both ranks at several moments once the first checkpoint (every 20 steps) exists.
  for delay in 0 0.15 0.4; do
    d="$tmp/$kind-kill$delay"
    $MPIRUN -n 2 "$FDEM" run "$CASE" --out "$d" -q --set time.steps=$LONG --set output.checkpoint_every=20 \
      --set output.snapshot_every=100 >"$tmp/kill.log" 2>&1 &
    pid=$!
    for i in $(seq 1 600); do [ -f "$d/checkpoint.h5" ] && break; sleep 0.05; done
    sleep $delay
    ranks=$(ps -o pid= --ppid $pid)
    [ -n "$ranks" ] && kill -KILL $ranks
    wait $pid
    s=$(ck_step "$d/checkpoint.h5") || fail "$kind: no readable checkpoint after kill -9 (delay $delay s)"
    [ "$s" -lt $LONG ] || fail "$kind: the run reached its end before the kill"
    t=$(( (s / 100 + 2) * 100 ))
    $MPIRUN -n 2 "$FDEM" run "$CASE" --out "$d" -q --restart "$d/checkpoint.h5" --set time.steps=$t \
      --set output.snapshot_every=100 >"$tmp/re.log" 2>&1 || { cat "$tmp/re.log"; fail "$kind: restart after kill -9 at step $s"; }
    echo -n "$kind, kill -9 (checkpoint of step $s) and restart to $t: "
    bitwise "$(reference "$CASE" $kind $t)" "$d" $t || fail "$kind: restart after kill -9 differs"
  done
done

# 3. Coupled: SIGTERM writes checkpoint.h5 (DEM and FE state in one file) at the end of a
# sub-cycle and exits 143; the restart ends bitwise equal, with the same particle count.
d="$tmp/term"
$MPIRUN -n 2 "$FDEM" run "$CCASE" --out "$d" -q --set time.steps=$LONG --set output.snapshot_every=100 \
  >"$tmp/term.log" 2>&1 &
pid=$!
for i in $(seq 1 600); do grep -q '"status": "running"' "$d/run.json" 2>/dev/null && break; sleep 0.05; done
sleep 0.3
kill -TERM $(ps -o pid= --ppid $pid)  # the ranks (mpirun itself would abort the job on SIGTERM)
wait $pid; code=$?
[ $code -eq 143 ] || { cat "$tmp/term.log"; fail "coupled run stopped by SIGTERM exited $code, expected 143"; }
[ ! -e "$d/fe_checkpoint.h5" ] || fail "a coupled run wrote fe_checkpoint.h5 (its FE state belongs in checkpoint.h5)"
h5ls "$d/checkpoint.h5/fe" >/dev/null 2>&1 || fail "coupled checkpoint.h5 has no group /fe"
s=$(ck_step "$d/checkpoint.h5"); t=$(( (s / 100 + 2) * 100 ))
$MPIRUN -n 2 "$FDEM" run "$CCASE" --out "$d" -q --restart "$d/checkpoint.h5" --set time.steps=$t \
  --set output.snapshot_every=100 >"$tmp/re.log" 2>&1 || { cat "$tmp/re.log"; fail "restart after SIGTERM"; }
echo -n "coupled, SIGTERM at step $s, restarted to $t: "
bitwise "$(reference "$CCASE" coupled $t)" "$d" $t || fail "coupled restart after SIGTERM differs"
# A run ending inside a sub-cycle (n = 4; 303 steps) keeps the checkpoint of step 300.
d="$tmp/mid"
$MPIRUN -n 2 "$FDEM" run "$CCASE" --out "$d" --set time.steps=303 >"$tmp/mid.log" 2>&1 || { cat "$tmp/mid.log"; fail "303-step run"; }
grep -q "step 303 ends inside a sub-cycle of 4 steps: the checkpoint is the one of step 300" "$tmp/mid.log" \
  || { cat "$tmp/mid.log"; fail "no message about the sub-cycle's checkpoint"; }
[ "$(ck_step "$d/checkpoint.h5")" -eq 300 ] || fail "checkpoint of a run ending at step 303 is not of step 300"
$MPIRUN -n 2 "$FDEM" run "$CCASE" --out "$d" -q --restart "$d/checkpoint.h5" --set time.steps=600 \
  --set output.snapshot_every=100 >"$tmp/re.log" 2>&1 || { cat "$tmp/re.log"; fail "restart from step 300"; }
echo -n "coupled, ended at 303 (inside a sub-cycle), restarted to 600: "
bitwise "$tmp/coupled-ref" "$d" 600 || fail "coupled restart from the sub-cycle's start differs"

# Late in the run, most grains have left the domain (8 of 300 at step 5000): the automatic
# sub-cycle chosen from the grains left would be 6, not 4. The restart keeps the checkpoint's
# (n and dt_DEM are in checkpoint.h5) and continues the trajectory bitwise. (This was found by the
# SIGTERM case above when the signal landed late; it is deterministic here.)
d="$tmp/late"
$MPIRUN -n 2 "$FDEM" run "$CCASE" --out "$d" -q --set time.steps=5000 --set output.snapshot_every=5000 >"$tmp/late.log" 2>&1 \
  || { cat "$tmp/late.log"; fail "5000-step run"; }
$PY -c "import h5py,sys; n=int(h5py.File(sys.argv[1],'r')['fe'].attrs['subcycle']); assert n == 4, n" "$d/checkpoint.h5" \
  || fail "checkpoint.h5 does not record the sub-cycle 4"
$MPIRUN -n 2 "$FDEM" run "$CCASE" --out "$d" -q --restart "$d/checkpoint.h5" --set time.steps=5200 \
  --set output.snapshot_every=100 >"$tmp/re.log" 2>&1 || { cat "$tmp/re.log"; fail "restart from step 5000"; }
echo -n "coupled, 8 grains left at step 5000, restarted to 5200: "
bitwise "$(reference "$CCASE" coupled 5200)" "$d" 5200 || fail "coupled restart with most grains gone differs"

# 4. Damaged and foreign files: exit 2, one message naming the file and the problem.
good="$tmp/coupled-ref/checkpoint.h5"
bad="$tmp/bad"; mkdir -p "$bad"
$PY - "$good" "$bad" <<'PYEOF' || fail "making damaged files"
import sys, shutil, h5py, numpy as np
good, bad = sys.argv[1], sys.argv[2]
def corrupt(src, dst, dset):
    shutil.copy(src, dst)
    with h5py.File(dst, "r") as h:
        info = h[dset].id.get_chunk_info(0)
        off, size = info.byte_offset, info.size
    assert size > 128, (dset, size)
    with open(dst, "r+b") as f:  # 64 bytes in the middle of the dataset's first chunk
        f.seek(off + size // 2 - 32)
        f.write(bytes([0xA5]) * 64)
corrupt(good, bad + "/corrupt.h5", "particles/x")
corrupt(good, bad + "/corrupt_fe.h5", "fe/u")
data = open(good, "rb").read()
open(bad + "/truncated.h5", "wb").write(data[: len(data) // 2])
shutil.copy(good, bad + "/v3.h5")
with h5py.File(bad + "/v3.h5", "r+") as h:
    h.attrs.modify("version", np.int32(3))
with h5py.File(bad + "/random.h5", "w") as h:
    h["x"] = np.arange(10.0)
open(bad + "/text.h5", "w").write("id x y z r\n1 0 0 0 1\n")
PYEOF
cp "$tmp/coupled-ref/fe_00000000.h5" "$bad/snapshot.h5"
expect2() {  # expect2 CASE FILE MESSAGE [--specimen]
  local opt=--restart; [ $# -ge 4 ] && opt=$4
  $MPIRUN -n 2 "$FDEM" run "$1" --out "$tmp/o" -q $opt "$2" >"$tmp/o.log" 2>"$tmp/e.log"; local c=$?
  [ $c -eq 2 ] || { cat "$tmp/o.log" "$tmp/e.log"; fail "$opt $(basename "$2"): exit $c, expected 2"; }
  grep -qF "$2" "$tmp/e.log" && grep -qF "$3" "$tmp/e.log" || { cat "$tmp/e.log"; fail "$opt $(basename "$2"): expected '$3'"; }
  [ "$(grep -c "error" "$tmp/e.log")" -eq 1 ] || { cat "$tmp/e.log"; fail "$opt $(basename "$2"): not exactly one message"; }
  ! grep -qiE "backtrace|MPI_Abort|terminate called" "$tmp/e.log" "$tmp/o.log" || { cat "$tmp/e.log"; fail "crash"; }
  echo "$opt $(basename "$2"): $(head -1 "$tmp/e.log")"
}
expect2 "$CCASE" "$bad/corrupt.h5" "checksum mismatch in dataset /particles/x"
expect2 "$CCASE" "$bad/corrupt_fe.h5" "checksum mismatch in dataset /fe/u"
expect2 "$PCASE" "$bad/corrupt.h5" "checksum mismatch in dataset /particles/x"
expect2 "$CCASE" "$bad/truncated.h5" "truncated or corrupted"
expect2 "$CCASE" "$bad/v3.h5" "checkpoint format version 3, this fdem reads 1-2"
expect2 "$CCASE" "$bad/random.h5" "not an fdem checkpoint"
expect2 "$CCASE" "$bad/snapshot.h5" "not an fdem checkpoint"
expect2 "$PCASE" "$bad/text.h5" "not an HDF5 file"
# A coupled restart from a particle run's checkpoint (no /fe, no fe_checkpoint.h5 next to it).
expect2 "$CCASE" "$tmp/particles-ref/checkpoint.h5" "restarting a coupled run needs the FE state"
# Specimens are checkpoints: the same checks.
expect2 "$SRC/cases/specimens/pack_layers_ci.yaml" "$bad/corrupt.h5" "checksum mismatch in dataset /particles/x" --specimen
expect2 "$SRC/cases/specimens/pack_layers_ci.yaml" "$bad/snapshot.h5" "not an fdem checkpoint" --specimen
echo "kill/restart checks passed"
