#!/usr/bin/env bash
# FE memory per rank (docs/performance.md#fe-mesh-memory): Hex8 blocks of bench/fe_block.yaml at
# three sizes (25 000, 200 000 and 800 000 elements), 10 dynamic-relaxation steps on 1, 2 and 4
# ranks (oversubscribed is fine); each rank's peak resident memory from run.json (fe_partition). The
# mesh is read identically on every rank and METIS-split; the per-element data (element
# matrices, state, ghosted vectors) are held by the owners only. The figures give the replicated
# part per element and the rank count where it would be half of a rank's memory. The same with
# fem.distribute: rank 0 builds the whole mesh and sends the parts; the others hold their part only.
# Then a coupled case replicated and distributed (a sphere on a 200 000-element plate). And a
# restart: the 200 000-element block distributed on 4 ranks, one hold of 10 steps (its FE
# checkpoint), restarted for a second hold of 10 steps: the restart's peak against the first run's
# (the checkpoint is read by rows: each rank 1/P, sent to the owners).
#   bash bench/fe_memory.sh            output: bench/results/fe_memory.txt
set -euo pipefail
cd "$(dirname "$0")/.."
FDEM=${FDEM:-build/fdem}
[ -x "$FDEM" ] || { echo "fe_memory.sh: $FDEM not found; run 'make build' first" >&2; exit 2; }
W=bench/work/fe_memory; rm -rf "$W"; mkdir -p "$W" bench/results
peak() {  # run.json -> "busiest rank" and "busiest rank but rank 0" (MB)
  /usr/bin/python3 -c "import json, sys
r = [x['peak_rss_mb'] for x in json.load(open(sys.argv[1]))['fe_partition']['ranks']]
print(round(max(r)), round(max(r[1:])) if len(r) > 1 else '-')" "$1"
}
{
  echo "# bench/fe_memory.sh: Hex8 block, 10 relaxation steps; peak resident memory (MB) of the busiest rank;"
  echo "# distributed (fem.distribute): busiest rank / busiest rank but rank 0 (which builds the whole mesh)"
  printf "%10s %8s %8s %8s %14s %14s %14s\n" elements 1_rank 2_ranks 4_ranks dist_1_rank dist_2_ranks dist_4_ranks
  for div in "50, 25, 20" "100, 50, 40" "200, 100, 40"; do
    n=$(echo "$div" | tr -d ' ' | awk -F, '{print $1 * $2 * $3}')
    row="$(printf "%10d" "$n")"
    for dist in false true; do
      for np in 1 2 4; do
        rm -rf "$W/x"
        bash scripts/mpirun.sh -n "$np" "$FDEM" run bench/fe_block.yaml --out "$W/x" -q --set fem.max_steps=10 \
          --set fem.check_every=10 --set "fem.meshes.0.block.divisions=[$div]" --set fem.distribute=$dist >/dev/null
        read -r busiest others <<<"$(peak "$W/x/run.json")"
        if [ "$dist" = false ]; then row="$row $(printf "%8d" "$busiest")"
        else row="$row $(printf "%14s" "$busiest / $others")"; fi
      done
    done
    echo "$row"
  done
  A=(bench/fe_block.yaml -q --set fem.max_steps=10 --set fem.check_every=10 --set "fem.meshes.0.block.divisions=[100, 50, 40]"
     --set fem.distribute=true)
  rm -rf "$W/r1" "$W/r2"
  bash scripts/mpirun.sh --oversubscribe -n 4 "$FDEM" run "${A[@]}" --set 'fem.load_steps=[0.5]' --out "$W/r1" >/dev/null
  bash scripts/mpirun.sh --oversubscribe -n 4 "$FDEM" run "${A[@]}" --set 'fem.load_steps=[0.5, 1]' \
    --restart "$W/r1/fe_checkpoint.h5" --out "$W/r2" >/dev/null
  echo "# restart, 200000 elements, fem.distribute, 4 ranks (checkpoint $(du -m "$W/r1/fe_checkpoint.h5" | cut -f1) MB):"
  echo "#   first run $(peak "$W/r1/run.json" | tr ' ' '/') MB, restarted run $(peak "$W/r2/run.json" | tr ' ' '/') MB"
  # a coupled case: one sphere on a 200 000-element plate (cases/coupling/sphere_on_plate.yaml,
  # 100 x 100 x 20 Hex8, the whole top surface the interface: 40 000 triangles), 20 steps, 4 ranks
  for dist in false true; do
    rm -rf "$W/c"
    bash scripts/mpirun.sh --oversubscribe -n 4 "$FDEM" run cases/coupling/sphere_on_plate.yaml --out "$W/c" -q \
      --set time.steps=20 --set "fem.meshes.0.block.divisions=[100, 100, 20]" --set fem.distribute=$dist >/dev/null
    echo "# coupled, 200000-element plate, 4 ranks, fem.distribute: $dist: $(peak "$W/c/run.json" | tr ' ' '/') MB"
  done
} | tee bench/results/fe_memory.txt
