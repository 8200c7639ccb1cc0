#!/usr/bin/env bash
# Geogrid-reinforced fill over a void (thesis ch. 6; docs/cases/void.md): the unreinforced run
# (n0), the reinforced one (n1) and the reinforced one with a frictionless interface (n1 from n1's
# specimen, the sand-grid and surcharge-grid frictions set to 0: the thesis's parametric run),
# then the report. n1_f0's hold 2 runs at most as many steps as n1's: the two grids are compared
# at the same time after the removal.
#   scripts/void.sh VARIANT [OUT_PREFIX]
#     VARIANT      ci (minutes), slice (the validation slice, `make validate`) or full (the
#                  thesis's size: a cluster)
#     OUT_PREFIX   default out/void_VARIANT: runs in OUT_PREFIX_n0, _n1, _n1_f0; figures and the
#                  report's CSV in OUT_PREFIX_figures
#   environment: RANKS (default 2), FDEM (default build/fdem), RUNS (default "n0 n1 n1_f0")
# A run whose directory already holds a finished run (run.json "finished") is not run again: delete
# the directory to redo it; a run stopped by a signal resumes from its checkpoint.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(dirname "$here")
variant=${1:-}
case "$variant" in
  ci | slice | full) ;;
  *) echo "usage: scripts/void.sh ci|slice|full [OUT_PREFIX]" >&2; exit 2 ;;
esac
prefix=${2:-out/void_$variant}
ranks=${RANKS:-2}
fdem=${FDEM:-$root/build/fdem}
runs=${RUNS:-n0 n1 n1_f0}
[ -x "$fdem" ] || { echo "void.sh: no fdem binary at $fdem (make build, or set FDEM)" >&2; exit 2; }
finished() { [ -f "$1/run.json" ] && grep -q '"status": "finished"' "$1/run.json"; }
# the steps of hold 2 (interface.csv's last row of hold index 1 minus the last of hold 0), or nothing
hold2_steps() {
  [ -f "$1" ] && [ -f "$(dirname "$1")/run.json" ] && grep -q '"status": "finished"' "$(dirname "$1")/run.json" || return 0
  awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) { if ($i == "step") s = i; if ($i == "hold") h = i }; next }
           $h + 0 == 0 { e0 = $s } $h + 0 == 1 { e1 = $s }
           END { if (s && h && e1 != "" && e0 != "" && e1 > e0) print e1 - e0 }' "$1"
}
dirs=()
labels=()
for run in $runs; do
  extra=()
  case "$run" in
    n0) case_file="$root/cases/void/${variant}_n0.yaml"; labels+=("unreinforced") ;;
    n1) case_file="$root/cases/void/${variant}_n1.yaml"; labels+=("reinforced") ;;
    n1_f0)
      case_file="$root/cases/void/${variant}_n1.yaml"
      labels+=("reinforced, interface friction 0")
      [ -f "${prefix}_n1/specimen.h5" ] || { echo "void.sh: n1_f0 needs ${prefix}_n1/specimen.h5 (run n1 first)" >&2; exit 2; }
      # the same specimen; the interface frictionless (interactions 0 and 1: sand-grid, surcharge-grid)
      extra=(--specimen "${prefix}_n1/specimen.h5" --set interactions.0.friction=0 --set interactions.1.friction=0)
      # compared at the same time after the removal: hold 2 no longer than n1's (a slice's grid
      # still sinks when its hold ends, docs/cases/void.md)
      n1_steps=$(hold2_steps "${prefix}_n1/interface.csv")
      if [ -n "$n1_steps" ]; then
        extra+=(--set "fem.max_steps=$n1_steps")
        echo "void.sh: n1_f0: hold 2 at most $n1_steps steps, as n1's"
      else
        echo "void.sh: n1_f0: ${prefix}_n1 has no finished hold 2: n1_f0's holds end as the case says (not time-matched)" >&2
      fi ;;
    *) echo "void.sh: unknown run '$run' (n0, n1, n1_f0)" >&2; exit 2 ;;
  esac
  out="${prefix}_${run}"
  dirs+=("$out")
  if finished "$out"; then
    echo "void.sh: $out already finished (delete it to run again)"
    continue
  fi
  restart=()
  if [ -f "$out/checkpoint.h5" ] && [ -f "$out/run.json" ]; then
    restart=(--restart "$out/checkpoint.h5")
    # the checkpoint holds the grains: the specimen (n1_f0's) is not read again
    [ "${extra[0]:-}" = --specimen ] && extra=("${extra[@]:2}")
  fi
  echo "void.sh: $run: $case_file -> $out ($ranks ranks)"
  bash "$here/mpirun.sh" -n "$ranks" "$fdem" run "$case_file" --out "$out" "${extra[@]}" "${restart[@]}"
done
IFS=,; lab="${labels[*]}"; unset IFS
/usr/bin/python3 "$here/void_report.py" "${dirs[@]}" --labels "$lab" --figures "${prefix}_figures" \
  --csv "${prefix}_figures/void.csv"
