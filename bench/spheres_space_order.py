#!/usr/bin/python3
"""Renumber a sphere file along a Morton (Z-order) curve: the same spheres, ids 0..N-1 in space order.

Usage: /usr/bin/python3 bench/spheres_space_order.py IN.txt OUT.txt [--cell C]

fdem kept each rank's grains in id order until its order keys (2026-12-05; src/dem/particles.hpp),
so ids scattered in space -- a random sequential generation's -- made every contact read two
random places of the particle arrays. bench/run.sh runs fdem on both numberings of the dense bed:
with the keys the two agree (docs/performance.md#order-keys).
The spheres are ordered by the Morton code of their cell (cubes of side C, default twice the mean
diameter, from the lowest corner of the spheres' bounding box), ties by their old id.
"""
import argparse

import numpy as np


def spread(v):
    r = np.zeros_like(v)
    for b in range(21):
        r |= ((v >> b) & 1) << (3 * b)
    return r


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("inp")
    ap.add_argument("out")
    ap.add_argument("--cell", type=float, default=0.0, help="cell side in m (default: twice the mean diameter)")
    a = ap.parse_args()
    s = np.loadtxt(a.inp, comments="#", ndmin=2)
    if s.shape[1] != 5:
        raise SystemExit(f"{a.inp}: expected lines 'id x y z r'")
    x = s[:, 1:4]
    cell = a.cell if a.cell > 0 else 4.0 * s[:, 4].mean()
    c = np.floor((x - x.min(axis=0)) / cell).astype(np.int64)
    if c.max() >= 1 << 21:
        raise SystemExit(f"cell {cell} m too small for the bed: more than 2^21 cells along an axis")
    key = spread(c[:, 0]) | (spread(c[:, 1]) << 1) | (spread(c[:, 2]) << 2)
    order = np.lexsort((s[:, 0], key))
    with open(a.out, "w") as f:
        f.write(f"# {a.inp} renumbered along a Morton curve of {cell:.6g} m cells (bench/spheres_space_order.py)\n")
        for k, i in enumerate(order):
            f.write("%d %.17g %.17g %.17g %.17g\n" % (k, x[i, 0], x[i, 1], x[i, 2], s[i, 4]))


if __name__ == "__main__":
    main()
