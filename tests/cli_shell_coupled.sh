#!/usr/bin/env bash
# Shells as the coupled interface (issue 19, before the buried pipe):
# cases/coupling/sphere_on_shell_plate.yaml on 1, 2 and 3 ranks -- at rest the interface force is
# the sphere's weight (1e-9), the three runs are bitwise equal, and the plate's deflection field is
# the KSP static solution under the weight at the centre node (cases/fem/shell_plate_point_load.yaml)
# to 1e-4 (the sphere rests in the sagged plate's shallow cone and touches the facets around the
# node, not the node: r x slope / element ~ 1e-4 of the load leaves the node; measured 3.5e-6);
# cases/coupling/grains_on_shell_strip.yaml on 1 and 2 ranks -- bitwise equal; the interface carries
# the bed's weight (1e-2; frictionless walls), the clamps react with the interface force (5e-2: the
# strip still settles), and the mid-span deflection is 0.85-1.1 of the clamped beam's q L^4/(384 EI)
# under the bed's weight spread uniformly (measured 0.96).
# Usage: cli_shell_coupled.sh FDEM_BINARY SOURCE_DIR
source "$2/tests/support/cli_common.sh" "$@"
PLATE="$SRC/cases/coupling/sphere_on_shell_plate.yaml"
"$FDEM" run "$SRC/cases/fem/shell_plate_point_load.yaml" --out "$tmp/static" -q >"$tmp/static.log" 2>&1 \
  || { cat "$tmp/static.log"; fail "static shell plate"; }
for n in 1 2 3; do
  $MPIRUN -n $n "$FDEM" run "$PLATE" --out "$tmp/plate$n" -q >"$tmp/plate$n.log" 2>&1 \
    || { cat "$tmp/plate$n.log"; fail "sphere on shell plate, $n rank(s)"; }
done
$PY - "$tmp" <<'PYEOF' || fail "sphere on shell plate"
import sys, csv, glob, math
import h5py, numpy as np
t = sys.argv[1]
def field(d):
    with h5py.File(sorted(glob.glob(d + "/fe_[0-9]*.h5"))[-1], "r") as h:
        return h["nodes/coordinates"][:], h["nodes/displacement"][:]
W = 2650 * 4 / 3 * math.pi * 0.01**3 * 9.81
X, us = field(t + "/static")
centre = np.argmin(np.hypot(X[:, 0] - 0.1, X[:, 1] - 0.1))
rows = {n: list(csv.DictReader(open("%s/plate%d/interface.csv" % (t, n))))[-1] for n in (1, 2, 3)}
uc = {n: field("%s/plate%d" % (t, n))[1] for n in (1, 2, 3)}
fz = -float(rows[1]["fz"])
err = np.abs(uc[1] - us).max() / np.abs(us).max()
print("sphere on shell plate: Fz %.12g N, m g %.12g N (%.1e); centre deflection coupled %.9e m, KSP %.9e m; "
      "field max |coupled - KSP| / max |u| %.2e" % (fz, W, fz / W - 1, uc[1][centre, 2], us[centre, 2], err))
assert int(rows[1]["step"]) == 16000
assert abs(fz - W) < 1e-9 * W, "the interface force is not the weight"
assert us[centre, 2] < 0 and err < 1e-4, "the coupled deflection is not the static one"
# the snapshot's nodal interface forces: they sum to the interface force; the centre node takes
# all but the share that the facets around it pass on (~r slope / h)
with h5py.File(sorted(glob.glob(t + "/plate2/fe_[0-9]*.h5"))[-1], "r") as h:
    fi = h["nodes/interface_force"][:]
print("  nodal interface forces: sum %.12g N, the centre node's share %.8f" % (fi[:, 2].sum(), fi[centre, 2] / fi[:, 2].sum()))
assert abs(fi[:, 2].sum() + fz) < 1e-12 * W and abs(fi[:, :2].sum(axis=0)).max() < 1e-12 * W
assert 1 - 1e-4 < fi[centre, 2] / fi[:, 2].sum() <= 1
for n in (2, 3):
    assert rows[n] == rows[1], "%d ranks: interface.csv's last row differs from 1 rank's" % n
    assert np.array_equal(uc[n], uc[1]), "%d ranks: the plate's displacements differ from 1 rank's" % n
PYEOF
STRIP="$SRC/cases/coupling/grains_on_shell_strip.yaml"
for n in 1 2; do
  $MPIRUN -n $n "$FDEM" run "$STRIP" --out "$tmp/strip$n" -q >"$tmp/strip$n.log" 2>&1 \
    || { cat "$tmp/strip$n.log"; fail "grains on shell strip, $n rank(s)"; }
done
$PY - "$tmp" <<'PYEOF' || fail "grains on shell strip"
import sys, csv, glob
import h5py, numpy as np
t = sys.argv[1]
def last(d, pattern):
    return h5py.File(sorted(glob.glob(d + "/" + pattern))[-1], "r")
with last(t + "/strip1", "particles_[0-9]*.h5") as h:
    W = (2650 * 4 / 3 * np.pi * h["radius"][:] ** 3).sum() * 9.81
    assert len(h["radius"]) == 300
fe = {}
for n in (1, 2):
    with last("%s/strip%d" % (t, n), "fe_[0-9]*.h5") as h:
        fe[n] = (h["nodes/coordinates"][:], h["nodes/displacement"][:])
rows = {n: list(csv.DictReader(open("%s/strip%d/interface.csv" % (t, n))))[-1] for n in (1, 2)}
react = list(csv.DictReader(open(t + "/strip1/reactions.csv")))[-1]
rz = float(react["strip_xmin_rz"]) + float(react["strip_xmax_rz"])
fz = -float(rows[1]["fz"])
X, U = fe[1]
w = -U[np.abs(X[:, 0] - 0.15) < 1e-9, 2].mean()
EI = 2e9 * 0.06 * 0.005**3 / 12
beam = W / 0.3 * 0.3**4 / (384 * EI)
print("grains on shell strip: weight %.5f N, interface Fz %.5f N (%.1e), clamp reactions %.5f N (%.1e); "
      "mid-span deflection %.4e m, q L^4/(384 EI) %.4e m (ratio %.3f)" % (W, fz, fz / W - 1, rz, rz / fz - 1, w, beam, w / beam))
assert abs(fz / W - 1) < 1e-2, "the interface does not carry the bed's weight"
assert abs(rz / fz - 1) < 5e-2, "the clamps do not react with the interface force"
assert 0.85 < w / beam < 1.1, "mid-span deflection"
assert rows[2] == rows[1], "2 ranks: interface.csv's last row differs from 1 rank's"
assert np.array_equal(fe[2][1], fe[1][1]), "2 ranks: the strip's displacements differ from 1 rank's"
PYEOF
echo "cli_shell_coupled: OK"
