#!/usr/bin/env bash
# Collectives per DEM step of the coupled CI pullout (docs/performance.md, "Collectives per
# step"): a PMPI wrapper (bench/pmpi/count_collectives.c, built here with mpicc) counts every
# MPI_Allreduce / Allgather / Bcast / Barrier of rank 0 by caller; STEPS DEM steps on 2 ranks
# from the CI specimen (packed once, cached like bench/pullout_run.sh's).
#   bash bench/collectives.sh [FDEM] [STEPS]     (defaults build/fdem, 8000)
set -euo pipefail
cd "$(dirname "$0")/.."
FDEM=$(readlink -f "${1:-build/fdem}")
STEPS=${2:-8000}
WORK=${BENCH_WORK:-bench/work}
CASE=cases/geogrid_pullout/ci.yaml
[ -x "$FDEM" ] || { echo "collectives.sh: $FDEM not found; run 'make build' first" >&2; exit 2; }
mkdir -p "$WORK" && WORK=$(cd "$WORK" && pwd)
LIB=$WORK/libcount_collectives.so
mpicc -shared -fPIC -O1 -o "$LIB" bench/pmpi/count_collectives.c -ldl
SPEC=$WORK/pullout_ci_pack/specimen.h5
if [ ! -f "$SPEC" ]; then
  echo "== packing the CI specimen (2 ranks, not measured)"
  bash scripts/mpirun.sh -n 2 "$FDEM" run "$CASE" --set time.steps=1 --out "$WORK/pullout_ci_pack" -q
fi
rm -rf "$WORK/collectives_run"
export PMPI_OUT=$WORK/collectives.txt
bash scripts/mpirun.sh -n 2 -x LD_PRELOAD="$LIB" -x PMPI_OUT "$FDEM" run "$CASE" --specimen "$SPEC" \
  --set time.steps="$STEPS" --set output.snapshot_every=1000000 --set measure.every=1000000 \
  --out "$WORK/collectives_run" -q
/usr/bin/python3 - "$PMPI_OUT" "$STEPS" <<'PY'
import subprocess, sys, collections
rows = [l.split() for l in open(sys.argv[1])]
steps = int(sys.argv[2])
def name(tok):
    f, off = tok.rsplit(":", 1)
    out = subprocess.run(["addr2line", "-f", "-C", "-e", f, "0x" + off], capture_output=True, text=True).stdout.split("\n")
    return out[0].split("(")[0] if out and out[0] != "??" else "?"
total = sum(int(r[0]) for r in rows)
print("collectives on rank 0: %d in %d DEM steps = %.2f per step" % (total, steps, total / steps))
by = collections.Counter()
for r in rows:
    chain = [name(t) for t in r[2:5]]
    chain = [c for c in chain if not c.startswith("fdem::exact::allreduce")][:2] or ["(MPI start-up)"]
    by["%s %s" % (r[1], " <- ".join(chain))] += int(r[0])
for k, n in by.most_common(12):
    print("%8d  %5.2f/step  %s" % (n, n / steps, k))
PY
