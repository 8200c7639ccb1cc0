#!/usr/bin/env bash
# Bitwise comparison of two fdem binaries on a fixed set of quick cases (2 ranks each): a
# refactoring must not change a single bit of the results.
#
#   scripts/compare_results.sh REF_FDEM NEW_FDEM [WORKDIR]
#
# Runs every case below with both binaries (scripts/mpirun.sh -n 2 BIN run CASE --out DIR --set ...)
# and compares their outputs file by file: CSV and text files byte for byte; JSON files (packing.json,
# pullout.json, ...) byte for byte after dropping what measures the machine (timings, wall time,
# rates); run.json likewise; HDF5 files (snapshots, checkpoints, measurements) byte for byte, else
# their data with h5diff (exact, no tolerance). Prints IDENTICAL / DIFFERS per file and exits 1 on
# any difference (or a run that fails, or a file only one side wrote -- except the names listed in
# NEW_ONLY_OK, e.g. NEW_ONLY_OK="case.yaml structures.json" against a binary older than them).
set -uo pipefail
if [ $# -lt 2 ]; then
  echo "usage: $0 REF_FDEM NEW_FDEM [WORKDIR]" >&2
  exit 2
fi
REF=$(readlink -f "$1")
NEW=$(readlink -f "$2")
WORK=${3:-$(mktemp -d /tmp/fdem_compare.XXXXXX)}
mkdir -p "$WORK"
SRC=$(cd "$(dirname "$0")/.." && pwd)
MPIRUN="bash $SRC/scripts/mpirun.sh"
PY=${PYTHON:-python3}

# name | case file (relative to the source tree) | extra arguments. Each takes seconds to a minute or two
# on 2 ranks; together they cover pure DEM (free, servo and velocity walls, lab outputs), packing,
# measurements, pure FE and the FE-DE coupling (interface sums, coupled holds).
CASES=(
  "settle|cases/demo/settle.yaml|--set time.steps=6000"
  "triaxial|cases/lab/triaxial_ci.yaml|--set time.steps=6000"
  "direct_shear|cases/lab/direct_shear_ci.yaml|--set time.steps=6000"
  "measure|cases/examples/measure.yaml|"
  "walls|cases/examples/walls.yaml|"
  "pack_layers|cases/specimens/pack_layers_ci.yaml|"
  "pipe_pressure|cases/fem/pipe_pressure.yaml|"
  "sphere_on_plate|cases/coupling/sphere_on_plate.yaml|"
  "bed_on_coarse_plate|cases/coupling/bed_on_coarse_plate.yaml|--set time.steps=4000"
  "pullout_ci|cases/geogrid_pullout/ci.yaml|--set packing.settle.max_steps=3000 --set time.steps=10000"
)

# JSON without the machine-dependent keys, canonical text (key order kept); the run's own output
# directory (which differs between the two sides) replaced by OUT.
json_clean() {
  "$PY" - "$1" "$2" <<'PYEOF'
import json, re, sys
drop = re.compile(r"(time_s|wall|timing|seconds|per_second|elapsed|rate|speed|date|host|comm_bytes|rss)", re.I)
def clean(v):
    if isinstance(v, dict):
        return {k: clean(x) for k, x in v.items() if not drop.search(k)}
    if isinstance(v, list):
        return [clean(x) for x in v]
    if isinstance(v, str):
        return v.replace(sys.argv[2], "OUT")
    return v
with open(sys.argv[1]) as f:
    print(json.dumps(clean(json.load(f)), indent=1))
PYEOF
}

status=0
ndiff=0
nsame=0
for entry in "${CASES[@]}"; do
  IFS='|' read -r name case extra <<<"$entry"
  echo "== $name ($case ${extra})"
  for side in ref new; do
    bin=$REF; [ $side = new ] && bin=$NEW
    out="$WORK/$name/$side"
    rm -rf "$out"
    mkdir -p "$WORK/$name"
    # shellcheck disable=SC2086
    if ! (cd "$SRC" && $MPIRUN -n 2 "$bin" run "$case" --out "$out" -q $extra) >"$WORK/$name/$side.log" 2>&1; then
      echo "  RUN FAILED ($side): see $WORK/$name/$side.log"
      status=1
    fi
  done
  ref_dir="$WORK/$name/ref"
  new_dir="$WORK/$name/new"
  files=$( (cd "$ref_dir" 2>/dev/null && find . -type f; cd "$new_dir" 2>/dev/null && find . -type f) | sort -u)
  for f in $files; do
    a="$ref_dir/$f"; b="$new_dir/$f"; rel=${f#./}
    # files that only the new side writes and that REF predates (NEW_ONLY_OK, space-separated names)
    if [ ! -f "$a" ] && [ -f "$b" ] && [[ " ${NEW_ONLY_OK:-} " == *" $(basename "$rel") "* ]]; then
      echo "  NEW        $rel (written only by NEW; allowed by NEW_ONLY_OK)"; continue
    fi
    if [ ! -f "$a" ] || [ ! -f "$b" ]; then
      echo "  DIFFERS    $rel (only in $([ -f "$a" ] && echo ref || echo new))"; status=1; ndiff=$((ndiff + 1)); continue
    fi
    how="bytes"
    same=0
    case "$rel" in
      *.json)
        how="json without timings"
        cmp -s <(json_clean "$a" "$ref_dir") <(json_clean "$b" "$new_dir") && same=1 ;;
      *.h5)
        if cmp -s "$a" "$b"; then same=1
        # (a packing's checkpoint: /packing holds wall-clock times; its layer rows are packing.json's)
        else how="h5diff, exact, without /packing"; h5diff -q --exclude-path /packing "$a" "$b" >/dev/null 2>&1 && same=1; fi ;;
      *)
        cmp -s "$a" "$b" && same=1 ;;
    esac
    if [ $same = 1 ]; then
      echo "  IDENTICAL  $rel ($how)"; nsame=$((nsame + 1))
    else
      echo "  DIFFERS    $rel ($how)"; status=1; ndiff=$((ndiff + 1))
    fi
  done
done
echo "== $nsame file(s) identical, $ndiff differ(s); outputs in $WORK"
[ $status = 0 ] && echo "RESULT: IDENTICAL" || echo "RESULT: DIFFERS"
exit $status
