#!/usr/bin/env bash
# The spread of a CI case's headline numbers over packing seeds, and the tolerances of its
# reference results from it (tests/reference/<case>.json; docs/verification.md#reference-results):
#   scripts/reference_spread.sh TEST CASE [SEED ...]     (default seeds 2 3 4)
#     TEST   the test that runs the case and checks it, e.g. cli_lab_direct_shear
#     CASE   the reference's name, e.g. direct_shear_ci
# runs tests/TEST.sh once per seed (FDEM_REFERENCE_SEED: the test packs with that seed and leaves
# its numbers in out/reference_spread/CASE instead of checking them), prints each number's range and
# standard deviation over those runs and the reference's own (the case's seed), and writes 2 x the
# range of the four as each number's tolerance with its source.
# Make the reference's values first: FDEM_REFERENCE_UPDATE=1 bash tests/TEST.sh build/fdem .
#   environment: FDEM (default build/fdem), FACTOR (default 2)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
[ $# -ge 2 ] || { echo "usage: scripts/reference_spread.sh TEST CASE [SEED ...]" >&2; exit 2; }
test=$1 case=$2; shift 2
seeds=("$@"); [ ${#seeds[@]} -gt 0 ] || seeds=(2 3 4)
fdem=${FDEM:-$root/build/fdem}
[ -f "$root/tests/$test.sh" ] || { echo "reference_spread.sh: no test tests/$test.sh" >&2; exit 2; }
[ -f "$root/tests/reference/$case.json" ] || {
  echo "reference_spread.sh: no tests/reference/$case.json: make its values first (FDEM_REFERENCE_UPDATE=1 bash tests/$test.sh $fdem $root)" >&2; exit 2; }
keep=$root/out/reference_spread/$case
rm -rf "$keep"; mkdir -p "$keep"
for s in "${seeds[@]}"; do
  echo "reference_spread.sh: $test with packing seed $s"
  FDEM_REFERENCE_SEED=$s FDEM_REFERENCE_KEEP=$keep bash "$root/tests/$test.sh" "$fdem" "$root" >"$keep/seed$s.log" 2>&1 ||
    { tail -20 "$keep/seed$s.log"; echo "reference_spread.sh: $test failed with seed $s (log: $keep/seed$s.log)" >&2; exit 1; }
done
files=()
for s in "${seeds[@]}"; do files+=("$keep/${case}_seed$s.json"); done
/usr/bin/python3 "$root/tests/support/reference.py" spread "$case" "${files[@]}" --write "${FACTOR:-2}"
