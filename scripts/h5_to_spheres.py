#!/usr/bin/python3
"""Write the spheres of an fdem particle snapshot in the thesis sphere text format.

Usage: /usr/bin/python3 scripts/h5_to_spheres.py SNAPSHOT.h5 OUT.txt

OUT.txt has one sphere per line, `id x y z r` (SI units: m), sorted by id, numbers written with
17 significant digits so that the doubles round-trip exactly. A `#` header line names the
source snapshot, its step and time. The file can be read back by a case with
`particles: - file: {path: OUT.txt, material: ...}` (docs/case-format.md).
"""
import sys

import h5py
import numpy as np


def main(argv):
    if len(argv) != 3:
        sys.stderr.write(__doc__.split("\n\n")[1] + "\n")
        return 2
    src, dst = argv[1], argv[2]
    with h5py.File(src, "r") as f:
        pos = np.asarray(f["position"][...], dtype=np.float64)
        rad = np.asarray(f["radius"][...], dtype=np.float64)
        ids = np.asarray(f["id"][...], dtype=np.int64)
        step = f.attrs.get("step", "?")
        time = f.attrs.get("time", "?")
    if pos.ndim != 2 or pos.shape[1] != 3 or len(rad) != len(pos) or len(ids) != len(pos):
        sys.stderr.write(f"{src}: unexpected dataset shapes position {pos.shape}, "
                         f"radius {rad.shape}, id {ids.shape}\n")
        return 1
    order = np.argsort(ids, kind="stable")
    with open(dst, "w") as out:
        out.write(f"# {len(ids)} spheres from {src} (step {step}, time {time}): id x y z r\n")
        for i in order:
            x, y, z = pos[i]
            out.write(f"{ids[i]:d} {x:.17g} {y:.17g} {z:.17g} {rad[i]:.17g}\n")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
