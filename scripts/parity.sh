#!/usr/bin/env bash
# make parity: fdem's contact kernel against YADE 2023.02a (Debian's `yade`), step by step.
# Installs yade if missing, runs tests/parity/yade_protocols.py headless into a fresh directory,
# replays those histories through fdem's kernel (build/unit_parity_yade with FDEM_PARITY_DIR) and
# prints the parity table. Exits non-zero if a row fails. docs/verification.md#parity-against-yade
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD=${BUILD:-build}
if ! command -v yade >/dev/null 2>&1; then
  echo "parity: installing Debian's yade"
  SUDO=; [ "$(id -u)" = 0 ] || SUDO=sudo
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get install -y -q yade || { $SUDO apt-get update -q && $SUDO apt-get install -y -q yade; }
fi
[ -x "$BUILD/unit_parity_yade" ] || cmake --build "$BUILD" -j 2 --target unit_parity_yade
OUT=$(mktemp -d /tmp/fdem_parity.XXXXXX)
trap 'rm -rf "$OUT"' EXIT
echo "parity: $(yade --version 2>/dev/null | head -1 || true); histories in $OUT"
# -n: no GUI, -x: exit when the script ends. The total form logs a warning every step: kept in the log.
if ! PARITY_OUT="$OUT" yade -n -x tests/parity/yade_protocols.py >"$OUT/yade.log" 2>&1; then
  tail -30 "$OUT/yade.log"; echo "parity: yade failed"; exit 1
fi
grep '^parity:' "$OUT/yade.log" || true
set +e
FDEM_PARITY_DIR="$OUT" "$BUILD/unit_parity_yade" >"$OUT/replay.log" 2>&1
rc=$?
set -e
echo
printf '%-18s %-12s %-58s %10s %6s %s\n' protocol law quantity "max diff" tol result
printf '%.0s-' {1..118}; echo
grep '^PARITY|' "$OUT/replay.log" | while IFS='|' read -r _ proto law q v tol res; do
  printf '%-18s %-12s %-58s %10s %6s %s\n' "$proto" "$law" "$q" "$v" "$tol" "$res"
done
echo "(max diff: max over the steps of |fdem - YADE| relative to the protocol's peak force or moment;"
echo " INFO rows: documented differences between the two codes, docs/verification.md#parity-against-yade)"
nfail=$(grep -c '^PARITY|.*|FAIL$' "$OUT/replay.log" || true)
if [ "$rc" != 0 ] || [ "$nfail" != 0 ]; then
  grep -E 'Failure|Expected|actual|FAILED' "$OUT/replay.log" | head -40
  echo "parity: FAILED ($nfail rows)"; exit 1
fi
echo "parity: all rows pass"
