#!/usr/bin/python3
"""Strip-footing report (thesis Tran 2013, ch. 5, figs 5-5, 5-9, 5-13): a per-hold table, the
ultimate pressure, the bearing capacity ratio and the figures of runs of one strip-footing variant
with N = 0, 1 or 2 geogrid layers (one output directory per N).

    /usr/bin/python3 scripts/footing_report.py DIR [DIR ...] [--figures FIGDIR] [--phi DEG]
                                               [--unit-weight KN_M3] [--triaxial TDIR ...]

Reads from each DIR what the run wrote: case.yaml (the case as run, defaults filled in),
holds.csv and walls.csv (required), structures.json (required when the case has `fem`), the FE
snapshots fe_<step>.h5, particles_<step>.h5 and measure_<step>.h5 written at every hold end
(optional). The footing is the wall named `footing` (else the first wall of `holds.walls`): B is
its x extent in case.yaml, L its y extent, its centre x the middle of its x extent. The floor is
the plane wall with normal +z. N is the number of fem meshes (0 without `fem`); the DIRs must
have different N, and the N = 0 run is the reference of the bearing capacity ratio. A file at a
hold's step whose `time` attribute is not the hold's time (left over from an older run in the
same directory) is ignored, with a warning.

Writes DIR/footing.csv per run, one row per row of holds.csv (blank where a value is unknown):

  N, hold, step               number of grid layers, hold index (from 1), its last step
  q_kPa, target_kPa           footing stress measured by the servo (holds.csv), its target
  settlement_mm, s_over_B     settlement since the footing was placed on the soil (holds.csv,
                              positive downward), and settlement / B (a fraction, not %)
  converged                   holds.csv's flag (0: max_steps reached, or the run's `stop`)
  rate_um                     the footing's settlement in the hold's last holds.check_every steps
                              (um, from walls.csv; blank without the rows)
  held                        1 if converged, or if not but the footing was at rest at the end
                              (rate_um below holds.creep, default 10 um, and s below holds.stop:
                              the misfit was elsewhere, e.g. the grid's FE residual)
  floor_fz_N, footing_fz_N    fz of the floor and of the footing in walls.csv at the step: the
                              force of the grains ON the wall (the floor's is negative: pushed down)
  grains_weight_N             sum of m g of the grains in particles_<step>.h5 (m from the radius
                              and the density of the particle's material, the index into the case's
                              `materials`); blank without the file
  reaction_balance            -floor_fz / (footing_fz + grains weight + grid weight): near 1 in
                              equilibrium (frictionless side walls; the grids' weight only with
                              fem.gravity, unit_weight x volume)
  <g>_max_down_mm             per grid mesh <g> (its name): max of -u_z over the mesh's nodes
  <g>_centre_down_mm          mean -u_z of the nodes within one pitch_x of the footing centre x
  <g>_max_sxx_MPa             max element S_xx (tension positive) of the mesh's active elements
  <g>_depth_mm                footing base z at the step (case min z + footing_uz in walls.csv:
                              the wall's displacement from its case position, the placement on
                              the soil included) minus the grid's reference mid-plane z

Ultimate pressure q_u: the target of the last held hold before the first hold that was not held
(the footing still settling at its end) or reached holds.stop; if every hold was held, q_u is not
reached (>= the last target).
BCR = q_u(N) / q_u(0) (or its bound), and at equal settlement: q at s/B = 2, 5, 10 % (linear
between the origin and the held hold ends) over N = 0's. For N = 0: q_u = 0.5 gamma B N_gamma
(surface strip footing) with gamma the dry unit weight (1 - n) rho_s g (n the specimen's interior
porosity in packing.json, rho_s the packing material's density) or --unit-weight, phi --phi
(default 41 deg), N_gamma after Vesic, Meyerhof and Brinch Hansen. With --triaxial TDIR ...
(drained triaxial or plane-strain runs of the footing's sand, `scripts/strip_footing.sh phi`):
the same q_u for each run's peak friction angle (sin phi = (s1 - s3)/(s1 + s3) at the peak of
s1/s3), and for a triaxial run also for the plane-strain angle estimated from it, 1.5 phi_tx - 17
deg (Lade & Lee 1976, an empirical fit for phi_tx > 34 deg; the footing is plane strain); a table
in FIGDIR/classical.csv.

Figures (--figures FIGDIR, default FIRST_DIR/figures): pressure_settlement.png (fig 5-5),
grid_profiles.png (grid settlement and S_xx along x/B, up to four holds nearest 45/75/95/125 kPa),
grid_max.png (fig 5-9), sigma_v_depth.png (fig 5-13, from the measurement grid; step 0 and the
holds nearest 45/75/95/125 kPa), displacements.png
(figs 5-10, 5-11: |u|/s of the grains in x-z at the last converged hold and the last hold, from
measure_<step>.h5's particles) with the displaced zone printed: how deep below the base and how
far from the centre the grains moved more than 10 % of the footing's settlement.
Needs Debian's python3-numpy, python3-h5py, python3-matplotlib. Exit 2 on bad input.
"""
import argparse
import json
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from fdem_common import load_case, read_csv, system_python_fallback, triaxial_peak  # noqa: E402

system_python_fallback(["numpy", "h5py", "matplotlib"])
import numpy as np  # noqa: E402
import h5py  # noqa: E402
import matplotlib  # noqa: E402

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

PROG = "footing_report"
PROFILE_Q_KPA = (45.0, 75.0, 95.0, 125.0)  # grid_profiles.png: the holds nearest these
S_OVER_B = (0.02, 0.05, 0.10)
NAN = float("nan")
GRID_KEYS = ("max_down_mm", "centre_down_mm", "max_sxx_MPa", "depth_mm")
BASE_COLS = ["N", "hold", "step", "q_kPa", "target_kPa", "settlement_mm", "s_over_B", "converged", "rate_um", "held",
             "floor_fz_N", "footing_fz_N", "grains_weight_N", "reaction_balance"]


class ReportError(Exception):
    pass


def warn(msg):
    print("%s: warning: %s" % (PROG, msg), file=sys.stderr)


def isnan(v):
    return v is None or (isinstance(v, float) and math.isnan(v))


# ---------------------------------------------------------------------------------------------
# The case
# ---------------------------------------------------------------------------------------------

def wall_list(case):
    return [w for w in (case.get("walls") or []) if isinstance(w, dict)]


def footing_wall(case, path):
    walls = wall_list(case)
    w = next((w for w in walls if w.get("name") == "footing"), None)
    if w is None:
        held = ((case.get("holds") or {}).get("walls") or [{}])[0].get("wall")
        w = next((w for w in walls if held and w.get("name") == held), None)
    if w is None or w.get("type") != "box" or "min" not in w or "max" not in w:
        raise ReportError("%s: no box wall named 'footing' (nor a held box wall)" % path)
    lo, hi = [float(v) for v in w["min"]], [float(v) for v in w["max"]]
    return {"name": w["name"], "B": hi[0] - lo[0], "L": hi[1] - lo[1], "xc": 0.5 * (lo[0] + hi[0]),
            "zmin": lo[2]}


def floor_wall(case, path):
    """The plane wall with normal +z (the lowest, if several)."""
    best = None
    for w in wall_list(case):
        n = [float(v) for v in (w.get("normal") or [0, 0, 0])]
        if w.get("type", "plane") != "plane" or n[2] < 0.99 * math.sqrt(sum(v * v for v in n) or 1):
            continue
        z = float((w.get("point") or [0, 0, 0])[2])
        if best is None or z < best[1]:
            best = (w["name"], z)
    if best is None:
        raise ReportError("%s: no plane wall with normal +z (the floor)" % path)
    return best[0]


def material_density(case, name):
    for m in case.get("materials") or []:
        if isinstance(m, dict) and m.get("name") == name:
            return float(m.get("density", NAN))
    return NAN


def gravity_z(case):
    g = case.get("gravity") or [0, 0, -9.81]
    return float(g[2]), math.sqrt(sum(float(v) ** 2 for v in g))


def stop_displacement(case):
    st = (case.get("holds") or {}).get("stop")
    if isinstance(st, dict) and "displacement" in st:
        return float(st["displacement"])
    return None


def creep_limit_um(case):
    """The footing's creep limit (um per holds.check_every steps): holds.creep, else 10 um."""
    c = (case.get("holds") or {}).get("creep")
    return 1e6 * float(c) if c else 10.0


def settling_rate(run, step):
    """The footing's settlement (um) in the holds.check_every steps (default 1000) before `step`,
    from walls.csv; NaN where walls.csv has no row there."""
    wc, name = run["wc"], run["foot"]["name"]
    every = int((run["case"].get("holds") or {}).get("check_every", 1000))
    j1, j0 = at_step(wc, step), at_step(wc, step - every)
    if j1 is None or j0 is None:
        return NAN
    return 1e6 * (wc[name + "_uz"][j0] - wc[name + "_uz"][j1])


def reached_stop(run, r):
    return run["stop"] is not None and r["settlement_mm"] >= 1e3 * run["stop"] * (1 - 1e-9)


def grid_weight(case, meshes):
    """Weight of the FE meshes carried by the soil (N): unit_weight x volume with fem.gravity."""
    fem = case.get("fem") or {}
    if not meshes or not fem.get("gravity"):
        return 0.0
    gz, g = gravity_z(case)
    uw = {m.get("name"): float(m.get("unit_weight", 0) or 0) for m in fem.get("materials") or []}
    spec = {m.get("name"): m for m in fem.get("meshes") or []}
    total = 0.0
    for m in meshes:
        vol = m.get("volume")
        if vol is None:
            warn("mesh %s: no volume in structures.json: its weight is left out" % m["name"])
            continue
        total += uw.get(spec.get(m["name"], {}).get("material"), 0.0) * vol * (-gz / g if g else 0)
    return total


# ---------------------------------------------------------------------------------------------
# Files of a run
# ---------------------------------------------------------------------------------------------

def step_file(run_dir, prefix, step, time=None):
    """prefix_<step>.h5, None if absent or (time given) written at another time."""
    p = os.path.join(run_dir, "%s_%08d.h5" % (prefix, int(step)))
    if not os.path.exists(p):
        return None
    if time is not None:
        with h5py.File(p, "r") as f:
            t = float(f.attrs.get("time", NAN))
        if not math.isnan(t) and abs(t - time) > 1e-9 * max(1.0, abs(time)):
            warn("%s: written at t = %.6g s, not at the hold's end (t = %.6g s): a file of an older "
                 "run? ignored" % (p, t, time))
            return None
    return p


def at_step(cols, step):
    steps = cols.get("step") or []
    for i in range(len(steps) - 1, -1, -1):
        if int(steps[i]) == int(step):
            return i
    return None


def read_meshes(path, case):
    """The FE meshes of structures.json, with the geogrid layout of each."""
    try:
        with open(path) as f:
            meshes = json.load(f).get("meshes") or []
    except (OSError, ValueError) as e:
        raise ReportError("%s: cannot read (%s)" % (path, e))
    out = []
    for m in meshes:
        gi = m.get("geogrid")
        if gi is None:
            raise ReportError("%s: mesh %s is not a generated geogrid" % (path, m.get("name")))
        out.append({
            "name": m["name"], "n0": int(m["node_offset"]), "nn": int(m["nodes"]),
            "e0": int(m["element_offset"]), "ne": int(m["elements"]),
            "mid_z": 0.5 * (float(m["min"][2]) + float(m["max"][2])), "volume": gi.get("volume"),
            "long_y": [float(v) for v in gi["longitudinal_y"]], "trans_x": [float(v) for v in gi["transverse_x"]],
            "w_long": float(gi["pitch_y"]) - float(gi["aperture_y"]),
            "w_trans": float(gi["pitch_x"]) - float(gi["aperture_x"]), "pitch_x": float(gi["pitch_x"]),
        })
    n_case = len((case.get("fem") or {}).get("meshes") or [])
    if len(out) != n_case:
        raise ReportError("%s: %d meshes, the case has %d" % (path, len(out), n_case))
    return out


def grains_weight(path, case):
    """Sum of m g (N) of the grains in a particles_<step>.h5."""
    with h5py.File(path, "r") as f:
        if "radius" not in f:
            return NAN
        r = f["radius"][()]
        mat = f["material"][()] if "material" in f else np.zeros(len(r), int)
    mats = [m for m in case.get("materials") or [] if isinstance(m, dict)]
    rho = np.array([float(m.get("density", NAN)) for m in mats])
    if len(mats) == 0 or mat.max(initial=0) >= len(mats):
        return NAN
    gz, _ = gravity_z(case)
    return float(np.sum(rho[mat] * 4.0 / 3.0 * math.pi * r ** 3) * -gz)


def on_ribs(y, starts, w, tol):
    m = np.zeros(len(y), bool)
    for y0 in starts:
        m |= (y >= y0 - tol) & (y <= y0 + w + tol)
    return m


def grid_state(X, U, conn, S, active, mesh, foot):
    """One grid mesh at one FE snapshot: maxima, centre settlement and profiles along x."""
    nsl = slice(mesh["n0"], mesh["n0"] + mesh["nn"])
    esl = slice(mesh["e0"], mesh["e0"] + mesh["ne"])
    Xm, down = X[nsl], -U[nsl, 2]
    C, Sm, act = conn[esl], S[esl], active[esl] != 0
    tol = 1e-6 + 1e-3 * mesh["w_long"]
    near = np.abs(Xm[:, 0] - foot["xc"]) <= mesh["pitch_x"] + tol
    # nodes on the longitudinal ribs (their edges: the centre line's value, averaged), per x
    node_long = on_ribs(Xm[:, 1], mesh["long_y"], mesh["w_long"], tol)
    xr = np.round(Xm[:, 0], 9)
    xs = np.unique(xr[node_long])
    prof_u = np.array([1e3 * down[node_long & (xr == x)].mean() for x in xs])
    cen = X[C].mean(axis=1)
    el = on_ribs(cen[:, 1], mesh["long_y"], mesh["w_long"], tol) & act
    return {
        "max_down_mm": 1e3 * float(down.max()),
        "centre_down_mm": 1e3 * float(down[near].mean()) if near.any() else NAN,
        "max_sxx_MPa": float(Sm[act, 0].max()) / 1e6 if act.any() else NAN,
        "prof_x": xs, "prof_u": prof_u, "sxx_x": cen[el, 0], "sxx": Sm[el, 0] / 1e6,
    }


def fe_snapshot(path, meshes, foot):
    with h5py.File(path, "r") as f:
        X = f["nodes/coordinates"][()]
        U = f["nodes/displacement"][()]
        conn = f["elements/connectivity"][()]
        S = f["elements/stress"][()]  # Voigt xx yy zz xy yz xz (src/io/fe_output.cpp)
        active = f["elements/active"][()] if "elements/active" in f else np.ones(len(conn), int)
        # element rows are written rank by rank; `index` (fdem >= Dec 2026) is each one's place in
        # the case's meshes (structures.json's offsets): put them in that order
        if "elements/index" in f:
            order = np.argsort(f["elements/index"][()], kind="stable")
            conn, S, active = conn[order], S[order], active[order]
    if conn.ndim != 2:
        raise ReportError("%s: a mixed-element mesh (not a generated geogrid)" % path)
    return {m["name"]: grid_state(X, U, conn, S, active, m, foot) for m in meshes}


def measure_column(path, xc):
    """(cell centre z, sigma_zz Pa) of the measurement grid's column at x = xc (mean over y)."""
    with h5py.File(path, "r") as f:
        if "grid" not in f or "stress" not in f["grid"]:
            return None
        g = f["grid"]
        a = {k: g.attrs[k] for k in g.attrs}
        S = g["stress"][()]  # xx yy zz xy xz yz, compression positive (src/dem/measure.hpp)
    nx, ny, nz = int(a["nx"]), int(a["ny"]), int(a["nz"])
    S = S.reshape(nz, ny, nx, 6)
    i = int(np.clip(math.floor((xc - a["origin_x"]) / a["spacing_x"]), 0, nx - 1))
    z = a["origin_z"] + (np.arange(nz) + 0.5) * a["spacing_z"]
    return z, np.nanmean(S[:, :, i, 2], axis=1)


# ---------------------------------------------------------------------------------------------
# Loading a run
# ---------------------------------------------------------------------------------------------

def read_case_files(run_dir):
    for f in ("case.yaml", "holds.csv", "walls.csv"):
        if not os.path.isfile(os.path.join(run_dir, f)):
            raise ReportError("%s is missing (is %s the output directory of a strip-footing run with "
                              "holds?)" % (os.path.join(run_dir, f), run_dir))
    path = os.path.join(run_dir, "case.yaml")
    try:
        case = load_case(path)
    except (OSError, ValueError) as e:
        raise ReportError("%s: cannot read the case (%s)" % (path, e))
    if not isinstance(case, dict):
        raise ReportError("%s: not a case file" % path)
    return case, path


def check_columns(run_dir, hc, wc, foot, floor):
    need_h = ["hold", "step", "time", "converged"] + [foot + s for s in ("_target", "_stress", "_settlement")]
    need_w = ["step", floor + "_fz", foot + "_fz", foot + "_uz"]
    for name, cols, need in (("holds.csv", hc, need_h), ("walls.csv", wc, need_w)):
        miss = [c for c in need if c not in cols]
        if miss:
            raise ReportError("%s: no column %s" % (os.path.join(run_dir, name), ", ".join(miss)))
    if not hc["step"]:
        raise ReportError("%s: no rows (no hold ended yet)" % os.path.join(run_dir, "holds.csv"))


def load_run(run_dir):
    case, case_path = read_case_files(run_dir)
    foot = footing_wall(case, case_path)
    floor = floor_wall(case, case_path)
    hc = read_csv(os.path.join(run_dir, "holds.csv"))
    wc = read_csv(os.path.join(run_dir, "walls.csv"))
    check_columns(run_dir, hc, wc, foot["name"], floor)
    n = len((case.get("fem") or {}).get("meshes") or [])
    meshes = []
    if n:
        sj = os.path.join(run_dir, "structures.json")
        if not os.path.isfile(sj):
            raise ReportError("%s is missing (the case has %d FE meshes)" % (sj, n))
        meshes = read_meshes(sj, case)
    packing = {}
    pj = os.path.join(run_dir, "packing.json")
    if os.path.isfile(pj):
        try:
            with open(pj) as f:
                packing = json.load(f)
        except ValueError as e:
            warn("%s: unreadable (%s)" % (pj, e))
    run = {"dir": run_dir, "case": case, "case_path": case_path, "foot": foot, "floor": floor, "N": n,
           "meshes": meshes, "hc": hc, "wc": wc, "packing": packing, "stop": stop_displacement(case),
           "creep_um": creep_limit_um(case),
           "w_grid": grid_weight(case, meshes)}
    run["uz0"] = placement_uz(run)
    build_rows(run)
    return run


def placement_uz(run):
    """footing_uz where the settlement is 0 (its placement on the soil): uz + settlement at a hold
    end that walls.csv has, else walls.csv's first row."""
    hc, wc, name = run["hc"], run["wc"], run["foot"]["name"]
    for step, s in zip(hc["step"], hc[name + "_settlement"]):
        j = at_step(wc, step)
        if j is not None:
            return wc[name + "_uz"][j] + s
    return wc[name + "_uz"][0]


def build_rows(run):
    hc, wc, foot, case = run["hc"], run["wc"], run["foot"], run["case"]
    name, B = foot["name"], foot["B"]
    rows, snaps, missing = [], [], []
    for i, step in enumerate(int(s) for s in hc["step"]):
        t = hc["time"][i]
        r = {"N": run["N"], "hold": int(hc["hold"][i]), "step": step, "time": t,
             "q_kPa": hc[name + "_stress"][i] / 1e3, "target_kPa": hc[name + "_target"][i] / 1e3,
             "settlement_mm": 1e3 * hc[name + "_settlement"][i], "converged": int(hc["converged"][i])}
        r["s_over_B"] = r["settlement_mm"] / 1e3 / B
        j = at_step(wc, step)
        r["floor_fz_N"] = wc[run["floor"] + "_fz"][j] if j is not None else NAN
        r["footing_fz_N"] = wc[name + "_fz"][j] if j is not None else NAN
        uz = wc[name + "_uz"][j] if j is not None else run["uz0"] - hc[name + "_settlement"][i]
        r["base_z"] = foot["zmin"] + uz
        r["rate_um"] = settling_rate(run, step)
        r["held"] = int(r["converged"] or (r["rate_um"] < run["creep_um"] and not reached_stop(run, r)))
        pf = step_file(run["dir"], "particles", step, t)
        r["grains_weight_N"] = grains_weight(pf, case) if pf else NAN
        den = r["footing_fz_N"] + r["grains_weight_N"] + run["w_grid"]
        r["reaction_balance"] = -r["floor_fz_N"] / den if den and not math.isnan(den) else NAN
        snap = None
        if run["meshes"]:
            fe = step_file(run["dir"], "fe", step, t)
            snap = fe_snapshot(fe, run["meshes"], foot) if fe else None
            if snap is None:
                missing.append(step)
        add_grid_columns(r, snap, run["meshes"])
        rows.append(r)
        snaps.append(snap)
    if missing:
        warn("%s: no FE snapshot at the end of the holds at steps %s: grid columns blank"
             % (run["dir"], ", ".join(str(s) for s in missing)))
    run["rows"], run["snaps"] = rows, snaps


def add_grid_columns(r, snap, meshes):
    for m in meshes:
        g = snap.get(m["name"]) if snap else None
        for k in GRID_KEYS[:3]:
            r["%s_%s" % (m["name"], k)] = g[k] if g else NAN
        r["%s_depth_mm" % m["name"]] = 1e3 * (r["base_z"] - m["mid_z"])


def write_table(run):
    cols = BASE_COLS + ["%s_%s" % (m["name"], k) for m in run["meshes"] for k in GRID_KEYS]
    path = os.path.join(run["dir"], "footing.csv")

    def fmt(v):
        if isinstance(v, (int, np.integer)):
            return str(int(v))
        return "" if isnan(v) else "%.9g" % v

    with open(path, "w") as f:
        f.write(",".join(cols) + "\n")
        for r in run["rows"]:
            f.write(",".join(fmt(r.get(c, NAN)) for c in cols) + "\n")
    return path


# ---------------------------------------------------------------------------------------------
# Ultimate pressure, BCR, bearing capacity
# ---------------------------------------------------------------------------------------------

def ultimate(run):
    """q_u (kPa) as an interval (lo, hi, text): lo == hi when reached, hi = inf when every hold
    was held, lo = 0 when the first hold already failed. A hold is held when it converged, or
    when it ended at holds.max_steps with the footing at rest (settling less than the creep
    limit: the misfit was elsewhere, e.g. the grid's FE residual); it fails when the footing was
    still settling at its end or reached holds.stop."""
    rows = run["rows"]
    fail = next((k for k, r in enumerate(rows) if not r["held"] or reached_stop(run, r)), None)
    if fail is None:
        q = rows[-1]["target_kPa"]
        return q, math.inf, ">= %.1f kPa (not reached: every hold held)" % q, None
    why = ("stop at s = %.1f mm" % (1e3 * run["stop"]) if reached_stop(run, rows[fail])
           else "not converged, the footing settling %.0f um per check" % rows[fail]["rate_um"])
    ok = [r for r in rows[:fail] if r["held"]]
    if not ok:
        q = rows[fail]["target_kPa"]
        return 0.0, q, "< %.1f kPa (hold %d, the first, %s)" % (q, rows[fail]["hold"], why), None
    q = ok[-1]["target_kPa"]
    return q, q, "%.1f kPa (hold %d; hold %d %s)" % (q, ok[-1]["hold"], rows[fail]["hold"], why), ok[-1]


def ratio_text(lo_n, hi_n, lo_0, hi_0):
    lo = lo_n / hi_0 if hi_0 > 0 and not math.isinf(hi_0) else 0.0
    hi = hi_n / lo_0 if lo_0 > 0 else math.inf
    if lo == hi:
        return "%.3f" % lo
    if math.isinf(hi) and lo > 0:
        return ">= %.3f" % lo
    if lo == 0 and not math.isinf(hi):
        return "<= %.3f" % hi
    if lo > 0:
        return "between %.3f and %.3f" % (lo, hi)
    return "undetermined (both q_u not reached)"


def q_at_settlement(run, s_over_b):
    """q (kPa) at settlement s/B, linear between the origin and the converged hold ends; NaN where
    the curve does not reach it."""
    pts = [(0.0, 0.0)] + [(r["s_over_B"], r["q_kPa"]) for r in run["rows"] if r["held"] and not reached_stop(run, r)]
    for (s0, q0), (s1, q1) in zip(pts, pts[1:]):
        if s0 <= s_over_b <= s1 and s1 > s0:
            return q0 + (q1 - q0) * (s_over_b - s0) / (s1 - s0)
    return NAN


def unit_weight(run, override):
    """(gamma kN/m3, how)."""
    if override is not None:
        return override, "--unit-weight"
    case, pk = run["case"], run["packing"]
    n = (pk.get("interior") or {}).get("porosity")
    src = "interior porosity"
    if n is None:
        n, src = pk.get("target_porosity"), "target porosity"
    rho = material_density(case, (case.get("packing") or {}).get("material"))
    if n is None or math.isnan(rho):
        return NAN, "unknown (no packing.json porosity or packing material density: give --unit-weight)"
    _, g = gravity_z(case)
    return (1 - n) * rho * g / 1e3, "(1 - n) rho_s g, n = %.4f (%s, packing.json), rho_s = %g kg/m3" % (n, src, rho)


def bulk_unit_weight(run):
    """Weight of the grains (first hold end) over the packing box's plan area times the height the
    specimen was struck off at (packing.json level.z), kN/m3; NaN when unknown."""
    box = (run["case"].get("packing") or {}).get("box") or {}
    z = (run["packing"].get("level") or {}).get("z")
    w = next((r["grains_weight_N"] for r in run["rows"] if not isnan(r["grains_weight_N"])), NAN)
    if not box or z is None or isnan(w):
        return NAN
    lo, hi = box["min"], box["max"]
    return w / ((hi[0] - lo[0]) * (hi[1] - lo[1]) * (z - lo[2])) / 1e3


def bearing_capacity(phi_deg, gamma, B):
    """{name: (N_gamma, q_u kPa)} for a surface strip footing, q_u = 0.5 gamma B N_gamma."""
    p = math.radians(phi_deg)
    nq = math.exp(math.pi * math.tan(p)) * math.tan(math.radians(45 + phi_deg / 2)) ** 2
    ng = {"Vesic 2(Nq+1)tan(phi)": 2 * (nq + 1) * math.tan(p),
          "Meyerhof (Nq-1)tan(1.4phi)": (nq - 1) * math.tan(1.4 * p),
          "Brinch Hansen 1.5(Nq-1)tan(phi)": 1.5 * (nq - 1) * math.tan(p)}
    return nq, {k: (v, 0.5 * gamma * B * v) for k, v in ng.items()}


# ---------------------------------------------------------------------------------------------
# Printing
# ---------------------------------------------------------------------------------------------

def fnum(v, fmt):
    return "-" if isnan(v) else fmt % v


def print_run(run):
    f = run["foot"]
    print("\n== %s  (N = %d; case %s; footing B = %.1f mm, L = %.1f mm, centre x = %.4f m; floor '%s')"
          % (run["dir"], run["N"], run["case"].get("name", "?"), 1e3 * f["B"], 1e3 * f["L"], f["xc"], run["floor"]))
    head = "hold   step    q(kPa) target  s(mm)  s/B(%)  conv  rate(um)  balance"
    for m in run["meshes"]:
        head += " | %s: down max, centre (mm)  Sxx max (MPa)  depth (mm)" % m["name"]
    print(head)
    for r in run["rows"]:
        line = "%4d %7d  %7.2f %6.1f %6.2f  %6.2f  %4s  %8s  %7s" % (
            r["hold"], r["step"], r["q_kPa"], r["target_kPa"], r["settlement_mm"], 100 * r["s_over_B"],
            "yes" if r["converged"] else ("rest" if r["held"] else "NO"), fnum(r["rate_um"], "%.1f"),
            fnum(r["reaction_balance"], "%.4f"))
        for m in run["meshes"]:
            g = [r["%s_%s" % (m["name"], k)] for k in GRID_KEYS]
            line += " | %s  %9s %7s  %13s  %10s" % (" " * len(m["name"]), fnum(g[0], "%.3f"), fnum(g[1], "%.3f"),
                                                    fnum(g[2], "%.3f"), fnum(g[3], "%.1f"))
        print(line)
    print_checks(run)


def print_checks(run):
    tol = float((run["case"].get("holds") or {}).get("tolerance", 0.01) or 0.01)
    for r in run["rows"]:
        mis = abs(r["q_kPa"] - r["target_kPa"]) / r["target_kPa"] if r["target_kPa"] else NAN
        if not isnan(mis) and mis > tol:
            print("  CHECK hold %d: footing stress %.2f kPa, %.1f %% off its target"
                  % (r["hold"], r["q_kPa"], 100 * mis))
        b = r["reaction_balance"]
        if not isnan(b) and abs(b - 1) > 0.02:
            print("  CHECK hold %d: reaction balance %.4f (floor vs footing + weight: off by more than 2 %%)"
                  % (r["hold"], b))
        if isnan(r["grains_weight_N"]):
            print("  note hold %d: no particles_%08d.h5: grains weight and reaction balance blank"
                  % (r["hold"], r["step"]))
    if run["w_grid"]:
        print("  grids' weight in the balance: %.4g N" % run["w_grid"])
    rz = fe_vertical_reactions(run)
    big = [(r["hold"], rz[r["step"]]) for r in run["rows"]
           if r["step"] in rz and abs(rz[r["step"]]) > 1e-3 * abs(r["floor_fz_N"] or 1)]
    if big:
        print("  note: the FE restraints carry a vertical force (reactions.csv, sum of *_rz), not in the balance: %s"
              % ", ".join("hold %d %.3g N" % b for b in big))


def fe_vertical_reactions(run):
    """{step: sum of the *_rz columns of reactions.csv}, empty without the file."""
    path = os.path.join(run["dir"], "reactions.csv")
    if not os.path.isfile(path):
        return {}
    rc = read_csv(path)
    cols = [k for k in rc if k.endswith("_rz")]
    if not cols or "step" not in rc:
        return {}
    return {int(s): sum(rc[k][i] for k in cols) for i, s in enumerate(rc["step"])}


def print_summary(runs, phi, gamma_override):
    print("\n== summary")
    qu = {}
    for run in runs:
        lo, hi, text, _ = ultimate(run)
        qu[run["N"]] = (lo, hi)
        print("N = %d: q_u %s; last hold: q = %.1f kPa at s = %.2f mm (s/B %.2f %%)"
              % (run["N"], text, run["rows"][-1]["q_kPa"], run["rows"][-1]["settlement_mm"],
                 100 * run["rows"][-1]["s_over_B"]))
    base = next((r for r in runs if r["N"] == 0), None)
    if base is None:
        print("BCR: no N = 0 run among the DIRs")
    else:
        for run in runs:
            if run is not base:
                print("BCR(N = %d) = q_u(%d) / q_u(0): %s" % (run["N"], run["N"], ratio_text(*qu[run["N"]], *qu[0])))
        print_bcr_settlement(runs, base)
    print_bearing(base or runs[0], base is None, phi, gamma_override)


def print_bcr_settlement(runs, base):
    for sb in S_OVER_B:
        q0 = q_at_settlement(base, sb)
        parts = ["q(N=0) %s kPa" % fnum(q0, "%.1f")]
        for run in runs:
            if run is base:
                continue
            qn = q_at_settlement(run, sb)
            parts.append("N=%d: q %s kPa, BCR %s" % (run["N"], fnum(qn, "%.1f"), fnum(qn / q0 if q0 else NAN, "%.3f")))
        print("at s/B = %g %%: %s" % (100 * sb, "; ".join(parts)))
    print("  (q at s/B: linear between the origin and the held hold ends; '-' beyond the last one)")


def print_bearing(run, not_n0, phi, gamma_override):
    gamma, how = unit_weight(run, gamma_override)
    B = run["foot"]["B"]
    print("bearing capacity, N = 0, surface strip footing q_u = 0.5 gamma B N_gamma%s:"
          % (" (no N = 0 run: the specimen of %s)" % run["dir"] if not_n0 else ""))
    print("  B = %.1f mm, phi = %g deg, gamma = %s kN/m3 (%s)" % (1e3 * B, phi, fnum(gamma, "%.3f"), how))
    gb = bulk_unit_weight(run)
    if not math.isnan(gb):
        print("  (cross-check: the grains' weight / (packing box plan x levelled height) = %.3f kN/m3, wall zones "
              "included)" % gb)
    nq, res = bearing_capacity(phi, gamma, B)
    print("  Nq = exp(pi tan phi) tan^2(45 + phi/2) = %.2f" % nq)
    for k, (ng, q) in res.items():
        print("  %-32s N_gamma = %7.2f   q_u = %s kPa" % (k, ng, fnum(q, "%.1f")))
    if not not_n0:
        print("  measured N = 0: q_u %s" % ultimate(run)[2])


def print_triaxial_bearing(run, tdirs, gamma_override, path):
    """The classical q_u for the peak friction angles of triaxial runs of the footing's sand
    (triaxial and plane strain), printed and written to `path` (CSV). Returns `path`."""
    gamma, _ = unit_weight(run, gamma_override)
    B = run["foot"]["B"]
    print("\nclassical q_u for the measured friction angles (triaxial, plane strain; Lade-Lee ps: the plane-strain "
          "angle estimated from the triaxial one, 1.5 phi_tx - 17 deg, Lade & Lee 1976):")
    names = list(bearing_capacity(40.0, gamma, B)[1])
    rows = []
    for d in tdirs:
        pk = triaxial_peak(read_csv(os.path.join(d, "lab.csv")))
        kinds = ((("plane strain", pk["phi"]),) if pk["plane"] else
                 (("triaxial", pk["phi"]), ("Lade-Lee ps", 1.5 * pk["phi"] - 17.0)))
        for kind, phi in kinds:
            res = bearing_capacity(phi, gamma, B)[1]
            rows.append([pk["s3"] / 1e3, kind, phi] + [res[k][1] for k in names])
            print("  sigma_3 %5.1f kPa, %-13s phi %4.1f deg: q_u %s kPa (%s)"
                  % (pk["s3"] / 1e3, kind, phi, " / ".join("%.0f" % res[k][1] for k in names),
                     ", ".join(k.split()[0] for k in names)))
    with open(path, "w") as f:
        f.write("sigma3_kPa,kind,phi_deg," + ",".join("qu_%s_kPa" % k.split()[0].replace(" ", "_") for k in names) + "\n")
        for r in rows:
            f.write("%.6g,%s,%.4f,%s\n" % (r[0], r[1], r[2], ",".join("%.6g" % x for x in r[3:])))
    return path


# ---------------------------------------------------------------------------------------------
# Figures
# ---------------------------------------------------------------------------------------------

LINESTYLES = ["-", "--", ":", "-."]
MARKERS = ["o", "s", "^", "D"]


def run_colour(run):
    return "C%d" % run["N"]


def history_curve(run):
    """(q kPa, s mm) of every walls.csv row up to the last hold's step."""
    wc, name = run["wc"], run["foot"]["name"]
    last = run["rows"][-1]["step"]
    keep = [i for i, s in enumerate(wc["step"]) if s <= last]
    q = np.array([wc[name + "_stress"][i] for i in keep]) / 1e3 if name + "_stress" in wc else None
    s = np.array([run["uz0"] - wc[name + "_uz"][i] for i in keep]) * 1e3
    return q, s


def fig_pressure_settlement(runs, path):
    fig, ax = plt.subplots(figsize=(7, 5.5))
    notes = []
    for run in runs:
        c = run_colour(run)
        q, s = history_curve(run)
        if q is not None:
            ax.plot(q, s, color=c, lw=0.6, alpha=0.45)
        rows = run["rows"]
        ax.plot([0] + [r["q_kPa"] for r in rows], [0] + [r["settlement_mm"] for r in rows], color=c, marker="o",
                label="N = %d (%s)" % (run["N"], os.path.basename(os.path.normpath(run["dir"]))))
        bad = [r for r in rows if not r["held"]]
        ax.plot([r["q_kPa"] for r in bad], [r["settlement_mm"] for r in bad], ls="none", marker="o", ms=9,
                mfc="white", mec=c)
        notes.append((mark_ultimate(ax, run, c), c))
    B = runs[0]["foot"]["B"]
    ax.set_xlabel("bearing pressure q (kPa)")
    ax.set_ylabel("settlement s (mm), downward")
    ax.set_xlim(0, 1.3 * max(r["q_kPa"] for run in runs for r in run["rows"]))
    ax.set_ylim(bottom=0)
    ax.invert_yaxis()
    sec = ax.secondary_yaxis("right", functions=(lambda s: 100 * s / 1e3 / B, lambda p: p / 100 * B * 1e3))
    sec.set_ylabel("s / B (%%), B = %.0f mm" % (1e3 * B))
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="lower left")
    for k, (text, c) in enumerate(notes):
        ax.text(0.98, 0.97 - 0.05 * k, text, transform=ax.transAxes, ha="right", va="top", fontsize=8, color=c)
    ax.set_title("Bearing pressure vs settlement (thesis fig. 5-5)\nq on x, s downward; dots: hold ends "
                 "(open: not converged); thin: the loading history\nstar: q_u; triangle: q_u not reached "
                 "(a lower bound)", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def mark_ultimate(ax, run, c):
    """q_u: a star on its hold end, a triangle on the last hold when not reached; returns the text."""
    lo, hi, _, row = ultimate(run)
    last = run["rows"][-1]
    if row is not None:
        ax.plot(row["q_kPa"], row["settlement_mm"], marker="*", ms=16, color=c, mec="k", ls="none")
        return "N = %d: q_u = %.0f kPa" % (run["N"], lo)
    if math.isinf(hi):
        ax.plot(last["q_kPa"], last["settlement_mm"], marker=">", ms=9, color=c, mec="k", ls="none")
        return "N = %d: q_u >= %.0f kPa (not reached)" % (run["N"], lo)
    return "N = %d: q_u < %.0f kPa (the first hold failed)" % (run["N"], hi)


def profile_holds(run):
    """Indices of the rows drawn in grid_profiles.png: all if <= 4 with a snapshot, else the
    nearest to PROFILE_Q_KPA."""
    ok = [k for k, s in enumerate(run["snaps"]) if s is not None]
    if len(ok) <= len(PROFILE_Q_KPA):
        return ok
    pick = {min(ok, key=lambda k: abs(run["rows"][k]["q_kPa"] - q)) for q in PROFILE_Q_KPA}
    return sorted(pick)


def fig_grid_profiles(runs, path):
    panels = [(run, m) for run in runs if run["N"] >= 1 for m in run["meshes"]
              if any(s is not None for s in run["snaps"])]
    if not panels:
        return False
    fig, axes = plt.subplots(2, len(panels), figsize=(max(6.5, 5.2 * len(panels)), 8), squeeze=False, sharex=True)
    for col, (run, m) in enumerate(panels):
        draw_profile_panel(axes[0, col], axes[1, col], run, m)
    axes[0, 0].set_ylabel("grid settlement $-u_z$ (mm)")
    axes[1, 0].set_ylabel("$S_{xx}$ (MPa, tension positive)")
    fig.suptitle("Grid settlement (nodes of the longitudinal ribs, mean per x)\nand $S_{xx}$ (dots: "
                 "longitudinal-rib elements at their centroid x; line: mean per x)\ngrey: transverse ribs; "
                 "dashed: the footing's edges", fontsize=9)
    fig.tight_layout(rect=(0, 0, 1, 0.93))
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return True


def draw_profile_panel(ax_u, ax_s, run, m):
    xc, B = run["foot"]["xc"], run["foot"]["B"]
    ks = profile_holds(run)
    cols = plt.cm.viridis(np.linspace(0, 0.9, max(len(ks), 1)))
    for c, k in zip(cols, ks):
        r, g = run["rows"][k], run["snaps"][k][m["name"]]
        lab = "q = %.0f kPa (hold %d%s)" % (r["q_kPa"], r["hold"], "" if r["converged"] else ", not conv.")
        ax_u.plot((g["prof_x"] - xc) / B, g["prof_u"], color=c, marker="o", ms=2.5, label=lab)
        ax_s.plot((g["sxx_x"] - xc) / B, g["sxx"], ls="none", marker=".", ms=4, color=c)
        xr = np.round(g["sxx_x"], 9)
        xs = np.unique(xr)
        ax_s.plot((xs - xc) / B, [g["sxx"][xr == x].mean() for x in xs], color=c, lw=1)
    for ax in (ax_u, ax_s):
        for x0 in m["trans_x"]:
            ax.axvspan((x0 - xc) / B, (x0 + m["w_trans"] - xc) / B, color="0.88", lw=0)
        for e in (-0.5, 0.5):
            ax.axvline(e, color="k", ls="--", lw=0.7)
        ax.grid(alpha=0.3)
    ax_u.invert_yaxis()
    ax_s.axhline(0, color="k", lw=0.5)
    ax_s.set_xlabel("x / B from the footing centre")
    ax_u.set_title("N = %d, grid '%s' (mid-plane %.0f mm below the surface)"
                   % (run["N"], m["name"], 1e3 * (run["foot"]["zmin"] + run["uz0"] - m["mid_z"])), fontsize=9)
    ax_u.legend(fontsize=7)


def fig_grid_max(runs, path):
    series = [(run, m) for run in runs for m in run["meshes"]]
    if not series:
        return False
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4.8))
    for k, (run, m) in enumerate(series):
        rows = [r for r in run["rows"] if not isnan(r["%s_max_down_mm" % m["name"]])]
        q = [r["q_kPa"] for r in rows]
        style = dict(color=run_colour(run), ls=LINESTYLES[k % 4], marker=MARKERS[k % 4])
        lab = "N = %d, %s" % (run["N"], m["name"])
        ax1.plot(q, [r["%s_max_down_mm" % m["name"]] for r in rows], label=lab + " (max)", **style)
        ax1.plot(q, [r["%s_centre_down_mm" % m["name"]] for r in rows], lw=0.8, alpha=0.6,
                 label=lab + " (centre +-1 pitch)", **dict(style, marker="x"))
        ax2.plot(q, [r["%s_max_sxx_MPa" % m["name"]] for r in rows], label=lab, **style)
    ax1.set_ylabel("grid settlement $-u_z$ (mm)")
    ax1.invert_yaxis()
    ax2.set_ylabel("max $S_{xx}$ (MPa, tension positive)")
    for ax in (ax1, ax2):
        ax.set_xlabel("bearing pressure q (kPa)")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
    fig.suptitle("Maximum grid settlement and tensile stress vs bearing pressure (thesis fig. 5-9)", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return True


def sigma_v_curves(run):
    """[(label, q kPa, depth/B array, sigma_v kPa array)] under the footing centre: step 0 and
    the hold ends with a measure file (the four nearest 45/75/95/125 kPa when there are more) (a measurement without any stress, e.g. step 0's, taken
    before the first contact forces, is left out)."""
    B, xc = run["foot"]["B"], run["foot"]["xc"]
    first = step_file(run["dir"], "measure", 0)
    items = [("step 0 (q = 0)", 0.0, run["foot"]["zmin"] + run["uz0"], first)] if first else []
    rows = [r for r in run["rows"] if step_file(run["dir"], "measure", r["step"], r["time"])]
    if len(rows) > len(PROFILE_Q_KPA):  # the holds nearest 45/75/95/125 kPa (the thesis's), as grid_profiles
        rows = sorted({id(r): r for r in (min(rows, key=lambda r: abs(r["q_kPa"] - q))
                                          for q in PROFILE_Q_KPA)}.values(), key=lambda r: r["step"])
    for r in rows:
        items.append(("q = %.0f kPa" % r["q_kPa"], r["q_kPa"], r["base_z"],
                      step_file(run["dir"], "measure", r["step"], r["time"])))
    out, empty = [], []
    for lab, q, base, p in items:
        col = measure_column(p, xc)
        if col is None:
            continue
        z, szz = col
        keep = (z < base) & np.isfinite(szz)
        if not np.any(szz[keep] != 0):
            empty.append(os.path.basename(p))
            continue
        out.append((lab, q, (base - z[keep]) / B, szz[keep] / 1e3))
    if empty:
        print("note: %s: no stress in %s (measured before any contact force): left out of sigma_v_depth.png"
              % (run["dir"], ", ".join(empty)))
    return out


ZONE_FRACTION = 0.1  # the displaced zone: grains that moved more than this fraction of the settlement


def displacement_states(run):
    """[(label, row, measure file)] of the states whose grain displacements the report shows: the
    last converged hold and, if the run went on, its last hold (failure or holds.stop)."""
    rows = run["rows"]
    conv = [r for r in rows if r["held"] and not reached_stop(run, r)]
    picks = ([conv[-1]] if conv else []) + ([rows[-1]] if not conv or rows[-1] is not conv[-1] else [])
    out = []
    for r in picks:
        p = step_file(run["dir"], "measure", r["step"], r["time"])
        if p is None:
            continue
        with h5py.File(p, "r") as f:
            if "particles" not in f:
                continue
        out.append(("q = %.0f kPa%s, s = %.1f mm" % (r["q_kPa"], "" if r in conv else " (not held)",
                                                   r["settlement_mm"]), r, p))
    return out


def displaced_zone(run, r, path):
    """(depth/B, half-width/B) of the zone where grains moved more than ZONE_FRACTION of the
    footing's settlement: the depth below the base to which the mean |u| of the grains under the
    footing (|x - xc| <= B/2), in slices 0.25B thick, stays above it; the distance from the centre
    to which the mean |u| of the grains within 1.5B below the base, in 0.25B wide columns, does."""
    B, xc = run["foot"]["B"], run["foot"]["xc"]
    with h5py.File(path, "r") as f:
        x = f["particles/position"][...]
        u = f["particles/displacement"][...]
    um = np.linalg.norm(u, axis=1)
    lim = ZONE_FRACTION * r["settlement_mm"] / 1e3
    depth = (r["base_z"] - x[:, 2]) / B
    dx = np.abs(x[:, 0] - xc) / B

    def extent(coord, sel):
        edge = 0.0
        for k in range(200):
            band = sel & (coord >= 0.25 * k) & (coord < 0.25 * (k + 1))
            if not np.any(band) or um[band].mean() <= lim:
                break
            edge = 0.25 * (k + 1)
        return edge
    return extent(depth, (dx <= 0.5) & (depth >= 0)), extent(dx, (depth >= 0) & (depth <= 1.5))


def print_zones(runs):
    print("\ndisplaced zone (grains moving more than %.0f %% of the settlement; 0.25B bins): depth below the "
          "base under the footing, half-width within 1.5B of the base" % (100 * ZONE_FRACTION))
    for run in runs:
        for lab, r, p in displacement_states(run):
            d, w = displaced_zone(run, r, p)
            print("  N = %d, %s: depth %.2fB, half-width %.2fB" % (run["N"], lab, d, w))


def fig_displacements(runs, path):
    """Grain displacement magnitude |u| / s in the x-z plane (thesis figs 5-10, 5-11) at the
    last converged hold and at the last hold of every run."""
    panels = [(run, st) for run in runs for st in displacement_states(run)]
    if not panels:
        return False
    fig, axes = plt.subplots(len(panels), 1, figsize=(7, 3.0 * len(panels)), squeeze=False)
    for ax, (run, (lab, r, p)) in zip(axes[:, 0], panels):
        B, xc = run["foot"]["B"], run["foot"]["xc"]
        with h5py.File(p, "r") as f:
            x = f["particles/position"][...]
            u = f["particles/displacement"][...]
        s = max(r["settlement_mm"] / 1e3, 1e-12)
        order = np.argsort(np.linalg.norm(u, axis=1))
        sc = ax.scatter((x[order, 0] - xc) / B, (r["base_z"] - x[order, 2]) / B, c=np.linalg.norm(u[order], axis=1) / s,
                        s=2, cmap="viridis", vmin=0, vmax=1)
        d, w = displaced_zone(run, r, p)
        ax.plot([-w, -w, w, w], [0, d, d, 0], color="r", lw=0.9, ls="--",
                label="|u| > %.0f %% of s: %.2fB deep, +-%.2fB" % (100 * ZONE_FRACTION, d, w))
        ax.plot([-0.5, 0.5], [0, 0], color="k", lw=3)
        for m in run["meshes"]:
            ax.axhline((r["base_z"] - m["mid_z"]) / B, color="w", lw=0.6, ls="-.")
        ax.invert_yaxis()
        ax.set_aspect("equal")
        ax.set_title("N = %d: %s" % (run["N"], lab), fontsize=9)
        ax.set_ylabel("depth / B")
        ax.legend(fontsize=7, loc="lower right")
        fig.colorbar(sc, ax=ax, label="|u| / s", fraction=0.03, pad=0.02)
    axes[-1, 0].set_xlabel("(x - x_footing) / B")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return True


def fig_sigma_v(runs, path, gamma):
    fig, ax = plt.subplots(figsize=(7.5, 6.5))
    curves = [(k, run, sigma_v_curves(run)) for k, run in enumerate(runs)]
    qmax = max([c[1] for _, _, cs in curves for c in cs] + [1.0])
    drawn = set()
    for k, run, cs in curves:
        for lab, q, d, s in cs:
            c = plt.cm.plasma(0.85 * q / qmax)
            ax.plot(s, d, color=c, ls=LINESTYLES[k % 4], marker=MARKERS[k % 4], ms=4,
                    label="N = %d, %s" % (run["N"], lab))
            if q > 0 and round(q) not in drawn and not math.isnan(gamma):
                drawn.add(round(q))
                draw_elastic(ax, run, q, d, c, gamma)
        for m in run["meshes"]:
            ax.axhline((run["foot"]["zmin"] + run["uz0"] - m["mid_z"]) / run["foot"]["B"], color=run_colour(run),
                       lw=0.7, ls="-.", label="N = %d: grid '%s' (below the base as placed)" % (run["N"], m["name"]))
    if not any(cs for _, _, cs in curves):
        plt.close(fig)
        return False
    ax.invert_yaxis()
    ax.set_xlabel("vertical stress $\\sigma_v$ (kPa, compression positive)")
    ax.set_ylabel("depth below the footing base / B")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)
    ax.set_title("Vertical stress under the footing centre (thesis fig. 5-13)\nmeasurement cells (Love-Weber "
                 "average); dotted: elastic strip (Boussinesq)\non the centre line + gamma z, gamma %s kN/m3"
                 % fnum(gamma, "%.2f"), fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return True


def draw_elastic(ax, run, q, d, c, gamma):
    """Centre line of a uniformly loaded strip on an elastic half-space, plus the overburden."""
    B = run["foot"]["B"]
    zz = np.linspace(max(1e-3, min(d) * 0.5), max(d) * 1.05, 60) * B
    alpha = 2 * np.arctan(B / (2 * zz))
    sv = q / math.pi * (alpha + np.sin(alpha)) + gamma * zz
    ax.plot(sv, zz / B, color=c, ls=":", lw=0.9)


# ---------------------------------------------------------------------------------------------

def load_all(dirs):
    runs = []
    for d in dirs:
        if not os.path.isdir(d):
            raise ReportError("%s: not a directory" % d)
        runs.append(load_run(d))
    seen = {}
    for run in runs:
        if run["N"] in seen:
            raise ReportError("%s and %s are both runs with N = %d: give one run per N"
                              % (seen[run["N"]], run["dir"], run["N"]))
        seen[run["N"]] = run["dir"]
    B0 = runs[0]["foot"]["B"]
    for run in runs[1:]:
        if abs(run["foot"]["B"] - B0) > 1e-9:
            warn("%s: footing B = %.1f mm, %s's %.1f mm: not the same variant?"
                 % (run["dir"], 1e3 * run["foot"]["B"], runs[0]["dir"], 1e3 * B0))
    return sorted(runs, key=lambda r: r["N"])


def make_figures(runs, figdir, gamma):
    def fp(name):
        return os.path.join(figdir, name)

    written = [fp("pressure_settlement.png")]
    fig_pressure_settlement(runs, written[0])
    if fig_grid_profiles(runs, fp("grid_profiles.png")):
        written.append(fp("grid_profiles.png"))
    else:
        print("note: no run with a grid and FE snapshots at the hold ends: grid_profiles.png skipped")
    if fig_grid_max(runs, fp("grid_max.png")):
        written.append(fp("grid_max.png"))
    else:
        print("note: no run with a grid: grid_max.png skipped")
    if fig_displacements(runs, fp("displacements.png")):
        written.append(fp("displacements.png"))
    else:
        print("note: no measure_<step>.h5 with particle displacements at the hold ends: displacements.png skipped")
    if fig_sigma_v(runs, fp("sigma_v_depth.png"), gamma):
        written.append(fp("sigma_v_depth.png"))
    else:
        print("note: no measure_<step>.h5 with a measurement grid: sigma_v_depth.png skipped")
    return written


def main(argv):
    ap = argparse.ArgumentParser(prog="footing_report.py", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("runs", nargs="+", metavar="DIR", help="output directory of a strip-footing run")
    ap.add_argument("--figures", metavar="FIGDIR", help="figure directory (default: FIRST_DIR/figures)")
    ap.add_argument("--phi", type=float, default=41.0, metavar="DEG", help="friction angle for N_gamma (default 41)")
    ap.add_argument("--unit-weight", type=float, metavar="KN_M3", help="soil unit weight (default: from the specimen)")
    ap.add_argument("--triaxial", nargs="+", default=[], metavar="TDIR",
                    help="triaxial runs of the footing's sand (scripts/strip_footing.sh phi): q_u for their phi")
    a = ap.parse_args(argv[1:])
    if not 0 < a.phi < 60 or (a.unit_weight is not None and not a.unit_weight > 0):
        print("%s: --phi must be in (0, 60) deg and --unit-weight > 0" % PROG, file=sys.stderr)
        return 2
    try:
        runs = load_all(a.runs)
    except ReportError as e:
        print("%s: %s" % (PROG, e), file=sys.stderr)
        return 2
    except (OSError, KeyError, ValueError, IndexError) as e:
        print("%s: cannot read the run: %s" % (PROG, e), file=sys.stderr)
        return 2
    figdir = a.figures or os.path.join(a.runs[0], "figures")
    try:
        os.makedirs(figdir, exist_ok=True)
    except OSError as e:
        print("%s: cannot create %s: %s" % (PROG, figdir, e), file=sys.stderr)
        return 2
    written = []
    for run in runs:
        written.append(write_table(run))
        print_run(run)
    print_summary(runs, a.phi, a.unit_weight)
    print_zones(runs)
    base = next((r for r in runs if r["N"] == 0), runs[0])
    if a.triaxial:
        try:
            written.append(print_triaxial_bearing(base, a.triaxial, a.unit_weight, os.path.join(figdir, "classical.csv")))
        except (OSError, KeyError, ValueError, IndexError) as e:
            print("%s: cannot read the triaxial runs: %s" % (PROG, e), file=sys.stderr)
            return 2
    written += make_figures(runs, figdir, unit_weight(base, a.unit_weight)[0])
    print("\nwrote:")
    for w in written:
        print("  " + w)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
