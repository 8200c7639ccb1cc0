#!/usr/bin/python3
"""Geogrid-reinforced fill over a void (thesis Tran 2013, ch. 6, figs 6-5 to 6-10): equilibrium,
porosity change, stress redistribution, settlement, contact fabric and grid response of void runs
(cases/void/*.yaml, scripts/void_case.py), one output directory per run.

    /usr/bin/python3 scripts/void_report.py DIR [DIR ...] [--labels A,B,C] [--figures FIGDIR]
                                           [--csv FILE] [--check]

Typical use: unreinforced (n0), reinforced (n1), and n1 with the sand-grid friction set to 0
(scripts/void.sh). --labels is split at the commas not followed by a space. Default labels: the
case name (+ ", interface friction 0" when the case's sand-grid friction is 0; + the directory's
name when two coincide). Reads from each DIR: case.yaml (the `formation` block's
void {min, max}; packing.box: L, W, the soil from its min z to its top H), interface.csv (the
hold ends: the last row of hold 0 = "rest", the grid released; of hold 1 = "final", after the
void's elements were removed), structures.json (the geogrid layout), and at the two hold ends
measure_<step>.h5, particles_<step>.h5 and (with a grid) fe_<step>.h5, all required.
packing.json is optional (absent when the run started from a specimen).
Printed per run (--csv: one row per run with every number):
 1 equilibrium at both hold ends: dem/fe_unbalanced, the hold's steps (from the previous hold's
   end) vs fem.max_steps (reached: "not converged"), the fastest grain, the grains' weight
   sum(m g) vs -fz (the side walls are frictionless).
 2 porosity change rest -> final in windows 0.1 m (x) x the width x 0.1 m (z) over the soil, each
   the plain mean of its 0.05 m cells (equal volumes); relative 100 (n_f - n_r)/n_r (%) and
   absolute 100 (n_f - n_r) (percentage points); the largest, the largest above the void (window
   centre in [x0, x1]), tables with z rows top to bottom.
 3 sigma_zz, sigma_xx (Love-Weber, compression +, mean over y) in 0.05 m cell rows on the
   formation, at mid-height and under the surcharge, rest and final; final/rest over the void's
   centre (cells within half a cell of the centre line) and beside it (the cells just outside).
 4 settlement u_z = final - rest position of the sand grains (by id), in 0.05 m cells of the rest
   position; profiles at the surface (rest z in the top 0.05 m) and mid-depth (0.05 m band at
   H/2) in 0.025 m bins (0.05 m in a box longer than 0.6 m); the largest surface settlement above
   the void and / void depth (arching: no collapse at the surface); the distance from the centre
   line beyond which |u_z| < 0.1 mm (thesis: nothing beyond 0.45 m); the grains in the void.
 5 contact orientations (/force_network branch vectors, midpoint over the void: x in [x0, x1], z
   in the soil) in the xz, yz, xy planes, folded to [0, 180), 18 bins, rest and final; in xz the
   share within 30 deg of horizontal and of vertical.
 6 with a grid: -u_z of the nodes on the longitudinal ribs per x (mean over y; final and since
   rest); sigma_xx of the rib elements per x column (MPa) and T = sum(sigma_xx A_e) / W (kN/m).
   The grid's elements are those of its fem material inside its structures.json bounding box
   (element rows are written rank by rank; runs of fdem before Dec 2026 also wrote the node rows
   in the solver's numbering, so nothing here relies on structures.json's offsets).
 7 when the run wrote particle snapshots during hold 2 (output.snapshot_every): the time
   history after the removal -- per snapshot the largest surface settlement over the void (as in
   4), the grains in the void, the fastest grain and interface.csv's DEM and FE unbalanced ratios
   at that step; and the first interface.csv row of hold 2 with both ratios below
   coupling.tolerance (the thesis's "all forces balanced" alone, without fdem's kinetic-energy
   condition), with the surface settlement at the snapshot nearest to it. With a grid, from the
   fe_<step>.h5 written with each snapshot: its largest settlement since rest and its mean T over
   the void (as in 6).
Figures (--figures FIGDIR): void_porosity.png, void_displacement.png, void_stress.png,
void_roses.png, void_grid.png (runs with a grid), void_history.png (runs with section 7: the
surface's and the grid's settlement against the time after the removal); the void is shaded or
hatched on every x axis.
--check: every porosity window has 2 x 2 x ny cells and equals their mean; rest and final have
the same grain ids (and position change = displacement change); at rest the grains' weight is
within 5 % of -fz. Exit 1 when one fails. Needs Debian's python3-numpy, -h5py, -matplotlib,
-yaml. Exit 2 on bad input.
"""
import argparse
import json
import math
import os
import re
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from fdem_common import load_case, read_csv, system_python_fallback  # noqa: E402

system_python_fallback(["numpy", "h5py", "matplotlib", "yaml"])
import numpy as np  # noqa: E402
import h5py  # noqa: E402
import matplotlib  # noqa: E402

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.colors import SymLogNorm  # noqa: E402

PROG = "void_report"
NAN = float("nan")
INF = float("inf")
WIN = 0.1          # porosity windows (m), thesis figs 6-8 to 6-10
CELL = 0.05        # displacement field cells (m)
PROFILE_BIN = 0.025
U_NEGLIGIBLE = 1e-4   # |u_z| below 0.1 mm: negligible (thesis: beyond 0.45 m from the centre line)
ROSE_BINS = 18
PLANES = (("xz", 0, 2), ("yz", 1, 2), ("xy", 0, 1))
WEIGHT_TOL = 0.05
TOL = 1e-9


class ReportError(Exception):
    pass


class CheckError(Exception):
    pass


def warn(msg):
    print("%s: warning: %s" % (PROG, msg), file=sys.stderr)


def f_(v, fmt="%.3g"):
    return "-" if v is None or (isinstance(v, float) and not math.isfinite(v)) else fmt % v


# --- Reading a run -----------------------------------------------------------------------------

def hold_file(d, prefix, end, names, attrs_of=None):
    """{dataset: array} of prefix_<step>.h5 at a hold end (the attributes of group attrs_of as
    '@attrs'); ReportError naming the file when it is missing, lacks a dataset or was written at
    another time (a file of an older run)."""
    p = os.path.join(d, "%s_%08d.h5" % (prefix, end["step"]))
    if not os.path.isfile(p):
        raise ReportError("%s is missing (the %s state, step %d)" % (p, end["name"], end["step"]))
    out = {"path": p}
    try:
        with h5py.File(p, "r") as f:
            t = float(f.attrs.get("time", NAN))
            if math.isfinite(t) and abs(t - end["time"]) > 1e-9 * max(1.0, end["time"]):
                raise ReportError("%s: written at t = %.6g s, not at the hold's end (%.6g s): an older run's?"
                                  % (p, t, end["time"]))
            for n in names:
                if n not in f:
                    raise ReportError("%s: no dataset %s" % (p, n))
                out[n] = f[n][()]
            if attrs_of:
                out["@attrs"] = {k: float(v) for k, v in f[attrs_of].attrs.items()}
    except OSError as e:
        raise ReportError("%s: cannot read (%s)" % (p, e))
    return out


def geometry(case, path):
    form = next((m for m in (case.get("fem") or {}).get("meshes") or []
                 if isinstance(m, dict) and m.get("name") == "formation"), None)
    blk = (form or {}).get("block") or {}
    box = (case.get("packing") or {}).get("box") or {}
    if not isinstance(blk.get("void"), dict) or "min" not in box or "max" not in box:
        raise ReportError("%s: no fem mesh 'formation' with a block void {min, max}, or no packing.box "
                          "(not a void case?)" % path)
    vmin, vmax = [float(v) for v in blk["void"]["min"]], [float(v) for v in blk["void"]["max"]]
    bmin, bmax = [float(v) for v in box["min"]], [float(v) for v in box["max"]]
    ztop = float(blk.get("max", [0, 0, 0])[2])   # the formation's top
    return {"x0": vmin[0], "x1": vmax[0], "xm": 0.5 * (vmin[0] + vmax[0]), "depth": ztop - vmin[2], "ztop": ztop,
            "xa": bmin[0], "L": bmax[0] - bmin[0], "W": bmax[1] - bmin[1], "zb": bmin[2], "zt": bmax[2],
            "H": bmax[2] - bmin[2]}


def interface_friction(case):
    """The sand-grid friction: the interactions pair, else the smaller of the two materials'."""
    soil = (case.get("packing") or {}).get("material", "sand")
    iface = (case.get("coupling") or {}).get("material", "grid")
    for it in case.get("interactions") or []:
        if isinstance(it, dict) and sorted(it.get("materials") or []) == sorted([soil, iface]) and "friction" in it:
            return float(it["friction"])
    fr = [float(m.get("friction", NAN)) for m in case.get("materials") or [] if m.get("name") in (soil, iface)]
    return min(fr) if fr else NAN


def hold_ends(ic, path, max_steps):
    """The last interface.csv row of hold 0 (rest) and hold 1 (final). A hold starts where the
    previous one ended (not at its first row, one output interval later)."""
    miss = [c for c in ("step", "time", "hold", "fz", "fe_unbalanced", "dem_unbalanced") if c not in ic]
    if miss:
        raise ReportError("%s: no column %s" % (path, ", ".join(miss)))
    ends, start = [], int(ic["step"][0]) if ic["step"] else 0
    for h, name in ((0, "rest"), (1, "final")):
        rows = [i for i, v in enumerate(ic["hold"]) if int(v) == h]
        if not rows:
            raise ReportError("%s: no row of hold %d (the run did not reach the %s state)" % (path, h + 1, name))
        i = rows[-1]
        e = {"name": name, "hold": h, "step": int(ic["step"][i]), "time": ic["time"][i], "fz": ic["fz"][i],
             "dem_unb": ic["dem_unbalanced"][i], "fe_unb": ic["fe_unbalanced"][i]}
        e["steps"] = e["step"] - start
        e["converged"] = int(max_steps is None or e["steps"] < max_steps)
        ends.append(e)
        start = e["step"]
    return ends


def grid_mesh(run):
    """The geogrid of structures.json (with its fem material index), or None without one."""
    fem = run["case"].get("fem") or {}
    spec = next((m for m in fem.get("meshes") or [] if isinstance(m, dict) and m.get("geogrid")), None)
    if spec is None:
        return None
    sj = os.path.join(run["dir"], "structures.json")
    try:
        with open(sj) as f:
            m = next(m for m in json.load(f).get("meshes") or [] if m.get("name") == spec.get("name"))
        gi = m["geogrid"]
        mats = [x.get("name") for x in fem.get("materials") or []]
        return {"name": m["name"], "nodes": int(m["nodes"]), "min": np.array(m["min"], float),
                "max": np.array(m["max"], float), "z": 0.5 * (m["min"][2] + m["max"][2]),
                "mat": mats.index(spec["material"]) if spec.get("material") in mats else None,
                "long_y": [float(v) for v in gi.get("longitudinal_y") or []],
                "w_long": float(gi["pitch_y"]) - float(gi["aperture_y"])}
    except (OSError, ValueError, StopIteration, KeyError, TypeError) as e:
        raise ReportError("%s: no usable geogrid mesh '%s' (%s: %s)" % (sj, spec.get("name"), type(e).__name__, e))


def load_run(d, label):
    cp, ip = os.path.join(d, "case.yaml"), os.path.join(d, "interface.csv")
    for p in (cp, ip):
        if not os.path.isfile(p):
            raise ReportError("%s is missing (is %s the output directory of a void run?)" % (p, d))
    try:
        case = load_case(cp)
    except (OSError, ValueError) as e:
        raise ReportError("%s: cannot read (%s)" % (cp, " ".join(str(e).split())))
    try:
        ic = read_csv(ip)
    except (OSError, ValueError, StopIteration) as e:
        raise ReportError("%s: cannot read (%s)" % (ip, e or "an empty file"))
    if not isinstance(case, dict):
        raise ReportError("%s: not a case file" % cp)
    run = {"dir": d, "case": case, "geo": geometry(case, cp), "mu": interface_friction(case), "ic": ic}
    ms = (case.get("fem") or {}).get("max_steps")
    run["max_steps"] = int(ms) if ms else None
    run["ends"] = hold_ends(ic, ip, run["max_steps"])
    mats = [m for m in case.get("materials") or [] if isinstance(m, dict)]
    run["rho"] = np.array([float(m.get("density", NAN)) for m in mats])
    soil = (case.get("packing") or {}).get("material", "sand")
    if soil not in [m.get("name") for m in mats]:
        raise ReportError("%s: the packing material %s is not in materials" % (cp, soil))
    run["soil_mat"] = [m.get("name") for m in mats].index(soil)
    run["g"] = abs(float((case.get("gravity") or [0, 0, -9.81])[2]))
    run["grid"] = grid_mesh(run)
    run["packed"] = os.path.isfile(os.path.join(d, "packing.json"))
    run["label"] = label or (str(case.get("name", os.path.basename(os.path.normpath(d))))
                             + (", interface friction 0" if run["grid"] and run["mu"] == 0 else ""))
    for e in run["ends"]:
        e["particles"] = s = hold_file(d, "particles", e, ["id", "position", "radius", "material", "velocity",
                                                          "displacement"])
        if s["material"].size and s["material"].max() >= len(mats):
            raise ReportError("%s: material index %d beyond the case's materials" % (s["path"], s["material"].max()))
        e["measure"] = hold_file(d, "measure", e, ["grid/porosity", "grid/stress", "force_network/points",
                                                   "force_network/connectivity"], attrs_of="grid")
        if run["grid"]:
            e["fe"] = hold_file(d, "fe", e, ["nodes/coordinates", "nodes/displacement", "elements/connectivity",
                                             "elements/stress", "elements/active", "elements/material"])
    return run


# --- 1. Equilibrium ----------------------------------------------------------------------------

def equilibrium(run):
    """The grains' weight sum(m g) against -fz: with frictionless side walls the structures
    (formation + grid) carry all of it, whether the grains rest on the soil or in the void."""
    for e in run["ends"]:
        s = e["particles"]
        e["weight"] = float(np.sum(run["rho"][s["material"]] * 4.0 / 3.0 * math.pi * s["radius"] ** 3)) * run["g"]
        e["weight_ratio"] = -e["fz"] / e["weight"] if e["weight"] > 0 else NAN
        v = np.linalg.norm(s["velocity"], axis=1)
        i = int(np.argmax(v))
        e["vmax"], e["vmax_at"] = float(v[i]), s["position"][i]


# --- 2., 3. The measurement grid: porosity windows and cell stresses ---------------------------

def grid_fields(m):
    """x, z cell centres, porosity[nz, ny, nx], stress[nz, ny, nx, 6], the grid's attributes."""
    a = m["@attrs"]
    nx, ny, nz = int(a["nx"]), int(a["ny"]), int(a["nz"])
    xc = a["origin_x"] + (np.arange(nx) + 0.5) * a["spacing_x"]
    zc = a["origin_z"] + (np.arange(nz) + 0.5) * a["spacing_z"]
    # cells x fastest, then y, then z (src/dem/measure.hpp); stress xx yy zz xy xz yz, compression +
    return xc, zc, m["grid/porosity"].reshape(nz, ny, nx), m["grid/stress"].reshape(nz, ny, nx, 6), a


def porosity_windows(run):
    """WIN x width x WIN windows over the soil: the plain mean of the cells whose centres lie
    inside (the cells have equal volumes: the volume-weighted mean)."""
    g = run["geo"]
    nxw, nzw = int(round(g["L"] / WIN)), int(round(g["H"] / WIN))
    xe, ze = g["xa"] + WIN * np.arange(nxw + 1), g["zb"] + WIN * np.arange(nzw + 1)
    res = {"xe": xe, "ze": ze, "xc": 0.5 * (xe[1:] + xe[:-1]), "zc": 0.5 * (ze[1:] + ze[:-1])}
    for e in run["ends"]:
        xc, zc, por, _, _ = grid_fields(e["measure"])
        n, cnt = np.full((nzw, nxw), NAN), np.zeros((nzw, nxw), int)
        for k in range(nzw):
            for i in range(nxw):
                cells = por[(zc >= ze[k]) & (zc < ze[k + 1])][:, :, (xc >= xe[i]) & (xc < xe[i + 1])]
                cnt[k, i] = cells.size
                n[k, i] = float(cells.mean()) if cells.size else NAN
        res[e["name"]], res["count"] = n, cnt
    nr, nf = res["rest"], res["final"]
    res["rel"] = 100.0 * (nf - nr) / nr      # % of the rest porosity (dilation +)
    res["abs"] = 100.0 * (nf - nr)           # percentage points
    above = np.broadcast_to((res["xc"] >= g["x0"] - TOL) & (res["xc"] <= g["x1"] + TOL), nr.shape)
    for key, mask in (("max", np.ones(nr.shape, bool)), ("max_above", above)):
        v = np.where(mask & np.isfinite(res["rel"]), np.abs(res["rel"]), -1)
        k, i = np.unravel_index(int(np.argmax(v)), v.shape)
        res[key] = {"rel": res["rel"][k, i], "abs": res["abs"][k, i], "x": res["xc"][i], "z": res["zc"][k]} \
            if v[k, i] >= 0 else None
    return res


def stress_rows(run):
    """sigma_zz, sigma_xx (Pa, mean over y) along x in three cell rows of the soil (on the
    formation, mid-height, under the surcharge), rest and final, and final / rest over the void's
    centre and just beside it: arching takes the load off the void onto its sides."""
    g = run["geo"]
    xc, zc, _, _, a = grid_fields(run["ends"][0]["measure"])
    sx, sz = a["spacing_x"], a["spacing_z"]
    soil = np.where((zc > g["zb"]) & (zc < g["zt"]))[0]
    if not len(soil):
        raise ReportError("%s: the measurement grid has no cell in the soil" % run["ends"][0]["measure"]["path"])
    mid = int(soil[np.argmin(np.abs(zc[soil] - (g["zb"] + 0.5 * g["H"] + 0.5 * sz)))])
    centre = np.abs(xc - g["xm"]) <= 0.5 * sx + 1e-6
    beside = ((xc > g["x0"] - sx) & (xc < g["x0"])) | ((xc > g["x1"]) & (xc < g["x1"] + sx))
    S = {e["name"]: grid_fields(e["measure"])[3].mean(axis=1) for e in run["ends"]}
    rows = []
    for k in sorted({int(soil[0]), mid, int(soil[-1])}, reverse=True):
        r = {"z": zc[k], "z0": zc[k] - 0.5 * sz, "z1": zc[k] + 0.5 * sz}
        for c, j in (("szz", 2), ("sxx", 0)):
            for st in ("rest", "final"):
                r[c + "_" + st] = S[st][k, :, j]
            for where, m in (("centre", centre), ("beside", beside)):
                rest = r[c + "_rest"][m].mean() if m.any() else NAN
                r["%s_%s" % (c, where)] = r[c + "_final"][m].mean() / rest if rest else NAN
        rows.append(r)
    return {"x": xc, "rows": rows, "sx": sx}


# --- 4. Soil displacement (particle snapshots, matched by id) ----------------------------------

def matched(run):
    """The grains of both states sorted by id; the common ones' positions, radii, materials and
    the change of the snapshots' own displacement datasets (for --check)."""
    r, f = run["ends"][0]["particles"], run["ends"][1]["particles"]
    ir, jf = np.argsort(r["id"], kind="stable"), np.argsort(f["id"], kind="stable")
    common, a, b = np.intersect1d(r["id"][ir], f["id"][jf], return_indices=True)
    return {"ids_rest": r["id"][ir], "ids_final": f["id"][jf], "id": common, "xr": r["position"][ir][a],
            "xf": f["position"][jf][b], "du": f["displacement"][jf][b] - r["displacement"][ir][a],
            "mat": r["material"][ir][a], "rf": f["radius"][jf][b]}


def binned(x, v, edges):
    """Mean of v per bin of x (NaN where empty)."""
    k = np.digitize(x, edges) - 1
    return np.array([v[k == i].mean() if np.any(k == i) else NAN for i in range(len(edges) - 1)])


def extent(xc, uz, xm, dbin):
    """(distance from the centre line beyond which every bin has |u_z| < 0.1 mm, whether that is
    the box's end, i.e. no bin is that small)."""
    big = np.isfinite(uz) & (np.abs(uz) >= U_NEGLIGIBLE)
    if not big.any():
        return 0.0, False
    d = np.abs(xc - xm) + 0.5 * dbin
    return float(d[big].max()), bool(d[big].max() >= d[np.isfinite(uz)].max() - TOL)


def displacements(run):
    g, mt = run["geo"], matched(run)
    run["match"] = mt
    soil = mt["mat"] == run["soil_mat"]          # the sand; the surcharge grains left out
    xr, uz = mt["xr"][soil], (mt["xf"] - mt["xr"])[soil, 2]
    xe = g["xa"] + CELL * np.arange(int(round(g["L"] / CELL)) + 1)
    ze = g["zb"] + CELL * np.arange(int(round(g["H"] / CELL)) + 1)
    field = np.array([binned(xr[s, 0], uz[s], xe) for s in ((xr[:, 2] >= z0) & (xr[:, 2] < z1)
                                                              for z0, z1 in zip(ze[:-1], ze[1:]))])
    pb = PROFILE_BIN if g["L"] / PROFILE_BIN <= 24 else CELL     # printable widths
    pe = g["xa"] + pb * np.arange(int(round(g["L"] / pb)) + 1)
    pc = 0.5 * (pe[1:] + pe[:-1])
    res = {"xe": xe, "ze": ze, "field": field, "pc": pc, "pb": pb, "n_soil": int(soil.sum())}
    zmid = g["zb"] + 0.5 * g["H"]
    for key, sel in (("surface", xr[:, 2] >= g["zt"] - CELL), ("mid", np.abs(xr[:, 2] - zmid) <= 0.5 * CELL)):
        res[key] = binned(xr[sel, 0], uz[sel], pe)
        res[key + "_extent"] = extent(pc, res[key], g["xm"], pb)
    above = (pc >= g["x0"] - TOL) & (pc <= g["x1"] + TOL)
    res["surface_max"] = float(-np.nanmin(res["surface"][above])) if above.any() else NAN
    res["surface_ratio"] = res["surface_max"] / g["depth"]
    # grains (any material) whose final centre is below the formation's top over the void
    inv = (mt["xf"][:, 2] < g["ztop"]) & (mt["xf"][:, 0] >= g["x0"]) & (mt["xf"][:, 0] <= g["x1"])
    res["void_grains"] = int(inv.sum())
    res["void_fill"] = float(np.sum(4.0 / 3.0 * math.pi * mt["rf"][inv] ** 3)) / (
        (g["x1"] - g["x0"]) * g["W"] * g["depth"])
    return res


# --- 7. Time history of hold 2 ------------------------------------------------------------------

def history(run):
    """Per particle snapshot strictly inside hold 2 (and its end): the surface settlement over the
    void, the grains in the void, the fastest grain, the unbalanced ratios; the first row of hold 2
    with both ratios below coupling.tolerance. None without such snapshots."""
    g, ic = run["geo"], run["ic"]
    rest, final = run["ends"]
    steps = []
    for name in os.listdir(run["dir"]):
        m = re.fullmatch(r"particles_(\d{8})\.h5", name)
        if m and rest["step"] < int(m.group(1)) <= final["step"]:
            steps.append(int(m.group(1)))
    if len(steps) < 2:
        return None
    r = rest["particles"]
    ir = np.argsort(r["id"], kind="stable")
    rid, rx, rmat = r["id"][ir], r["position"][ir], r["material"][ir]
    top = (rx[:, 2] >= g["zt"] - CELL) & (rmat == run["soil_mat"])
    pb = PROFILE_BIN if g["L"] / PROFILE_BIN <= 24 else CELL
    pe = g["xa"] + pb * np.arange(int(round(g["L"] / pb)) + 1)
    pc = 0.5 * (pe[1:] + pe[:-1])
    above = (pc >= g["x0"] - TOL) & (pc <= g["x1"] + TOL)
    ic_step = np.array(ic["step"], float)
    rows = []
    grest = grid_state(run, rest["fe"], run["grid"]) if run["grid"] else None   # once, not per snapshot
    for st in sorted(steps):
        p = os.path.join(run["dir"], "particles_%08d.h5" % st)
        try:
            with h5py.File(p, "r") as f:
                fid, fx, fv = f["id"][()], f["position"][()], f["velocity"][()]
                ft = float(f.attrs.get("time", NAN))
        except (OSError, KeyError) as e:
            raise ReportError("%s: cannot read (%s)" % (p, e))
        jf = np.argsort(fid, kind="stable")
        common, a, b = np.intersect1d(rid, fid[jf], return_indices=True)
        sel = top[a]
        uz = fx[jf][b][sel, 2] - rx[a][sel, 2]
        prof = binned(rx[a][sel, 0], uz, pe)
        inv = (fx[:, 2] < g["ztop"]) & (fx[:, 0] >= g["x0"]) & (fx[:, 0] <= g["x1"])
        k = int(np.argmin(np.abs(ic_step - st)))
        rows.append({"step": st, "since": st - rest["step"], "surface": float(-np.nanmin(prof[above])),
                     "void_grains": int(inv.sum()), "vmax": float(np.linalg.norm(fv, axis=1).max()) if len(fv) else 0.0,
                     "dem_unb": ic["dem_unbalanced"][k], "fe_unb": ic["fe_unbalanced"][k],
                     "t": ft - rest["time"]})
        rows[-1].update(grid_at(run, st, grest))
    tol = float((run["case"].get("coupling") or {}).get("tolerance", 0.01))
    first = None
    for i, st in enumerate(ic["step"]):
        if int(ic["hold"][i]) == 1 and st > rest["step"] and ic["dem_unbalanced"][i] < tol and ic["fe_unbalanced"][i] < tol:
            first = int(st)
            break
    near = min(rows, key=lambda q: abs(q["step"] - first)) if first is not None else None
    return {"rows": rows, "tol": tol, "first_balanced": first, "near": near}


def grid_at(run, step, rest):
    """The grid's largest settlement since rest and its mean T over the void in fe_<step>.h5
    (written with the particle snapshot of a coupled run); NaN without a grid or that file."""
    p = os.path.join(run["dir"], "fe_%08d.h5" % step)
    if not run["grid"] or not os.path.isfile(p):
        return {"grid_sag": NAN, "grid_T_void": NAN}
    names = ["nodes/coordinates", "nodes/displacement", "elements/connectivity", "elements/stress",
             "elements/active", "elements/material"]
    try:
        with h5py.File(p, "r") as f:
            fe = {n: f[n][()] for n in names}
    except (OSError, KeyError) as e:
        raise ReportError("%s: cannot read (%s)" % (p, e))
    fe["path"], g = p, run["geo"]
    st = grid_state(run, fe, run["grid"])
    over = (st["ex"] >= g["x0"]) & (st["ex"] <= g["x1"])
    return {"grid_sag": float(-np.min(st["uz"] - rest["uz"])),
            "grid_T_void": float(st["T"][over].mean()) if over.any() else NAN}


# --- 5. Contact-orientation roses --------------------------------------------------------------

def roses(run):
    """Orientation of the branch vectors (centre to centre) of the grain pairs in contact whose
    midpoint lies over the void, per plane, as a share per bin."""
    g, out = run["geo"], {}
    for e in run["ends"]:
        pts, conn = e["measure"]["force_network/points"], e["measure"]["force_network/connectivity"].astype(int)
        pa, pb = pts[conn[:, 0]], pts[conn[:, 1]]
        mid, d = 0.5 * (pa + pb), pb - pa
        sel = (mid[:, 0] >= g["x0"]) & (mid[:, 0] <= g["x1"]) & (mid[:, 2] >= g["zb"]) & (mid[:, 2] <= g["zt"])
        d, r = d[sel], {"n": int(sel.sum())}
        for name, a0, a1 in PLANES:
            ok = np.hypot(d[:, a0], d[:, a1]) > 1e-9 * np.linalg.norm(d, axis=1)
            th = np.degrees(np.arctan2(d[ok, a1], d[ok, a0])) % 180.0  # n and -n: one line
            h = np.histogram(th, bins=ROSE_BINS, range=(0.0, 180.0))[0]
            r[name] = h / max(h.sum(), 1)
            if name == "xz":   # arching turns contacts towards the horizontal
                r["horizontal"] = float(np.mean((th < 30) | (th >= 150))) if len(th) else NAN
                r["vertical"] = float(np.mean((th >= 60) & (th < 120))) if len(th) else NAN
        out[e["name"]] = r
    return out


# --- 6. The grid -------------------------------------------------------------------------------

def grid_state(run, fe, gm):
    """Settlement per node x on the longitudinal ribs, sigma_xx and T per element column. The
    grid's elements are those of its material inside its bounding box (not structures.json's
    offsets: element rows are written rank by rank)."""
    X, U, C = fe["nodes/coordinates"], fe["nodes/displacement"], fe["elements/connectivity"].astype(int)
    if C.ndim != 2:
        raise ReportError("%s: a mixed-element mesh (not a generated geogrid)" % fe["path"])
    cen, tol = X[C].mean(axis=1), 1e-6 + 1e-3 * gm["w_long"]
    el = np.all((cen >= gm["min"] - tol) & (cen <= gm["max"] + tol), axis=1)
    if gm["mat"] is not None:
        el &= fe["elements/material"] == gm["mat"]
    nodes = np.unique(C[el])
    if len(nodes) != gm["nodes"]:
        warn("%s: %d grid nodes found, structures.json says %d" % (fe["path"], len(nodes), gm["nodes"]))

    def on_ribs(y):
        m = np.zeros(len(y), bool)
        for y0 in gm["long_y"]:
            m |= (y >= y0 - tol) & (y <= y0 + gm["w_long"] + tol)
        return m if m.any() else np.ones(len(y), bool)   # no layout: every node
    rib = nodes[on_ribs(X[nodes, 1])]
    xr = np.round(X[rib, 0], 7)
    xs = np.unique(xr)
    er = el & on_ribs(cen[:, 1]) & (fe["elements/active"] != 0)
    ex = np.round(cen[er, 0], 7)
    exs = np.unique(ex)
    ext = X[C[er]].max(axis=1) - X[C[er]].min(axis=1)   # element extents: cross-section A = dy dz
    sxx = fe["elements/stress"][er, 0]                  # Voigt xx first; tension positive
    return {"x": xs, "uz": np.array([U[rib][xr == x, 2].mean() for x in xs]),
            "ux": np.array([U[rib][xr == x, 0].mean() for x in xs]), "ex": exs,
            "sxx": np.array([sxx[ex == x].mean() for x in exs]),
            "A": np.array([np.sum((ext[:, 1] * ext[:, 2])[ex == x]) for x in exs]) / run["geo"]["W"],
            "T": np.array([np.sum((sxx * ext[:, 1] * ext[:, 2])[ex == x]) for x in exs]) / run["geo"]["W"]}


def grid_report(run):
    if not run["grid"]:
        return None
    rest, fin = (grid_state(run, e["fe"], run["grid"]) for e in run["ends"])
    if not np.array_equal(rest["x"], fin["x"]):
        raise ReportError("%s: the grid's nodes differ between the hold ends" % run["ends"][1]["fe"]["path"])
    fin["duz"], fin["rest"], g = fin["uz"] - rest["uz"], rest, run["geo"]
    for k in ("uz", "duz"):
        i = int(np.argmin(fin[k]))
        fin[k + "_max"], fin[k + "_at"] = -fin[k][i], fin["x"][i]
    for k, i in (("Tmax", int(np.argmax(fin["T"]))), ("Tmin", int(np.argmin(fin["T"])))):
        fin[k], fin[k + "_at"], fin[k + "_sxx"] = fin["T"][i], fin["ex"][i], fin["sxx"][i]
    over = (fin["ex"] >= g["x0"]) & (fin["ex"] <= g["x1"])
    fin["T_void"] = float(fin["T"][over].mean()) if over.any() else NAN
    fin["T_ends"] = 0.5 * (fin["T"][0] + fin["T"][-1])
    fin["membrane"] = membrane(run, fin, g["x0"], g["x1"]) if over.any() else None
    return fin


def membrane(run, gr, x0, x1):
    """The test of the small-strain grid over the void: the span's axial elongation as fdem's FE
    sees it (the ribs' u_x at the void's edges) against the term a geometrically nonlinear
    (Green-Lagrange) strain adds for the same sagged shape, the integral of (du_z/dx)^2 / 2; and the
    tension T = E A eps / W each gives. The small-strain answer is valid only where the second is
    much smaller than the first."""
    i = (gr["x"] >= x0 - 1e-9) & (gr["x"] <= x1 + 1e-9)
    x, ux, uz = gr["x"][i], gr["ux"][i], gr["uz"][i]
    if len(x) < 3:
        return None
    L = x[-1] - x[0]
    lin = (ux[-1] - ux[0]) / L
    geo = float(np.sum(0.5 * (np.diff(uz) / np.diff(x)) ** 2 * np.diff(x))) / L
    mats = (run["case"].get("fem") or {}).get("materials") or []
    mat = run["grid"]["mat"]
    E = float(mats[mat].get("young", NAN)) if mat is not None and mat < len(mats) else NAN
    nl = bool(mats[mat].get("nlgeom", False)) if mat is not None and mat < len(mats) else False
    over = (gr["ex"] >= x0) & (gr["ex"] <= x1)
    AW = float(gr["A"][over].mean())
    return {"L": L, "eps_lin": lin, "eps_geo": geo, "E": E, "A_per_W": AW, "nlgeom": nl,
            "T_lin": E * AW * lin, "T_nonlinear": E * AW * (lin + geo)}


# --- Printing and the CSV row ------------------------------------------------------------------

def mm(v):
    return "%g" % round(1e3 * v, 1)


def line(head, vals, fmt, w=8):
    print("    %-24s" % head + "".join(("%" + str(w) + "s") % f_(v, fmt) for v in vals))


def table(title, xs, zs, vals, fmt, row=None, key=None, scale=1.0):
    """Print z rows top to bottom (x, z: window or cell centres, mm) and put the values in row."""
    print("  %s" % title)
    line("z \\ x (mm)", [mm(x) for x in xs], "%s")
    for k in range(len(zs) - 1, -1, -1):
        line(mm(zs[k]), scale * vals[k], fmt)
        for i, x in enumerate(xs):
            if row is not None:
                row["%s_x%s_z%s" % (key, mm(x), mm(zs[k]))] = scale * vals[k][i]


def report(run):
    g, row, p, s, dsp, ro, gr = (run[k] for k in ("geo", "row", "por", "stress", "disp", "roses", "gridres"))
    print("\n=== %s  (%s)" % (run["label"], run["dir"]))
    print("void x %.3f-%.3f m (centre %.3f), %.3f m deep; soil z %.3f-%.3f m; L %.3f m, W %.4f m; %s; %s"
          % (g["x0"], g["x1"], g["xm"], g["depth"], g["zb"], g["zt"], g["L"], g["W"],
             "grid '%s' at z %.4f m, sand-grid friction %g" % (run["grid"]["name"], run["grid"]["z"], run["mu"])
             if run["grid"] else "no grid",
             "packed in this run" if run["packed"] else "from a specimen (no packing.json)"))
    row.update(label=run["label"], dir=run["dir"], case=run["case"].get("name"), grid=int(bool(run["grid"])),
               interface_friction=run["mu"], void_x0=g["x0"], void_x1=g["x1"], void_depth=g["depth"], H=g["H"],
               L=g["L"], W=g["W"])
    print("1. equilibrium at the hold ends (weight: sum m g of all grains; -fz: their force on the structures)")
    for e in run["ends"]:
        print("   %-5s hold %d, step %d: %d steps, %s; unbalanced DEM %.2e FE %.2e; weight %.2f N, -fz %.2f N "
              "(-fz/weight %.3f); fastest grain %.3g m/s at (%.3f, %.3f, %.3f)"
              % (e["name"], e["hold"] + 1, e["step"], e["steps"], "converged" if e["converged"] else
                 "NOT CONVERGED (fem.max_steps %d reached)" % run["max_steps"], e["dem_unb"], e["fe_unb"],
                 e["weight"], -e["fz"], e["weight_ratio"], e["vmax"], *e["vmax_at"]))
        for k, c in (("step", ""), ("steps", ""), ("converged", ""), ("dem_unb", ""), ("fe_unb", ""),
                     ("weight", "_N"), ("weight_ratio", ""), ("vmax", "_m_s")):
            row["%s_%s%s" % (e["name"], "minus_fz_over_weight" if k == "weight_ratio" else k, c)] = e[k]
        row[e["name"] + "_minus_fz_N"] = -e["fz"]
    print("2. porosity n, rest -> final, in %g m (x) x the width x %g m (z) windows (plain mean of the cells): "
          "relative change 100 (n_final - n_rest)/n_rest %%, absolute 100 (n_final - n_rest) points" % (WIN, WIN))
    for key, t in (("max", "largest"), ("max_above", "largest above the void")):
        m = p[key]
        if m:
            print("   %-23s %+.2f %% (%+.2f points) in the window centred at x %.3f, z %.3f m"
                  % (t, m["rel"], m["abs"], m["x"], m["z"]))
            row.update({"por_%s_rel_pct" % key: m["rel"], "por_%s_abs_pp" % key: m["abs"],
                        "por_%s_x" % key: m["x"], "por_%s_z" % key: m["z"]})
    table("relative change (%%; void x %s-%s mm)" % (mm(g["x0"]), mm(g["x1"])), p["xc"], p["zc"], p["rel"],
          "%+.2f", row, "dn_rel_pct")
    table("absolute change (points)", p["xc"], p["zc"], p["abs"], "%+.2f", row, "dn_abs_pp")
    table("n at rest", p["xc"], p["zc"], p["rest"], "%.4f", row, "n_rest")
    table("n final", p["xc"], p["zc"], p["final"], "%.4f", row, "n_final")
    print("3. cell stresses (kPa, compression +, mean over y); final/rest over the void's centre (cells with "
          "|x - %.3f| <= %.3f) and beside it (the cells just outside x0, x1)" % (g["xm"], 0.5 * s["sx"]))
    line("cells z (mm) / x (mm)", [mm(x) for x in s["x"]] + ["centre", "beside"], "%s")
    for r in s["rows"]:
        zt = "%s-%s" % (mm(r["z0"]), mm(r["z1"]))
        for c, cn in (("szz", "s_zz"), ("sxx", "s_xx")):
            for st in ("rest", "final"):
                extra = [r[c + "_centre"], r[c + "_beside"]] if st == "final" else []
                line("%s %s %s" % (zt, cn, st), list(r[c + "_" + st] / 1e3) + extra, "%.2f")
                for x, v in zip(s["x"], r[c + "_" + st]):
                    row["%s_Pa_%s_x%s_z%s" % (c, st, mm(x), mm(r["z"]))] = v
            row["%s_ratio_centre_z%s" % (c, mm(r["z"]))] = r[c + "_centre"]
            row["%s_ratio_beside_z%s" % (c, mm(r["z"]))] = r[c + "_beside"]
    print("4. settlement of %d sand grains: u_z = final - rest position by id (mm, - = down)" % dsp["n_soil"])
    table("mean u_z in %g m cells of the rest position" % CELL, 0.5 * (dsp["xe"][1:] + dsp["xe"][:-1]),
          0.5 * (dsp["ze"][1:] + dsp["ze"][:-1]), dsp["field"], "%+.3f", row, "uz_mm", 1e3)
    line("profile bin x (mm)", [mm(x) for x in dsp["pc"]], "%s", 7)
    for key, t in (("surface", "surface z>=%s" % mm(g["zt"] - CELL)), ("mid", "mid z %s+-%s" % (
            mm(g["zb"] + 0.5 * g["H"]), mm(0.5 * CELL)))):
        line(t, 1e3 * dsp[key], "%+.3f", 7)
        for x, v in zip(dsp["pc"], dsp[key]):
            row["uz_%s_mm_x%s" % (key, mm(x))] = 1e3 * v
        d, edge = dsp[key + "_extent"]
        print("   %-8s |u_z| < 0.1 mm beyond %s%.3f m from the centre line%s" % (key, ">= " if edge else "", d,
              " (the box's end: no bin below 0.1 mm)" if edge else ""))
        row[key + "_extent_m"], row[key + "_extent_at_box_end"] = d, int(edge)
    print("   largest surface settlement above the void %.3f mm = %.2f %% of the void's depth (%.0f mm); grains in "
          "the void at the end: %d, %.1f %% of its volume" % (
              1e3 * dsp["surface_max"], 100 * dsp["surface_ratio"], 1e3 * g["depth"], dsp["void_grains"],
              100 * dsp["void_fill"]))
    row.update(surface_max_settlement_mm=1e3 * dsp["surface_max"], surface_settlement_over_depth=dsp["surface_ratio"],
               void_grains=dsp["void_grains"], void_fill_fraction=dsp["void_fill"])
    print("5. contact orientations over the void (midpoints x in [%.3f, %.3f], z in the soil), %% per %g deg bin"
          % (g["x0"], g["x1"], 180 / ROSE_BINS))
    line("plane state / deg", [b * 180 // ROSE_BINS for b in range(ROSE_BINS)], "%d", 5)
    for st in ("rest", "final"):
        for name, _, _ in PLANES:
            line("%s %s" % (name, st), 100 * ro[st][name], "%.1f", 5)
            for b, v in enumerate(ro[st][name]):
                row["rose_%s_%s_%d" % (name, st, b * 180 // ROSE_BINS)] = v
    for st in ("rest", "final"):
        print("   %-5s %d contacts; xz: %.1f %% within 30 deg of horizontal, %.1f %% within 30 deg of vertical"
              % (st, ro[st]["n"], 100 * ro[st]["horizontal"], 100 * ro[st]["vertical"]))
        row.update({"contacts_" + st: ro[st]["n"], "fabric_horizontal_" + st: ro[st]["horizontal"],
                    "fabric_vertical_" + st: ro[st]["vertical"]})
    if gr is None:
        print("6. no grid")
        return
    print("6. grid '%s' (longitudinal ribs): -u_z (mm, mean over y), sigma_xx (MPa, tension +) and T = sum(sigma_xx "
          "A) / W (kN/m) per element column; printed as means in %g m bins" % (run["grid"]["name"], CELL))
    xe = g["xa"] + CELL * np.arange(int(round(g["L"] / CELL)) + 1)
    line("bin x (mm)", [mm(x) for x in 0.5 * (xe[1:] + xe[:-1])], "%s")
    for t, x, v, sc, fmt in (("-u_z final", gr["x"], gr["uz"], -1e3, "%.3f"), ("-u_z since rest", gr["x"], gr["duz"],
                             -1e3, "%.3f"), ("s_xx", gr["ex"], gr["sxx"], 1e-6, "%+.3f"),
                             ("T", gr["ex"], gr["T"], 1e-3, "%+.4f")):
        line(t, sc * binned(x, v, xe), fmt)
    print("   largest settlement %.3f mm at x %.4f m (since rest %.3f mm at x %.4f m); T over the void %+.4f kN/m, "
          "largest tension %+.4f kN/m (s_xx %+.3f MPa) at x %.4f m, largest compression %+.4f kN/m at x %.4f m, "
          "at the grid's ends %+.4f kN/m" % (1e3 * gr["uz_max"], gr["uz_at"], 1e3 * gr["duz_max"], gr["duz_at"],
                                              gr["T_void"] / 1e3, gr["Tmax"] / 1e3, gr["Tmax_sxx"] / 1e6,
                                              gr["Tmax_at"], gr["Tmin"] / 1e3, gr["Tmin_at"], gr["T_ends"] / 1e3))
    row.update(grid_max_settlement_mm=1e3 * gr["uz_max"], grid_max_settlement_x=gr["uz_at"],
               grid_max_settlement_since_rest_mm=1e3 * gr["duz_max"], grid_max_settlement_since_rest_x=gr["duz_at"],
               grid_T_void_kN_m=gr["T_void"] / 1e3, grid_T_max_kN_m=gr["Tmax"] / 1e3, grid_T_max_x=gr["Tmax_at"],
               grid_T_min_kN_m=gr["Tmin"] / 1e3, grid_T_min_x=gr["Tmin_at"], grid_T_ends_kN_m=gr["T_ends"] / 1e3)
    mb = gr["membrane"]
    if mb:
        print("   membrane test over the void (x %.3f-%.3f m; the grid is %s): the span's axial strain from u_x of its "
              "edges %+.3e; the Green-Lagrange term (du_z/dx)^2/2 of its sagged shape %+.3e (ratio %.3g; %s); "
              "E A/W %.4g kN/m: T %+.4f kN/m from the first, %+.4f kN/m from both"
              % (g["x0"], g["x1"], "nlgeom" if mb["nlgeom"] else "small-strain", mb["eps_lin"], mb["eps_geo"],
                 abs(mb["eps_geo"] / mb["eps_lin"]) if mb["eps_lin"] else INF,
                 "counted by the FE" if mb["nlgeom"] else "not counted by the FE",
                 mb["E"] * mb["A_per_W"] / 1e3, mb["T_lin"] / 1e3, mb["T_nonlinear"] / 1e3))
        row.update(grid_membrane_eps_lin=mb["eps_lin"], grid_membrane_eps_geo=mb["eps_geo"],
                   grid_membrane_T_lin_kN_m=mb["T_lin"] / 1e3, grid_membrane_T_nonlinear_kN_m=mb["T_nonlinear"] / 1e3)
    for x, u, du in zip(gr["x"], gr["uz"], gr["duz"]):
        row["grid_down_mm_x%.1f" % (1e3 * x)], row["grid_down_since_rest_mm_x%.1f" % (1e3 * x)] = -1e3 * u, -1e3 * du
    for x, s_, t in zip(gr["ex"], gr["sxx"], gr["T"]):
        row["grid_sxx_MPa_x%.1f" % (1e3 * x)], row["grid_T_kN_m_x%.1f" % (1e3 * x)] = s_ / 1e6, t / 1e3


def report_history(run):
    h, row = run["hist"], run["row"]
    if h is None:
        return
    print("7. hold 2 step by step (particle snapshots): the largest surface settlement over the void, grains in the "
          "void, the fastest grain, the unbalanced ratios (interface.csv)")
    grid = run["grid"] is not None
    print("    %9s %9s %8s %12s %8s %9s %9s %9s%s" % ("step", "since rm", "t s", "surface mm", "in void", "vmax m/s",
                                                  "DEM unb", "FE unb", "  grid sag mm  T void kN/m" if grid else ""))
    for q in h["rows"]:
        print("    %9d %9d %8.4f %12.3f %8d %9.3g %9.2e %9.2e%s"
              % (q["step"], q["since"], q["t"], 1e3 * q["surface"], q["void_grains"], q["vmax"], q["dem_unb"],
                 q["fe_unb"], "  %12s %12s" % (f_(1e3 * q["grid_sag"], "%.3f"), f_(1e-3 * q["grid_T_void"], "%+.4f"))
                 if grid else ""))
    last = h["rows"][-1]
    row.update(history_snapshots=len(h["rows"]), history_last_step=last["step"], history_last_t_s=last["t"],
               history_last_surface_mm=1e3 * last["surface"], history_last_void_grains=last["void_grains"],
               history_last_grid_sag_mm=1e3 * last["grid_sag"], history_last_grid_T_void_kN_m=1e-3 * last["grid_T_void"])
    if h["first_balanced"] is None:
        print("   no row of hold 2 has both unbalanced ratios below %g" % h["tol"])
        return
    n = h["near"]
    print("   both unbalanced ratios first below %g (coupling.tolerance; the thesis's \"all forces balanced\" alone) at "
          "step %d, %d steps after the removal; surface settlement over the void at the nearest snapshot (step %d): "
          "%.3f mm, %d grains in the void (at the end: %.3f mm, %d)"
          % (h["tol"], h["first_balanced"], h["first_balanced"] - run["ends"][0]["step"], n["step"],
             1e3 * n["surface"], n["void_grains"], 1e3 * h["rows"][-1]["surface"], h["rows"][-1]["void_grains"]))
    row.update(first_balanced_step=h["first_balanced"], first_balanced_surface_mm=1e3 * n["surface"],
               first_balanced_void_grains=n["void_grains"])


def write_csv(runs, path):
    cols = []
    for r in runs:
        cols += [c for c in r["row"] if c not in cols]

    def fmt(v):
        if isinstance(v, (float, np.floating)):
            return "%.6g" % v if math.isfinite(v) else ""
        return "" if v is None else str(v).replace(",", ";")
    with open(path, "w") as f:
        f.write(",".join(cols) + "\n")
        for r in runs:
            f.write(",".join(fmt(r["row"].get(c)) for c in cols) + "\n")


# --- Figures -----------------------------------------------------------------------------------

def shade_void(ax, g):
    ax.axvspan(g["x0"], g["x1"], color="0.87", zorder=0, lw=0)
    ax.grid(alpha=0.3)


def section(ax, run, x, z, vals, title, text, **kw):
    """An x-z map of cell values, text(k, i) written in the cells when there are few, the void
    hatched below the formation's top and the grid dashed."""
    g = run["geo"]
    pc = ax.pcolormesh(x, z, vals, **kw)
    for k in range(vals.shape[0]):
        for i in range(vals.shape[1] if vals.size <= 60 else 0):
            dark = np.isfinite(vals[k, i]) and abs(pc.norm(vals[k, i]) - 0.5) > 0.35
            ax.text(0.5 * (x[i] + x[i + 1]), 0.5 * (z[k] + z[k + 1]), text(k, i), ha="center", va="center",
                    fontsize=7, color="w" if dark else "k")
    ax.add_patch(plt.Rectangle((g["x0"], g["ztop"] - g["depth"]), g["x1"] - g["x0"], g["depth"], fill=False,
                               hatch="//", ec="k", lw=0.8))
    ax.axhline(g["ztop"], color="k", lw=1.2)
    if run["grid"]:
        ax.axhline(run["grid"]["z"], color="m", ls="--", lw=1)
    ax.set(xlim=(g["xa"], g["xa"] + g["L"]), ylim=(g["ztop"] - g["depth"], g["zt"]), aspect="equal", xlabel="x (m)")
    ax.set_title(title, fontsize=9)
    return pc


def fig_porosity(runs, path):
    fig, axes = plt.subplots(1, len(runs), figsize=(4.2 * len(runs) + 1.5, 3.8), squeeze=False)
    vmax = max(1.0, min(20.0, max(np.nanmax(np.abs(r["por"]["rel"])) for r in runs)))
    for ax, run in zip(axes[0], runs):
        p = run["por"]
        pc = section(ax, run, p["xe"], p["ze"], p["rel"], run["label"], cmap="RdBu_r", vmin=-vmax, vmax=vmax,
                     text=lambda k, i: "%+.2f %%\n(%+.2f pt)" % (p["rel"][k, i], p["abs"][k, i]))
    axes[0, 0].set_ylabel("z (m)")
    fig.colorbar(pc, ax=list(axes[0]), label="100 (n_final - n_rest) / n_rest (%)", extend="both", shrink=0.9)
    fig.suptitle("Porosity change rest -> final in %g m windows (hatched: the void; magenta: the grid)" % WIN,
                 fontsize=10)
    fig.savefig(path, dpi=120)
    plt.close(fig)


def fig_displacement(runs, path):
    n = len(runs)
    fig = plt.figure(figsize=(4.2 * n + 1.5, 7.5))
    gs = fig.add_gridspec(2, n, hspace=0.3)
    vmax = max(1e-3, max(np.nanmax(np.abs(r["disp"]["field"])) for r in runs) * 1e3)
    top = [fig.add_subplot(gs[0, j]) for j in range(n)]
    for ax, run in zip(top, runs):
        d = run["disp"]
        pc = section(ax, run, d["xe"], d["ze"], 1e3 * d["field"], "%s: u_z (mm) by rest position" % run["label"],
                     lambda k, i: f_(1e3 * d["field"][k, i], "%.2f"), cmap="RdBu",
                     norm=SymLogNorm(linthresh=0.1, vmin=-vmax, vmax=vmax, base=10))
    top[0].set_ylabel("z (m)")
    fig.colorbar(pc, ax=top, label="u_z (mm, symlog, - = down)", shrink=0.9)
    ax = fig.add_subplot(gs[1, :])
    for k, run in enumerate(runs):
        d = run["disp"]
        ax.plot(d["pc"], -1e3 * d["surface"], color="C%d" % k, marker="o", ms=3, label="%s: surface" % run["label"])
        ax.plot(d["pc"], -1e3 * d["mid"], color="C%d" % k, ls="--", marker="x", ms=3,
                label="%s: mid-depth" % run["label"])
    shade_void(ax, runs[0]["geo"])
    ax.axhspan(-0.1, 0.1, color="g", alpha=0.12, lw=0, label="|u_z| < 0.1 mm")
    big = max(np.nanmax(np.abs(r["disp"][k])) for r in runs for k in ("surface", "mid")) * 1e3
    if big > 2:
        ax.set_yscale("symlog", linthresh=0.1)
    ax.invert_yaxis()
    ax.set(xlabel="x (m); grey: the void", ylabel="settlement -u_z (mm%s)" % (", symlog" if big > 2 else ""),
           title="Settlement profiles: surface (rest z in the top %g m) and mid-depth (%g m band)" % (CELL, CELL))
    ax.title.set_fontsize(9)
    ax.legend(fontsize=7, ncol=2)
    fig.savefig(path, dpi=120, bbox_inches="tight")
    plt.close(fig)


def fig_stress(runs, path):
    fig, axes = plt.subplots(2, 2, figsize=(11, 7), sharex=True)
    for k, run in enumerate(runs):
        s = run["stress"]
        for a, r in enumerate((s["rows"][0], s["rows"][-1])):   # under the surcharge, on the formation
            for b, (c, cn) in enumerate((("szz", "$\\sigma_{zz}$"), ("sxx", "$\\sigma_{xx}$"))):
                axes[a, b].plot(s["x"], r[c + "_rest"] / 1e3, color="C%d" % k, ls="--", marker="o", ms=3,
                                label="%s rest" % run["label"])
                axes[a, b].plot(s["x"], r[c + "_final"] / 1e3, color="C%d" % k, marker="s", ms=3,
                                label="%s final" % run["label"])
                axes[a, b].set_title("%s, cells z %.3f-%.3f m" % (cn, r["z0"], r["z1"]), fontsize=9)
    for ax in axes.flat:
        shade_void(ax, runs[0]["geo"])
        ax.set_ylabel("kPa (compression +)")
    for ax in axes[1]:
        ax.set_xlabel("x (m), cell centres; grey: the void")
    axes[0, 0].legend(fontsize=7)
    fig.suptitle("Cell stresses along x, rest (dashed) and final (solid)", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def fig_roses(runs, path):
    fig, axes = plt.subplots(len(runs), 3, figsize=(10, 3.9 * len(runs)), subplot_kw={"projection": "polar"},
                             squeeze=False)
    th = np.radians((np.arange(2 * ROSE_BINS + 1) + 0.5) * 180.0 / ROSE_BINS)
    rmax = 110 * max(r["roses"][st][name].max() for r in runs for st in ("rest", "final") for name, _, _ in PLANES)
    for j, run in enumerate(runs):
        ro = run["roses"]
        for i, (name, _, _) in enumerate(PLANES):
            for st, ls in (("rest", "--"), ("final", "-")):
                v = 100 * np.tile(ro[st][name], 3)[:len(th)]   # folded [0, 180): drawn both ways, closed
                axes[j, i].plot(th, v, ls=ls, color="C%d" % j, label=st)
            axes[j, i].set_title("%s: %s plane (0 deg = +%s)" % (run["label"], name, name[0]), fontsize=8, pad=12)
            axes[j, i].tick_params(labelsize=6)
            axes[j, i].set_ylim(0, rmax)   # one radial scale: the planes and runs compare
        axes[j, 0].set_xlabel("xz: within 30 deg of horizontal %.0f%% -> %.0f%%, of vertical %.0f%% -> %.0f%%"
                              % (100 * ro["rest"]["horizontal"], 100 * ro["final"]["horizontal"],
                                 100 * ro["rest"]["vertical"], 100 * ro["final"]["vertical"]), fontsize=7)
        axes[j, 2].legend(fontsize=7, loc="upper right", bbox_to_anchor=(1.35, 1.12))
    fig.suptitle("Contact orientations over the void (%% of contacts per %g deg bin; rest dashed, final solid)"
                 % (180 / ROSE_BINS), fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def fig_grid(runs, path):
    gr = [(k, r) for k, r in enumerate(runs) if r["gridres"]]
    if not gr:
        return False
    fig, axes = plt.subplots(3, 1, figsize=(8, 8.5), sharex=True)
    for k, run in gr:
        g, c, lab = run["gridres"], "C%d" % k, run["label"]
        axes[0].plot(g["x"], -1e3 * g["uz"], color=c, marker="o", ms=3, label="%s: final" % lab)
        axes[0].plot(g["x"], -1e3 * g["duz"], color=c, ls="--", label="%s: since rest" % lab)
        axes[1].plot(g["ex"], g["sxx"] / 1e6, color=c, marker=".", label="%s: final" % lab)
        axes[1].plot(g["rest"]["ex"], g["rest"]["sxx"] / 1e6, color=c, ls="--", lw=0.8, label="%s: rest" % lab)
        axes[2].plot(g["ex"], g["T"] / 1e3, color=c, marker=".", label="%s: final" % lab)
        axes[2].plot(g["rest"]["ex"], g["rest"]["T"] / 1e3, color=c, ls="--", lw=0.8, label="%s: rest" % lab)
    axes[0].invert_yaxis()
    axes[0].set_ylabel("grid settlement -u_z (mm)")
    axes[1].set_ylabel("$\\sigma_{xx}$ of the ribs (MPa, tension +)")
    axes[2].set_ylabel("T = sum($\\sigma_{xx}$ A) / W (kN/m)")
    axes[2].set_xlabel("x (m); grey: the void")
    for ax in axes:
        shade_void(ax, gr[0][1]["geo"])
        ax.axhline(0, color="k", lw=0.5)
        ax.legend(fontsize=7)
    fig.suptitle("Grid along x (longitudinal ribs, mean over y)", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def fig_history(runs, path):
    hr = [(k, r) for k, r in enumerate(runs) if r["hist"]]
    if not hr:
        return False
    fig, ax = plt.subplots(figsize=(7, 4.2))
    for k, run in hr:
        rows, c = run["hist"]["rows"], "C%d" % k
        t = [0.0] + [q["t"] for q in rows]
        ax.plot(t, [0.0] + [1e3 * q["surface"] for q in rows], color=c, ls="--", marker=".",
                label="%s: surface over the void" % run["label"])
        if run["grid"]:
            ax.plot(t, [0.0] + [1e3 * q["grid_sag"] for q in rows], color=c, marker="o", ms=4,
                    label="%s: grid, largest since rest" % run["label"])
    ax.set_xlabel("time after the removal (s)")
    ax.set_ylabel("settlement (mm)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)
    fig.suptitle("Hold 2: settlement against time (particle / FE snapshots)", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def make_figures(runs, figdir):
    os.makedirs(figdir, exist_ok=True)
    done = []
    for name, fn in (("void_porosity.png", fig_porosity), ("void_displacement.png", fig_displacement),
                     ("void_stress.png", fig_stress), ("void_roses.png", fig_roses), ("void_grid.png", fig_grid),
                     ("void_history.png", fig_history)):
        if fn(runs, os.path.join(figdir, name)) is not False:
            done.append(os.path.join(figdir, name))
    return done


# --- --check -----------------------------------------------------------------------------------

def check(run):
    """Self-consistency; CheckError on the first failure."""
    p, d, g = run["por"], run["dir"], run["geo"]
    for e in run["ends"]:   # every window: its 2 x 2 x ny cells by index, and their mean
        _, _, por, _, a = grid_fields(e["measure"])
        fx, fz = int(round(WIN / a["spacing_x"])), int(round(WIN / a["spacing_z"]))
        i0 = int(round((g["xa"] - a["origin_x"]) / a["spacing_x"]))
        k0 = int(round((g["zb"] - a["origin_z"]) / a["spacing_z"]))
        for k in range(len(p["zc"])):
            for i in range(len(p["xc"])):
                cells = por[k0 + k * fz:k0 + (k + 1) * fz, :, i0 + i * fx:i0 + (i + 1) * fx]
                if p["count"][k, i] != fx * fz * por.shape[1] or not abs(cells.mean() - p[e["name"]][k, i]) < 1e-12:
                    raise CheckError("%s: porosity window x %.3f z %.3f (%s): %d cells, their mean %.6g, window %.6g"
                                     % (e["measure"]["path"], p["xc"][i], p["zc"][k], e["name"], p["count"][k, i],
                                        cells.mean() if cells.size else NAN, p[e["name"]][k, i]))
    mt = run["match"]
    if len(np.unique(mt["ids_rest"])) != len(mt["ids_rest"]) or not np.array_equal(mt["ids_rest"], mt["ids_final"]):
        raise CheckError("%s: the grain ids differ between rest (%d grains) and final (%d)"
                         % (d, len(mt["ids_rest"]), len(mt["ids_final"])))
    err = float(np.abs((mt["xf"] - mt["xr"]) - mt["du"]).max()) if len(mt["id"]) else 0.0
    if err > 1e-9:
        raise CheckError("%s: final - rest position differs from the change of the displacement datasets by %.3g m"
                         % (d, err))
    e = run["ends"][0]
    if not abs(e["weight_ratio"] - 1) <= WEIGHT_TOL:
        raise CheckError("%s: at rest (step %d) -fz %.2f N vs the grains' weight %.2f N: %+.1f %% (limit %.0f %%)"
                         % (d, e["step"], -e["fz"], e["weight"], 100 * (e["weight_ratio"] - 1), 100 * WEIGHT_TOL))


def main(argv):
    ap = argparse.ArgumentParser(prog="void_report.py", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("runs", nargs="+", metavar="DIR", help="output directory of a void run")
    ap.add_argument("--labels", help="comma-separated labels, one per DIR (', ' is part of a label)")
    ap.add_argument("--figures", metavar="FIGDIR", help="write the figures there")
    ap.add_argument("--csv", metavar="FILE", help="one row per run with every number")
    ap.add_argument("--check", action="store_true", help="also the self-consistency checks (exit 1 on a failure)")
    a = ap.parse_args(argv[1:])
    # a comma followed by a space stays in the label ("reinforced, interface friction 0": scripts/void.sh)
    labels = [s.strip() for s in re.split(r",(?!\s)", a.labels)] if a.labels else [None] * len(a.runs)
    if len(labels) != len(a.runs):
        print("%s: --labels gives %d labels for %d runs" % (PROG, len(labels), len(a.runs)), file=sys.stderr)
        return 2
    runs = []
    for d, lab in zip(a.runs, labels):
        try:
            if not os.path.isdir(d):
                raise ReportError("%s: not a directory" % d)
            run = load_run(d, lab)
            equilibrium(run)
            run.update(por=porosity_windows(run), stress=stress_rows(run), disp=displacements(run), roses=roses(run),
                       gridres=grid_report(run), hist=history(run), row={})
        except ReportError as e:
            print("%s: %s" % (PROG, e), file=sys.stderr)
            return 2
        except (OSError, KeyError, ValueError, IndexError, TypeError) as e:
            print("%s: %s: cannot read the run (%s: %s)" % (PROG, d, type(e).__name__, e), file=sys.stderr)
            return 2
        runs.append(run)
    labs = [r["label"] for r in runs]
    for r in runs:
        r["label"] += " [%s]" % os.path.basename(os.path.normpath(r["dir"])) if labs.count(r["label"]) > 1 else ""
        report(r)
        report_history(r)
    try:
        if a.csv and os.path.dirname(a.csv):
            os.makedirs(os.path.dirname(a.csv), exist_ok=True)
        written = ([a.csv] if a.csv and write_csv(runs, a.csv) is None else []) + \
            (make_figures(runs, a.figures) if a.figures else [])
    except OSError as e:
        print("%s: cannot write: %s" % (PROG, e), file=sys.stderr)
        return 2
    if written:
        print("\nwrote:\n  " + "\n  ".join(written))
    bad = 0
    for r in runs if a.check else []:
        try:
            check(r)
            print("check %s: ok (porosity windows = the mean of their cells; the same grain ids; -fz within %.0f %% "
                  "of the weight at rest)" % (r["label"], 100 * WEIGHT_TOL))
        except CheckError as e:
            print("%s: check failed: %s" % (PROG, e), file=sys.stderr)
            bad = 1
    return bad


if __name__ == "__main__":
    try:
        sys.exit(main(sys.argv))
    except BrokenPipeError:   # the output piped into e.g. head
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        sys.exit(1)
