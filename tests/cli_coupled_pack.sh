#!/usr/bin/env bash
# A structure packed into soil, then coupled (cases/coupling/pack_around_plate.yaml, 2 ranks):
# the plate joins the packing after layer 1 as a rigid obstacle (grains overlapping it removed,
# none inside it afterwards, soil below and above it), is held rigid, then released; at the end
# its top carries roughly the weight of the soil column above it.
# Usage (ctest): cli_coupled_pack.sh FDEM_BINARY SOURCE_DIR
source "$2/tests/support/cli_common.sh" "$@"
CASE="$SRC/cases/coupling/pack_around_plate.yaml"
$MPIRUN -n 2 "$FDEM" run "$CASE" --out "$tmp/o" >"$tmp/log" 2>&1 || { tail -30 "$tmp/log"; fail "run"; }
grep -q "structure 'plate' inserted" "$tmp/log" || { cat "$tmp/log"; fail "no 'structure inserted' line"; }
grep -q "step 2000: structure released" "$tmp/log" || { cat "$tmp/log"; fail "not released at step 2000"; }
$PY - "$tmp/o" <<'PYEOF' || fail "packing around the plate / coupled result"
import sys, json, csv, math
d = sys.argv[1]
j = json.load(open(d + "/packing.json"))
s = j["structure"]
assert s["inserted_after_layer"] == 1 and s["triangles"] == 608 and s["grains_removed"] > 0, s
# the plate: x [0, 0.04], y [0.008, 0.032], z [0.021, 0.025]
lo, hi = (0.0, 0.008, 0.021), (0.04, 0.032, 0.025)
worst, below, above = 1e9, 0, 0
for line in open(d + "/specimen.txt"):
    if line.startswith("#") or not line.strip():
        continue
    i, x, y, z, r = line.split()
    p, r = (float(x), float(y), float(z)), float(r)
    dist = math.sqrt(sum(max(lo[k] - p[k], 0, p[k] - hi[k]) ** 2 for k in range(3)))
    if lo[0] <= p[0] <= hi[0] and lo[1] <= p[1] <= hi[1]:
        worst = min(worst, dist / r)
        below += p[2] < lo[2]
        above += p[2] > hi[2]
print("packed: %d grains, %d removed at the insertion; over the plate: %d below, %d above; closest grain "
      "centre at %.3f r from the plate" % (j["particles"], s["grains_removed"], below, above, worst))
assert worst > 0.9, "a grain overlaps the plate by more than 10 % of its radius"
assert below > 50 and above > 50
rows = list(csv.DictReader(open(d + "/interface.csv")))
last = rows[-1]
assert all(float(r["max_fe_displacement"]) == 0.0 for r in rows if int(r["step"]) <= 2000), "moved while rigid"
assert float(last["max_fe_displacement"]) > 0
# the soil column above the plate: its height from the specimen surface, bulk density from the porosity
surf = j["surface_z"]
W = (surf - hi[2]) * (hi[0] - lo[0]) * (hi[1] - lo[1]) * 2650 * (1 - j["interior"]["porosity"]) * 9.81
top = -float(last["top_fz"])
print("top of the plate carries %.4f N; soil column above it %.4f N (ratio %.2f); bottom %.4f N, total %.4f N"
      % (top, W, top / W, float(last["bottom_fz"]), float(last["fz"])))
assert 0.5 < top / W < 1.5
assert abs(float(last["top_fz"]) + float(last["bottom_fz"]) + float(last["rest_fz"]) - float(last["fz"])) < 1e-9
PYEOF

# The packing stopped after layer 1, when the plate has joined it (the signal sent as layer 1's
# checkpoint appears: it stops layer 2 at its first settle check; a singleton run: exit 143), and
# resumed from OUT/checkpoint.h5 on 2 ranks: the plate joins again where it was, layer 2 goes on
# settling, and the specimen and the whole coupled run after it are those of the unstopped run above.
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
"$FDEM" run "$CASE" --out "$tmp/r" >"$tmp/rlog" 2>&1 &
pid=$!
for i in $(seq 1 1200); do [ -f "$tmp/r/checkpoint.h5" ] && break; sleep 0.1; done
kill -TERM $pid
wait $pid; code=$?
[ $code -eq 143 ] || { cat "$tmp/rlog"; fail "the packing was not stopped after layer 1 (exit $code)"; }
$MPIRUN -n 2 "$FDEM" run "$CASE" --out "$tmp/r" --restart "$tmp/r/checkpoint.h5" >"$tmp/rlog2" 2>&1 ||
  { tail -30 "$tmp/rlog2"; fail "resumed run"; }
grep -q "resuming from .*1 of 2 layers done" "$tmp/rlog2" || { cat "$tmp/rlog2"; fail "did not resume after layer 1"; }
cmp "$tmp/o/specimen.txt" "$tmp/r/specimen.txt" || fail "the resumed packing's specimen differs"
cmp "$tmp/o/interface.csv" "$tmp/r/interface.csv" || fail "the coupled run after the resumed packing differs"
echo "resumed after the plate joined: specimen and interface.csv identical to the unstopped run's"
echo "packing around a structure, then coupling: passed"
