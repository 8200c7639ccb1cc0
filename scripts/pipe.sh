#!/usr/bin/env bash
# The buried pipe (thesis appendix A, problem 8; docs/cases/pipe.md): the run and its report.
#   scripts/pipe.sh VARIANT [OUT]
#     VARIANT  ci (minutes; `make test` runs it in tests/cli_pipe.sh) or full (the thesis's box and
#              holds 50 .. 500 kPa; 50 711 grains of 10 mm: 47 min on 1 rank)
#     OUT      default out/pipe_VARIANT; figures and the report's CSV in OUT/figures
#   environment: RANKS (default 2), FDEM (default build/fdem)
# The case (cases/pipe/VARIANT.yaml and its soil mesh) is written by scripts/pipe_case.py; a run
# whose directory holds a finished run is not run again (delete it to redo it); a run stopped by a
# signal resumes from its checkpoint.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(dirname "$here")
variant=${1:-}
case "$variant" in
  ci | full) ;;
  *) echo "usage: scripts/pipe.sh ci|full [OUT]" >&2; exit 2 ;;
esac
out=${2:-out/pipe_$variant}
ranks=${RANKS:-2}
fdem=${FDEM:-$root/build/fdem}
[ -x "$fdem" ] || { echo "pipe.sh: no fdem binary at $fdem (make build, or set FDEM)" >&2; exit 2; }
case_file="$root/cases/pipe/$variant.yaml"
[ -f "$case_file" ] || /usr/bin/python3 "$here/pipe_case.py" "$variant" "$root/cases/pipe"
if [ -f "$out/run.json" ] && grep -q '"status": "finished"' "$out/run.json"; then
  echo "pipe.sh: $out already finished (delete it to run again)"
else
  restart=()
  [ -f "$out/checkpoint.h5" ] && [ -f "$out/run.json" ] && restart=(--restart "$out/checkpoint.h5")
  echo "pipe.sh: $case_file -> $out ($ranks ranks)"
  bash "$here/mpirun.sh" -n "$ranks" "$fdem" run "$case_file" --out "$out" "${restart[@]}"
fi
/usr/bin/python3 "$here/pipe_report.py" "$out" --figures "$out/figures" --csv "$out/figures/pipe.csv"
