"""FE output of a run directory, read by the command-line tests (tests/cli_*.sh; cli_common.sh puts
this folder on PYTHONPATH): the fe_<step>.h5 snapshots, fe.xdmf and fe_history.csv."""
import csv
import glob
import os
import re

import h5py
import numpy as np


def tip_of(f):
    """Snapshot file f: the mean z displacement of the nodes at the largest x (a cantilever's tip),
    the largest nodal displacement, and the file's step and time attributes."""
    with h5py.File(f, "r") as h:
        x = h["nodes/coordinates"][:]
        u = h["nodes/displacement"][:]
        step, time = int(h.attrs["step"]), float(h.attrs["time"])
    sel = np.abs(x[:, 0] - x[:, 0].max()) < 1e-12
    return u[sel, 2].mean(), np.sqrt((u**2).sum(axis=1)).max(), step, time


def tip(d):
    """The tip deflection (see tip_of) of run directory d's last snapshot."""
    return tip_of(sorted(glob.glob(d + "/fe_[0-9]*.h5"))[-1])[0]


def listed(d):
    """The steps fe.xdmf lists, in its order; each must reference its own snapshot file."""
    x = open(d + "/fe.xdmf").read()
    steps = [int(s) for s in re.findall(r'<Grid Name="step_([0-9]+)"', x)]
    for s in steps:
        assert "fe_%08d.h5:/nodes/coordinates" % s in x, "%s: step %d: its file is not referenced" % (d, s)
    return steps


def files(d):
    """The steps of the fe_<step>.h5 files in d, ascending."""
    return sorted(int(re.fullmatch(r"fe_([0-9]+)\.h5", os.path.basename(f)).group(1))
                  for f in glob.glob(d + "/fe_[0-9]*.h5"))


def hold_ends(d):
    """The step column of fe_history.csv (one row per finished hold)."""
    return [int(float(r["step"])) for r in csv.DictReader(open(d + "/fe_history.csv"))]


def displacement(f):
    """Snapshot file f: the nodal displacement field (n_nodes x dim) in the order of the user's node
    ids (rows are the partition's global numbers, which depend on the rank count)."""
    with h5py.File(f, "r") as h:
        return h["nodes/displacement"][:][np.argsort(h["nodes/id"][:], kind="stable")]


def ksp_bounds(d):
    """A static run's fe_history.csv: per hold, the KSP error bound kappa * |B r| / |B b| (the
    relative 2-norm error of that hold's displacements the solve guarantees, r = b - A u computed
    afresh). Checks that the bound is the product of its parts and that each solve converged: its
    true residual within 100 rtol (round-off makes it exceed rtol 1e-12 by a few times)."""
    rows = list(csv.DictReader(open(d + "/fe_history.csv")))
    for r in rows:
        res, rtol, kappa = float(r["ksp_residual"]), float(r["ksp_rtol"]), float(r["ksp_condition"])
        assert 0 < res <= 100 * rtol, "%s: hold %s: true residual %.3e vs rtol %.1e" % (d, r["hold"], res, rtol)
        assert kappa >= 1 and float(r["ksp_error_bound"]) == kappa * res, r
    return [float(r["ksp_error_bound"]) for r in rows]


def agree_within_ksp(a, b, bound, what):
    """Two static solutions (displacement fields) of one system differ, in the relative 2-norm, by
    at most the sum of their solves' error bounds; returns the measured difference."""
    d = np.linalg.norm(a - b) / np.linalg.norm(b)
    print("%s: relative 2-norm difference %.2e, KSP guarantee %.2e" % (what, d, bound))
    assert d <= bound, "%s: differ by %.2e, more than the KSP solves guarantee (%.2e)" % (what, d, bound)
    return d
