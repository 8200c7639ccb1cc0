#!/usr/bin/python3
"""Convert a thesis sphere text file (`id x y z r` per line) to a LAMMPS/LIGGGHTS data file.

Usage: /usr/bin/python3 bench/spheres_to_liggghts.py SPHERES.txt OUT.data \
           --box XLO XHI YLO YHI ZLO ZHI [--density 2640] [--type 1]

The data file is for `atom_style granular` (LIGGGHTS: `atom_style sphere` in LAMMPS), whose
Atoms lines are `atom-ID atom-type diameter density x y z`. LIGGGHTS atom ids start at 1, so the
atom id is the sphere id + 1 (ids in the file must be >= 0). All atoms get one atom type and
one density. Every sphere centre must lie inside the box (LIGGGHTS drops atoms outside it when
reading a data file with fixed boundaries); the script checks that and stops otherwise.
"""
import argparse
import sys


def read_spheres(path):
    spheres = []
    with open(path) as f:
        for lineno, line in enumerate(f, 1):
            line = line.split("#", 1)[0].strip()
            if not line:
                continue
            parts = line.split()
            if len(parts) != 5:
                raise SystemExit(f"{path}:{lineno}: expected 5 values 'id x y z r', got {len(parts)}")
            sid = int(parts[0])
            x, y, z, r = (float(v) for v in parts[1:])
            if sid < 0 or r <= 0:
                raise SystemExit(f"{path}:{lineno}: id must be >= 0 and r > 0")
            spheres.append((sid, x, y, z, r))
    return spheres


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("spheres")
    ap.add_argument("out")
    ap.add_argument("--box", nargs=6, type=float, required=True,
                    metavar=("XLO", "XHI", "YLO", "YHI", "ZLO", "ZHI"))
    ap.add_argument("--density", type=float, default=2640.0, help="kg/m^3 (default 2640)")
    ap.add_argument("--type", type=int, default=1, help="atom type (default 1)")
    a = ap.parse_args()
    xlo, xhi, ylo, yhi, zlo, zhi = a.box
    if not (xlo < xhi and ylo < yhi and zlo < zhi):
        raise SystemExit("--box: need lo < hi in every direction")
    spheres = read_spheres(a.spheres)
    for sid, x, y, z, r in spheres:
        if not (xlo <= x < xhi and ylo <= y < yhi and zlo <= z < zhi):
            raise SystemExit(f"sphere {sid} at ({x}, {y}, {z}) lies outside the box {a.box}")
    with open(a.out, "w") as out:
        out.write(f"LIGGGHTS data file: {len(spheres)} spheres from {a.spheres} (atom_style granular)\n\n")
        out.write(f"{len(spheres)} atoms\n1 atom types\n\n")
        out.write(f"{xlo:.17g} {xhi:.17g} xlo xhi\n")
        out.write(f"{ylo:.17g} {yhi:.17g} ylo yhi\n")
        out.write(f"{zlo:.17g} {zhi:.17g} zlo zhi\n\n")
        out.write("Atoms\n\n")
        for sid, x, y, z, r in spheres:
            out.write(f"{sid + 1} {a.type} {2 * r:.17g} {a.density:.17g} {x:.17g} {y:.17g} {z:.17g}\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
