#!/usr/bin/env bash
# The direct-shear calibration of the thesis (ch. 3.5; docs/cases/direct_shear.md): the full-size
# box packed the thesis's way (cases/lab/direct_shear_packed.yaml), sheared at the three normal
# stresses for each packing seed, then the report (tau-displacement curves, the tau-sigma_n
# envelope, the Mohr-Coulomb fits, the checks against the thesis's targets).
#   scripts/direct_shear.sh [OUT_PREFIX]
#     OUT_PREFIX   default out/direct_shear: runs in OUT_PREFIX_s<seed>_<sigma_n in kPa>, e.g.
#                  out/direct_shear_s1_13.6; figures and tables in OUT_PREFIX_figures
#   environment: RANKS (default 2), FDEM (default build/fdem), CASE (default
#                cases/lab/direct_shear_packed.yaml; direct_shear_packed_ci.yaml is the CI size),
#                SEEDS (default "1 2": packing
#                seeds; each packs once, at its first normal stress, and the others start from
#                that specimen), SIGMAS (default "13.6 27.3 40.9", kPa)
# A run whose directory already holds a finished run (run.json "finished") is not run again: delete
# the directory to redo it.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(dirname "$here")
prefix=${1:-out/direct_shear}
ranks=${RANKS:-2}
fdem=${FDEM:-$root/build/fdem}
case_file=${CASE:-$root/cases/lab/direct_shear_packed.yaml}
[ -x "$fdem" ] || { echo "direct_shear.sh: no fdem binary at $fdem (make build, or set FDEM)" >&2; exit 2; }
finished() { [ -f "$1/run.json" ] && grep -q '"status": "finished"' "$1/run.json"; }
dirs=()
for seed in ${SEEDS:-1 2}; do
  specimen=()
  for sn in ${SIGMAS:-13.6 27.3 40.9}; do
    out="${prefix}_s${seed}_${sn}"
    dirs+=("$out")
    pa=$(awk -v s="$sn" 'BEGIN { printf "%.10g", 1000 * s }')
    if finished "$out"; then
      echo "direct_shear.sh: $out already finished (delete it to run again)"
    else
      echo "direct_shear.sh: seed $seed, sigma_n = $sn kPa -> $out ($ranks ranks)"
      bash "$here/mpirun.sh" -n "$ranks" "$fdem" run "$case_file" --out "$out" "${specimen[@]}" \
        --set "packing.seed=$seed" --set "walls[top].motion.0.servo.stress=$pa" --set "walls[top].motion.1.servo.stress=$pa"
    fi
    [ ${#specimen[@]} -gt 0 ] || specimen=(--specimen "$out/specimen.h5")
  done
done
/usr/bin/python3 "$here/direct_shear_report.py" "${dirs[@]}" --figures "${prefix}_figures"
