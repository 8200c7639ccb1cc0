#!/usr/bin/env bash
# The Slurm batch script (scripts/slurm/fdem.sbatch, docs/user-guide.md#running-on-a-cluster), with
# srun, sbatch and scancel replaced by stand-ins (srun: scripts/mpirun.sh -n 2; the first srun
# sends SIGUSR1 to the ranks mid-run, as Slurm's --signal=USR1@300 does before the time limit):
#  * job 1 queues its continuation (sbatch --dependency=afterany:1001, CHAIN counted down), is
#    stopped by the signal (exit 138, a checkpoint), and exits 0;
#  * job 2 resumes from the checkpoint and finishes; its last snapshot is bitwise the uninterrupted
#    run's;
#  * job 3 finds run.json finished and does nothing (queues nothing);
#  * a run that fails (a bad case: exit 2) exits 2 and cancels the job it queued.
# Usage (ctest): cli_slurm.sh FDEM_BINARY SOURCE_DIR
source "$2/tests/support/cli_common.sh" "$@"
SB="$SRC/scripts/slurm/fdem.sbatch"
CASE="$SRC/cases/demo/settle.yaml"
STEPS=15000
bin="$tmp/bin"; mkdir -p "$bin"
cat >"$bin/srun" <<EOF
#!/usr/bin/env bash
# first call: signal the ranks once the run is under way
if [ ! -f "$tmp/signalled" ]; then
  touch "$tmp/signalled"
  bash "$SRC/scripts/mpirun.sh" -n 2 "\$@" &
  pid=\$!
  for a in "\$@"; do case "\$prev" in --out) out=\$a ;; esac; prev=\$a; done
  for i in \$(seq 1 600); do grep -q '"status": "running"' "\$out/run.json" 2>/dev/null && break; sleep 0.05; done
  sleep 1
  kill -USR1 \$(ps -o pid= --ppid \$pid)
  wait \$pid
  exit \$?
fi
exec bash "$SRC/scripts/mpirun.sh" -n 2 "\$@"
EOF
cat >"$bin/sbatch" <<EOF
#!/usr/bin/env bash
echo "\$*" >>"$tmp/sbatch.log"
echo \$((1001 + \$(wc -l <"$tmp/sbatch.log")))
EOF
cat >"$bin/scancel" <<EOF
#!/usr/bin/env bash
echo "\$*" >>"$tmp/scancel.log"
EOF
chmod +x "$bin"/*
export PATH="$bin:$PATH"
out="$tmp/run"
job() {  # JOB_ID [more env]: one link of the chain
  local id=$1; shift
  env SLURM_JOB_ID="$id" SLURM_SUBMIT_DIR="$SRC" CASE="$CASE" OUT="$out" FDEM="$FDEM" \
    ARGS="--set time.steps=$STEPS --set output.snapshot_every=$STEPS" "$@" bash "$SB" >"$tmp/job$id.log" 2>&1
}

job 1001 CHAIN=5 || { cat "$tmp/job1001.log"; fail "job 1 exited non-zero"; }
grep -q "stopped by the time-limit signal (exit 138)" "$tmp/job1001.log" || { cat "$tmp/job1001.log"; fail "job 1 was not stopped by the signal"; }
[ -f "$out/checkpoint.h5" ] || fail "job 1 left no checkpoint"
grep -q '"status": "interrupted"' "$out/run.json" || fail "run.json not interrupted after job 1"
[ "$(wc -l <"$tmp/sbatch.log")" -eq 1 ] || fail "job 1 queued $(wc -l <"$tmp/sbatch.log") jobs, expected 1"
grep -q -- "--dependency=afterany:1001 " "$tmp/sbatch.log" || { cat "$tmp/sbatch.log"; fail "continuation not after job 1"; }
grep -q "CHAIN=4" "$tmp/sbatch.log" || { cat "$tmp/sbatch.log"; fail "CHAIN not counted down"; }

job 1002 CHAIN=4 || { cat "$tmp/job1002.log"; fail "job 2 exited non-zero"; }
grep -q "resuming from $out/checkpoint.h5" "$tmp/job1002.log" || { cat "$tmp/job1002.log"; fail "job 2 did not resume"; }
grep -q '"status": "finished"' "$out/run.json" || { cat "$tmp/job1002.log"; fail "job 2 did not finish the run"; }

$MPIRUN -n 2 "$FDEM" run "$CASE" --out "$tmp/ref" -q --set time.steps=$STEPS --set output.snapshot_every=$STEPS \
  >"$tmp/ref.log" 2>&1 || { cat "$tmp/ref.log"; fail "reference run"; }
$PY - "$out" "$tmp/ref" $STEPS <<'PYEOF' || fail "the chained run differs from the uninterrupted one"
import sys, h5py, numpy as np
a, b, s = sys.argv[1], sys.argv[2], int(sys.argv[3])
def parts(d):
    with h5py.File("%s/particles_%08d.h5" % (d, s), "r") as h:
        i = np.argsort(h["id"][:])
        return h["id"][:][i], h["position"][:][i], h["velocity"][:][i]
ia, xa, va = parts(a)
ib, xb, vb = parts(b)
assert len(ia) == len(ib) and (ia == ib).all(), (len(ia), len(ib))
assert (xa == xb).all() and (va == vb).all(), np.abs(xa - xb).max()
print("chained run (stopped by SIGUSR1, resumed): %d particles at step %d bitwise equal to the uninterrupted run" % (len(ia), s))
PYEOF

job 1003 CHAIN=3 || { cat "$tmp/job1003.log"; fail "job 3 exited non-zero"; }
grep -q "has finished; nothing to do" "$tmp/job1003.log" || { cat "$tmp/job1003.log"; fail "job 3 did not see the finished run"; }
[ "$(wc -l <"$tmp/sbatch.log")" -eq 2 ] || fail "jobs queued: $(wc -l <"$tmp/sbatch.log"), expected 2 (job 3 queues none)"

printf 'name: x\ntime: {steps: -1}\n' >"$tmp/bad.yaml"
out="$tmp/bad"
job 1004 CHAIN=1 CASE="$tmp/bad.yaml"
code=$?
[ $code -eq 2 ] || { cat "$tmp/job1004.log"; fail "a failing run: the script exited $code, expected 2"; }
grep -q "1004" "$tmp/scancel.log" 2>/dev/null || { cat "$tmp/job1004.log"; fail "the continuation of a failed run was not cancelled"; }
echo "cli_slurm: ok"
