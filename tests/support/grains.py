"""The grains of a run's first snapshot, for the command-line tests (PYTHONPATH: tests/support)."""
import h5py
import numpy as np


def weights(run, density, g=9.81):
    """(m g d: the mean grain mass x g x the mean diameter, the kinetic guard's unit; W: the total
    weight) from RUN/particles_00000000.h5, grains of one density (kg/m^3)."""
    with h5py.File(f"{run}/particles_00000000.h5") as f:
        r = f["radius"][:]
    m = density * 4.0 / 3.0 * np.pi * r**3
    return m.mean() * g * (2 * r).mean(), m.sum() * g
