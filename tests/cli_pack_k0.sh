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
#    so does the incremental ratio d s_h / d s_v from the packed state; the plate holds 10 kPa.
# Usage: cli_pack_k0.sh FDEM_BINARY SOURCE_DIR
source "$2/tests/support/cli_common.sh" "$@"
$MPIRUN -n 2 "$FDEM" run "$SRC/cases/specimens/pack_layers_ci.yaml" --out "$tmp/pack" -q \
  --set packing.save="$tmp/s.txt" >"$tmp/pack.log" 2>&1 || { cat "$tmp/pack.log"; fail "packing failed"; }
$MPIRUN -n 2 "$FDEM" run "$SRC/cases/specimens/reuse_ci.yaml" --out "$tmp/load" -q \
  --set particles.0.file.path="$tmp/s.txt" >"$tmp/load.log" 2>&1 || { cat "$tmp/load.log"; fail "loading failed"; }
$PY - "$tmp/pack/packing.json" "$tmp/load/measure.csv" "$tmp/load/walls.csv" <<'PYEOF' || fail "K0"
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
PYEOF
echo ok
