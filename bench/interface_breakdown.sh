#!/bin/bash
# Where an interface contact's time goes (docs/performance.md, "Coupled FE-DE step"): the
# developer probe of bench_coupled_split (the interface stage alone, repeated on the last step's
# particles with its data in cache) on a build of HEAD patched with bench/interface_breakdown.patch,
# which skips parts of Coupler::compute() in the probe only (the run before it is unchanged, so
# every variant times the same contacts):
#   FDEM_SKIP=0 all; 2 only the candidate scan (closest points); 1 the scan, the face/edge/vertex
#   selection and merging; bits 4 no surface-group sums, 8 no nodal force distribution, 16 no
#   contact records for measurements, 32 no contact law (a stand-in force).
# The stages are the differences. The production code has no such switches.
# Usage: bash bench/interface_breakdown.sh [REPEATS (3)] [PROBE_CALLS (1000)]   (1 rank, ~3 min)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
reps=${1:-3}
calls=${2:-1000}
tmp=$(mktemp -d)
cleanup() { git -C "$root" worktree remove --force "$tmp/src" 2>/dev/null || true; rm -rf "$tmp"; }
trap cleanup EXIT
git -C "$root" worktree add -q --detach "$tmp/src" HEAD
git -C "$tmp/src" apply "$root/bench/interface_breakdown.patch" || {
  echo "interface_breakdown.sh: bench/interface_breakdown.patch no longer applies to HEAD (Coupler::compute" \
       "changed): redo its switches on the new code and regenerate it with git diff" >&2
  exit 2
}
cmake -S "$tmp/src" -B "$tmp/build" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$tmp/build" -j2 --target bench_coupled_split >/dev/null 2>&1
probe() {
  FDEM_SKIP=$1 FDEM_IFACE_WARM=1 FDEM_IFACE_REPEAT=$calls "$tmp/build/bench_coupled_split" 20 2>&1 |
    sed -n 's/.*slowest rank): \([0-9.]*\) ms per call.*/\1/p'
}
declare -A best
for ((k = 0; k < reps; ++k)); do
  for s in 0 1 2 4 8 16 32; do
    t=$(probe $s)
    if [[ -z "${best[$s]:-}" ]] || awk -v a="$t" -v b="${best[$s]}" 'BEGIN{exit !(a < b)}'; then best[$s]=$t; fi
  done
done
contacts=$(FDEM_IFACE_REPEAT=1 "$tmp/build/bench_coupled_split" 20 2>&1 | sed -n 's/.*interface [0-9.]* ns (\([0-9]*\) contacts).*/\1/p')
awk -v all="${best[0]}" -v s1="${best[1]}" -v s2="${best[2]}" -v g="${best[4]}" -v d="${best[8]}" \
    -v m="${best[16]}" -v l="${best[32]}" -v n="$contacts" 'BEGIN {
  printf "interface stage, data in cache, best of the repeats (ms per call; ns per contact, %d contacts):\n", n
  row("candidate scan (plane tests, closest points)", s2)
  row("face/edge/vertex selection, merging", s1 - s2)
  row("contact law", all - l)
  row("nodal force distribution (fixed-point vertex sums)", all - d)
  row("surface-group sums", all - g)
  row("contact records (measurements)", all - m)
  row("rest (history, surface velocity, particle forces)", all - s1 - (all - l) - (all - d) - (all - g) - (all - m))
  row("whole stage", all)
}
function row(name, t) { printf "  %-52s %7.4f ms  %6.1f ns\n", name, t, 1e6 * t / n }'
