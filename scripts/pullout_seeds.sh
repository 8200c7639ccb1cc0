#!/usr/bin/env bash
# Realization scatter of a geogrid pullout case (docs/cases/geogrid_pullout.md, "How far apart two
# specimens are"): the case packed with several seeds, each specimen pulled at 49 and 93 kPa, the
# reports, then scripts/pullout_scatter.py over all of them.
#   scripts/pullout_seeds.sh [CASE] [OUT_PREFIX]
#     CASE         default cases/geogrid_pullout/ci.yaml
#     OUT_PREFIX   default out/pullout_seeds: runs in OUT_PREFIX_s<SEED>_49 and _93, the table in
#                  OUT_PREFIX_scatter.csv
#   environment: SEEDS (default "11 12 13 14 15"; the case's own seed is 11), STRESSES (default
#                "49 93": kPa; the first packs, the others start from its specimen), SERVO_WALL
#                (default top: the name of the servo plate among the case's walls), RANKS (default 2),
#                FDEM (default build/fdem)
# A run whose directory already holds a finished run (run.json "finished") is not run again: delete
# the directory to redo it. The CI variant: ~2 min per seed and stress on 2 cores.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(dirname "$here")
case_file=${1:-$root/cases/geogrid_pullout/ci.yaml}
prefix=${2:-out/pullout_seeds}
ranks=${RANKS:-2}
fdem=${FDEM:-$root/build/fdem}
wall=${SERVO_WALL:-top}
[ -x "$fdem" ] || { echo "pullout_seeds.sh: no fdem binary at $fdem (make build, or set FDEM)" >&2; exit 2; }
[ -f "$case_file" ] || { echo "pullout_seeds.sh: no case file $case_file" >&2; exit 2; }
finished() { [ -f "$1/run.json" ] && grep -q '"status": "finished"' "$1/run.json"; }
dirs=()
for seed in ${SEEDS:-11 12 13 14 15}; do
  specimen=()
  for s in ${STRESSES:-49 93}; do
    out="${prefix}_s${seed}_${s}"
    pa=$(awk -v s="$s" 'BEGIN { printf "%.10g", 1000 * s }')
    if finished "$out"; then
      echo "pullout_seeds.sh: $out already finished (delete it to run again)"
    else
      echo "pullout_seeds.sh: seed $seed, $s kPa -> $out ($ranks ranks)"
      bash "$here/mpirun.sh" -n "$ranks" "$fdem" run "$case_file" --out "$out" "${specimen[@]}" \
        --set "packing.seed=$seed" --set "walls[$wall].motion.servo.stress=$pa"
    fi
    [ ${#specimen[@]} -gt 0 ] || specimen=(--specimen "$out/specimen.h5")
    /usr/bin/python3 "$here/pullout_report.py" "$out" --figures "$out/figures" > "$out/report.txt"
    dirs+=("$out")
  done
done
/usr/bin/python3 "$here/pullout_scatter.py" "${dirs[@]}" --csv "${prefix}_scatter.csv"
