#!/usr/bin/env python3
"""K0 against depth on the side walls of a packed bed (issue 17 part 2; cases/specimens/k0_column.yaml).

    /usr/bin/python3 scripts/k0_report.py DIR [DIR ...] [--phi DEG ...]

Reads from each DIR: case.yaml (the packing box, the plane side walls with `bands` along z),
walls.csv (its last row: the side walls' force per depth band, `<wall>_b<k>_fx/fy`), specimen.txt
(the packed grains, `id x y z r`) and packing.json (the interior box's K0 from the grains' stress).
The side walls are frictionless and plane, so at rest the vertical stress at height z is the
weight of the solid above z over the box's plan area (grains cut by the plane count by their
cap's volume); a band's horizontal stress is its force across the wall over (band height x the
wall's width, the box's side). K0 = sigma_h / sigma_v per band (sigma_v averaged over the band),
and for the whole wall as sum sigma_h / sum sigma_v over the bands below the surface. With
--phi, Jaky's 1 - sin(phi) for each angle and the measured K0's deviation from it.
"""
import argparse
import csv
import json
import math
import os

import yaml


def cap_volume(r, h):
    """Volume of a sphere's cap of height h (0 <= h <= 2r)."""
    h = min(max(h, 0.0), 2 * r)
    return math.pi * h * h * (3 * r - h) / 3


def analyse(d):
    case = yaml.safe_load(open(os.path.join(d, "case.yaml")))
    box = case["packing"]["box"]
    lo, hi = box["min"], box["max"]
    wx, wy = hi[0] - lo[0], hi[1] - lo[1]
    rho = next(m["density"] for m in case["materials"] if m["name"] == case["packing"]["material"])
    g = abs(case.get("gravity", [0, 0, -9.81])[2])
    grains = []
    for line in open(os.path.join(d, "specimen.txt")):
        if line.startswith("#") or not line.strip():
            continue
        _, x, y, z, r = map(float, line.split())
        grains.append((z, r))
    top = max(z + r for z, r in grains)
    last = list(csv.DictReader(open(os.path.join(d, "walls.csv"))))[-1]
    sides = []  # (name, index of the horizontal axis, sign of the normal, width)
    edges = None
    for w in case["walls"]:
        if w.get("type") != "plane" or "bands" not in w:
            continue
        n = w["normal"]
        k = 0 if abs(n[0]) > 0.9 else 1 if abs(n[1]) > 0.9 else None
        if k is None:
            continue
        sides.append((w["name"], k, math.copysign(1, n[k]), wy if k == 0 else wx))
        edges = w["bands"]["edges"]

    def sigma_v(z):
        s = sum(cap_volume(r, zc + r - z) for zc, r in grains if zc + r > z)
        return s * rho * g / (wx * wy)

    rows = []
    for b in range(len(edges) - 1):
        z0, z1 = edges[b], min(edges[b + 1], top)
        if z1 <= z0:
            break
        sh = []
        for name, k, sign, width in sides:
            f = float(last["%s_b%d_f%s" % (name, b + 1, "xy"[k])])
            sh.append(-sign * f / ((z1 - z0) * width))  # the grains push the wall against its normal
        n = 20
        sv = sum(sigma_v(z0 + (i + 0.5) * (z1 - z0) / n) for i in range(n)) / n
        rows.append((z0, z1, top - 0.5 * (z0 + z1), sh, sv))
    pj = json.load(open(os.path.join(d, "packing.json")))
    return top, sides, rows, pj["interior"]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("dirs", nargs="+", metavar="DIR")
    ap.add_argument("--phi", type=float, nargs="*", default=[], metavar="DEG",
                    help="friction angles for Jaky's K0 = 1 - sin(phi)")
    a = ap.parse_args()
    for d in a.dirs:
        top, sides, rows, interior = analyse(d)
        print("== %s: surface z %.3f m, interior porosity %.3f, interior K0 (grains' stress) %.3f"
              % (d, top, interior["porosity"], interior["k0"]))
        print("  band z (m)     depth (m)  sigma_h on %s (kPa)  sigma_v (kPa)  K0"
              % " / ".join(s[0] for s in sides))
        for z0, z1, depth, sh, sv in rows:
            print("  %.3f-%.3f   %.3f      %s   %7.2f       %.3f"
                  % (z0, z1, depth, " / ".join("%5.2f" % (x / 1e3) for x in sh), sv / 1e3, sum(sh) / len(sh) / sv))
        k0 = sum(sum(sh) / len(sh) for *_, sh, _ in rows) / sum(sv for *_, sv in rows)
        print("  K0 over the walls (sum sigma_h / sum sigma_v over the bands): %.3f" % k0)
        for phi in a.phi:
            j = 1 - math.sin(math.radians(phi))
            print("  Jaky 1 - sin(%.1f deg) = %.3f: walls %+.0f %%, interior %+.0f %%"
                  % (phi, j, 100 * (k0 / j - 1), 100 * (interior["k0"] / j - 1)))


if __name__ == "__main__":
    main()
