#!/usr/bin/env bash
# K0 of a gravity-packed column, the honest protocol (docs/verification.md#specimens-and-packing):
# cases/specimens/pack_layers_ci.yaml packs the column FRICTIONLESS (the thesis's procedure, for
# density), then restores the sand's friction (0.5) and settles; cases/specimens/reuse_ci.yaml
# loads that specimen, friction on, with a servo plate at 10 kPa (~10x its own weight) between
# frictionless walls -- one-dimensional compression, what a user does next.
#  - as packed (frictionless, friction restored): nearly hydrostatic, K0 > 0.75 (frictionless
#    grains carry almost no shear; restoring friction does not change the stress state);
#  - under the surcharge, friction on: K0 = (s_xx + s_yy) / (2 s_zz) of the Love-Weber stress in
#    the interior box lies between 0.3 and 0.7 (issue 5), steady over the last measurements, and
#    so does the incremental ratio d s_h / d s_v from the packed state; the plate holds 10 kPa;
#  - gravity only: one more layer poured over it WITH friction (cases/specimens/overburden_ci.yaml,
#    settle.unbalanced 0.02 here): K0 of the old interior box lies between 0.3 and 0.7, below the
#    as-packed value, steady to 2 % over the last two measurements.
#  - the step-0 measurement of the loaded specimen sees its contacts (Z > 3) and the packed,
#    nearly hydrostatic stress (K0 0.75-1.05): it is taken once the first forces are computed.
# Usage: cli_pack_k0.sh FDEM_BINARY SOURCE_DIR
source "$2/tests/support/cli_common.sh" "$@"
$MPIRUN -n 2 "$FDEM" run "$SRC/cases/specimens/pack_layers_ci.yaml" --out "$tmp/pack" -q \
  --set packing.save="$tmp/s.txt" "${ref_seed[@]}" >"$tmp/pack.log" 2>&1 || { cat "$tmp/pack.log"; fail "packing failed"; }
$MPIRUN -n 2 "$FDEM" run "$SRC/cases/specimens/reuse_ci.yaml" --out "$tmp/load" -q \
  --set particles.0.file.path="$tmp/s.txt" >"$tmp/load.log" 2>&1 || { cat "$tmp/load.log"; fail "loading failed"; }
$MPIRUN -n 2 "$FDEM" run "$SRC/cases/specimens/overburden_ci.yaml" --out "$tmp/ob" -q --set packing.settle.unbalanced=0.02 \
  --set particles.0.file.path="$tmp/s.txt" >"$tmp/ob.log" 2>&1 || { cat "$tmp/ob.log"; fail "overburden layer failed"; }
$PY - "$tmp/pack/packing.json" "$tmp/load/measure.csv" "$tmp/load/walls.csv" "$tmp/ob/measure.csv" <<'PYEOF' || fail "K0"
import csv, json, sys
d = json.load(open(sys.argv[1]))
s0 = d["interior"]["stress"]
k_packed = d["interior"]["k0"]
rows = [r for r in csv.DictReader(open(sys.argv[2])) if float(r["szz"]) > 0]
last = rows[-1]
sh, sv = 0.5 * (float(last["sxx"]) + float(last["syy"])), float(last["szz"])
k = sh / sv
k_prev = 0.5 * (float(rows[-2]["sxx"]) + float(rows[-2]["syy"])) / float(rows[-2]["szz"])
k_inc = (sh - 0.5 * (s0[0] + s0[1])) / (sv - s0[2])
plate = float(list(csv.DictReader(open(sys.argv[3])))[-1]["top_stress"])
print(f"packed frictionless (friction restored): K0 {k_packed:.3f} (s_h {0.5*(s0[0]+s0[1]):.0f}, s_v {s0[2]:.0f} Pa)")
print(f"under the 10 kPa plate, friction on: K0 {k:.3f} (s_h {sh:.0f}, s_v {sv:.0f} Pa; previous measurement {k_prev:.3f}); "
      f"incremental d s_h / d s_v {k_inc:.3f}; plate {plate:.0f} Pa")
assert s0[2] > 0 and 0.75 < k_packed < 1.05, k_packed
assert abs(plate / 1e4 - 1) < 0.01, plate
assert 0.3 <= k <= 0.7, k
assert abs(k - k_prev) < 0.01 * k, (k, k_prev)
assert 0.3 <= k_inc <= 0.7, k_inc
ob = [r for r in csv.DictReader(open(sys.argv[4])) if float(r["szz"]) > 0]
kob = [0.5 * (float(r["sxx"]) + float(r["syy"])) / float(r["szz"]) for r in ob]
print(f"one more layer poured with friction on: K0 of the old interior {kob[-1]:.3f} (previous {kob[-2]:.3f}; s_v {float(ob[-1]['szz']):.0f} Pa)")
assert 0.3 <= kob[-1] <= 0.7 and kob[-1] < k_packed, kob
assert abs(kob[-1] - kob[-2]) < 0.02 * kob[-1], kob
# the step-0 measurement of the loaded specimen is taken once its contact forces are computed
# (inside the first step): the packed state's stress and contacts, not zeros
r0 = next(r for r in csv.DictReader(open(sys.argv[2])) if int(float(r["step"])) == 0)
k0_step0 = 0.5 * (float(r0["sxx"]) + float(r0["syy"])) / float(r0["szz"]) if float(r0["szz"]) > 0 else float("nan")
print(f"the loaded specimen at step 0: Z {float(r0['Z']):.2f}, s_zz {float(r0['szz']):.0f} Pa, K0 {k0_step0:.3f}")
assert float(r0["Z"]) > 3 and float(r0["szz"]) > 0 and 0.75 < k0_step0 < 1.05, r0
# the headline numbers (docs/verification.md#specimens-and-packing) for the reference
import os
json.dump({"porosity": d["interior"]["porosity"], "k0_packed": k_packed, "k0_plate": k, "k0_incremental": k_inc,
           "k0_overburden": kob[-1]}, open(os.path.join(os.path.dirname(sys.argv[1]), "..", "numbers.json"), "w"), indent=1)
PYEOF
reference_check pack_k0_ci "$tmp/numbers.json"
echo ok
