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
