#!/usr/bin/env python3
"""Write the geogrid-reinforced fill over a void cases (thesis Tran 2013, ch. 6, sections 6.2-6.4).

    python3 scripts/void_case.py ci|slice|full n0|n1 > cases/void/VARIANT_N.yaml

n0: unreinforced; n1: the SS-0 grid 0.1 m above the formation. (The thesis's third run, the grid
with a frictionless interface, is n1 from n1's specimen with the sand-grid friction set to 0:
scripts/void.sh does it with --specimen and --set.)

The model (thesis fig 6-1; docs/cases/void.md): a rigid formation -- an FE block, every node
fixed -- whose top is z = 0, with a void region 0.2 m wide (x) and `depth` deep centred in x
through the whole width in y (the block's `void` element set); on it, in this order, 0.1 m of
"natural soil" (layer 1), the grid laid on it (joins the packing after layer 1, rigid), the fill
(the other layers, 0.1 m each), struck off level, and a surcharge layer of dense grains worth
5 kPa (packing.surcharge). Then: hold 1 releases the grid (coupling.rigid_steps) and runs to
equilibrium; hold 2 begins by removing the void's elements at once (fem.remove) and runs to
equilibrium. The grains, the sand and the interface are chapter 5's (Table 6-1 = Table 5-1):
d 10.2 mm, sd 2.0 mm (6.2-14.2 mm), tan phi 0.68, interface tan phi 0.42; packed frictionless,
shaken, porosity 0.36. The formation's surface is interface too: it takes the interface's 0.42
(the thesis gives one interface; its own material `formation`, so that the frictionless-interface
run changes the grid's alone).
Variants (the grains are never scaled; the domain is):
  ci    L 0.30 m, void 0.1 m wide and 0.1 m deep, 0.1 m of fill, y two aperture pitches
        (a test of the machinery: minutes)
  slice L 1.10 m (the thesis's length: the 0.45 m either side of the void's centre kept), void
        0.2 x 0.3 m, 0.6 m of fill, y four aperture pitches (0.1184 m = 11.6 d) between
        frictionless walls on mid-aperture planes (the grid restrained in y there)
  full  the thesis's box: L 1.1 m, y 0.3 m, grid 1.06 x 0.3 m (29 x 11 ribs)
  w05, w10, w15  measurements, not shipped cases (docs/cases/void.md, "Over a narrower void"):
        the slice's grains and y width over a void W = 0.05 / 0.10 / 0.15 m wide (4.9 / 9.8 /
        14.7 grain diameters), 1.5 W deep, 1.5 W of soil either side, soil 0.2 / 0.3 / 0.5 m
        deep; n0 only. Does the unreinforced fill arch, and from what width on does it not?
"""
import sys

VARIANTS = {
    "ci": dict(L=0.30, W=0.0592, void=(0.10, 0.20), depth=0.10, base=0.15, fill_layers=1, long_ribs=2,
               overhang=0.0128, symmetric_y=True, dx=0.05, dz=0.05, max_steps=40000, check=500,
               kinetic=1e-3, grid_div=[6, 1, 5]),
    "slice": dict(L=1.10, W=0.1184, void=(0.45, 0.65), depth=0.30, base=0.40, fill_layers=6, long_ribs=4,
                  overhang=0.0128, symmetric_y=True, dx=0.05, dz=0.10, max_steps=400000, check=1000,
                  kinetic=1e-4, grid_div=[22, 1, 20]),
    "full": dict(L=1.10, W=0.30, void=(0.45, 0.65), depth=0.30, base=0.40, fill_layers=6, long_ribs=11,
                 overhang=0.0, symmetric_y=False, dx=0.05, dz=0.10, max_steps=400000, check=1000,
                 kinetic=1e-4, grid_div=[22, 1, 20]),
}


def narrow(w, fill_layers):
    """A measurement of whether the slice's grains arch over a void w wide (docs/cases/void.md, "Over
    a narrower void"): the slice's y width, the void 1.5 w deep, 1.5 w of soil either side, n0 only."""
    return dict(L=4 * w, W=0.1184, void=(1.5 * w, 2.5 * w), depth=1.5 * w, base=2 * w,
                fill_layers=fill_layers, long_ribs=4, overhang=0.0128, symmetric_y=True, dx=w / 2, dz=w / 2,
                max_steps=300000, check=1000, kinetic=1e-4, grid_div=[round(4 * w / 0.05), 1, 20])


VARIANTS.update(w05=narrow(0.05, 1), w10=narrow(0.10, 2), w15=narrow(0.15, 4))


NATURAL = 0.1        # m of natural soil under the grid (one layer)
LAYER = 0.1          # every layer's nominal height
SURCHARGE = 0.05     # m
SURCHARGE_KPA = 5.0
POROSITY = 0.36
RIB, APERTURE_X, THICK = 0.004, 0.0338, 0.0009
PITCH_X = RIB + APERTURE_X
RHO_SURCHARGE = SURCHARGE_KPA * 1000 / (9.81 * (1 - POROSITY) * SURCHARGE)


def fmt(v):
    return ("%.6f" % v).rstrip("0").rstrip(".") if abs(v) > 1e-12 else "0"


def vec(v):
    return "[" + ", ".join(fmt(x) for x in v) + "]"


def main():
    if len(sys.argv) != 3 or sys.argv[1] not in VARIANTS or sys.argv[2] not in ("n0", "n1"):
        sys.exit("usage: void_case.py ci|slice|full|w05|w10|w15 n0|n1 > cases/void/VARIANT_N.yaml")
    name, n = sys.argv[1], sys.argv[2]
    if name.startswith("w") and n != "n0":
        sys.exit("void_case.py: %s is a measurement of the unreinforced fill: n0 only" % name)
    v = VARIANTS[name]
    L, W, depth, base = v["L"], v["W"], v["depth"], v["base"]
    x0, x1 = v["void"]
    layers = 1 + v["fill_layers"]
    H = layers * LAYER
    grid = n == "n1"
    # transverse ribs along x: as many as fit with at least 5 mm to the end walls, centred
    nt = int((L - RIB - 0.01) / PITCH_X) + 1
    glen = nt * RIB + (nt - 1) * APERTURE_X
    gx = (L - glen) / 2
    top = H + SURCHARGE + 0.25  # the domain's top: room for the packing clouds
    o = []
    w = o.append
    w("# Geogrid-reinforced fill over a void, %s variant, %s (thesis ch. 6; written by" % (
        name, "reinforced (N = 1)" if grid else "unreinforced (N = 0)"))
    w("# scripts/void_case.py %s %s). A rigid formation (FE block, every node fixed) with a void" % (name, n))
    w("# %s m wide x %s m deep centred at x = %s m; %s m natural soil%s, %s m fill, a %s kPa surcharge;" % (
        fmt(x1 - x0), fmt(depth), fmt((x0 + x1) / 2), fmt(NATURAL), ", the SS-0 grid on it" if grid else "",
        fmt(H - NATURAL), fmt(SURCHARGE_KPA)))
    w("# hold 1: %s equilibrium; hold 2: the void's elements removed at once, equilibrium." % (
        "the grid released," if grid else ""))
    w("#   mpirun -n 2 build/fdem run cases/void/%s_%s.yaml --out out/void_%s_%s" % (name, n, name, n))
    w("#   scripts/void.sh %s        (n0, n1, n1 with a frictionless interface, and the report)" % name)
    w("# docs/cases/void.md")
    w("name: void_%s_%s" % (name, n))
    w("domain: {min: %s, max: %s}" % (vec([-0.01, -0.01, -base - 0.01]), vec([L + 0.01, W + 0.01, top])))
    w("gravity: [0, 0, -9.81]")
    w("time: {safety: 0.3, steps: 5000000}   # an upper bound: the run ends with its last hold")
    w("damping: 0.2")
    w("rolling_law: total   # the thesis's rolling law (eqs 3-7/3-8; its engine: YADE's NormalInelasticity law), docs/case-format.md#rolling-laws")
    w("materials:   # Table 6-1 (= Table 5-1)")
    w("  - {name: sand, young: 3.8e7, density: 2650, kt_kn: 0.25, friction: 0.68, rolling_stiffness: 0.01, rolling_limit: 1.0}")
    w("  - {name: smooth, young: 3.8e7, density: 7850, kt_kn: 0.25, friction: 0.0}")
    if grid:
        w("  - {name: grid, young: 3.8e7, density: 950, kt_kn: 0.25, friction: 0.42}   # the grid's interface")
    w("  - {name: formation, young: 3.8e7, density: 2000, kt_kn: 0.25, friction: 0.42}   # the formation's (the thesis: one interface)")
    w("  # the surcharge: the sand's contact parameters, dense enough that %s m at porosity %s weigh %s kPa" % (
        fmt(SURCHARGE), fmt(POROSITY), fmt(SURCHARGE_KPA)))
    w("  - {name: surcharge, young: 3.8e7, density: %.0f, kt_kn: 0.25, friction: 0.68, rolling_stiffness: 0.01, rolling_limit: 1.0}" % RHO_SURCHARGE)
    w("# the interface's friction is the pair's (docs/case-format.md#interactions)")
    if grid:
        w("interactions:   # 0, 1: the grid's (scripts/void.sh sets them to 0 for the frictionless-interface run)")
        w("  - {materials: [sand, grid], friction: 0.42}")
        w("  - {materials: [surcharge, grid], friction: 0.42}")
    else:
        w("interactions:")
    w("  - {materials: [sand, formation], friction: 0.42}")
    w("walls:")
    w("  - {name: xmin, type: plane, material: smooth, point: [0, 0, 0], normal: [1, 0, 0]}")
    w("  - {name: xmax, type: plane, material: smooth, point: %s, normal: [-1, 0, 0]}" % vec([L, 0, 0]))
    w("  - {name: ymin, type: plane, material: smooth, point: [0, 0, 0], normal: [0, 1, 0]}")
    w("  - {name: ymax, type: plane, material: smooth, point: %s, normal: [0, -1, 0]}" % vec([0, W, 0]))
    w("packing:")
    w("  material: sand")
    w("  box: {min: [0, 0, 0], max: %s}" % vec([L, W, H]))
    w("  layers: %d   # 0.1 m each: the natural soil, then the fill" % layers)
    w("  porosity: %s" % fmt(POROSITY))
    w("  size: {distribution: normal, mean: 0.0102, sd: 0.002, min: 0.0062, max: 0.0142}")
    w("  seed: 61")
    w("  friction: 0")
    w("  cloud_fraction: 0.3")
    w("  shaking: {walls: [xmin, xmax], amplitude: 0.0005, frequency: 50, cycles: 3, direction: [1, 0, 0]}")
    w("  settle: {criterion: porosity, porosity_change: 0.005, max_steps: 50000, check_every: 500}")
    w("  structures:   # the formation from the start%s" % (", the grid after the natural soil" if grid else ""))
    w("    - {mesh: formation, after_layer: 0}")
    if grid:
        w("    - {mesh: grid, after_layer: 1}")
    w("  level: true   # struck off at the box's top")
    w("  surcharge: {material: surcharge, thickness: %s}" % fmt(SURCHARGE))
    w("  final_steps: 1000")
    w("fem:")
    w("  mass_scaling: 500   # dynamic relaxation: the static answer does not depend on the grid's mass")
    w("  damping: 1000   # 1/s: until the first check, then at most this (coupling.creep_damping)")
    w("  load_steps: [1, 1]   # two holds: 1 at rest, 2 after the removal (no FE loads)")
    w("  max_steps: %d" % v["max_steps"])
    w("  check_every: %d" % v["check"])
    w("  materials:")
    w("    - {name: rock, young: 1.0e8, poisson: 0.3, density: 2000}   # the formation (every node fixed)")
    if grid:
        w("    # SS-0, Table 5-1; nlgeom: the grid over the void stretches as it sags (a small-strain grid")
        w("    # misses that strain and reads the soil's drag towards the void as compression)")
        w("    - {name: pp, young: 1.4e9, poisson: 0.3, density: 950, nlgeom: true}")
    w("  meshes:")
    w("    - name: formation")
    w("      material: rock")
    w("      block:")
    w("        min: %s" % vec([0, 0, -base]))
    w("        max: %s" % vec([L, W, 0]))
    w("        divisions: [%d, 1, %d]" % (round(L / v["dx"]), round(base / v["dz"])))
    w("        void: {min: %s, max: %s}   # element set `void`" % (vec([x0, 0, -depth]), vec([x1, W, 0])))
    if grid:
        w("    - name: grid")
        w("      material: pp")
        w("      geogrid:")
        w("        origin: %s   # mid-plane z = %s m, on the natural soil" % (vec([gx, 0, NATURAL - THICK / 2]), fmt(NATURAL)))
        w("        length: %s   # %d transverse ribs, centred" % (fmt(glen), nt))
        w("        width: %s" % fmt(W))
        if v["overhang"] > 0:
            w("        side_overhang: %s   # half an aperture: the y walls are mid-aperture planes" % fmt(v["overhang"]))
        w("        longitudinal_ribs: %d" % v["long_ribs"])
        w("        transverse_ribs: %d" % nt)
        w("        rib_width: %s" % fmt(RIB))
        w("        thickness: %s" % fmt(THICK))
        w("        max_element_length: 0.0085")
        w("        element: hex8i   # one brick through a rib's 0.9 mm: hex8 would lock (34 x too stiff in bending)")
    w("  restraints:")
    w("    - {mesh: formation, region: {min: %s, max: %s}, fixed: [x, y, z]}   # rigid" % (
        vec([-1, -1, -base - 1]), vec([L + 1, W + 1, 1])))
    if grid and v["symmetric_y"]:
        w("    - {mesh: grid, node_set: ymin, fixed: [y]}   # symmetry planes through the apertures")
        w("    - {mesh: grid, node_set: ymax, fixed: [y]}")
    w("  remove:")
    w("    - {mesh: formation, element_set: void, at_hold: 1}   # at the start of hold 2")
    w("coupling:")
    w("  material: %s" % ("grid" if grid else "formation"))
    w("  surfaces:")
    w("    - {mesh: formation, name: formation, material: formation}")
    if grid:
        w("    - {mesh: grid, name: grid}")
    w("  rigid_steps: 2000")
    w("  tolerance: 0.01")
    w("  kinetic_ratio: %g   # and nothing still falling into the void" % v["kinetic"])
    w("  # the fill balanced as a whole: the mass-scaled grid rings on the soil after its release, its")
    w("  # supports' force swinging about the weight while each grain is nearly balanced")
    w("  grain_resultant: 0.01")
    w("  # a part at rest drifts less than 10 nm per DEM step between checks; the FE damping at each")
    w("  # check half the largest with which a part creeping at that rate still balances as a whole")
    w("  creep: %s" % fmt(1e-8 * v["check"]))
    w("  creep_damping: 0.5")
    w("# at step 0 and each hold's end: porosity and stress in 0.05 m cells over the soil and the void")
    w("# (figs 6-8 to 6-10: the report sums the porosity windows of 0.1 m), the contact network (roses,")
    w("# figs 6-6, 6-7) and the grains' positions (displacements, fig 6-5)")
    w("measure:")
    w("  every: 1000000000")
    gd = v["grid_div"]
    w("  grid: {min: %s, max: %s, divisions: %s}" % (vec([0, 0, -depth]), vec([L, W, H]),
                                                   "[%d, %d, %d]" % (gd[0], gd[1], round((H + depth) / 0.05))))
    w("  force_network: true")
    w("  particle_displacements: true")
    w("output:")
    w("  history_every: 1000")
    w("  snapshot_every: 0")
    print("\n".join(o))


if __name__ == "__main__":
    main()
