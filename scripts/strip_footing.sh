#!/usr/bin/env bash
# Strip footing on geogrid-reinforced sand (thesis ch. 5; docs/cases/strip_footing.md): runs
# N = 0, 1 and 2 grid layers of one variant and the report.
#   scripts/strip_footing.sh VARIANT [OUT_PREFIX]
#     VARIANT      ci (minutes), slice (the validation slice, `make validate`) or full (the
#                  thesis's size: a cluster); or phi: drained triaxial tests of the footing's sand
#                  (cases/strip_footing/triaxial_sand.yaml, ~1-2 min each) at the confining
#                  stresses SIGMAS and the same in plane strain (the y walls fixed while loading),
#                  the friction angles for the classical bearing capacity
#     OUT_PREFIX   default out/footing_VARIANT: runs in OUT_PREFIX_n0, _n1, _n2 (phi: OUT_PREFIX_5,
#                  _10, ... by sigma_3 in kPa, plane strain OUT_PREFIX_ps_5, ...), figures and the
#                  report's tables in OUT_PREFIX_figures
#   environment: RANKS (default 2), FDEM (default build/fdem), NS (default "0 1 2": which N to run),
#                SIGMAS (phi; default "5 10 25 50": sigma_3 in kPa; the first run packs the
#                specimen, the others start from it), TRIAXIAL (ci/slice/full: the output
#                directories of a phi run, passed to the report's --triaxial)
# A run whose directory already holds a finished run (run.json "finished") is not run again: delete
# the directory to redo it; a run stopped by a signal resumes from its checkpoint.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(dirname "$here")
variant=${1:-}
case "$variant" in
  ci | slice | full | phi) ;;
  *) echo "usage: scripts/strip_footing.sh ci|slice|full|phi [OUT_PREFIX]" >&2; exit 2 ;;
esac
prefix=${2:-out/footing_$variant}
ranks=${RANKS:-2}
fdem=${FDEM:-$root/build/fdem}
ns=${NS:-0 1 2}
[ -x "$fdem" ] || { echo "strip_footing.sh: no fdem binary at $fdem (make build, or set FDEM)" >&2; exit 2; }
finished() { [ -f "$1/run.json" ] && grep -q '"status": "finished"' "$1/run.json"; }
if [ "$variant" = phi ]; then
  case_file="$root/cases/strip_footing/triaxial_sand.yaml"
  specimen=()
  for test in triaxial plane; do
    dirs=()
    for s3 in ${SIGMAS:-5 10 25 50}; do
      if [ $test = triaxial ]; then out="${prefix}_${s3}"; else out="${prefix}_ps_${s3}"; fi
      dirs+=("$out")
      pa=$(awk -v s="$s3" 'BEGIN { printf "%.10g", 1000 * s }')
      sets=()
      for w in xmin xmax ymin ymax; do sets+=(--set "walls[$w].motion.servo.stress=$pa"); done
      for w in bottom top; do sets+=(--set "walls[$w].motion.0.servo.stress=$pa"); done
      if [ $test = plane ]; then  # plane strain: the y walls stop where the isotropic stage left them
        for w in ymin ymax; do
          sets+=(--set "walls[$w].motion=[{servo: {stress: $pa, area: {between: [[xmin, xmax], [bottom, top]]}, max_velocity: 0.05}}, {from_step: 20000, fixed: true}]")
        done
      fi
      if finished "$out"; then
        echo "strip_footing.sh: $out already finished (delete it to run again)"
      else
        echo "strip_footing.sh: $test, sigma_3 = $s3 kPa -> $out ($ranks ranks)"
        bash "$here/mpirun.sh" -n "$ranks" "$fdem" run "$case_file" --out "$out" "${specimen[@]}" "${sets[@]}"
      fi
      [ ${#specimen[@]} -gt 0 ] || specimen=(--specimen "$out/specimen.h5")
    done
    mkdir -p "${prefix}_figures"
    /usr/bin/python3 "$here/plot_lab.py" "${dirs[@]}" --png "${prefix}_figures/$test.png"
  done
  exit 0
fi
dirs=()
for n in $ns; do
  case_file="$root/cases/strip_footing/${variant}_n${n}.yaml"
  [ -f "$case_file" ] || { echo "strip_footing.sh: no case $case_file" >&2; exit 2; }
  out="${prefix}_n${n}"
  dirs+=("$out")
  if finished "$out"; then
    echo "strip_footing.sh: $out already finished (delete it to run again)"
    continue
  fi
  restart=()
  [ -f "$out/checkpoint.h5" ] && restart=(--restart "$out/checkpoint.h5")
  echo "strip_footing.sh: N = $n: $case_file -> $out ($ranks ranks)"
  bash "$here/mpirun.sh" -n "$ranks" "$fdem" run "$case_file" --out "$out" "${restart[@]}"
done
tri=()
[ -z "${TRIAXIAL:-}" ] || tri=(--triaxial $TRIAXIAL)
/usr/bin/python3 "$here/footing_report.py" "${dirs[@]}" --figures "${prefix}_figures" "${tri[@]}"
