#!/usr/bin/env bash
# One assembly in both codes: the direct-shear CI box (cases/lab/direct_shear_packed_ci.yaml, the
# incremental rolling law) packed by fdem and sheared from the same packing by fdem and by YADE
# 2023.02a (tests/parity/yade_direct_shear.py), then the comparison table and figure
# (tests/parity/direct_shear_compare.py). docs/verification.md, "One assembly: the direct-shear CI
# box in both codes".
#
#   scripts/parity_direct_shear.sh [OUT]           (default out/parity_direct_shear)
#
# Environment: SEEDS fdem's packing seeds ("1 2 3 4": seed 2 is the issue's yardstick, 3 and 4 give
# the range), STRESSES sigma_n in Pa ("13600 40900"; the first one packs, the others start from its
# specimen.h5), YADE_SEEDS the packings YADE shears ("1 2"), FIGURE a PNG path (default
# OUT/parity_direct_shear.png), BUILD (build), NICE (5), PY (/usr/bin/python3). One process at a
# time (fdem on 1 rank, about 1 min a run here; YADE about 2 min): about 20 min for the defaults.
# A run whose lab.csv is complete is not run again (delete it to redo). Diagnostics (not run here):
#   SPECIMEN=OUT/fdem_s1_13600/specimen.txt OUT=DIR FDEM_ROLL=1 yade -n -x tests/parity/yade_direct_shear.py
#   (fdem's rolling values for unequal radii; RATCHET=1 instead: YADE's avoidGranularRatcheting)
set -euo pipefail
cd "$(dirname "$0")/.."
OUT=${1:-out/parity_direct_shear}
BUILD=${BUILD:-build}
SEEDS=${SEEDS:-"1 2 3 4"}
STRESSES=${STRESSES:-"13600 40900"}
YADE_SEEDS=${YADE_SEEDS:-"1 2"}
FIGURE=${FIGURE:-$OUT/parity_direct_shear.png}
N=${NICE:-5}
# PyYAML and matplotlib: the system python (Debian python3-yaml, python3-matplotlib)
PY=${PY:-$( [ -x /usr/bin/python3 ] && echo /usr/bin/python3 || echo python3 )}
CASE=cases/lab/direct_shear_packed_ci.yaml
mkdir -p "$OUT"
first=${STRESSES%% *}
stress_set() { echo "--set walls[top].motion.0.servo.stress=$1 --set walls[top].motion.1.servo.stress=$1"; }
fdem_run() {  # dir, args...
  local dir=$1; shift
  [ -f "$dir/lab.csv" ] && [ "$(grep -c . "$dir/lab.csv")" -ge 53 ] && { echo "parity_direct_shear: $dir done"; return; }
  echo "parity_direct_shear: fdem -> $dir"
  nice -n "$N" bash scripts/mpirun.sh -n 1 "$BUILD/fdem" run "$@" --out "$dir" -q --set rolling_law=incremental >"$dir.log" 2>&1 ||
    { tail -20 "$dir.log"; exit 1; }
}
yade_run() {  # dir, specimen, sigma
  [ -f "$1/lab.csv" ] && { echo "parity_direct_shear: $1 done"; return; }
  echo "parity_direct_shear: yade -> $1"
  SPECIMEN=$2 OUT=$1 SIGMA=$3 nice -n "$N" yade -n -x tests/parity/yade_direct_shear.py >"$1.log" 2>&1 ||
    { tail -20 "$1.log"; exit 1; }
}
command -v yade >/dev/null || { echo "parity_direct_shear: needs Debian's yade (apt-get install yade)"; exit 1; }
for s in $SEEDS; do
  # the specimen of the documented comparison: the thesis's printed protocol (frictionless raining,
  # e 0.50), not the case's friction-on raining (e ~0.85)
  fdem_run "$OUT/fdem_s${s}_$first" "$CASE" --set packing.seed="$s" --set packing.friction=0 $(stress_set "$first")
  for sg in $STRESSES; do
    [ "$sg" = "$first" ] && continue
    fdem_run "$OUT/fdem_s${s}_$sg" "$CASE" --set packing.seed="$s" --specimen "$OUT/fdem_s${s}_$first/specimen.h5" $(stress_set "$sg")
  done
done
# fdem started as YADE starts: seed 1's positions only (no velocities, no contact histories)
"$PY" tests/parity/direct_shear_from_txt.py "$OUT/fdem_s1_$first/specimen.txt" "$OUT/fdem_txt_s1.yaml"
for sg in $STRESSES; do
  fdem_run "$OUT/fdem_txt_s1_$sg" "$OUT/fdem_txt_s1.yaml" $(stress_set "$sg")
done
for s in $YADE_SEEDS; do
  for sg in $STRESSES; do
    yade_run "$OUT/yade_s${s}_$sg" "$OUT/fdem_s${s}_$first/specimen.txt" "$sg"
  done
done
"$PY" tests/parity/direct_shear_compare.py "$OUT" --figure "$FIGURE"
