#!/usr/bin/env bash
# Seeded fuzzing of the input readers through the real command line (docs/verification.md):
# every valid case under cases/ (YAML-aware mutations), the sphere files and the mesh formats
# (Gmsh 4.1, the thesis's node/element/restraint/load files) mutated with a fixed seed, each
# mutant through `fdem check`, a sample through `fdem run` on 1 and 2 ranks. Each input must be
# refused with exit 2 and one `...: error: ...` line, or be accepted only where the mutation can
# leave it valid; never a signal, an abort, a hang or exit 1. Known failures owned by other
# parts of the code: XFAIL in tests/support/fuzz_inputs.py (with their finding id).
# Usage: cli_fuzz.sh FDEM_BINARY SOURCE_DIR [fuzz_inputs.py options, e.g. --seed 7 --only settle]
source "$2/tests/support/cli_common.sh" "$@"
shift 2
$PY "$SRC/tests/support/fuzz_inputs.py" --fdem "$FDEM" --src "$SRC" --work "$tmp/fuzz" \
  --seed "${FDEM_FUZZ_SEED:-14}" "$@"
