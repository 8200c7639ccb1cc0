#!/usr/bin/env bash
# Strip footing on geogrid-reinforced sand (thesis ch. 5; docs/cases/strip_footing.md): runs
# N = 0, 1 and 2 grid layers of one variant and the report.
#   scripts/strip_footing.sh VARIANT [OUT_PREFIX]
#     VARIANT      ci (minutes), slice (the validation slice, `make validate`) or full (the
#                  thesis's size: a cluster)
#     OUT_PREFIX   default out/footing_VARIANT: runs in OUT_PREFIX_n0, _n1, _n2, figures and the
#                  report's tables in OUT_PREFIX_figures
#   environment: RANKS (default 2), FDEM (default build/fdem), NS (default "0 1 2": which N to run)
# A run whose directory already holds a finished run (run.json "finished") is not run again: delete
# the directory to redo it; a run stopped by a signal resumes from its checkpoint.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(dirname "$here")
variant=${1:-}
case "$variant" in
  ci | slice | full) ;;
  *) echo "usage: scripts/strip_footing.sh ci|slice|full [OUT_PREFIX]" >&2; exit 2 ;;
esac
prefix=${2:-out/footing_$variant}
ranks=${RANKS:-2}
fdem=${FDEM:-$root/build/fdem}
ns=${NS:-0 1 2}
[ -x "$fdem" ] || { echo "strip_footing.sh: no fdem binary at $fdem (make build, or set FDEM)" >&2; exit 2; }
dirs=()
for n in $ns; do
  case_file="$root/cases/strip_footing/${variant}_n${n}.yaml"
  [ -f "$case_file" ] || { echo "strip_footing.sh: no case $case_file" >&2; exit 2; }
  out="${prefix}_n${n}"
  dirs+=("$out")
  if [ -f "$out/run.json" ] && grep -q '"status": "finished"' "$out/run.json"; then
    echo "strip_footing.sh: $out already finished (delete it to run again)"
    continue
  fi
  restart=()
  [ -f "$out/checkpoint.h5" ] && restart=(--restart "$out/checkpoint.h5")
  echo "strip_footing.sh: N = $n: $case_file -> $out ($ranks ranks)"
  bash "$here/mpirun.sh" -n "$ranks" "$fdem" run "$case_file" --out "$out" "${restart[@]}"
done
/usr/bin/python3 "$here/footing_report.py" "${dirs[@]}" --figures "${prefix}_figures"
