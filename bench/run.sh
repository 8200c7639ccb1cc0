#!/usr/bin/env bash
# Dense-packing benchmark: fdem vs LIGGGHTS 3.8 and LAMMPS on 1 and 2 ranks, on the same settled bed.
#   bash bench/run.sh [N] [STEPS]        (make bench = bash bench/run.sh)
# N      spheres (default 100000; also $BENCH_N)
# STEPS  measured steps per run (default 3000; also $BENCH_STEPS)
# $LIGGGHTS  the LIGGGHTS binary (default: liggghts on PATH); missing -> its runs are skipped.
# $LAMMPS    the LAMMPS binary (default: lmp on PATH, Debian's lammps); missing -> skipped.
#
# 1. Preparation (not measured; cached in bench/work/): settle N spheres with bench/settle.yaml
#    on 2 ranks, convert the last snapshot to bench/work/spheres_N.txt
#    (scripts/h5_to_spheres.py) and to a LIGGGHTS data file (bench/spheres_to_liggghts.py).
#    Delete bench/work/ (or bench/work/spheres_N.txt) to redo it.
# 2. Measured: fdem (bench/dense.yaml), fdem on the same bed with its ids renumbered in space
#    order (bench/spheres_space_order.py: fdem orders grains by space-following keys, not ids, so
#    the two should agree within the machine's noise), LIGGGHTS (bench/in.dense)
#    and LAMMPS (bench/in.dense.lammps) on 1 and 2 ranks, one after the other, each STEPS steps
#    from the same dense state, no output during the run.
# 3. bench/report.py prints the table and writes bench/results/latest.json and latest.md.
# Builds nothing: build/fdem must exist (make build).
set -euo pipefail
cd "$(dirname "$0")/.."
N=${1:-${BENCH_N:-100000}}
STEPS=${2:-${BENCH_STEPS:-3000}}
PY=/usr/bin/python3
FDEM=build/fdem
MPIRUN="bash $PWD/scripts/mpirun.sh"
WORK=${BENCH_WORK:-bench/work}
SETTLE_STEPS=${BENCH_SETTLE_STEPS:-35000}   # fixed (bench/settle.yaml): the bed rests from ~29 000
LIGGGHTS=${LIGGGHTS:-liggghts}
LAMMPS=${LAMMPS:-lmp}

if [[ ! -x $FDEM ]]; then
  echo "bench/run.sh: $FDEM not found; build it first (make build, or" >&2
  echo "  cmake -S . -B build -DCMAKE_BUILD_TYPE=Release && cmake --build build -j2 --target fdem)" >&2
  exit 1
fi
mkdir -p "$WORK" bench/results

# ---------------------------------------------------------------- preparation (not measured)
SPHERES=$WORK/spheres_$N.txt
SETTLE=$WORK/settle_$N
if [[ ! -s $SPHERES && -f $SETTLE/run.json ]] && grep -q '"status": "finished"' "$SETTLE/run.json"; then
  echo "== using the finished settling run in $SETTLE"
  LAST=$(ls "$SETTLE"/particles_*.h5 | sort | tail -n 1)
  $PY scripts/h5_to_spheres.py "$LAST" "$SPHERES"
elif [[ ! -s $SPHERES ]]; then
  # Generation box height scales with N (0.16 m for 100 000: solid fraction ~0.27).
  H=$($PY -c "print(f'{0.16 * $N / 100000:.6g}')")
  ZMAX=$($PY -c "print(f'{0.16 * $N / 100000 + 0.01:.6g}')")
  echo "== preparing the dense state: settling $N spheres (bench/settle.yaml, 2 ranks; not measured)"
  rm -rf "$SETTLE"
  $MPIRUN -n 2 $FDEM run bench/settle.yaml --out "$SETTLE" \
    --set particles.0.generate.count=$N \
    --set "particles.0.generate.box.max=[0.1, 0.1, $H]" \
    --set "domain.max=[0.102, 0.102, $ZMAX]" --set time.steps=$SETTLE_STEPS | tee "$WORK/settle_$N.log"
  LAST=$(ls "$SETTLE"/particles_*.h5 | sort | tail -n 1)
  $PY scripts/h5_to_spheres.py "$LAST" "$SPHERES.tmp"
  mv "$SPHERES.tmp" "$SPHERES"
else
  echo "== using the cached dense state $SPHERES (delete it to settle again)"
fi
# settled? last history line: step,time,particles,kinetic_energy,unbalanced,contacts
if [[ -f $SETTLE/history.csv ]]; then
  tail -n 1 "$SETTLE/history.csv" | awk -F, '{printf "   settled state: step %d, %d particles, kinetic energy %.3g J, unbalanced ratio %.3g, %d contacts\n", $1, $3, $4, $5, $6;
     if ($5 > 0.05) print "   WARNING: unbalanced ratio above 0.05: the bed is not at rest"}'
  tail -n 1 "$SETTLE/history.csv" | awk -F, '{printf "{\"step\": %d, \"particles\": %d, \"kinetic_energy\": %.6g, \"unbalanced\": %.6g, \"contacts\": %d}\n", $1, $3, $4, $5, $6}' > "$WORK/settle_$N.json"
fi

# Bed top and the common box: x, y in [-0.002, 0.102], z in [-0.002, top + 0.005]
ZTOP=$(awk '!/^#/ && NF == 5 { t = $4 + $5; if (t > m) m = t } END { printf "%.6f", m + 0.005 }' "$SPHERES")
NREAD=$(grep -vc '^#' "$SPHERES")
echo "   $NREAD spheres, bed top + 5 mm = $ZTOP m"
DATA=$WORK/dense_$N.data
if [[ ! -s $DATA || $DATA -ot $SPHERES ]]; then
  $PY bench/spheres_to_liggghts.py "$SPHERES" "$DATA" --box -0.002 0.102 -0.002 0.102 -0.002 "$ZTOP" --density 2640
fi

# ---------------------------------------------------------------- measured runs
# run_fdem NAME SPHERE_FILE LABEL: fdem on 1 and 2 ranks from the sphere file, into WORK/NAME_n{1,2}
run_fdem() {
  local name=$1 spheres=$2 label=$3
  for P in 1 2; do
    echo "== fdem$label, $P rank(s), $STEPS steps"
    rm -rf "$WORK/${name}_n$P"
    $MPIRUN -n $P $FDEM run bench/dense.yaml --out "$WORK/${name}_n$P" \
      --set "particles.0.file.path=$(realpath "$spheres")" \
      --set "domain.max=[0.102, 0.102, $ZTOP]" \
      --set time.steps=$STEPS > "$WORK/${name}_n$P.log" 2>&1 || { cat "$WORK/${name}_n$P.log"; exit 1; }
    grep -E "^fdem: (finished|time per stage)" "$WORK/${name}_n$P.log" | sed 's/^/   /'
  done
}
run_fdem fdem "$SPHERES" ""

# The same bed with its ids renumbered along a Morton curve (bench/spheres_space_order.py): the
# settled bed's ids (the generation's) are scattered in space; fdem orders grains and pairs by
# order keys that follow space (src/dem/particles.hpp), so the numbering should not matter
# (before the keys it did: docs/performance.md#order-keys).
SPACE=$WORK/spheres_${N}_space.txt
if [[ ! -s $SPACE || $SPACE -ot $SPHERES ]]; then
  $PY bench/spheres_space_order.py "$SPHERES" "$SPACE"
fi
run_fdem fdem_space "$SPACE" ", ids in space order"

# run_peer NAME BINARY INPUT LOGPREFIX DEBIAN_PACKAGE: the peer on 1 and 2 ranks from bench/work (so
# that nothing it may write lands in the source tree); prints the reason to skip when the binary is
# missing, nothing otherwise.
run_peer() {
  local name=$1 bin=$2 input=$3 log=$4 pkg=$5
  if ! command -v "$bin" > /dev/null 2>&1; then
    echo "$name binary '$bin' not found (install the Debian package $pkg or set ${name^^}=/path/to/binary)"
    return 0
  fi
  for P in 1 2; do
    echo "== $name, $P rank(s), $STEPS steps" >&2
    ( cd "$WORK" && $MPIRUN -n $P "$bin" -in "$OLDPWD/$input" -echo none -log none \
        -var datafile "$(basename "$DATA")" -var steps "$STEPS" -var skin 0.0002 ) \
      > "$WORK/${log}_n$P.log" 2>&1 || { tail -n 30 "$WORK/${log}_n$P.log" >&2; exit 1; }
    grep -E "^Loop time" "$WORK/${log}_n$P.log" | sed 's/^/   /' >&2
  done
}
LIG_SKIP=$(run_peer LIGGGHTS "$LIGGGHTS" bench/in.dense liggghts liggghts)
[ -z "$LIG_SKIP" ] || echo "== SKIPPING the LIGGGHTS runs: $LIG_SKIP"
LMP_SKIP=$(run_peer LAMMPS "$LAMMPS" bench/in.dense.lammps lammps lammps)
[ -z "$LMP_SKIP" ] || echo "== SKIPPING the LAMMPS runs: $LMP_SKIP"

$PY bench/report.py --n "$N" --steps "$STEPS" --work "$WORK" --out bench/results \
  --settle-info "$WORK/settle_$N.json" ${LIG_SKIP:+--lig-skipped "$LIG_SKIP"} ${LMP_SKIP:+--lammps-skipped "$LMP_SKIP"}
