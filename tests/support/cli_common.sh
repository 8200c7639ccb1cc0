# Sourced by the command-line tests (tests/cli_*.sh, run by ctest as `cli_X.sh FDEM_BINARY SOURCE_DIR`):
#   source "$2/tests/support/cli_common.sh" "$@"
# sets FDEM (the binary), SRC (the source tree), MPIRUN (scripts/mpirun.sh), PY (Debian's python3),
# tmp (a temporary directory, removed at exit) and fail() (message, exit 1); Python snippets can
# import tests/support/fe_out.py (FE output of a run directory).
set -u
FDEM=$1; SRC=$2
MPIRUN="bash $SRC/scripts/mpirun.sh"
PY=/usr/bin/python3
export PYTHONPATH="$SRC/tests/support${PYTHONPATH:+:$PYTHONPATH}"
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }
# Reference results (tests/reference/<case>.json, tests/support/reference.py): `ref_seed` is the
# packing seed a test adds to its packing run (empty unless FDEM_REFERENCE_SEED is set, as
# scripts/reference_spread.sh sets it to measure the numbers' spread over seeds);
# `reference_check CASE NUMBERS.json` compares a run's numbers with the reference (or, with a seed
# given, leaves them in FDEM_REFERENCE_KEEP for the spread; FDEM_REFERENCE_UPDATE=1: rewrites them).
# (`ref_seed_at KEY`: the seed's key for a case without packing, e.g. particles.0.generate.seed)
ref_seed_at() { ref_seed=(); if [ -n "${FDEM_REFERENCE_SEED:-}" ]; then ref_seed=(--set "$1=$FDEM_REFERENCE_SEED"); fi; }
ref_seed_at packing.seed
reference_check() {
  if [ -n "${FDEM_REFERENCE_SEED:-}" ]; then
    mkdir -p "${FDEM_REFERENCE_KEEP:?set FDEM_REFERENCE_KEEP: where to leave the numbers of seed $FDEM_REFERENCE_SEED}"
    cp "$2" "$FDEM_REFERENCE_KEEP/$1_seed$FDEM_REFERENCE_SEED.json" || fail "cannot keep the numbers in $FDEM_REFERENCE_KEEP"
    echo "reference: the numbers of $1 with packing seed $FDEM_REFERENCE_SEED are in $FDEM_REFERENCE_KEEP (not checked)"
    return 0
  fi
  $PY "$SRC/tests/support/reference.py" check "$1" "$2" --runs "tests/$(basename "$0") (seed: the case's)" || fail "the reference results of $1 (tests/reference/$1.json)"
}
