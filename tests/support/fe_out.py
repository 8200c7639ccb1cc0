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
