#!/usr/bin/env bash
# FE memory per rank (docs/performance.md#fe-mesh-memory): Hex8 blocks of bench/fe_block.yaml at
# three sizes (25 000, 200 000 and 800 000 elements), 10 dynamic-relaxation steps on 1, 2 and 4
# ranks (oversubscribed is fine); each rank's peak resident memory from run.json (fe_partition). The
# mesh is read identically on every rank and METIS-split; the per-element data (element
# matrices, state, ghosted vectors) are held by the owners only. The figures give the replicated
# part per element and the rank count where it would be half of a rank's memory.
#   bash bench/fe_memory.sh            output: bench/results/fe_memory.txt
set -euo pipefail
cd "$(dirname "$0")/.."
FDEM=${FDEM:-build/fdem}
[ -x "$FDEM" ] || { echo "fe_memory.sh: $FDEM not found; run 'make build' first" >&2; exit 2; }
W=bench/work/fe_memory; rm -rf "$W"; mkdir -p "$W" bench/results
{
  echo "# bench/fe_memory.sh: Hex8 block, 10 relaxation steps; peak resident memory (MB), busiest rank"
  printf "%10s %8s %8s %8s\n" elements 1_rank 2_ranks 4_ranks
  for div in "50, 25, 20" "100, 50, 40" "200, 100, 40"; do
    n=$(echo "$div" | tr -d ' ' | awk -F, '{print $1 * $2 * $3}')
    row="$(printf "%10d" "$n")"
    for np in 1 2 4; do
      rm -rf "$W/x"
      bash scripts/mpirun.sh -n "$np" "$FDEM" run bench/fe_block.yaml --out "$W/x" -q --set fem.max_steps=10 \
        --set fem.check_every=10 --set "fem.meshes.0.block.divisions=[$div]" >/dev/null
      peak=$(/usr/bin/python3 -c "import json, sys; print(round(max(r['peak_rss_mb'] for r in json.load(open(sys.argv[1]))['fe_partition']['ranks'])))" "$W/x/run.json")
      row="$row $(printf "%8d" "$peak")"
    done
    echo "$row"
  done
} | tee bench/results/fe_memory.txt
