#!/usr/bin/env bash
# Geometrically nonlinear FE (fem.materials[].nlgeom, total Lagrangian): the membrane strip
# (cases/fem/membrane_strip.yaml: a 0.9 mm polypropylene strip held 0.2 m apart under a central
# line load) sags as a string. Checked: the mid-span sag against the string's
# delta = (L/2) (P/EA)^(1/3) (below it by the strip's bending stiffness: 0.85-1.0); its growth with
# the load as P^(1/3) from hold 1 to hold 2 (small strain gives P^1); the axial force at the
# quarter span equal to EA times the sagged chord's strain 2 (delta/L)^2 (15 %) and carrying most
# of the load (2 T sin(theta) in 0.7-1.0 P); 1 and 2 ranks bitwise equal.
# Usage: cli_nlgeom.sh FDEM_BINARY SOURCE_DIR
source "$2/tests/support/cli_common.sh" "$@"
CASE="$SRC/cases/fem/membrane_strip.yaml"
$MPIRUN -n 2 "$FDEM" run "$CASE" --out "$tmp/r2" -q >"$tmp/r2.log" 2>&1 || { cat "$tmp/r2.log"; fail "2-rank run"; }
$MPIRUN -n 1 "$FDEM" run "$CASE" --out "$tmp/r1" -q >"$tmp/r1.log" 2>&1 || { cat "$tmp/r1.log"; fail "1-rank run"; }
$PY - "$tmp/r2" "$tmp/r1" <<'PYEOF' || fail "results"
import sys, glob, h5py, numpy as np
E, L, b, t, P = 1.4e9, 0.2, 0.01, 0.0009, 13.0
EA = E * b * t
def holds(d):
    out = []
    for f in sorted(glob.glob(d + "/fe_[0-9]*.h5"))[1:]:
        with h5py.File(f, "r") as h:
            X, U = h["nodes/coordinates"][:], h["nodes/displacement"][:]
            C, S = h["elements/connectivity"][:], h["elements/stress"][:]
        mid = np.abs(X[:, 0] - L / 2) < 1e-9
        cen = X[C].mean(axis=1)
        q = np.abs(cen[:, 0] - L / 4) < 0.002          # one element column at the quarter span
        out.append((-U[mid, 2].mean(), S[q, 0].mean() * b * t, U))
    return out
r2, r1 = holds(sys.argv[1]), holds(sys.argv[2])
assert len(r2) == 2 and len(r1) == 2, "expected two holds' snapshots"
for (d2, T2, U2), (d1, T1, U1) in zip(r2, r1):
    assert np.array_equal(U2, U1), "1 and 2 ranks differ"
print("1 and 2 ranks: displacements bitwise equal")
for k, (f, (d, T, _)) in enumerate(zip((0.25, 1.0), r2)):
    Pk = f * P
    string = L / 2 * (Pk / EA) ** (1 / 3)
    th = 2 * d / L
    chord = EA * 2 * (d / L) ** 2
    share = 2 * T * th / np.sqrt(1 + th**2) / Pk
    print("hold %d: P %.2f N: sag %.3f mm, string %.3f mm (ratio %.3f); axial force %.2f N, EA 2(d/L)^2 %.2f N "
          "(ratio %.3f); 2 T sin(theta) / P %.3f" % (k + 1, Pk, 1e3 * d, 1e3 * string, d / string, T, chord, T / chord, share))
    assert 0.85 < d / string < 1.0, "sag not the string's"
    assert abs(T / chord - 1) < 0.15, "axial force not EA times the chord's strain"
    assert 0.7 < share < 1.0, "the tension does not carry the load"
g = r2[0][0] / r2[1][0]
print("sag hold 1 / hold 2 %.3f, (P1/P2)^(1/3) %.3f (small strain: %.3f)" % (g, 0.25 ** (1 / 3), 0.25))
assert abs(g / 0.25 ** (1 / 3) - 1) < 0.1, "the sag does not grow as P^(1/3)"
PYEOF
echo "PASS"
