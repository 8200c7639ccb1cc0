#!/usr/bin/env bash
# The reference-results tool itself (tests/support/reference.py; docs/verification.md#reference-results),
# on made-up numbers in a scratch reference directory:
#  - update mode writes the run's values; a new number has no tolerance, so update and check fail
#    until one is measured;
#  - spread over three more "seeds" (0.9, 1.1, 1.2 around the reference's 1.0) gives 2 x the range of
#    the four (0.6) as the tolerance, with its source;
#  - check passes inside the tolerance (1.55), fails outside it (1.65), on a missing number, a new
#    number and a non-finite one, and prints the table;
#  - an exact number fails on any difference; a relative tolerance scales with the value;
#  - the test-side helper (reference_check): with FDEM_REFERENCE_SEED set it keeps the numbers
#    and checks nothing.
# Usage (ctest): cli_reference.sh FDEM_BINARY SOURCE_DIR
source "$2/tests/support/cli_common.sh" "$@"
export FDEM_REFERENCE_DIR="$tmp/ref"
mkdir -p "$FDEM_REFERENCE_DIR"
R="$PY $SRC/tests/support/reference.py"
num() { echo "$1" >"$tmp/n.json"; }
num '{"force": 1.0, "count": 7}'
FDEM_REFERENCE_UPDATE=1 $R check toy "$tmp/n.json" >"$tmp/o" 2>&1 && { cat "$tmp/o"; fail "update with unsourced numbers passed"; }
grep -q "no tolerance yet for: force, count" "$tmp/o" || { cat "$tmp/o"; fail "update: the unsourced numbers not named"; }
$R check toy "$tmp/n.json" >"$tmp/o" 2>&1 && { cat "$tmp/o"; fail "check without tolerances passed"; }
grep -q "NO TOLERANCE" "$tmp/o" || { cat "$tmp/o"; fail "check: no NO TOLERANCE verdict"; }
for s in 2 3 4; do
  v=$(echo "$s" | awk '{print ($1 == 2) ? 0.9 : ($1 == 3) ? 1.1 : 1.2}')
  echo "{\"force\": $v, \"count\": 7}" >"$tmp/toy_seed$s.json"
done
$R spread toy "$tmp/toy_seed2.json" "$tmp/toy_seed3.json" "$tmp/toy_seed4.json" --write 2 >"$tmp/o" 2>&1 || { cat "$tmp/o"; fail "spread"; }
$PY - "$FDEM_REFERENCE_DIR/toy.json" <<'PYEOF' || fail "spread: the tolerances written"
import json, sys
ref = {e["name"]: e for e in json.load(open(sys.argv[1]))["numbers"]}
f = ref["force"]
assert f["kind"] == "abs" and abs(f["tolerance"] - 0.6) < 1e-12, f
assert "4 packings" in f["source"] and "2, 3, 4" in f["source"] and "0.9 .. 1.2" in f["source"], f["source"]
c = ref["count"]  # no spread: the floor, 1e-9 x the value
assert c["kind"] == "abs" and 0 < c["tolerance"] <= 1e-8, c
PYEOF
num '{"force": 1.55, "count": 7}'
$R check toy "$tmp/n.json" >"$tmp/o" 2>&1 || { cat "$tmp/o"; fail "a number inside its tolerance failed"; }
grep -qE "^  force +1 +1.55 +\+-0.6 +ok$" "$tmp/o" || { cat "$tmp/o"; fail "the table's row"; }
for bad in '{"force": 1.65, "count": 7}' '{"force": 1.0}' '{"force": 1.0, "count": 7, "extra": 2}' '{"force": NaN, "count": 7}'; do
  num "$bad"
  $R check toy "$tmp/n.json" >"$tmp/o" 2>&1 && { cat "$tmp/o"; fail "check passed with $bad"; }
  grep -qE "FAIL|MISSING|NEW|NOT A NUMBER" "$tmp/o" || { cat "$tmp/o"; fail "no verdict for $bad"; }
done
$PY - "$FDEM_REFERENCE_DIR/toy.json" <<'PYEOF' || fail "editing the toy reference"
import json, sys
r = json.load(open(sys.argv[1]))
for e in r["numbers"]:
    if e["name"] == "count": e["kind"], e["tolerance"] = "exact", None
    if e["name"] == "force": e["kind"], e["tolerance"] = "rel", 0.1
json.dump(r, open(sys.argv[1], "w"))
PYEOF
num '{"force": 1.09, "count": 7}'; $R check toy "$tmp/n.json" >"$tmp/o" 2>&1 || { cat "$tmp/o"; fail "rel 10 %: 1.09 failed"; }
num '{"force": 1.11, "count": 7}'; $R check toy "$tmp/n.json" >"$tmp/o" 2>&1 && { cat "$tmp/o"; fail "rel 10 %: 1.11 passed"; }
num '{"force": 1.0, "count": 8}'; $R check toy "$tmp/n.json" >"$tmp/o" 2>&1 && { cat "$tmp/o"; fail "exact: 8 for 7 passed"; }
# update keeps the tolerances and sources, takes the values
num '{"force": 1.3, "count": 7}'
FDEM_REFERENCE_UPDATE=1 $R check toy "$tmp/n.json" >"$tmp/o" 2>&1 || { cat "$tmp/o"; fail "update"; }
$PY -c "
import json, sys
r = {e['name']: e for e in json.load(open(sys.argv[1]))['numbers']}
assert r['force']['value'] == 1.3 and r['force']['kind'] == 'rel' and r['force']['tolerance'] == 0.1, r
assert r['count']['kind'] == 'exact' and r['count']['value'] == 7, r" "$FDEM_REFERENCE_DIR/toy.json" || fail "update: tolerances kept"
# the helper in a test: with a seed given, the numbers are kept, not checked
( FDEM_REFERENCE_SEED=5 FDEM_REFERENCE_KEEP="$tmp/keep"; reference_check toy "$tmp/n.json" ) >"$tmp/o" 2>&1 || { cat "$tmp/o"; fail "reference_check with a seed"; }
cmp -s "$tmp/n.json" "$tmp/keep/toy_seed5.json" || fail "reference_check did not keep the numbers of seed 5"
( ref_seed_at packing.seed; FDEM_REFERENCE_SEED=5; ref_seed_at particles.0.generate.seed; echo "${ref_seed[*]}" ) | grep -qx -- "--set particles.0.generate.seed=5" ||
  fail "ref_seed_at"
echo "cli_reference: ok"
