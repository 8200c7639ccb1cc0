#!/usr/bin/env bash
# The buried pipe's CI variant, end to end (issue 19 part 2; docs/cases/pipe.md):
#  * cases/pipe/{ci,full}.yaml and their soil meshes are what `scripts/pipe_case.py` writes (byte
#    for byte).
#  * On 2 ranks: 2 997 grains packed in 4 layers around the shell pipe on the Hex20 Mohr-Coulomb
#    soil, the servo plate at 50 and 100 kPa; scripts/pipe_report.py --check: both holds
#    converge, plate force + the grains' weight = -fz of the interface within 2 % (frictionless
#    walls; measured 0.44 % and 0.26 %), the pipe ovalises (dD_v < 0 < dD_h) more at 100 kPa.
#  * The pipe's vertical diameter change is of the modified Iowa formula's order at the last hold:
#    within a factor 3 of its band (E' from 0.5 to 1.5 x the fill's constrained modulus measured
#    from the plate's settlement; measured -1.32 mm against 1.52 .. 4.50 mm at 103 kPa: the lower
#    half tied into the FE soil stiffens the ring). A Hex20 surface loaded at its corners only
#    (before December 2026) punched the soil by 40 mm. The window is a sanity bound, not the
#    magnitude's test: the formula is for a ring in uniform backfill (its own constants, the bedding
#    constant K 0.083-0.110 and E', span more than the factor), and this ring's lower half is tied
#    to the FE soil; the magnitude is held by the reference (tests/reference/pipe_ci.json: dD_v and
#    dD_h at both holds, within 2 x their range over four packing seeds: -1.04 .. -1.29 mm at hold 2).
#  * The holds again on 1 rank from the 2-rank run's specimen: every FE displacement at both hold
#    ends equal bit for bit (1 = 2 ranks, shells tied to Hex20 Mohr-Coulomb soil).
# Usage: cli_pipe.sh FDEM_BINARY SOURCE_DIR
source "$2/tests/support/cli_common.sh" "$@"
$PY "$SRC/scripts/pipe_case.py" ci "$tmp/gen" >"$tmp/gen.log" 2>&1 || { cat "$tmp/gen.log"; fail "pipe_case.py ci"; }
cmp "$tmp/gen/ci.yaml" "$SRC/cases/pipe/ci.yaml" || fail "cases/pipe/ci.yaml is not what scripts/pipe_case.py ci writes"
cmp "$tmp/gen/ci_soil.msh" "$SRC/cases/pipe/ci_soil.msh" || fail "cases/pipe/ci_soil.msh is not what scripts/pipe_case.py ci writes"
$PY "$SRC/scripts/pipe_case.py" full "$tmp/gen" >"$tmp/gen.log" 2>&1 || { cat "$tmp/gen.log"; fail "pipe_case.py full"; }
for f in full.yaml full_soil.msh; do
  cmp "$tmp/gen/$f" "$SRC/cases/pipe/$f" || fail "cases/pipe/$f is not what scripts/pipe_case.py full writes"
done

$MPIRUN -n 2 "$FDEM" run "$SRC/cases/pipe/ci.yaml" --out "$tmp/r2" -q "${ref_seed[@]}" >"$tmp/r2.log" 2>&1 \
  || { tail -30 "$tmp/r2.log"; fail "pipe ci, 2 ranks"; }
$PY "$SRC/scripts/pipe_report.py" "$tmp/r2" --csv "$tmp/r2.csv" --check || fail "pipe report checks"
"$FDEM" run "$SRC/cases/pipe/ci.yaml" --out "$tmp/r1" --specimen "$tmp/r2/specimen.h5" -q >"$tmp/r1.log" 2>&1 \
  || { tail -30 "$tmp/r1.log"; fail "pipe ci holds, 1 rank"; }

$PY - "$tmp" <<'PYEOF' || fail "pipe ci"
import sys, csv, glob, os
import h5py, numpy as np
t = sys.argv[1]
rows = list(csv.DictReader(open(t + "/r2.csv")))
assert len(rows) == 2, "two holds expected, got %d" % len(rows)
last = rows[-1]
dv, lo, hi = -float(last["dDv_mm"]), float(last["iowa_lo_mm"]), float(last["iowa_hi_mm"])
print("pipe ci: -dD_v %.3f mm at sigma_v %.1f kPa; Iowa band %.3f .. %.3f mm" % (dv, float(last["sigma_v"]) / 1e3, lo, hi))
assert lo / 3 <= dv <= 3 * hi, "the vertical diameter change is not of the Iowa formula's order"
steps = [int(r["step"]) for r in rows]
for s in steps:
    a = h5py.File("%s/r2/fe_%08d.h5" % (t, s), "r")["nodes/displacement"][:]
    b = h5py.File("%s/r1/fe_%08d.h5" % (t, s), "r")["nodes/displacement"][:]
    print("pipe ci: step %d: max |u| %.4e m, max |u(2 ranks) - u(1 rank)| %.1e" % (s, np.abs(a).max(), np.abs(a - b).max()))
    assert np.array_equal(a, b), "1 and 2 ranks differ at step %d" % s
# the case page's headline numbers (docs/cases/pipe.md): the diameter changes at each hold
import json
numbers = {}
for k, r in enumerate(rows, 1):
    for c in ("dDv_mm", "dDh_mm"):
        numbers["hold%d_%s" % (k, c)] = float(r[c])
json.dump(numbers, open(t + "/numbers.json", "w"), indent=1)
PYEOF
reference_check pipe_ci "$tmp/numbers.json"
echo "cli_pipe: ok"
