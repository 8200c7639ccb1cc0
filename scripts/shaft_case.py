#!/usr/bin/env python3
"""Write the shaft active earth pressure cases (thesis Tran 2013, ch. 3, sections 3.2, 3.6, 3.7).

    python3 scripts/shaft_case.py ci|slice|full > cases/shaft/VARIANT.yaml

A quarter model with the shaft's axis on the z axis (x = y = 0): the soil fills x, y in [0, L],
z in [0, H]; the symmetry planes x = 0 and y = 0, the outer walls x = L and y = L and the floor
are frictionless planes. The shaft (radius a = 75 mm) is three facet walls of 30 degrees each
(seg1: 0-30, seg2: 30-60, the middle one whose pressure the thesis records, seg3: 60-90 deg),
each a curved strip of `panels` flat panels from z = 0 to the top of the domain (the layers
overfill the box before `level` strikes them off at H: a shaft that ended lower let grains roll
over its rim and fall inside). Each
segment is moved towards the axis along its bisector by displacement holds (the radius reduced
in steps), and its force is summed in depth bands (`walls.bands`). The grains rain in layers
with their friction on and the walls' own frictions (packing.wall_friction: case; the shaft's
0.2 kept through packing as in the thesis), around the shaft (packing.exclude).
Variants (the grains are never scaled; the domain is):
  ci    L 0.25 m, H 0.30 m, grains d 12.5-25 mm (coarser: the CI form), 3 layers, one 0.5 mm step
  slice L 0.40 m, H 1.0 m, the thesis's shaft grains d 6.25-25 mm, 10 layers, 0.5 ... 5 mm
        (the thesis finds every change within 0.3 m of the axis)
  full  L 0.65 m, the thesis's size
"""
import math
import sys

VARIANTS = {
    "ci": dict(L=0.25, H=0.30, layers=3, sizes=[0.0125, 0.01875, 0.025], passing=[0, 50, 100],
               steps=[0, 0.0005], band=0.05, grid_div=[5, 5, 3], max_steps=60000, check=1000),
    "slice": dict(L=0.40, H=1.0, layers=10, sizes=[0.00625, 0.009375, 0.0125, 0.01875, 0.025],
                  passing=[0, 16.7, 33.3, 66.7, 100],
                  steps=[0, 0.0005, 0.001, 0.0015, 0.002, 0.003, 0.004, 0.005], band=0.1,
                  grid_div=[5, 5, 10], max_steps=100000, check=2000),
    "full": dict(L=0.65, H=1.0, layers=10, sizes=[0.00625, 0.009375, 0.0125, 0.01875, 0.025],
                 passing=[0, 16.7, 33.3, 66.7, 100],
                 steps=[0, 0.0005, 0.001, 0.0015, 0.002, 0.003, 0.004, 0.005], band=0.1,
                 grid_div=[8, 8, 10], max_steps=100000, check=2000),
}
A = 0.075      # shaft radius (D 150 mm)
PANELS = 3     # flat panels per 30-degree segment (10 degrees each)


def fmt(v):
    return ("%.6f" % v).rstrip("0").rstrip(".") if abs(v) > 1e-12 else "0"


def segment(k, top):
    """Vertices and triangles of segment k (0..2): panels from angle 30k to 30(k+1) degrees."""
    verts, tris = [], []
    for j in range(PANELS + 1):
        t = math.radians(30 * k + 30 * j / PANELS)
        for z in (0.0, top):
            verts.append([A * math.cos(t), A * math.sin(t), z])
    for j in range(PANELS):
        b = 2 * j  # (bottom, top) of this edge; the next edge is b + 2, b + 3
        tris += [[b, b + 2, b + 3], [b, b + 3, b + 1]]
    return verts, tris


def main():
    if len(sys.argv) != 2 or sys.argv[1] not in VARIANTS:
        sys.exit("usage: shaft_case.py ci|slice|full")
    name = sys.argv[1]
    v = VARIANTS[name]
    L, H = v["L"], v["H"]
    top = H + 0.6  # the domain's top: the segments stand above the overfilled layers and the rain
    nb = int(round(H / v["band"]))
    edges = [round(i * v["band"], 6) for i in range(nb)] + [round(H + 0.1, 6)]
    out = []
    w = out.append
    w("# Shaft active earth pressure, %s variant (thesis ch. 3; written by scripts/shaft_case.py %s)." % (name, name))
    w("# Quarter model: shaft axis on z (x = y = 0), soil x, y in [0, %s] m, H %s m; three 30-degree" % (fmt(L), fmt(H)))
    w("# segments (seg2 the middle one) moved towards the axis in held steps; force per depth band.")
    w("#   mpirun -n 2 build/fdem run cases/shaft/%s.yaml --out out/shaft_%s" % (name, name))
    w("#   python3 scripts/shaft_report.py out/shaft_%s --figures out/shaft_%s_figures" % (name, name))
    w("# docs/cases/shaft.md")
    w("name: shaft_%s" % name)
    w("domain: {min: [-0.03, -0.03, -0.03], max: [%s, %s, %s]}" % (fmt(L + 0.03), fmt(L + 0.03), fmt(H + 0.6)))
    w("gravity: [0, 0, -9.81]")
    w("time: {safety: 0.3, steps: 5000000}   # an upper bound: the run ends with its last hold")
    w("damping: 0.2")
    w("rolling_law: total   # the thesis's rolling law (eqs 3-7/3-8; its engine: YADE's NormalInelasticity law), docs/case-format.md#rolling-laws")
    w("materials:   # Table 3-2")
    w("  - {name: sand, young: 3.8e7, density: 2650, kt_kn: 0.25, friction: 0.6745, rolling_stiffness: 0.05, rolling_limit: 1.0}")
    w("  - {name: smooth, young: 3.8e7, density: 7850, kt_kn: 0.25, friction: 0.0}")
    w("  - {name: shaft, young: 3.8e7, density: 7850, kt_kn: 0.25, friction: 0.2}   # particle-shaft 0.2 (sec. 3.6)")
    w("walls:")
    w("  - {name: bottom, type: plane, material: smooth, point: [0, 0, 0], normal: [0, 0, 1]}")
    w("  - {name: sym_x, type: plane, material: smooth, point: [0, 0, 0], normal: [1, 0, 0]}")
    w("  - {name: sym_y, type: plane, material: smooth, point: [0, 0, 0], normal: [0, 1, 0]}")
    w("  - {name: outer_x, type: plane, material: smooth, point: [%s, 0, 0], normal: [-1, 0, 0]}" % fmt(L))
    w("  - {name: outer_y, type: plane, material: smooth, point: [0, %s, 0], normal: [0, -1, 0]}" % fmt(L))
    for k in range(3):
        verts, tris = segment(k, top)
        w("  - name: seg%d   # %d-%d degrees" % (k + 1, 30 * k, 30 * (k + 1)))
        w("    type: facets")
        w("    material: shaft")
        w("    vertices: [%s]" % ", ".join("[%s]" % ", ".join(fmt(c) for c in p) for p in verts))
        w("    triangles: [%s]" % ", ".join("[%d, %d, %d]" % tuple(t) for t in tris))
        if k == 0:
            w("    bands: &depth {axis: [0, 0, 1], edges: [%s]}" % ", ".join(fmt(e) for e in edges))
        else:
            w("    bands: *depth")
    w("packing:")
    w("  material: sand")
    w("  box: {min: [0, 0, 0], max: [%s, %s, %s]}" % (fmt(L), fmt(L), fmt(H)))
    w("  layers: %d" % v["layers"])
    w("  porosity: 0.38   # at or below what the layers reach: they overfill, `level` strikes off at H")
    w("  level: true")
    w("  size:")
    w("    distribution: sieve")
    w("    sizes:   [%s]" % ", ".join(fmt(s) for s in v["sizes"]))
    w("    passing: [%s]" % ", ".join(fmt(p) for p in v["passing"]))
    w("  seed: 1")
    w("  friction: 0.6745      # rained with the sand's friction: K0 near 1 - sin(phi) (docs/cases/shaft.md)")
    w("  wall_friction: case   # the walls keep theirs: the shaft 0.2, the boundaries 0")
    w("  exclude: [{point: [0, 0, 0], axis: [0, 0, 1], radius: %s}]   # the shaft" % fmt(A))
    w("  cloud_fraction: 0.3")
    w("  settle: {criterion: porosity, porosity_change: 0.002, max_steps: 100000, check_every: 1000}")
    w("  report: {margin: 0.1}   # the interior box clear of the shaft")
    w("  final_steps: 2000")
    w("holds:")
    segs = [(1, 15), (2, 45), (3, 75)]
    steps = ", ".join(fmt(s) for s in v["steps"])
    for k, t in segs:
        ax = [-math.cos(math.radians(t)), -math.sin(math.radians(t)), 0]
        w("    %s{wall: seg%d, displacement: [%s], axis: [%s, %s, 0], velocity: 0.005}" %
          ("- " if True else "", k, steps, fmt(ax[0]), fmt(ax[1])))
    w("  tolerance: 0.01")
    w("  check_every: %d" % v["check"])
    w("  min_steps: %d" % (2 * v["check"]))
    w("  max_steps: %d" % v["max_steps"])
    g = v["grid_div"]
    w("measure:   # stresses in cells (sigma_r, sigma_theta, sigma_v: scripts/shaft_report.py)")
    w("  every: 1000000000")
    w("  grid: {min: [0, 0, 0], max: [%s, %s, %s], divisions: [%d, %d, %d]}" % (fmt(L), fmt(L), fmt(H), g[0], g[1], g[2]))
    if name == "ci":   # checks scripts/shaft_network.py's forces rebuilt from the snapshots (cli_shaft)
        w("  force_network: true")
    w("output:")
    w("  history_every: %d" % v["check"])
    w("  snapshot_every: 0")
    text = "\n".join(out) + "\n"
    text = text.replace("holds:\n    - {wall", "holds:\n  walls:\n    - {wall")
    sys.stdout.write(text)


if __name__ == "__main__":
    main()
