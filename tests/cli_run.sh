#!/usr/bin/env bash
# The command line end to end on 2 ranks: a run stopped by SIGTERM writes a checkpoint and says
# so in run.json; restarting it on 1 rank with --restart continues the same trajectory: the
# final particle positions equal (bitwise) those of an uninterrupted 2-rank run.
# Usage: cli_run.sh FDEM_BINARY SOURCE_DIR
set -u
FDEM=$1; SRC=$2
MPIRUN="bash $SRC/scripts/mpirun.sh"
PY=/usr/bin/python3
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
CASE="$SRC/cases/demo/settle.yaml"
fail() { echo "FAIL: $*"; exit 1; }

# 1. A long run, stopped by SIGTERM once it has written the snapshot of step 1000.
$MPIRUN -n 2 "$FDEM" run "$CASE" --out "$tmp/a" -q --set time.steps=100000000 \
  --set output.snapshot_every=1000 >"$tmp/a.log" 2>&1 &
pid=$!
for i in $(seq 1 600); do [ -f "$tmp/a/particles_00001000.h5" ] && break; sleep 0.1; done
[ -f "$tmp/a/particles_00001000.h5" ] || fail "no snapshot after 60 s"
kill -TERM $pid
wait $pid; code=$?
[ $code -ne 0 ] || fail "a run stopped by a signal exited with 0"
grep -q "writing checkpoint" "$tmp/a.log" || { cat "$tmp/a.log"; fail "no checkpoint message"; }
[ -f "$tmp/a/checkpoint.h5" ] || { cat "$tmp/a.log"; ls "$tmp/a"; fail "no checkpoint written"; }
grep -q '"status": "interrupted"' "$tmp/a/run.json" || fail "run.json does not say interrupted"
stop=$($PY -c "import json;print(json.load(open('$tmp/a/run.json'))['steps'])")
final=$((stop + 500))
echo "stopped at step $stop; continuing to $final"

# 2. Restart on 1 rank up to step $final.
$MPIRUN -n 1 "$FDEM" run "$CASE" --out "$tmp/a" -q --restart "$tmp/a/checkpoint.h5" \
  --set time.steps=$final --set output.snapshot_every=1000 >"$tmp/b.log" 2>&1 || { cat "$tmp/b.log"; fail "restart failed"; }
grep -q '"status": "finished"' "$tmp/a/run.json" || fail "restarted run did not finish"

# 3. The same case uninterrupted on 2 ranks.
$MPIRUN -n 2 "$FDEM" run "$CASE" --out "$tmp/c" -q --set time.steps=$final >"$tmp/c.log" 2>&1 || { cat "$tmp/c.log"; fail "reference run failed"; }

f=$(printf "particles_%08d.h5" $final)
$PY - "$tmp/a/$f" "$tmp/c/$f" <<'PYEOF' || fail "restarted trajectory differs"
import sys, h5py, numpy as np
def load(p):
    with h5py.File(p, "r") as h:
        i = np.argsort(h["id"][:])
        return h["id"][:][i], h["position"][:][i], h["velocity"][:][i]
ia, xa, va = load(sys.argv[1]); ib, xb, vb = load(sys.argv[2])
assert len(ia) > 1000, "too few particles"
assert (ia == ib).all(), "different particle sets"
d = np.abs(xa - xb).max()
print("max position difference restart vs uninterrupted: %.3e m" % d)
assert d == 0.0 and (va == vb).all(), "not bitwise equal"
PYEOF
# run.json's decomposition: the process grid covers the ranks, the owned particles add up to the
# run's, every rank holds ghosts (the bed spans both subdomains), the busiest sender is
# comm_bytes_max_rank.
$PY - "$tmp/c/run.json" "$tmp/c/$f" <<'PYEOF' || fail "run.json decomposition"
import sys, json, h5py
j = json.load(open(sys.argv[1]))
d = j["decomposition"]
g, rk = d["grid"], d["ranks"]
assert g[0] * g[1] * g[2] == j["ranks"] == len(rk) == 2, (g, len(rk))
with h5py.File(sys.argv[2], "r") as h:
    n = len(h["id"])
assert sum(r["owned"] for r in rk) == n == j["particles"]["final"], (rk, n)
assert all(r["ghosts"] > 0 and r["messages"] > 0 for r in rk), rk
assert max(r["bytes_sent"] for r in rk) == j["comm_bytes_max_rank"], (rk, j["comm_bytes_max_rank"])
print("decomposition %s: owned %s, ghosts %s" % (g, [r["owned"] for r in rk], [r["ghosts"] for r in rk]))
PYEOF
# History rows after the checkpoint were replaced, not duplicated.
n=$(grep -c "^$final," "$tmp/a/history.csv")
[ "$n" -eq 1 ] || fail "history.csv has $n rows for step $final"
echo "restart check passed"
