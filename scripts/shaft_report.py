#!/usr/bin/python3
"""Shaft active earth pressure report (thesis Tran 2013, ch. 3, figs 3-9 to 3-17 and 3-21 to
3-23): the pressure on the shaft's segments against depth and against the radial displacement s,
at the thesis's three depths, compared with K0 and with the thesis's DEM; one table per run.

    /usr/bin/python3 scripts/shaft_report.py DIR [DIR ...] [--figures FIGDIR] [--phi DEG]
                                             [--k0 K0] [--unit-weight KN_M3] [--zone-fraction F]

Each DIR is the output directory of a shaft run (cases/shaft/{ci,slice,full}.yaml, written by
scripts/shaft_case.py). Several DIRs (e.g. two packing seeds): one table each, figures overlaid.
Reads from each DIR:
  case.yaml      the case as run: the segments (facet walls seg1, seg2, seg3; falls back to the
                 held facet walls), their force bands along z, the holds (their move axes), the
                 packing box and `packing.level`, the packing material's density, gravity
  holds.csv      one row per hold end: hold, step, time, converged, unbalanced, per segment
                 <seg>_target, <seg>_force (N, along its inward move axis), <seg>_displacement (m)
  walls.csv      per wall <name>_fx/_fy/_fz and per band <name>_b<k>_fx/_fy/_fz (N, the grains'
                 force on the wall); the row at each hold's step (else the last row before it)
  specimen.txt   the packed grains (`id x y z r`): the surface and the grains' weight
  packing.json   the interior porosity (the unit weight gamma = (1 - n) rho_s g), the level
  removed.csv    grains removed during the run (their weight is taken off from their step)
  measure_<step>.h5  (optional) the measurement grid at the hold ends: sigma_r, sigma_theta,
                 sigma_v against r in the cell layer nearest 0.49H deep
  particles_<step>.h5  (optional) the particle snapshots at the hold ends (holds.csv's step; id,
                 position): the failure zone (fig 3-18)

The segment geometry comes from its vertices: a = their mean distance from the z axis, the
segment's angular span (30 deg) and bisector theta_m; the inward move axis m is the hold's `axis`
(else -(cos theta_m, sin theta_m, 0)). The pressure in band k is p = (F_band . m) / (h_k w) with
w = 2 a sin(span / 2) the chord (the projection of the curved segment across its bisector) and
h_k the band's height clipped to the soil [z_bottom, H_s]. H_s, the surface: the packing box top
(or packing.json's level z) when `packing.level` is true, else the highest grain top in
specimen.txt. H = H_s - z_bottom. Depth below the surface d = H_s - z.
p is given for the middle segment (seg2, where the thesis's load cells were) and as the mean over
the three segments (three times the contacts: less noise). At the depths 0.24H, 0.49H and 0.84H
p is interpolated linearly between the band centres (the nearest band's value, flagged '*', when
the depth lies outside them). p0 = p at the first hold with every target 0 (the at-rest state).

Printed per run: the specimen (grains, porosity, gamma, surface), a per-hold table (s, converged,
unbalanced, each segment's force, p and p/p0 at the three depths for seg2 and the mean, the
equilibrium imbalance), the band table (p of the mean and of seg2 per band and hold, kPa), p0
against K0 gamma d and the measured K = p0 / (gamma d), the bands' sum against the segment's
force, and the thesis's targets, each `met` / `NOT met`:
  p0 within 15 % of K0 gamma d at each depth (K0 = 1 - sin 41 deg = 0.344, the thesis's);
  p/p0 within 10 points of the thesis's DEM (55/55/45 % at 0.5 mm, 25/25/18 % at 1 and
  2 mm, 20/20/10 % at 3 mm and beyond; the lab's 65/65/50 % at 0.5 mm printed beside it);
  the full active state by 2-3 mm: p at 3 mm within 5 % of p at the last hold.
Equilibrium per hold: the sum of all walls' forces minus the grains' weight vector (the grains'
m g summed from specimen.txt with the packing material's density, less the grains removed by
then) as a fraction of the weight; ~0 at rest. gamma uses the interior porosity of packing.json,
else the bulk porosity of specimen.txt (solid / ((box plan - the quarter shaft) x H)), else the
case's packing.porosity (a note), or --unit-weight. With several DIRs, p/p0 (mean of the segments)
averaged over the runs per displacement, with its range.
Stresses (measure files with a grid): the Love-Weber cell stress (compression positive, as fdem
writes it) divided by the cell's soil fraction (the part of the cell's plan outside the shaft
r < a, and below the surface), rotated to cylindrical axes at the soil centroid of the cell
(sigma_rr = c^2 sxx + 2cs sxy + s^2 syy, sigma_tt = s^2 sxx - 2cs sxy + c^2 syy), binned in r
(bins of the larger cell side from r = a); the ratio to the first hold in the first bin (the
thesis: sigma_r near the wall about 60 % at 1 mm and 40 % at 3 mm).
Failure zone (thesis fig 3-18, SH8: at s = 3 mm conical, radius about 0.2 m at the surface, about
2.5 a, alpha about 75 deg; particle snapshots at the hold ends): for every hold after the first, the
displacement |u| of each grain since the first hold's end (grains matched by id; grains removed
meanwhile left out), placed at its position at the first hold's end (r = hypot(x, y), depth
d = H_s - z). Displaced: |u| > F s (F = --zone-fraction, default 0.1; s the hold's mean segment
displacement less the first hold's). Like footing_report's displaced zone, a binned measure rather
than single grains: per depth bin of 0.1 m from the surface (the last bin takes the rest), the
grains in r bins of 0.025 m from a out to the box side L = min(box max x, y) (grains beyond L, in
the box's corner, left out: the annulus is complete only to L); r_zone is where the share of
displaced grains, going out from the shaft bin by bin, first falls below one half (linear between
the centres of the last majority bin and the next; a share rather than footing_report's mean |u|,
so that a few rolling surface grains do not widen it); r_zone = L, flagged '>=' (a lower bound), when
every bin to L is a majority, = a when not even the first is. Also the 90th percentile r of the
displaced grains per bin. Per hold: r at the surface (the top bin's r_zone) and at the base (the
deepest bin's), the zone's depth (the bottom of the deepest bin, counted from the surface without a
gap, whose r_zone - a exceeds two r bins, 0.05 m: wider than the grains dragged along the wall), the
apparent alpha = atan(depth / (r_surface - a)) and alpha fitted to r_zone against the bin-centre
depths down to that depth (tan alpha = -1 / slope; 90 deg: vertical; more: widening downward)
with the line's r at the surface. Target: the surface radius at 3 mm within 25 % of 0.2 m
(undecided when the box side limits it at L <= 0.25 m).

Writes DIR/shaft.csv (hold, s_mm, band, z_centre, depth, p_seg2, p_mean, then z_lo, z_hi, h,
p_seg1, p_seg3; Pa and m), DIR/shaft_depths.csv (hold, s_mm, p and p/p0 at the three depths, mean
and seg2) and, with a grid, DIR/shaft_stress.csv (hold, s_mm, r bin, sigma_r/theta/v in Pa), with
particle snapshots DIR/shaft_zone.csv (hold, s_mm, depth_bin, depth_lo, depth_hi, r_zone, grains,
displaced, r_zone_at_box_side, r_p90_displaced, threshold_mm; m).
Figures in FIGDIR (default FIRST_DIR/figures): pressure_displacement.png (p against s at the three
depths, figs 3-10..3-13), pressure_ratio.png (p/p0 against s with the thesis's DEM and lab
points), pressure_profile.png (p/(a gamma) against d/a at s = 1 and 4 mm or the nearest
holds, every band, with K0 and Rankine's Ka lines and, fig 3-17, Berezantzev's (lambda = 1),
Cheng & Hu's and Prater's (lambda = --k0) solutions at --phi from scripts/shaft_theory.py;
Terzaghi's is not drawn), p0_depth.png (p0 against depth with K0 gamma d, fig 3-9), stress_radius.png
(sigma_r, sigma_theta, sigma_v against r per hold, figs 3-21..3-23; only with measure files),
failure_zone.png (fig 3-18: |u| / s of the grains against (r, depth) at the hold nearest 3 mm and
at the last hold, the zone's outline r_zone per depth bin, the 90th percentiles, the fitted line,
the thesis's cone drawn from the shaft's foot at 75 deg, r = min(a + (H - d) / tan 75 deg, 0.2 m),
and, dotted, the 75 deg cone through r = 0.2 m at the surface; only with particle snapshots).
Needs Debian's python3-numpy, python3-h5py, python3-matplotlib, python3-yaml. Exit 2 on bad input.
"""
import argparse
import csv
import json
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from fdem_common import load_case, read_csv, system_python_fallback  # noqa: E402
import shaft_theory  # noqa: E402

system_python_fallback(["numpy", "h5py", "matplotlib", "yaml"])
import numpy as np  # noqa: E402

PROG = "shaft_report"
NAN = float("nan")
DEPTHS = (0.24, 0.49, 0.84)            # the thesis's load cells, depth / H
PHI = 41.0                              # Table 3-1
K0_THESIS = 1 - math.sin(math.radians(PHI))   # 0.344
P0_TOL = 0.15                           # p0 within 15 % of K0 gamma d
RATIO_TOL = 10.0                        # p/p0 within 10 percentage points of the thesis's DEM
ACTIVE_TOL = 0.05                       # "full active state by 2-3 mm"
# thesis DEM p/p0 (%) at the three depths; s >= 3 mm: the 3 mm values
THESIS_DEM = {0.5: (55, 55, 45), 1.0: (25, 25, 18), 2.0: (25, 25, 18), 3.0: (20, 20, 10)}
THESIS_LAB = {0.5: (65, 65, 50)}
THESIS_SIGMA_R = {1.0: 60, 3.0: 40}     # sigma_r near the wall / at rest (%), figs 3-21..3-23
PROFILE_S_MM = (1.0, 4.0)               # fig 3-17
THESIS_ZONE_R = 0.2                     # fig 3-18 (SH8): the failure zone's radius at the surface at 3 mm (m)
THESIS_ZONE_ALPHA = 75.0                # its cone angle from the horizontal (deg), read from the figure
ZONE_R_TOL = 0.25                       # the surface radius within 25 % of the thesis's
ZONE_FRACTION = 0.1                     # displaced: moved more than this fraction of s since hold 1
ZONE_DZ = 0.1                           # depth bins of the zone (m)
ZONE_DR = 0.025                         # r bins of the zone (m), about one to two grain diameters
ZONE_S_MM = 3.0                         # the hold drawn in failure_zone.png (the nearest), with the last
SEGMENT_NAMES = ("seg1", "seg2", "seg3")


class ReportError(Exception):
    pass


def warn(msg):
    print("%s: warning: %s" % (PROG, msg), file=sys.stderr)


def finite(v):
    return v is not None and isinstance(v, (int, float)) and math.isfinite(v)


def thesis_dem(s_mm):
    """The thesis's DEM p/p0 (%) at the three depths for a displacement s (mm), or None."""
    if s_mm >= 3.0 - 0.05:
        return THESIS_DEM[3.0]
    for s, v in THESIS_DEM.items():
        if abs(s_mm - s) < 0.05:
            return v
    return None


# ---------------------------------------------------------------------------------------------
# Reading a run
# ---------------------------------------------------------------------------------------------

def walls_of(case):
    return [w for w in (case.get("walls") or []) if isinstance(w, dict) and w.get("name")]


def segments_of(case, path):
    """The shaft's segments: [{name, a, span, theta_m, m (inward axis), edges}]."""
    walls = walls_of(case)
    held = {h.get("wall"): h for h in ((case.get("holds") or {}).get("walls") or []) if isinstance(h, dict)}
    names = [n for n in SEGMENT_NAMES if any(w["name"] == n for w in walls)]
    if not names:  # another naming: the held facet walls
        names = [w["name"] for w in walls if w.get("type") == "facets" and w["name"] in held]
    if not names:
        raise ReportError("%s: no shaft segments (facet walls seg1..seg3 or held facet walls)" % path)
    segs = []
    for n in names:
        w = next(x for x in walls if x["name"] == n)
        v = np.asarray(w.get("vertices") or [], dtype=float)
        if v.ndim != 2 or v.shape[0] < 2:
            raise ReportError("%s: wall %s has no vertices" % (path, n))
        rad = np.hypot(v[:, 0], v[:, 1])
        ang = np.arctan2(v[:, 1], v[:, 0])
        t0, t1 = float(ang.min()), float(ang.max())
        tm = 0.5 * (t0 + t1)
        m = -np.array([math.cos(tm), math.sin(tm), 0.0])
        h = held.get(n)
        if h and h.get("axis") is not None:
            ax = np.asarray(h["axis"], dtype=float)
            if np.linalg.norm(ax) > 0:
                ax = ax / np.linalg.norm(ax)
                if float(ax @ m) < 0.99:
                    warn("%s: the hold axis of %s %s is not the inward bisector %s" % (path, n, ax.round(4), m.round(4)))
                m = ax
        bands = w.get("bands") if isinstance(w.get("bands"), dict) else None
        edges = None
        if bands and bands.get("edges"):
            bax = np.asarray(bands.get("axis") or [0, 0, 1], dtype=float)
            if bax[2] / (np.linalg.norm(bax) or 1) < 0.999:
                warn("%s: the bands of %s are not along +z: ignored" % (path, n))
            else:
                edges = [float(e) for e in bands["edges"]]
        # the panels' inner radius: the chords between neighbouring vertices (in plan)
        o = np.argsort(ang, kind="stable")
        xy = v[o, :2]
        mids = 0.5 * (xy[1:] + xy[:-1])
        far = np.hypot(*(xy[1:] - xy[:-1]).T) > 1e-12
        r_in = float(np.hypot(mids[far, 0], mids[far, 1]).min()) if far.any() else float(rad.min())
        segs.append({"name": n, "a": float(rad.mean()), "span": t1 - t0, "theta_m": tm, "m": m,
                     "w": 2 * float(rad.mean()) * math.sin(0.5 * (t1 - t0)), "edges": edges, "r_in": r_in})
    return segs


def read_specimen(path):
    """{id: (x, y, z, r)} of specimen.txt, or None."""
    if not os.path.isfile(path):
        return None
    out = {}
    with open(path) as f:
        for line in f:
            if line.startswith("#") or not line.strip():
                continue
            p = line.split()
            if len(p) < 5:
                continue
            out[int(float(p[0]))] = tuple(float(x) for x in p[1:5])
    return out


def read_removed(path):
    """[(step, id)] of removed.csv."""
    if not os.path.isfile(path):
        return []
    c = read_csv(path)
    return [(int(s), int(i)) for s, i in zip(c.get("step", []), c.get("id", []))]


def row_at(wc, step):
    """The walls.csv row at `step` (the last such), else the last row before it; (index, exact)."""
    steps = wc.get("step") or []
    best = None
    for i, s in enumerate(steps):
        if int(s) == int(step):
            best = (i, True)
        elif s < step and (best is None or not best[1]):
            best = (i, False)
    return best


def material_density(case, name):
    for m in case.get("materials") or []:
        if isinstance(m, dict) and m.get("name") == name:
            return float(m.get("density", NAN))
    return NAN


def load_run(d, args):
    paths = {k: os.path.join(d, k) for k in ("case.yaml", "holds.csv", "walls.csv")}
    for p in paths.values():
        if not os.path.isfile(p):
            raise ReportError("%s is missing" % p)
    try:
        case = load_case(paths["case.yaml"])
        hc = read_csv(paths["holds.csv"])
        wc = read_csv(paths["walls.csv"])
    except (OSError, ValueError, StopIteration) as e:
        raise ReportError("%s: %s" % (d, e))
    if not hc.get("hold"):
        raise ReportError("%s has no hold rows (yet)" % paths["holds.csv"])
    run = {"dir": d, "case": case, "hc": hc, "wc": wc, "notes": []}
    run["label"] = os.path.basename(os.path.normpath(d))
    pk = case.get("packing") or {}
    run["seed"] = pk.get("seed")
    run["segs"] = segments_of(case, paths["case.yaml"])
    g = [float(x) for x in (case.get("gravity") or [0, 0, -9.81])]
    run["gvec"] = np.asarray(g)
    run["g"] = float(np.linalg.norm(run["gvec"])) or 9.81
    run["rho"] = material_density(case, pk.get("material")) if pk.get("material") else NAN
    if not finite(run["rho"]):
        run["rho"] = 2650.0
        run["notes"].append("no packing material density in case.yaml: 2650 kg/m3 assumed")
    box = pk.get("box") or {}
    bmin = [float(x) for x in box.get("min", [0, 0, 0])]
    bmax = [float(x) for x in box.get("max", [NAN, NAN, NAN])]
    run["box"] = (bmin, bmax)
    try:
        with open(os.path.join(d, "packing.json")) as f:
            pj = json.load(f)
    except (OSError, ValueError):
        pj = {}
        run["notes"].append("no packing.json")
    run["pj"] = pj
    spec = read_specimen(os.path.join(d, "specimen.txt"))
    run["spec"] = spec
    if spec is None:
        run["notes"].append("no specimen.txt: no grain weight (equilibrium check skipped)")
    # grains inside the shaft (centre within the panels' inner radius): they fell in over its rim
    # while packing and press on the segments from inside
    r_in = min(sg["r_in"] for sg in run["segs"])
    run["inside"] = sum(1 for (x, y, _, _) in spec.values() if math.hypot(x, y) < r_in) if spec else 0
    if run["inside"]:
        run["notes"].append("%d grain centres inside the shaft (r < %.4f m) in specimen.txt: they push the segments "
                            "outward from inside; the pressures are not the soil's alone (segments lower than the "
                            "packing's overfill? scripts/shaft_case.py makes them reach the domain's top)"
                            % (run["inside"], r_in))
    # the surface
    top_grains = max(z + r for (_, _, z, r) in spec.values()) if spec else NAN
    if pk.get("level"):
        hs = float((pj.get("level") or {}).get("z", bmax[2]))
        src = "the levelled packing box top"
    elif finite(top_grains):
        hs, src = top_grains, "the highest grain top"
    else:
        hs, src = float(pj.get("surface_z", bmax[2])), "packing.json surface_z"
    if not finite(hs):
        raise ReportError("%s: no surface (no specimen.txt, no packing box)" % d)
    run["Hs"], run["Hs_src"], run["top_grains"] = hs, src, top_grains
    run["zb"] = bmin[2]
    run["H"] = hs - run["zb"]
    # grains, porosity, unit weight
    a = float(np.mean([s["a"] for s in run["segs"]]))
    run["a"] = a
    if spec:
        r = np.array([v[3] for v in spec.values()])
        run["weight"] = float(np.sum(run["rho"] * 4.0 / 3.0 * math.pi * r ** 3) * run["g"])
        run["mass"] = run["weight"] / run["g"]
        if finite(bmax[0]) and finite(bmax[1]):
            area = (bmax[0] - bmin[0]) * (bmax[1] - bmin[1]) - 0.25 * math.pi * a * a
            vs = float(np.sum(4.0 / 3.0 * math.pi * r ** 3))
            run["n_bulk"] = 1 - vs / (area * run["H"])
        else:
            run["n_bulk"] = NAN
    else:
        run["weight"] = run["mass"] = run["n_bulk"] = NAN
    run["n_interior"] = float((pj.get("interior") or {}).get("porosity", NAN))
    if args.unit_weight:
        run["gamma"], run["gamma_src"] = 1e3 * args.unit_weight, "--unit-weight"
    elif finite(run["n_interior"]):
        run["gamma"], run["gamma_src"] = (1 - run["n_interior"]) * run["rho"] * run["g"], "interior porosity"
    elif finite(run["n_bulk"]):
        run["gamma"], run["gamma_src"] = (1 - run["n_bulk"]) * run["rho"] * run["g"], "bulk porosity (no interior)"
    elif finite(float(pk.get("porosity", NAN))):
        run["gamma"], run["gamma_src"] = (1 - float(pk["porosity"])) * run["rho"] * run["g"], "case packing.porosity"
        run["notes"].append("no measured porosity (packing.json, specimen.txt): gamma from the case's target "
                            "packing.porosity %.3f (give --unit-weight)" % float(pk["porosity"]))
    else:
        raise ReportError("%s: no porosity (packing.json, specimen.txt, packing.porosity) and no --unit-weight" % d)
    run["removed"] = read_removed(os.path.join(d, "removed.csv"))
    return run


# ---------------------------------------------------------------------------------------------
# Pressures per hold and band
# ---------------------------------------------------------------------------------------------

def band_layout(run):
    """The bands (common to the segments with bands): [(k, z_lo, z_hi clipped, h, z_centre, depth)]."""
    edges = None
    for s in run["segs"]:
        if s["edges"]:
            if edges is None:
                edges = s["edges"]
            elif s["edges"] != edges:
                run["notes"].append("the segments' band edges differ: %s's used" % run["segs"][0]["name"])
    if not edges:
        return []
    out = []
    for k in range(len(edges) - 1):
        lo, hi = max(edges[k], run["zb"]), min(edges[k + 1], run["Hs"])
        if hi - lo <= 1e-6:
            continue
        zc = 0.5 * (lo + hi)
        out.append((k + 1, lo, hi, hi - lo, zc, run["Hs"] - zc))
    return out


def compute(run):
    hc, wc, segs = run["hc"], run["wc"], run["segs"]
    bands = band_layout(run)
    have = [s for s in segs if s["edges"] and all("%s_b%d_fx" % (s["name"], b[0]) in wc for b in bands)]
    if bands and len(have) < len(segs):
        missing = [s["name"] for s in segs if s not in have]
        run["notes"].append("no band columns in walls.csv for %s" % ", ".join(missing))
    if not bands or not have:
        run["notes"].append("no force bands: the pressure against depth is skipped")
        bands = []
    run["bands"] = bands
    run["band_segs"] = [s["name"] for s in have]
    mid = "seg2" if any(s["name"] == "seg2" for s in have) else (have[len(have) // 2]["name"] if have else None)
    run["mid"] = mid
    wall_names = [w["name"] for w in walls_of(run["case"]) if w["name"] + "_fx" in wc]
    holds = []
    for i in range(len(hc["hold"])):
        h = {"hold": int(hc["hold"][i]), "step": int(hc["step"][i]), "time": hc["time"][i],
             "converged": int(hc.get("converged", [1] * len(hc["hold"]))[i]),
             "unbalanced": hc.get("unbalanced", [NAN] * len(hc["hold"]))[i]}
        tg = [hc[s["name"] + "_target"][i] for s in segs if s["name"] + "_target" in hc]
        dp = [hc[s["name"] + "_displacement"][i] for s in segs if s["name"] + "_displacement" in hc]
        h["target_mm"] = 1e3 * float(np.mean(tg)) if tg else NAN
        h["s_mm"] = 1e3 * float(np.mean(dp)) if dp else h["target_mm"]
        h["force"] = {s["name"]: hc.get(s["name"] + "_force", [NAN] * len(hc["hold"]))[i] for s in segs}
        ra = row_at(wc, h["step"])
        h["row"], h["row_exact"] = (ra if ra else (None, False))
        if ra and not ra[1]:
            run["notes"].append("walls.csv has no row at step %d (hold %d): the row at step %d used"
                                % (h["step"], h["hold"], int(wc["step"][ra[0]])))
        h["p"], h["p_seg"], h["band_sum"], h["wall_force"] = {}, {}, {}, {}
        j = h["row"]
        if j is not None:
            for s in segs:
                n = s["name"]
                if n + "_fx" in wc:
                    F = np.array([wc[n + "_fx"][j], wc[n + "_fy"][j], wc[n + "_fz"][j]])
                    h["wall_force"][n] = float(F @ s["m"])
            for s in have:
                n = s["name"]
                ps = []
                tot = 0.0
                for (k, lo, hi, hh, zc, dep) in bands:
                    F = np.array([wc["%s_b%d_f%s" % (n, k, c)][j] for c in "xyz"])
                    fm = float(F @ s["m"])
                    tot += fm
                    ps.append(fm / (hh * s["w"]))
                # bands above the surface (dropped from the layout) still count in the sum
                kk = 1
                while "%s_b%d_fx" % (n, kk) in wc:
                    if kk not in [b[0] for b in bands]:
                        F = np.array([wc["%s_b%d_f%s" % (n, kk, c)][j] for c in "xyz"])
                        tot += float(F @ s["m"])
                    kk += 1
                h["p_seg"][n] = np.array(ps)
                h["band_sum"][n] = tot
            if have:
                h["p"]["mean"] = np.mean([h["p_seg"][s["name"]] for s in have], axis=0)
                h["p"]["seg2"] = h["p_seg"][mid]
            h["equilibrium"] = equilibrium(run, wall_names, j, h["step"])
        else:
            h["equilibrium"] = None
        holds.append(h)
    run["holds"] = holds
    # the at-rest hold
    rest = next((h for h in holds if finite(h["target_mm"]) and abs(h["target_mm"]) < 1e-9), None)
    if rest is None:
        rest = holds[0]
        run["notes"].append("no hold with displacement 0: p0 from hold %d" % rest["hold"])
    run["rest"] = rest
    # the three depths
    run["depths"] = [f * run["H"] for f in DEPTHS]
    for h in holds:
        h["pd"], h["ratio"], h["outside"] = {}, {}, {}
        for key, pv in h["p"].items():
            vals, outs = [], []
            for dep in run["depths"]:
                v, out = interp_depth(bands, pv, dep)
                vals.append(v)
                outs.append(out)
            h["pd"][key] = np.array(vals)
            h["outside"][key] = outs
    for h in holds:
        for key in h["pd"]:
            p0 = rest["pd"].get(key)
            with np.errstate(divide="ignore", invalid="ignore"):
                h["ratio"][key] = np.where(p0 != 0, h["pd"][key] / p0, NAN) if p0 is not None else np.full(3, NAN)
    return run


def interp_depth(bands, p, dep):
    """p at depth `dep` linear between the band centres; (value, outside the centres?)."""
    if not bands:
        return NAN, True
    d = np.array([b[5] for b in bands])
    o = np.argsort(d)
    d, v = d[o], np.asarray(p)[o]
    if dep < d[0] or dep > d[-1]:
        return float(v[0] if dep < d[0] else v[-1]), True
    return float(np.interp(dep, d, v)), False


def equilibrium(run, wall_names, j, step):
    """Sum of the walls' forces minus the grains' weight vector m g (N), and |that| / weight."""
    if run["spec"] is None or not wall_names:
        return None
    wc = run["wc"]
    F = np.zeros(3)
    for n in wall_names:
        F += np.array([wc[n + "_fx"][j], wc[n + "_fy"][j], wc[n + "_fz"][j]])
    mass = run["mass"]
    gone = [i for (s, i) in run["removed"] if s <= step and i in run["spec"]]
    if gone:
        mass -= sum(run["rho"] * 4.0 / 3.0 * math.pi * run["spec"][i][3] ** 3 for i in gone)
    imb = F - mass * run["gvec"]
    W = mass * run["g"]
    return {"F": F, "imb": imb, "frac": float(np.linalg.norm(imb) / W), "W": W, "removed": len(gone)}


# ---------------------------------------------------------------------------------------------
# Stresses in the measurement grid
# ---------------------------------------------------------------------------------------------

def measure_files(run):
    """{step: path} of measure_<step>.h5 at the hold ends (files of another time are ignored)."""
    import h5py
    out = {}
    for h in run["holds"]:
        p = os.path.join(run["dir"], "measure_%08d.h5" % h["step"])
        if not os.path.isfile(p):
            continue
        try:
            with h5py.File(p, "r") as f:
                t = float(f.attrs.get("time", NAN))
                if "grid" not in f:
                    continue
        except OSError as e:
            warn("%s: %s" % (p, e))
            continue
        if finite(t) and abs(t - h["time"]) > 1e-9 * max(1.0, abs(h["time"])):
            warn("%s: written at t = %.6g s, not at the hold's end (%.6g s): ignored" % (p, t, h["time"]))
            continue
        out[h["step"]] = p
    return out


def stress_profiles(run):
    """Per hold with a measure file: r bins with sigma_r, sigma_theta, sigma_v (Pa, compression +)
    in the cell layer nearest 0.49H deep. Sets run['stress'] = {layer info, holds: [...]}."""
    import h5py
    files = measure_files(run)
    if not files:
        run["stress"] = None
        run["notes"].append("no measure_<step>.h5 with a grid at the hold ends: the stresses are skipped")
        return
    a, Hs = run["a"], run["Hs"]
    zt = Hs - 0.49 * run["H"]
    res = {"holds": []}
    flipped = False
    for h in run["holds"]:
        p = files.get(h["step"])
        if p is None:
            continue
        with h5py.File(p, "r") as f:
            g = f["grid"]
            at = g.attrs
            nx, ny, nz = int(at["nx"]), int(at["ny"]), int(at["nz"])
            o = [float(at["origin_x"]), float(at["origin_y"]), float(at["origin_z"])]
            sp = [float(at["spacing_x"]), float(at["spacing_y"]), float(at["spacing_z"])]
            S = np.asarray(g["stress"], dtype=float).reshape(nz, ny, nx, 6)
            npart = np.asarray(g["particles"], dtype=float).reshape(nz, ny, nx)
        zc = o[2] + (np.arange(nz) + 0.5) * sp[2]
        k = int(np.argmin(np.abs(zc - zt)))
        z0, z1 = o[2] + k * sp[2], o[2] + (k + 1) * sp[2]
        fz = max(0.0, min(z1, Hs) - max(z0, run["zb"])) / sp[2]
        m = 24  # plan sampling per cell side
        rows = []
        for j in range(ny):
            for i in range(nx):
                if npart[k, j, i] <= 0:
                    continue
                xs = o[0] + (i + (np.arange(m) + 0.5) / m) * sp[0]
                ys = o[1] + (j + (np.arange(m) + 0.5) / m) * sp[1]
                X, Y = np.meshgrid(xs, ys)
                soil = np.hypot(X, Y) >= a
                frac = soil.mean() * fz
                if frac < 0.25:
                    continue  # mostly shaft (or air): its Love-Weber stress is a few grains' share
                xc, yc = float(X[soil].mean()), float(Y[soil].mean())
                rc, th = math.hypot(xc, yc), math.atan2(yc, xc)
                sxx, syy, szz, sxy = (S[k, j, i, q] / frac for q in (0, 1, 2, 3))
                c, s = math.cos(th), math.sin(th)
                srr = c * c * sxx + 2 * c * s * sxy + s * s * syy
                stt = s * s * sxx - 2 * c * s * sxy + c * c * syy
                rows.append((rc, srr, stt, szz))
        if not rows:
            continue
        rows = np.array(rows)
        if np.mean(rows[:, 3]) < 0 and not flipped:
            flipped = True
            run["notes"].append("the grid's sigma_zz is negative on average: taken as tension positive, sign flipped")
        if flipped:
            rows[:, 1:] *= -1
        dr = max(sp[0], sp[1])
        nb = int(math.ceil((rows[:, 0].max() - a) / dr)) + 1
        bins = []
        for b in range(max(nb, 1)):
            lo, hi = a + b * dr, a + (b + 1) * dr
            sel = (rows[:, 0] < hi) & ((rows[:, 0] >= lo) | (b == 0))
            if not sel.any():
                continue
            bins.append({"bin": b + 1, "r_lo": lo, "r_hi": hi, "r": float(rows[sel, 0].mean()), "cells": int(sel.sum()),
                         "sr": float(rows[sel, 1].mean()), "st": float(rows[sel, 2].mean()),
                         "sv": float(rows[sel, 3].mean())})
        res["holds"].append({"hold": h["hold"], "s_mm": h["s_mm"], "step": h["step"], "bins": bins})
        res.update({"layer": k, "z0": z0, "z1": z1, "depth": Hs - 0.5 * (z0 + min(z1, Hs)), "dr": dr})
    run["stress"] = res if res["holds"] else None
    if run["stress"] is None:
        run["notes"].append("the measure files have no stressed cells in the layer near 0.49H")


# ---------------------------------------------------------------------------------------------
# The failure (displaced) zone from the particle snapshots (thesis fig 3-18, SH8)
# ---------------------------------------------------------------------------------------------

def snapshot_file(run, h):
    """particles_<step>.h5 of hold h, None if absent or written at another time (an older run's)."""
    import h5py
    p = os.path.join(run["dir"], "particles_%08d.h5" % h["step"])
    if not os.path.isfile(p):
        return None
    try:
        with h5py.File(p, "r") as f:
            t = float(f.attrs.get("time", NAN))
            if "id" not in f or "position" not in f:
                warn("%s: no id/position datasets: ignored" % p)
                return None
    except OSError as e:
        warn("%s: %s" % (p, e))
        return None
    if finite(t) and abs(t - h["time"]) > 1e-9 * max(1.0, abs(h["time"])):
        warn("%s: written at t = %.6g s, not at the hold's end (%.6g s): ignored" % (p, t, h["time"]))
        return None
    return p


def read_snapshot(path):
    """(ids, positions) of a particle snapshot, sorted by id."""
    import h5py
    with h5py.File(path, "r") as f:
        ids = np.asarray(f["id"][...], dtype=np.int64)
        x = np.asarray(f["position"][...], dtype=float)
    o = np.argsort(ids, kind="stable")
    return ids[o], x[o]


def zone_of(r, dep, um, lim, a, L, H, dz, dr):
    """The displaced zone of grains at (r, depth) that moved um (m), displaced where um > lim:
    per depth bin dz from the surface (the last bin takes the rest down to H and anything deeper),
    r bins dr from a (grains at r < a counted in the first) up to L (grains beyond L left out)."""
    disp = um > lim
    nz = max(1, int(math.ceil(H / dz - 1e-9)))
    nr = max(1, int(math.ceil((L - a) / dr - 1e-9)))
    kz = np.minimum((dep / dz).astype(int), nz - 1)
    jr = np.clip(((r - a) / dr).astype(int), 0, nr - 1)
    inside = r <= L
    bins = []
    for k in range(nz):
        sel = inside & (kz == k)
        frac = []
        for j in range(nr):
            cell = sel & (jr == j)
            frac.append(float(disp[cell].mean()) if cell.any() else NAN)
        # the run of majority bins from the shaft outward; r_zone where the fraction falls through 1/2,
        # linear between the centres of the last majority bin and the next
        m = 0
        while m < nr and finite(frac[m]) and frac[m] > 0.5:
            m += 1
        limited = m == nr
        if m == 0:
            rz = a
        elif limited:
            rz = L
        else:
            c0, c1 = a + (m - 0.5) * dr, min(a + (m + 0.5) * dr, 0.5 * (a + m * dr + L))
            f0, f1 = frac[m - 1], frac[m] if finite(frac[m]) else 0.0
            rz = c0 + (c1 - c0) * (f0 - 0.5) / (f0 - f1)
        dsel = sel & disp
        lo, hi = k * dz, min((k + 1) * dz, H)
        bins.append({"bin": k + 1, "d_lo": lo, "d_hi": hi, "d": 0.5 * (lo + hi), "r_zone": rz, "limited": limited,
                     "r_p90": float(np.percentile(r[dsel], 90)) if dsel.any() else NAN,
                     "grains": int(sel.sum()), "displaced": int(dsel.sum()), "frac": frac})
    return bins


def zone_summary(bins, a, dr):
    """Surface and base radius, the zone's depth, the apparent and the fitted cone angle."""
    top, base = bins[0], bins[-1]
    wide = [b for b in bins if b["r_zone"] - a > 2 * dr + 1e-9]
    # the zone's depth: the bottom of the deepest bin wider than the wall layer (2 r bins), counted
    # down from the surface without a gap
    depth = 0.0
    for b in bins:
        if b not in wide:
            break
        depth = b["d_hi"]
    out = {"r_surface": top["r_zone"], "r_base": base["r_zone"], "limited": top["limited"], "depth": depth,
           "alpha_app": NAN, "alpha_fit": NAN, "fit_bins": 0, "fit": None, "r_fit0": NAN}
    if depth > 0 and top["r_zone"] > a:
        out["alpha_app"] = math.degrees(math.atan2(depth, top["r_zone"] - a))
    fit = [b for b in bins if b["d_hi"] <= depth + 1e-9]
    if len(fit) >= 2:
        d = np.array([b["d"] for b in fit])
        rr = np.array([b["r_zone"] for b in fit])
        slope, icpt = (float(c) for c in np.polyfit(d, rr, 1))
        out["alpha_fit"] = math.degrees(math.atan2(1.0, -slope))
        out["fit_bins"] = len(fit)
        out["fit"] = (slope, icpt, 0.0, depth)
        out["r_fit0"] = icpt
    return out


def zone_profiles(run, fraction, dz=ZONE_DZ, dr=ZONE_DR):
    """Per hold after the first with a particle snapshot: the grains' displacement since the first
    hold's end and the zone where it exceeds `fraction` of the hold's shaft movement s (s less the
    first hold's). Sets run['zone'] = {ref hold, L, holds: [{hold, s_mm, lim, bins, summary, data}]}
    or None (a note)."""
    run["zone"] = None
    holds = run["holds"]
    if len(holds) < 2:
        run["notes"].append("one hold only: no failure zone (needs a later hold)")
        return
    ref = holds[0]
    pref = snapshot_file(run, ref)
    later = [(h, snapshot_file(run, h)) for h in holds[1:]]
    missing = [h["step"] for h, p in later if p is None]
    if pref is None or len(missing) == len(later):
        run["notes"].append("no particle snapshots particles_<step>.h5 at the hold ends (%s): the failure zone is skipped"
                            % ("hold %d, step %d" % (ref["hold"], ref["step"]) if pref is None
                               else "steps %s" % ", ".join(str(m) for m in missing)))
        return
    if missing:
        run["notes"].append("no particle snapshot at the end of the holds at steps %s: no failure zone there"
                            % ", ".join(str(m) for m in missing))
    bmin, bmax = run["box"]
    L = min(bmax[0], bmax[1]) if finite(bmax[0]) and finite(bmax[1]) else NAN
    ids0, x0 = read_snapshot(pref)
    if not finite(L):
        L = float(min(x0[:, 0].max(), x0[:, 1].max()))
    a, Hs, H = run["a"], run["Hs"], run["H"]
    res = {"ref": ref, "L": L, "dz": dz, "dr": dr, "fraction": fraction, "holds": []}
    for h, p in later:
        if p is None:
            continue
        s = (h["s_mm"] - ref["s_mm"]) / 1e3
        if not (finite(s) and s > 0):
            run["notes"].append("hold %d: shaft movement %.3g mm since hold %d: no failure zone"
                                % (h["hold"], 1e3 * s, ref["hold"]))
            continue
        ids, x = read_snapshot(p)
        _, i0, i1 = np.intersect1d(ids0, ids, assume_unique=True, return_indices=True)
        if len(i0) < len(ids0):
            run["notes"].append("hold %d: %d grains of hold %d's snapshot are gone (removed) and left out of its zone"
                                % (h["hold"], len(ids0) - len(i0), ref["hold"]))
        xr = x0[i0]
        um = np.linalg.norm(x[i1] - xr, axis=1)
        r = np.hypot(xr[:, 0], xr[:, 1])
        dep = np.clip(Hs - xr[:, 2], 0.0, None)
        lim = fraction * s
        bins = zone_of(r, dep, um, lim, a, L, H, dz, dr)
        res["holds"].append({"hold": h["hold"], "step": h["step"], "s_mm": 1e3 * s, "lim": lim, "bins": bins,
                             "sum": zone_summary(bins, a, dr), "r": r, "dep": dep, "um": um})
    run["zone"] = res if res["holds"] else None


def zone_hold(run, s_mm):
    z = run.get("zone")
    if not z:
        return None
    return min(z["holds"], key=lambda zh: abs(zh["s_mm"] - s_mm))


def print_zone(run):
    z = run.get("zone")
    if not z:
        return
    a = run["a"]
    print("failure zone (thesis fig 3-18): grains moving more than %.0f %% of s since hold %d's end (matched by id, "
          "placed at their hold-%d position); depth bins %.2f m, r bins %.3f m from a = %.3f m to the box side L = %.3f m;"
          % (100 * z["fraction"], z["ref"]["hold"], z["ref"]["hold"], z["dz"], z["dr"], a, z["L"]))
    print("  r_zone: where the share of displaced grains in the r bins, going out from the shaft, first falls below one "
          "half (linear between bin centres; '>=': still over one half at L, the box limits it); p90: the 90th "
          "percentile r of the displaced grains")
    hs = z["holds"]
    print("  %-13s " % "depth (m)" + " ".join("%15s" % ("%.2fmm r_zone p90" % zh["s_mm"]) for zh in hs))
    for k, b in enumerate(hs[0]["bins"]):
        cells = []
        for zh in hs:
            bb = zh["bins"][k]
            cells.append("%2s%6.3f %6.3f" % (">=" if bb["limited"] else "", bb["r_zone"], bb["r_p90"]))
        print("  %5.2f-%5.2f   %s   (%d grains)" % (b["d_lo"], b["d_hi"], " ".join("%15s" % c for c in cells), b["grains"]))
    for zh in hs:
        sm = zh["sum"]
        lim = any(b["limited"] for b in zh["bins"] if b["d_hi"] <= sm["depth"] + 1e-9)
        print("  s %.2f mm (hold %d, threshold %.3f mm, %d of %d grains displaced): r at the surface (top bin) %s%.3f m "
              "(%.2f a), at the base %s%.3f m; depth %.2f m%s (where the zone is wider than 2 r bins, %.3f m); alpha "
              "%s%s apparent atan(depth / (r_surface - a)), %s fitted to r_zone(depth) over %d bins (the line at the "
              "surface: r %s)%s"
              % (zh["s_mm"], zh["hold"], 1e3 * zh["lim"], sum(b["displaced"] for b in zh["bins"]),
                 sum(b["grains"] for b in zh["bins"]), ">=" if sm["limited"] else "", sm["r_surface"],
                 sm["r_surface"] / a, ">=" if zh["bins"][-1]["limited"] else "", sm["r_base"], sm["depth"],
                 " (to the base)" if sm["depth"] >= run["H"] - 1e-9 else "", 2 * z["dr"],
                 "<=" if sm["limited"] else "", "%.0f deg" % sm["alpha_app"] if finite(sm["alpha_app"]) else "-",
                 "%.0f deg" % sm["alpha_fit"] if finite(sm["alpha_fit"]) else "-", sm["fit_bins"],
                 "%.3f m" % sm["r_fit0"] if finite(sm["r_fit0"]) else "-",
                 "; the box side limits the zone: the radii are lower bounds, the angles uncertain" if lim else ""))
    print("  thesis (fig 3-18, SH8) at s = 3 mm: conical, r about %.2f m at the surface (about 2.5 a), alpha about %.0f deg"
          % (THESIS_ZONE_R, THESIS_ZONE_ALPHA))


def zone_target(run):
    name = "failure zone radius at the surface at 3 mm about %.1f m (within +-25 %%)" % THESIS_ZONE_R
    z = run.get("zone")
    if not z:
        return (name, "no particle snapshots", None)
    zh = next((x for x in z["holds"] if abs(x["s_mm"] - 3.0) < 0.05), None)
    if zh is None:
        return (name, "no 3 mm hold (the last at %.2f mm)" % z["holds"][-1]["s_mm"], None)
    sm = zh["sum"]
    rs = sm["r_surface"]
    if sm["limited"]:
        # at least L: beyond the band when L is, else undecided
        lim_hi = (1 + ZONE_R_TOL) * THESIS_ZONE_R
        return (name, ">= %.3f m (the box side)" % rs, False if rs > lim_hi else None)
    return (name, "%.3f m (%+.0f %%)" % (rs, 100 * (rs / THESIS_ZONE_R - 1)), abs(rs / THESIS_ZONE_R - 1) <= ZONE_R_TOL)


# ---------------------------------------------------------------------------------------------
# Printing
# ---------------------------------------------------------------------------------------------

def kpa(v, fmt="%7.2f"):
    return fmt % (v / 1e3) if finite(v) else " " * (len(fmt % 0.0) - 1) + "-"


def pct(v, fmt="%5.0f%%"):
    return fmt % (100 * v) if finite(v) else " " * (len(fmt % 0.0) - 1) + "-"


def print_run(run):
    pj = run["pj"]
    print("== %s%s" % (run["dir"], "  (packing seed %s)" % run["seed"] if run["seed"] is not None else ""))
    segs = run["segs"]
    print("shaft: a %.4f m; segments %s (span %s deg, w = 2 a sin(span/2) = %s m)"
          % (run["a"], ", ".join(s["name"] for s in segs), "/".join("%.1f" % math.degrees(s["span"]) for s in segs),
             "/".join("%.4f" % s["w"] for s in segs)))
    print("specimen: %s grains, weight %.1f N; surface H_s %.4f m (%s; grain tops reach %.4f m), soil H %.4f m; "
          "%d grain centres inside the shaft"
          % (len(run["spec"]) if run["spec"] else "?", run["weight"], run["Hs"], run["Hs_src"], run["top_grains"],
             run["H"], run["inside"]))
    print("porosity: interior %.3f (packing.json, %s grains), bulk %.3f (grains / (box - shaft) x H); gamma %.2f kN/m3 "
          "(%s, rho_s %.0f kg/m3)" % (run["n_interior"], (pj.get("interior") or {}).get("particles", "?"),
                                     run["n_bulk"], run["gamma"] / 1e3, run["gamma_src"], run["rho"]))
    if finite(run["n_bulk"]) and finite(run["n_interior"]) and run["gamma_src"] == "interior porosity":
        print("  (gamma from the bulk porosity would be %.2f kN/m3)" % ((1 - run["n_bulk"]) * run["rho"] * run["g"] / 1e3))
    dtxt = ", ".join("%.2fH = %.3f m" % (f, d) for f, d in zip(DEPTHS, run["depths"]))
    print("depths: %s" % dtxt)
    # per-hold table
    segn = [s["name"] for s in segs]
    dl = " ".join("%6s " % ("%.2fH" % f) for f in DEPTHS)   # 23 characters, like the values
    rl = " ".join("%5s" % ("%.2fH" % f) for f in DEPTHS)   # 17
    mid = run["mid"] or "seg2"
    print("%4s %8s %6s %4s %9s " % ("", "", "", "", "") + " ".join("%8s" % "" for _ in segn) +
          " | " + " | ".join(("%-23s", "%-17s", "%-23s", "%-17s")[i] % t for i, t in enumerate(
              ("p %s (kPa)" % mid, "p/p0 %s (%%)" % mid, "p mean (kPa)", "p/p0 mean (%)"))) + " |")
    print("%4s %8s %6s %4s %9s " % ("hold", "step", "s(mm)", "conv", "unbal") +
          " ".join("%8s" % ("F_" + n) for n in segn) + " | " + " | ".join((dl, rl, dl, rl)) + " | equil.")
    for h in run["holds"]:
        line = "%4d %8d %6.3f %4d %9.2e " % (h["hold"], h["step"], h["s_mm"], h["converged"], h["unbalanced"])
        line += " ".join("%8.3f" % h["force"][n] if finite(h["force"][n]) else "%8s" % "-" for n in segn)
        parts = []
        for key in ("seg2", "mean"):
            pd = h["pd"].get(key)
            if pd is None:
                parts += ["%23s" % "-", "%17s" % "-"]
                continue
            parts.append(" ".join(kpa(v, "%6.2f") + ("*" if o else " ") for v, o in zip(pd, h["outside"][key])))
            parts.append(" ".join(pct(v, "%5.0f") for v in h["ratio"][key]))
        eq = h["equilibrium"]
        line += " | " + " | ".join(parts) + " | %s" % ("%.2f%%" % (100 * eq["frac"]) if eq else "-")
        print(line)
    print("  F_<seg>: holds.csv's force along the inward axis (N); equil.: |sum of the walls' forces - m g| / m g")
    if any(any(h["outside"].get("mean", [])) for h in run["holds"]):
        print("  * the depth lies outside the band centres: the nearest band's pressure")
    # equilibrium details
    eqs = [(h, h["equilibrium"]) for h in run["holds"] if h["equilibrium"]]
    if eqs:
        print("equilibrium (sum of the walls' forces - m g, N; the weight %.1f N):" % eqs[0][1]["W"])
        for h, eq in eqs:
            print("  hold %d: (%+.3f, %+.3f, %+.3f) N, |.| = %.2f %% of the weight%s"
                  % (h["hold"], eq["imb"][0], eq["imb"][1], eq["imb"][2], 100 * eq["frac"],
                     ", %d grains removed" % eq["removed"] if eq["removed"] else ""))
    # consistency: bands vs the wall, walls.csv vs holds.csv
    worst_b, worst_h = 0.0, 0.0
    for h in run["holds"]:
        for n, tot in h["band_sum"].items():
            wf = h["wall_force"].get(n)
            if finite(wf) and abs(wf) > 1e-12:
                worst_b = max(worst_b, abs(tot / wf - 1))
        for n, wf in h["wall_force"].items():
            hf = h["force"].get(n)
            if finite(hf) and abs(hf) > 1e-12 and h["row_exact"]:
                worst_h = max(worst_h, abs(wf / hf - 1))
    if run["bands"]:
        print("consistency: the bands add up to the segments' force along m within %.2g %%; walls.csv's F.m matches "
              "holds.csv's <seg>_force within %.2g %%" % (100 * worst_b, 100 * worst_h))
    # band table
    if run["bands"]:
        for key, title in (("mean", "mean of %s" % "/".join(run["band_segs"])), ("seg2", run["mid"])):
            print("p per band (kPa), %s; K0 gamma d with K0 %.3f:" % (title, run["k0"]))
            print("  %4s %13s %7s %8s " % ("band", "z (m)", "depth", "K0gd") +
                  " ".join("%7s" % ("%.1fmm" % h["s_mm"]) for h in run["holds"]))
            for b, band in enumerate(run["bands"]):
                k, lo, hi, hh, zc, dep = band
                vals = " ".join(kpa(h["p"][key][b]) if key in h["p"] else "%7s" % "-" for h in run["holds"])
                print("  %4d %6.3f-%6.3f %7.3f %8.2f %s" % (k, lo, hi, dep, run["k0"] * run["gamma"] * dep / 1e3, vals))
    # at rest
    rest = run["rest"]
    if rest["pd"]:
        print("at rest (hold %d): K = p0 / (gamma d) (K0 %.3f):" % (rest["hold"], run["k0"]))
        for i, (f, dep) in enumerate(zip(DEPTHS, run["depths"])):
            ref = run["k0"] * run["gamma"] * dep
            print("  %.2fH (d %.3f m): K0 gamma d %.2f kPa; p0 seg2 %.2f kPa (K %.3f), mean %.2f kPa (K %.3f)"
                  % (f, dep, ref / 1e3, rest["pd"]["seg2"][i] / 1e3, rest["pd"]["seg2"][i] / (run["gamma"] * dep),
                     rest["pd"]["mean"][i] / 1e3, rest["pd"]["mean"][i] / (run["gamma"] * dep)))
        allb = run["bands"]
        kb = [rest["p"]["mean"][b] / (run["gamma"] * band[5]) for b, band in enumerate(allb)]
        wsum = sum(rest["p"]["mean"][b] * band[3] for b, band in enumerate(allb))
        wref = sum(run["gamma"] * band[5] * band[3] for band in allb)
        print("  K of the mean per band (top first): %s; over the whole height (sum p h / sum gamma d h): %.3f"
              % (" ".join("%.2f" % v for v in kb[::-1]), wsum / wref))
    print_stress(run)
    print_theory(run)
    print_zone(run)
    print_targets(run)
    for n in dict.fromkeys(run["notes"]):
        print("note: %s" % n)


def print_theory(run):
    """p / (a gamma) at the three depths at the holds nearest 1 and 4 mm against the analytical
    solutions (fig 3-17) at --phi with lambda = --k0."""
    a, gam, phi, lam = run["a"], run["gamma"], run["phi"], run["k0"]
    hs = [h for h in (nearest_hold(run, s) for s in PROFILE_S_MM) if h is not None and "mean" in h["pd"]]
    if not hs or not finite(gam):
        return
    print("p / (a gamma) at the three depths (mean of the segments) against the analytical solutions at phi %.1f deg, "
          "lambda = K0 %.3f (fig 3-17; scripts/shaft_theory.py):" % (phi, lam))
    print("  %6s %6s %7s | %11s %11s %11s %7s" % ("depth", "d/a", "s(mm)", "DEM", "Berezantzev", "Cheng&Hu", "Prater"))
    for i, (f, dep) in enumerate(zip(DEPTHS, run["depths"])):
        h_a = dep / a
        th = (shaft_theory.slipline_p(h_a, phi, 1.0), shaft_theory.slipline_p(h_a, phi, lam),
              shaft_theory.prater_p(h_a, phi, lam))
        for h in hs:
            print("  %5.2fH %6.2f %7.2f | %11.3f %11.3f %11.3f %7.3f"
                  % (f, h_a, h["s_mm"], h["pd"]["mean"][i] / (a * gam), th[0], th[1], th[2]))


def print_stress(run):
    st = run.get("stress")
    if not st:
        return
    print("stresses in the grid layer %d (z %.3f-%.3f m, depth %.3f m, nearest 0.49H = %.3f m; kPa, compression +; "
          "cell stress / soil fraction; r bins of %.3f m from a, r the mean soil-centroid radius of the bin's cells):"
          % (st["layer"], st["z0"], st["z1"], st["depth"], 0.49 * run["H"], st["dr"]))
    hs = st["holds"]
    bins = sorted({b["bin"]: b for sh in hs for b in sh["bins"]}.values(), key=lambda b: b["bin"])
    for key, name in (("sr", "sigma_r"), ("st", "sigma_theta"), ("sv", "sigma_v")):
        print("  %-11s %6s %5s " % (name, "r (m)", "cells") + " ".join("%7s" % ("%.1fmm" % sh["s_mm"]) for sh in hs))
        for b in bins:
            vals = []
            for sh in hs:
                x = next((y for y in sh["bins"] if y["bin"] == b["bin"]), None)
                vals.append(kpa(x[key]) if x else "%7s" % "-")
            print("  %-11s %6.3f %5d %s" % ("", b["r"], b["cells"], " ".join(vals)))
    base = hs[0]
    if base["bins"]:
        b0 = base["bins"][0]
        print("  near the wall (bin 1, r %.3f m) / hold %d:" % (b0["r"], base["hold"]))
        for sh in hs[1:]:
            b = next((x for x in sh["bins"] if x["bin"] == b0["bin"]), None)
            if b is None:
                continue
            ref = next((v for s, v in THESIS_SIGMA_R.items() if abs(sh["s_mm"] - s) < 0.05), None)
            print("    s %.2f mm: sigma_r %s, sigma_theta %s, sigma_v %s%s"
                  % (sh["s_mm"], pct(b["sr"] / b0["sr"] if b0["sr"] else NAN), pct(b["st"] / b0["st"] if b0["st"] else NAN),
                     pct(b["sv"] / b0["sv"] if b0["sv"] else NAN),
                     "  (thesis sigma_r about %d %%)" % ref if ref else ""))


def print_together(runs):
    """p/p0 (mean of the three segments) at the three depths, averaged over the runs, per target s."""
    rs = [r for r in runs if r["rest"]["pd"]]
    if len(rs) < 2:
        return
    ss = sorted({round(h["target_mm"], 3) for r in rs for h in r["holds"] if finite(h["target_mm"])})
    print("\nall %d runs together: p/p0 of the mean of the segments (%%), mean over the runs [range]:" % len(rs))
    print("  %6s %4s  %s   %s" % ("s(mm)", "runs", "  ".join("%16s" % ("%.2fH" % f) for f in DEPTHS), "thesis DEM"))
    for s_mm in ss:
        hs = [h for r in rs for h in r["holds"] if abs(h["target_mm"] - s_mm) < 1e-6 and "mean" in h["ratio"]]
        if not hs:
            continue
        cells = []
        for i in range(3):
            v = [100 * h["ratio"]["mean"][i] for h in hs if finite(h["ratio"]["mean"][i])]
            cells.append("%5.0f [%3.0f-%3.0f]" % (np.mean(v), min(v), max(v)) if v else "%16s" % "-")
        ref = thesis_dem(s_mm) if s_mm > 0 else None
        print("  %6.2f %4d  %s   %s" % (s_mm, len(hs), "  ".join("%16s" % c for c in cells),
                                     "/".join("%d" % t for t in ref) if ref else ""))


def targets(run):
    """[(name, value text, met or None)]."""
    out = []
    rest = run["rest"]
    if not rest["pd"]:
        return [("the pressure against depth", "no force bands", None)]
    for key in ("mean", "seg2"):
        for i, (f, dep) in enumerate(zip(DEPTHS, run["depths"])):
            ref = run["k0"] * run["gamma"] * dep
            v = rest["pd"][key][i]
            out.append(("p0 %s at %.2fH within 15 %% of K0 gamma d (%.2f kPa)" % (key, f, ref / 1e3),
                        "%.2f kPa (%+.0f %%)" % (v / 1e3, 100 * (v / ref - 1)), abs(v / ref - 1) <= P0_TOL))
    for h in run["holds"]:
        if h is rest or not finite(h["target_mm"]):
            continue
        ref = thesis_dem(h["target_mm"])
        if ref is None:
            continue
        lab = next((v for s, v in THESIS_LAB.items() if abs(h["target_mm"] - s) < 0.05), None)
        for key in ("mean", "seg2"):
            r = h["ratio"].get(key)
            if r is None:
                continue
            ok = all(finite(x) and abs(100 * x - t) <= RATIO_TOL for x, t in zip(r, ref))
            out.append(("p/p0 %s at %.1f mm within 10 pts of the thesis DEM %s%s" % (
                key, h["target_mm"], "/".join("%d" % t for t in ref),
                " (lab %s)" % "/".join("%d" % t for t in lab) if lab else ""),
                "/".join("%.0f" % (100 * x) if finite(x) else "-" for x in r) + " %", ok))
    # full active state by 2-3 mm
    three = next((h for h in run["holds"] if abs(h["target_mm"] - 3.0) < 0.05), None)
    last = run["holds"][-1]
    if three is None:
        out.append(("full active state by 2-3 mm (p at 3 mm within 5 % of the last hold's)",
                    "no 3 mm hold (the run ends at %.2f mm): not reached" % last["s_mm"], None))
    elif last is three:
        out.append(("full active state by 2-3 mm (p at 3 mm within 5 % of the last hold's)",
                    "3 mm is the last hold: no later hold to compare", None))
    else:
        for key in ("mean", "seg2"):
            a, b = three["pd"][key], last["pd"][key]
            dev = [abs(x / y - 1) if finite(x) and finite(y) and y else NAN for x, y in zip(a, b)]
            out.append(("full active state by 2-3 mm: p %s at 3 mm / at %.1f mm within 5 %%" % (key, last["s_mm"]),
                        "/".join("%+.0f" % (100 * (x / y - 1)) if finite(x) and finite(y) and y else "-"
                                 for x, y in zip(a, b)) + " %", all(finite(d) and d <= ACTIVE_TOL for d in dev)))
    out.append(zone_target(run))
    return out


def print_targets(run):
    for name, val, ok in targets(run):
        print("target: %-78s %-28s %s" % (name, val, "-" if ok is None else ("met" if ok else "NOT met")))


# ---------------------------------------------------------------------------------------------
# Tables
# ---------------------------------------------------------------------------------------------

def write_tables(run, outdir):
    def f(v, fmt="%.6g"):
        return fmt % v if finite(v) else ""
    written = []
    if run["bands"]:
        p = os.path.join(outdir, "shaft.csv")
        with open(p, "w", newline="") as fh:
            w = csv.writer(fh)
            w.writerow(["hold", "s_mm", "band", "z_centre", "depth", "p_seg2", "p_mean", "z_lo", "z_hi", "h"]
                       + ["p_" + n for n in run["band_segs"] if n != "seg2"])
            for h in run["holds"]:
                if "mean" not in h["p"]:
                    continue
                for b, (k, lo, hi, hh, zc, dep) in enumerate(run["bands"]):
                    w.writerow([h["hold"], f(h["s_mm"]), k, f(zc), f(dep), f(h["p"]["seg2"][b]), f(h["p"]["mean"][b]),
                                f(lo), f(hi), f(hh)] + [f(h["p_seg"][n][b]) for n in run["band_segs"] if n != "seg2"])
        written.append(p)
        p = os.path.join(outdir, "shaft_depths.csv")
        with open(p, "w", newline="") as fh:
            w = csv.writer(fh)
            cols = ["hold", "s_mm"]
            for key in ("mean", "seg2"):
                for fr in DEPTHS:
                    cols += ["p_%s_%.2fH" % (key, fr), "ratio_%s_%.2fH" % (key, fr)]
            w.writerow(cols)
            for h in run["holds"]:
                if "mean" not in h["pd"]:
                    continue
                row = [h["hold"], f(h["s_mm"])]
                for key in ("mean", "seg2"):
                    for i in range(3):
                        row += [f(h["pd"][key][i]), f(h["ratio"][key][i])]
                w.writerow(row)
        written.append(p)
    if run.get("stress"):
        p = os.path.join(outdir, "shaft_stress.csv")
        with open(p, "w", newline="") as fh:
            w = csv.writer(fh)
            w.writerow(["hold", "s_mm", "bin", "r_lo", "r_hi", "r", "cells", "sigma_r", "sigma_theta", "sigma_v"])
            for sh in run["stress"]["holds"]:
                for b in sh["bins"]:
                    w.writerow([sh["hold"], f(sh["s_mm"]), b["bin"], f(b["r_lo"]), f(b["r_hi"]), f(b["r"]), b["cells"],
                                f(b["sr"]), f(b["st"]), f(b["sv"])])
        written.append(p)
    if run.get("zone"):
        p = os.path.join(outdir, "shaft_zone.csv")
        with open(p, "w", newline="") as fh:
            w = csv.writer(fh)
            w.writerow(["hold", "s_mm", "depth_bin", "depth_lo", "depth_hi", "r_zone", "grains", "displaced",
                        "r_zone_at_box_side", "r_p90_displaced", "threshold_mm"])
            for zh in run["zone"]["holds"]:
                for b in zh["bins"]:
                    w.writerow([zh["hold"], f(zh["s_mm"]), b["bin"], f(b["d_lo"]), f(b["d_hi"]), f(b["r_zone"]),
                                b["grains"], b["displaced"], int(b["limited"]), f(b["r_p90"]), f(1e3 * zh["lim"])])
        written.append(p)
    return written


# ---------------------------------------------------------------------------------------------
# Figures
# ---------------------------------------------------------------------------------------------

STYLES = ["-", "--", ":", "-."]
MARKERS = ["o", "s", "^", "v", "D"]


def colours():
    import matplotlib.pyplot as plt
    return plt.rcParams["axes.prop_cycle"].by_key()["color"]


def fig_pressure(runs, path, ratio):
    import matplotlib.pyplot as plt
    rs = [r for r in runs if r["rest"]["pd"]]
    if not rs:
        return False
    cols = colours()
    fig, axes = plt.subplots(1, 3, figsize=(13, 4.2), sharey=ratio)
    for i, (ax, fr) in enumerate(zip(axes, DEPTHS)):
        for k, run in enumerate(rs):
            hs = [h for h in run["holds"] if "mean" in h["pd"]]
            s = [h["s_mm"] for h in hs]
            for key, ls, mk in (("mean", "-", "o"), ("seg2", "--", "s")):
                y = [(100 * h["ratio"][key][i]) if ratio else h["pd"][key][i] / 1e3 for h in hs]
                ax.plot(s, y, ls, marker=mk, ms=4, color=cols[k % len(cols)], mfc="none" if key == "seg2" else None,
                        label="%s, %s" % (run["label"], "mean of 3 segments" if key == "mean" else run["mid"]))
            if not ratio:
                ax.axhline(run["k0"] * run["gamma"] * run["depths"][i] / 1e3, color=cols[k % len(cols)], lw=0.7, ls=":",
                           label="K0 gamma d (%s)" % run["label"] if i == 0 else None)
        if ratio:
            sx = sorted(THESIS_DEM) + [4.0, 5.0]
            ax.plot(sx, [thesis_dem(s)[i] for s in sx], "k*", ms=9, label="thesis DEM")
            ax.plot(list(THESIS_LAB), [v[i] for v in THESIS_LAB.values()], "kx", ms=8, label="thesis lab")
            ax.axhline(100, color="grey", lw=0.6)
            ax.set_ylabel("p / p0 (%)")
        else:
            ax.set_ylabel("p (kPa)")
        ax.set_xlabel("radial displacement s (mm)")
        ax.set_title("depth %.2fH" % fr)
        ax.set_ylim(bottom=0)
        ax.grid(True, alpha=0.3)
    axes[0].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return True


def nearest_hold(run, s_mm):
    hs = [h for h in run["holds"] if "mean" in h["p"] and h is not run["rest"]]
    if not hs:
        return None
    return min(hs, key=lambda h: abs(h["s_mm"] - s_mm))


def fig_profile(runs, path, phi):
    import matplotlib.pyplot as plt
    rs = [r for r in runs if r["bands"]]
    if not rs:
        return False
    cols = colours()
    ka = math.tan(math.radians(45 - phi / 2)) ** 2
    fig, axes = plt.subplots(1, len(PROFILE_S_MM), figsize=(5.2 * len(PROFILE_S_MM), 5.5), sharey=True)
    dmax = 0.0
    for ax, s_want in zip(np.atleast_1d(axes), PROFILE_S_MM):
        for k, run in enumerate(rs):
            a, gam = run["a"], run["gamma"]
            h = nearest_hold(run, s_want)
            da = [b[5] / a for b in run["bands"]]
            dmax = max(dmax, max(da))
            c = cols[k % len(cols)]
            ax.plot(run["rest"]["p"]["mean"] / (a * gam), da, ":", color=c, marker=".", label="%s, at rest (mean)" % run["label"])
            if h is None:
                continue
            ax.plot(h["p"]["mean"] / (a * gam), da, "-o", color=c, ms=4, label="%s, s %.2f mm, mean" % (run["label"], h["s_mm"]))
            ax.plot(h["p"]["seg2"] / (a * gam), da, "--s", color=c, ms=4, mfc="none",
                    label="%s, s %.2f mm, %s" % (run["label"], h["s_mm"], run["mid"]))
        dd = np.linspace(0, dmax * 1.05, 20)
        ax.plot(rs[0]["k0"] * dd, dd, color="grey", lw=0.8, label="K0 gamma d (K0 %.3f)" % rs[0]["k0"])
        ax.plot(ka * dd, dd, color="k", lw=0.8, ls="-.", label="Rankine Ka gamma d (phi %.0f deg)" % phi)
        for (name, (hh, pp)), st in zip(shaft_theory.curves(phi, rs[0]["k0"], dmax * 1.05).items(),
                                        ((0, (5, 2)), (0, (1, 1)), (0, (3, 1, 1, 1)))):
            ax.plot(pp, hh, color="tab:brown", lw=1.2, ls=st, label="%s, phi %.0f" % (name, phi))
        ax.set_title("s = %.0f mm (or the nearest hold)" % s_want)
        ax.set_xlabel("p / (a gamma)")
        ax.set_xlim(left=0)
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=6)
    ax0 = np.atleast_1d(axes)[0]
    ax0.set_ylabel("depth / a")
    ax0.set_ylim(dmax * 1.05, 0)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return True


def fig_p0(runs, path):
    import matplotlib.pyplot as plt
    rs = [r for r in runs if r["bands"]]
    if not rs:
        return False
    cols = colours()
    fig, ax = plt.subplots(figsize=(5.5, 6))
    dmax = 0.0
    for k, run in enumerate(rs):
        c = cols[k % len(cols)]
        d = [b[5] for b in run["bands"]]
        dmax = max(dmax, run["H"])
        ax.plot(run["rest"]["p"]["mean"] / 1e3, d, "-o", color=c, ms=4, label="%s, mean of 3 segments" % run["label"])
        ax.plot(run["rest"]["p"]["seg2"] / 1e3, d, "--s", color=c, ms=4, mfc="none", label="%s, %s" % (run["label"], run["mid"]))
        dd = np.array([0, run["H"]])
        ax.plot(run["k0"] * run["gamma"] * dd / 1e3, dd, color=c, lw=0.8, ls=":",
                label="K0 gamma d (K0 %.3f, gamma %.2f kN/m3)" % (run["k0"], run["gamma"] / 1e3))
        for dep in run["depths"]:
            ax.axhline(dep, color="grey", lw=0.4)
    ax.set_ylim(dmax, 0)
    ax.set_xlim(left=0)
    ax.set_xlabel("p0 at rest (kPa)")
    ax.set_ylabel("depth below the surface (m)")
    ax.set_title("at-rest pressure on the shaft (fig 3-9); grey: 0.24/0.49/0.84H", fontsize=9)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return True


def fig_stress(runs, path):
    import matplotlib.pyplot as plt
    rs = [r for r in runs if r.get("stress")]
    if not rs:
        return False
    fig, axes = plt.subplots(1, 3, figsize=(13, 4.2))
    smax = max(sh["s_mm"] for r in rs for sh in r["stress"]["holds"]) or 1.0
    for k, run in enumerate(rs):
        for sh in run["stress"]["holds"]:
            c = plt.cm.viridis(0.9 * sh["s_mm"] / smax)
            r = [b["r"] for b in sh["bins"]]
            for ax, key in zip(axes, ("sr", "st", "sv")):
                ax.plot(r, [b[key] / 1e3 for b in sh["bins"]], STYLES[k % 4], marker=MARKERS[k % 5], ms=4, color=c,
                        label="%s, s %.2f mm" % (run["label"], sh["s_mm"]))
    for ax, name in zip(axes, ("sigma_r", "sigma_theta", "sigma_v")):
        ax.axvline(rs[0]["a"], color="k", lw=0.6)
        ax.set_xlabel("r (m)")
        ax.set_ylabel("%s (kPa, compression +)" % name)
        ax.set_ylim(bottom=0)
        ax.grid(True, alpha=0.3)
    st = rs[0]["stress"]
    axes[1].set_title("grid layer at depth %.3f m (near 0.49H)" % st["depth"], fontsize=9)
    axes[0].legend(fontsize=6)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return True


def thesis_cone(a, H, d):
    """The thesis's cone as drawn: from the shaft's foot (r = a at depth H) up at 75 deg, clipped at
    0.2 m: r = min(a + (H - d) / tan 75 deg, 0.2)."""
    return np.minimum(a + (H - d) / math.tan(math.radians(THESIS_ZONE_ALPHA)), THESIS_ZONE_R)


def fig_zone(runs, path):
    """|u| / s of the grains against (r, depth) at the hold nearest 3 mm and the last hold, the
    zone's outline and the thesis's cone (fig 3-18)."""
    import matplotlib.pyplot as plt
    from matplotlib.colors import LogNorm
    panels = []
    for run in runs:
        if not run.get("zone"):
            continue
        zs = run["zone"]["holds"]
        picks = [zone_hold(run, ZONE_S_MM), zs[-1]]
        for zh in picks:
            if not any(zh is q for _, q in panels if _ is run):
                panels.append((run, zh))
    if not panels:
        return False
    L0 = max(run["zone"]["L"] for run, _ in panels)
    H0 = max(run["H"] for run, _ in panels)
    w = min(12.0, max(4.5, 6.5 * L0 / H0 + 1.5))
    fig, axes = plt.subplots(1, len(panels), figsize=(w * len(panels) if len(panels) < 3 else 4 * len(panels), 7.5),
                             squeeze=False)
    tan_a = math.tan(math.radians(THESIS_ZONE_ALPHA))
    for ax, (run, zh) in zip(axes[0], panels):
        a, H, L = run["a"], run["H"], run["zone"]["L"]
        s = zh["s_mm"] / 1e3
        inside = zh["r"] <= L
        v = zh["um"][inside] / s
        o = np.argsort(v)
        sc = ax.scatter(zh["r"][inside][o], zh["dep"][inside][o], c=np.clip(v[o], 1e-3, None), s=4, cmap="viridis",
                        norm=LogNorm(vmin=0.01, vmax=1.0), linewidths=0)
        ax.axvspan(0, a, color="0.75", zorder=0)
        # the zone's outline: r_zone per depth bin, a step line
        rr, dd = [], []
        for b in zh["bins"]:
            rr += [b["r_zone"], b["r_zone"]]
            dd += [b["d_lo"], b["d_hi"]]
        sm = zh["sum"]
        ax.plot(rr, dd, color="r", lw=1.6, ls="--",
                label="zone: most grains moved > %.0f %% of s (%.2f mm); surface r %s%.3f m, alpha %s"
                % (100 * run["zone"]["fraction"], 1e3 * zh["lim"], ">=" if sm["limited"] else "", sm["r_surface"],
                   "%.0f deg (fit)" % sm["alpha_fit"] if finite(sm["alpha_fit"]) else "-"))
        ax.plot([b["r_p90"] for b in zh["bins"]], [b["d"] for b in zh["bins"]], "rx", ms=6,
                label="90th percentile r of the displaced grains")
        if sm["fit"]:
            sl, ic, d0, d1 = sm["fit"]
            ax.plot([ic + sl * d0, ic + sl * d1], [d0, d1], color="m", lw=1.0,
                    label="line fitted to the zone: alpha %.0f deg" % sm["alpha_fit"])
        d = np.linspace(0, H, 200)
        ax.plot(thesis_cone(a, H, d), d, "k-", lw=1.3,
                label="thesis: about 0.2 m at the surface, alpha ~75 deg (fig 3-18, read from the figure)")
        d2 = np.linspace(0, min(H, (THESIS_ZONE_R - a) * tan_a), 50)
        ax.plot(THESIS_ZONE_R - d2 / tan_a, d2, color="k", lw=0.8, ls=":",
                label="a 75 deg cone through 0.2 m at the surface (meets the shaft %.2f m deep)"
                % ((THESIS_ZONE_R - a) * tan_a))
        ax.axvline(L, color="0.4", lw=0.6)
        ax.set_xlim(0, 1.02 * max(L, THESIS_ZONE_R))
        ax.set_ylim(H, 0)
        ax.set_aspect("equal")
        ax.set_xlabel("r = hypot(x, y) (m); grey: the shaft r < a = %.3f m" % a)
        ax.set_ylabel("depth below the surface (m), at hold %d's position" % run["zone"]["ref"]["hold"])
        ax.set_title("%s: hold %d, s = %.2f mm (displacement since hold %d)"
                     % (run["label"], zh["hold"], zh["s_mm"], run["zone"]["ref"]["hold"]), fontsize=9)
        ax.legend(fontsize=6, loc="upper center", bbox_to_anchor=(0.5, -0.1))
        cb = fig.colorbar(sc, ax=ax, fraction=0.04, pad=0.02, extend="both")
        cb.set_label("|u| / s")
        cb.ax.axhline(run["zone"]["fraction"], color="r", lw=1.2)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return True


def make_figures(runs, figdir, phi):
    import matplotlib
    matplotlib.use("Agg")
    os.makedirs(figdir, exist_ok=True)
    done = []
    for name, fn in (("pressure_displacement.png", lambda p: fig_pressure(runs, p, False)),
                     ("pressure_ratio.png", lambda p: fig_pressure(runs, p, True)),
                     ("pressure_profile.png", lambda p: fig_profile(runs, p, phi)),
                     ("p0_depth.png", lambda p: fig_p0(runs, p)),
                     ("stress_radius.png", lambda p: fig_stress(runs, p)),
                     ("failure_zone.png", lambda p: fig_zone(runs, p))):
        p = os.path.join(figdir, name)
        if fn(p):
            done.append(name)
    return done


def main(argv):
    ap = argparse.ArgumentParser(prog="shaft_report.py", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("runs", nargs="+", metavar="DIR", help="output directory of a shaft run")
    ap.add_argument("--figures", metavar="FIGDIR", help="figure directory (default: FIRST_DIR/figures)")
    ap.add_argument("--phi", type=float, default=PHI, metavar="DEG",
                    help="friction angle of Rankine's Ka and the analytical solutions in the profile figure (default 41)")
    ap.add_argument("--k0", type=float, default=K0_THESIS, help="K0 of the reference line and the lambda of Prater and Cheng & Hu (default 1 - sin 41 deg = 0.344)")
    ap.add_argument("--unit-weight", type=float, metavar="KN_M3",
                    help="soil unit weight (default (1 - n) rho_s g, n the interior porosity of packing.json)")
    ap.add_argument("--zone-fraction", type=float, default=ZONE_FRACTION, metavar="F",
                    help="the failure zone: grains that moved more than F times the shaft movement s since hold 1 "
                         "(default 0.1)")
    args = ap.parse_args(argv[1:])
    if not args.zone_fraction > 0:
        ap.error("--zone-fraction must be positive")
    runs = []
    for d in args.runs:
        try:
            run = load_run(d, args)
            run["k0"] = args.k0
            run["phi"] = args.phi
            compute(run)
            stress_profiles(run)
            zone_profiles(run, args.zone_fraction)
        except ReportError as e:
            print("%s: %s" % (PROG, e), file=sys.stderr)
            return 2
        runs.append(run)
    labels = [r["label"] for r in runs]
    if len(set(labels)) < len(labels):  # e.g. two seeds' runs named alike in different folders
        for r in runs:
            r["label"] = os.path.normpath(r["dir"])
    for k, run in enumerate(runs):
        if k:
            print()
        print_run(run)
        try:
            for p in write_tables(run, run["dir"]):
                print("wrote %s" % p)
        except OSError as e:
            warn("cannot write the tables in %s: %s" % (run["dir"], e))
    if len(runs) > 1:
        print_together(runs)
    figdir = args.figures or os.path.join(args.runs[0], "figures")
    done = make_figures(runs, figdir, args.phi)
    print("wrote %s/{%s}" % (figdir, ", ".join(done)) if done
          else "no figures (no bands, no measure files, no particle snapshots)")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
