#!/usr/bin/env bash
# Hex8I (incompatible modes) against beam theory where the thesis's Hex8 locks:
# cases/fem/rib_bending.yaml, one rib of the SS-0 grid (one brick through its 0.9 mm thickness,
# 24 along 0.2 m) clamped at both ends under a mid-span point load, one static solve. Checked:
# hex8i's mid-span deflection within 3 % of P L^3 / (192 E I) (+ shear), hex8's more than 10 times
# too small (locking), and hex8i's deflection the same on 1 and 2 ranks within the KSP tolerance.
# Usage: cli_hex8i.sh FDEM_BINARY SOURCE_DIR
source "$2/tests/support/cli_common.sh" "$@"
CASE="$SRC/cases/fem/rib_bending.yaml"
$MPIRUN -n 2 "$FDEM" run "$CASE" --out "$tmp/i2" -q >"$tmp/i2.log" 2>&1 || { cat "$tmp/i2.log"; fail "hex8i 2-rank run"; }
$MPIRUN -n 1 "$FDEM" run "$CASE" --out "$tmp/i1" -q >"$tmp/i1.log" 2>&1 || { cat "$tmp/i1.log"; fail "hex8i 1-rank run"; }
$MPIRUN -n 1 "$FDEM" run "$CASE" --out "$tmp/h1" -q --set fem.meshes.0.block.element=hex8 >"$tmp/h1.log" 2>&1 ||
  { cat "$tmp/h1.log"; fail "hex8 run"; }
$PY - "$tmp/i2" "$tmp/i1" "$tmp/h1" <<'PYEOF' || fail "results"
import sys, glob, h5py, numpy as np
E, nu, L, b, t, P = 1.4e9, 0.3, 0.2, 0.004, 0.0009, 0.05
I = b * t**3 / 12
beam = P * L**3 / (192 * E * I) + (P / 2) * (L / 2) / (5 / 6 * E / (2 * (1 + nu)) * b * t)
def sag(d):
    f = sorted(glob.glob(d + "/fe_[0-9]*.h5"))[-1]
    with h5py.File(f, "r") as h:
        X, U = h["nodes/coordinates"][:], h["nodes/displacement"][:]
    mid = np.abs(X[:, 0] - L / 2) < 1e-9
    return -U[mid, 2].mean()
i2, i1, h1 = (sag(d) for d in sys.argv[1:4])
print("beam %.4f mm; hex8i %.4f mm (%.4f of beam), hex8 %.4f mm (%.4f: %.1f x too stiff); hex8i 1 vs 2 ranks %.2e"
      % (1e3 * beam, 1e3 * i2, i2 / beam, 1e3 * h1, h1 / beam, beam / h1, abs(i1 - i2) / i2))
assert abs(i2 / beam - 1) < 0.03, "hex8i not the beam's deflection"
assert beam / h1 > 10, "hex8 should lock on this mesh"
assert abs(i1 - i2) < 1e-6 * i2, "1 and 2 ranks differ beyond the solver tolerance"
PYEOF
echo "PASS"
