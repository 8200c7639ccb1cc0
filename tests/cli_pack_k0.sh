#!/usr/bin/env bash
# K0 of a gravity-packed column: cases/specimens/pack_layers_ci.yaml packed WITH friction
# (packing.friction 0.7 = the grains' friction, the way a column deposited by pluviation is):
# the horizontal/vertical stress ratio K0 = (s_xx + s_yy) / (2 s_zz) of the Love-Weber stress
# in the interior box lies between 0.3 and 0.7. (Packed frictionless, as the thesis does for
# density, the column is nearly hydrostatic, K0 ~ 0.9: reported in docs/verification.md.)
# Usage: cli_pack_k0.sh FDEM_BINARY SOURCE_DIR
source "$2/tests/support/cli_common.sh" "$@"
$MPIRUN -n 2 "$FDEM" run "$SRC/cases/specimens/pack_layers_ci.yaml" --out "$tmp/k0" --set packing.friction=0.7 \
  --set materials.0.friction=0.7 --set packing.save="$tmp/s.txt" >"$tmp/k0.log" 2>&1 || { cat "$tmp/k0.log"; fail "packing failed"; }
grep -E "interior |layer [0-9] " "$tmp/k0.log"
$PY - "$tmp/k0/packing.json" <<'PYEOF' || fail "K0"
import json, sys
d = json.load(open(sys.argv[1]))
k0 = d["interior"]["k0"]
s = d["interior"]["stress"]
print(f"K0 {k0:.3f} (s_xx {s[0]:.1f}, s_yy {s[1]:.1f}, s_zz {s[2]:.1f} Pa), porosity {d['interior']['porosity']:.4f}")
assert s[2] > 0
assert 0.3 <= k0 <= 0.7, k0
PYEOF
echo ok
