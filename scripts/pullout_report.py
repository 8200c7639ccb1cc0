#!/usr/bin/python3
"""Geogrid pullout report (thesis ch. 4, figs 4-8 to 4-18): a per-hold table and the figures
of one or more pullout runs (one output directory per vertical stress).

    /usr/bin/python3 scripts/pullout_report.py OUT_DIR [OUT_DIR2 ...] [--figures DIR] [--label TEXT ...]

Reads from each OUT_DIR what the run wrote: case.yaml (the case as run: --set applied, defaults
filled in), structures.json (the geogrid's ribs as generated), interface.csv, reactions.csv,
walls.csv (all required), run.json, the FE snapshots fe_<step>.h5 written at every hold end,
measure_<step>.h5 and particles_<step>.h5 (optional). Nothing is re-derived: the rib positions
are structures.json's, the clamp displacement per hold and the front wall case.yaml's. The clamp
displacement is checked against the clamp nodes' displacement in fe_<step>.h5 (the measured
value wins, with a warning). Runs older than case.yaml and structures.json (fdem before
2026-12-02) are refused: re-run them.

Writes OUT_DIR/pullout.csv per run, one row per completed hold (the last row of each `hold` in
interface.csv; a hold still running is left out). Sign convention: forces are the soil's force ON
the grid along x; the grid is pulled along -x, so resistance is positive. Displacements are
positive in the pull direction (-u_x), in mm.

  hold, step, time_s, displacement_factor   hold index (0: consolidation), its last step
  clamp_displacement_mm        case: |value_x| * displacement_steps[hold] (frontal displacement)
  clamp_displacement_fe_mm     -u_x of the clamp's front-face nodes in fe_<step>.h5 (check)
  front_displacement_mm        grid displacement at the front wall (longitudinal ribs)
  clamp_force_N                -grid_clamp_rx (reactions.csv), positive in tension
  clamp_force_kN_per_m         clamp force / grid width
  F_total_N                    interface fx: all soil forces on the grid
  F_f_N = F_top_N + F_bottom_N + F_rest_N   frictional part: every face but the bearing faces
  F_bt_N = sum of ribK_bearing_N   bearing part (front faces of the transverse ribs)
  F_rest_N                     the other faces (rib sides, back faces), part of F_f
  ratio_Ff_Fbt_to_clamp        (F_f + F_bt) / clamp force;  ratio_total_to_clamp  F_total / clamp
  F_f_share, F_bt_share        F_f / (F_f + F_bt), F_bt / (F_f + F_bt)
  N_top_N, N_bottom_N          normal force of the soil on the top (-top_fz) and bottom faces
  mu_mobilised                 F_f / (N_top + N_bottom)
  sigma_v_kPa                  the servo plate's applied stress (walls.csv *_stress; the mean of
                               a segmented plate's) at the step
  ribK_bearing_N               bearing on transverse rib K (K = 1 nearest the front)
  ribK_disp_mm                 mean -u_x of rib K's nodes (fe_<step>.h5)
  interface_contacts, fe_unbalanced, fe_resultant, dem_unbalanced (interface.csv at the step)
  converged                    1 if max(fe_unbalanced, fe_resultant) <= fem.tolerance and
                               dem_unbalanced <= coupling.tolerance (the driver's test)

Figures (--figures DIR, default FIRST_OUT_DIR/figures): pullout_force.png (fig 4-8),
grid_displacement.png (4-9), rib_force.png (4-12), resistance_split.png (4-13),
bearing_per_rib.png (4-14), soil_stress.png (4-17/4-18), soil_displacement.png (4-15).
Needs Debian's python3-numpy, python3-h5py, python3-matplotlib. Exit 2 on bad input.
"""
import argparse
import glob
import json
import math
import os
import re
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from fdem_common import load_case, read_csv, servo_target, system_python_fallback  # noqa: E402

system_python_fallback(["numpy", "h5py", "matplotlib"])
import numpy as np  # noqa: E402
import h5py  # noqa: E402
import matplotlib  # noqa: E402
import matplotlib.collections  # noqa: E402

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

PROG = "pullout_report"
UX_TARGETS_MM = (3.0, 5.0, 10.0, 25.0)  # thesis figs 4-9, 4-12, 4-14
NAN = float("nan")


class ReportError(Exception):
    pass


def warn(msg):
    print("%s: warning: %s" % (PROG, msg), file=sys.stderr)


# ---------------------------------------------------------------------------------------------
# Case and geometry
# ---------------------------------------------------------------------------------------------

def layout_from_structures(path, g):
    """The layout the run's geogrid generator wrote (structures.json): rib positions read, not
    re-derived; clamp length and thickness from the case as run."""
    with open(path) as f:
        meshes = json.load(f).get("meshes") or []
    m = next((m for m in meshes if "geogrid" in m), None)
    if m is None:
        raise ReportError("%s: no generated geogrid among the meshes" % path)
    gi = m["geogrid"]
    lo, hi = m["min"], m["max"]
    trans_x, long_y = [float(v) for v in gi["transverse_x"]], [float(v) for v in gi["longitudinal_y"]]
    w = float(gi["pitch_x"]) - float(gi["aperture_x"])
    c = float(g.get("clamp_length", 0) or 0)
    return {
        "origin": [float(v) for v in lo], "length": hi[0] - lo[0], "width": hi[1] - lo[1],
        "n_l": len(long_y), "n_t": len(trans_x), "w": w, "t": float(g.get("thickness", hi[2] - lo[2])),
        "clamp": c, "gap": float(gi["clamp_gap"]), "a_x": float(gi["aperture_x"]), "a_y": float(gi["aperture_y"]),
        "clamp_end": lo[0] + c, "trans_x": trans_x, "long_y": long_y, "side_overhang": long_y[0] - lo[1],
        "notes": [],
    }


def front_wall_x(case):
    for wdef in case.get("walls") or []:
        if not isinstance(wdef, dict) or wdef.get("type", "plane") != "plane":
            continue
        n = wdef.get("normal") or [0, 0, 0]
        if wdef.get("name") == "front" or (abs(float(n[0])) > 0.99 and float(n[0]) > 0):
            try:
                return float(wdef["point"][0])
            except (KeyError, TypeError, ValueError, IndexError):
                pass
    return 0.0


def clamp_steps(case):
    fem = case.get("fem") or {}
    disp = fem.get("displacements") or []
    step = None
    for d in disp:
        if isinstance(d, dict) and d.get("node_set", "clamp") == "clamp":
            step = float(d["value"][0])
            break
    if step is None and disp:
        step = float(disp[0]["value"][0])
    factors = [float(v) for v in (fem.get("displacement_steps") or [])]
    return step, factors


# ---------------------------------------------------------------------------------------------
# Reading a run
# ---------------------------------------------------------------------------------------------

def step_file(run_dir, prefix, step):
    p = os.path.join(run_dir, "%s_%08d.h5" % (prefix, int(step)))
    return p if os.path.exists(p) else None


def step_files(run_dir, prefix):
    out = []
    for p in glob.glob(os.path.join(run_dir, prefix + "_*.h5")):
        m = re.match(r"%s_(\d+)\.h5$" % prefix, os.path.basename(p))
        if m:
            out.append((int(m.group(1)), p))
    return sorted(out)


def at_step(cols, step):
    """Row index of `step` in a column dict (the last one with that step), None if absent."""
    steps = cols.get("step") or []
    for i in range(len(steps) - 1, -1, -1):
        if int(steps[i]) == int(step):
            return i
    return None


def fe_snapshot(path, lay):
    """Grid quantities of one FE snapshot."""
    with h5py.File(path, "r") as f:
        X = f["nodes/coordinates"][()]
        U = f["nodes/displacement"][()]
        conn = f["elements/connectivity"][()]
        S = f["elements/stress"][()]
        active = f["elements/active"][()] if "elements/active" in f else np.ones(len(conn), int)
    w, ox = lay["w"], lay["origin"][0]
    tol = 1e-6 + 1e-3 * w
    on_long = np.zeros(len(X), bool)
    for y0 in lay["long_y"]:
        on_long |= (X[:, 1] >= y0 - tol) & (X[:, 1] <= y0 + w + tol)
    rib_disp = []
    for x0 in lay["trans_x"]:
        m = (X[:, 0] >= x0 - tol) & (X[:, 0] <= x0 + w + tol)
        rib_disp.append(-1e3 * U[m, 0].mean() if m.any() else NAN)
    clamp = np.abs(X[:, 0] - ox) < tol
    # Displacement along the grid: nodes on the longitudinal ribs, averaged at each x.
    xr = np.round(X[:, 0], 9)
    xs = np.unique(xr[on_long])
    prof = np.array([-1e3 * U[on_long & (xr == x), 0].mean() for x in xs])
    # Tensile force per longitudinal rib: S_xx * (y extent * z extent), summed over the
    # longitudinal-rib (and junction) elements at each x station, / n_l.
    XE = X[conn]  # (m, 8, 3)
    cen = XE.mean(1)
    area = (XE[:, :, 1].max(1) - XE[:, :, 1].min(1)) * (XE[:, :, 2].max(1) - XE[:, :, 2].min(1))
    el_long = np.zeros(len(conn), bool)
    for y0 in lay["long_y"]:
        el_long |= (cen[:, 1] > y0 - tol) & (cen[:, 1] < y0 + w + tol)
    el = el_long & (active != 0) & (cen[:, 0] > lay["clamp_end"])
    cx = np.round(cen[:, 0], 9)
    stations = np.unique(cx[el])
    pxx = np.array([(S[el & (cx == x), 0] * area[el & (cx == x)]).sum() / lay["n_l"] for x in stations])
    return {
        "rib_disp": rib_disp,
        "clamp_disp": -1e3 * U[clamp, 0].mean() if clamp.any() else NAN,
        "prof_x": xs, "prof_u": prof,
        "pxx_x": stations, "pxx": pxx,
        "X": X,
    }


def hold_ends(ic):
    """(hold, row) of the last row of each hold in interface.csv."""
    holds = [int(h) for h in ic["hold"]]
    out = []
    for i, h in enumerate(holds):
        if i + 1 == len(holds) or holds[i + 1] != h:
            out.append((h, i))
    return out


def load_run(run_dir, label):
    for f in ("interface.csv", "reactions.csv", "walls.csv"):
        if not os.path.isfile(os.path.join(run_dir, f)):
            raise ReportError("%s: %s is missing (is this the output directory of a coupled pullout run?)"
                              % (run_dir, f))
    run_json = {}
    rj = os.path.join(run_dir, "run.json")
    if os.path.isfile(rj):
        try:
            with open(rj) as f:
                run_json = json.load(f)
        except ValueError as e:
            warn("%s: unreadable (%s)" % (rj, e))
    # the case as run (--set applied, defaults filled in) and the structures as generated
    case_path, sj = os.path.join(run_dir, "case.yaml"), os.path.join(run_dir, "structures.json")
    for f in (case_path, sj):
        if not os.path.isfile(f):
            raise ReportError("%s is missing (a run of fdem before 2026-12-02? re-run it)" % f)
    try:
        case = load_case(case_path)
    except (OSError, ValueError) as e:
        raise ReportError("%s: cannot read the case (%s)" % (case_path, e))
    if not isinstance(case, dict):
        raise ReportError("%s: not a case file" % case_path)
    try:
        gspec = case["fem"]["meshes"][0]["geogrid"]
    except (KeyError, IndexError, TypeError):
        raise ReportError("%s: fem.meshes[0].geogrid is missing (not a geogrid pullout case)" % case_path)

    ic = read_csv(os.path.join(run_dir, "interface.csv"))
    rc = read_csv(os.path.join(run_dir, "reactions.csv"))
    wc = read_csv(os.path.join(run_dir, "walls.csv"))
    for col in ("step", "hold", "fx", "top_fx", "bottom_fx"):
        if col not in ic:
            raise ReportError("%s/interface.csv: no column '%s' (the case must name coupling surfaces "
                              "'top' and 'bottom')" % (run_dir, col))
    if not ic["step"]:
        raise ReportError("%s/interface.csv has no rows" % run_dir)
    rx = [k for k in rc if k.endswith("_rx")]
    if not rx:
        raise ReportError("%s/reactions.csv: no *_rx column" % run_dir)
    rx = "grid_clamp_rx" if "grid_clamp_rx" in rc else rx[0]
    # the servo plate's stress; a plate in segments (walls top_1 ... top_n, equal areas): their mean
    stress_cols = [k for k in wc if k.endswith("_stress")]
    stress_col = stress_cols[0] if stress_cols else None
    if len(stress_cols) > 1:
        stress_col = "servo_mean_stress"
        wc[stress_col] = [float(np.mean(v)) for v in zip(*(wc[k] for k in stress_cols))]

    # Bearing columns ribK_fx; K from the coupling surfaces' face sets transverse_front_K.
    rib_index = {}
    for s in ((case.get("coupling") or {}).get("surfaces") or []):
        if isinstance(s, dict) and s.get("name"):
            m = re.match(r"transverse_front_(\d+)$", str(s.get("face_set", "")))
            if m:
                rib_index[s["name"]] = int(m.group(1))
    ribs = []
    for k in ic:
        m = re.match(r"(.+)_fx$", k)
        if m and m.group(1) not in ("top", "bottom", "rest"):
            name = m.group(1)
            if name in rib_index:
                ribs.append((rib_index[name], name))
            elif re.match(r"rib(\d+)$", name):
                ribs.append((int(name[3:]), name))
    ribs.sort()
    if not ribs:
        warn("%s: no transverse-rib surfaces (ribK_fx) in interface.csv: F_bt = 0" % run_dir)

    lay = layout_from_structures(sj, gspec)
    for n in lay["notes"]:
        warn("%s: %s" % (run_dir, n))
    if ribs and ribs[-1][0] > lay["n_t"]:
        warn("%s: rib surface %s beyond the case's %d transverse ribs" % (run_dir, ribs[-1][1], lay["n_t"]))
    x_front = front_wall_x(case)
    ustep, factors = clamp_steps(case)
    tol_dem = float((case.get("coupling") or {}).get("tolerance", 0.01) or 0.01)
    tol_fe = float((case.get("fem") or {}).get("tolerance", tol_dem) or tol_dem)

    status = run_json.get("status", "unknown")
    ends = hold_ends(ic)
    if status == "unknown" and ends:
        warn("%s: no run status (run.json): taking the last hold (%d) as complete" % (run_dir, ends[-1][0]))
    elif status != "finished" and ends:
        h, i = ends[-1]
        print("%s: run %s: hold %d (step %d) still running, left out" % (run_dir, status, h, int(ic["step"][i])))
        ends = ends[:-1]
    if not ends:
        raise ReportError("%s: no completed hold yet" % run_dir)

    rows, snaps = [], []
    disp_mismatch = []
    for h, i in ends:
        step = int(ic["step"][i])
        r = {"hold": h, "step": step, "time_s": ic["time"][i] if "time" in ic else NAN}
        fac = factors[h] if h < len(factors) else NAN
        r["displacement_factor"] = fac
        r["clamp_displacement_mm"] = abs(1e3 * ustep * fac) if ustep is not None else NAN
        fe = step_file(run_dir, "fe", step)
        snap = None
        if fe:
            try:
                snap = fe_snapshot(fe, lay)
            except (OSError, KeyError) as e:
                warn("%s: %s" % (fe, e))
        else:
            warn("%s: no fe_%08d.h5 at the end of hold %d: no grid displacements for it" % (run_dir, step, h))
        snaps.append(snap)
        r["clamp_displacement_fe_mm"] = snap["clamp_disp"] if snap else NAN
        if snap and not math.isnan(r["clamp_displacement_fe_mm"]):
            if math.isnan(r["clamp_displacement_mm"]) or abs(r["clamp_displacement_mm"] - snap["clamp_disp"]) > 0.02 * abs(1e3 * (ustep or 0.0025)):
                disp_mismatch.append((h, r["clamp_displacement_mm"], snap["clamp_disp"]))
                r["clamp_displacement_mm"] = snap["clamp_disp"]
        if snap:
            r["front_displacement_mm"] = float(np.interp(x_front, snap["prof_x"], snap["prof_u"]))
        else:
            r["front_displacement_mm"] = NAN
        j = at_step(rc, step)
        r["clamp_force_N"] = -rc[rx][j] if j is not None else NAN
        r["clamp_force_kN_per_m"] = r["clamp_force_N"] / lay["width"] / 1e3
        r["F_total_N"] = ic["fx"][i]
        r["F_top_N"], r["F_bottom_N"] = ic["top_fx"][i], ic["bottom_fx"][i]
        bear = [ic[name + "_fx"][i] for _, name in ribs]
        r["F_bt_N"] = sum(bear)
        r["F_rest_N"] = (ic["rest_fx"][i] if "rest_fx" in ic
                         else r["F_total_N"] - r["F_top_N"] - r["F_bottom_N"] - r["F_bt_N"])
        # friction: every contact that is not bearing on a transverse rib's front face (top and
        # bottom faces, the ribs' sides and back faces: shear along the grid)
        r["F_f_N"] = r["F_top_N"] + r["F_bottom_N"] + r["F_rest_N"]
        cf = r["clamp_force_N"]
        r["ratio_Ff_Fbt_to_clamp"] = (r["F_f_N"] + r["F_bt_N"]) / cf if cf else NAN
        r["ratio_total_to_clamp"] = r["F_total_N"] / cf if cf else NAN
        fp = r["F_f_N"] + r["F_bt_N"]
        r["F_f_share"] = r["F_f_N"] / fp if fp > 0 else NAN
        r["F_bt_share"] = r["F_bt_N"] / fp if fp > 0 else NAN
        r["N_top_N"] = -ic["top_fz"][i] if "top_fz" in ic else NAN
        r["N_bottom_N"] = ic["bottom_fz"][i] if "bottom_fz" in ic else NAN
        nn = r["N_top_N"] + r["N_bottom_N"]
        r["mu_mobilised"] = r["F_f_N"] / nn if nn > 0 else NAN
        jw = at_step(wc, step)
        r["sigma_v_kPa"] = wc[stress_col][jw] / 1e3 if (stress_col and jw is not None) else NAN
        for (k, name), b in zip(ribs, bear):
            r["rib%d_bearing_N" % k] = b
        for k in range(lay["n_t"]):
            r["rib%d_disp_mm" % (k + 1)] = snap["rib_disp"][k] if snap else NAN
        r["interface_contacts"] = int(ic["interface_contacts"][i]) if "interface_contacts" in ic else -1
        r["fe_unbalanced"] = ic["fe_unbalanced"][i] if "fe_unbalanced" in ic else NAN
        r["dem_unbalanced"] = ic["dem_unbalanced"][i] if "dem_unbalanced" in ic else NAN
        r["fe_resultant"] = ic["fe_resultant"][i] if "fe_resultant" in ic else NAN
        # The driver's test: max(FE norm ratio, FE resultant ratio) and the DEM ratio.
        fe_ratio = max(r["fe_unbalanced"], r["fe_resultant"]) if "fe_resultant" in ic else r["fe_unbalanced"]
        r["converged"] = int(fe_ratio <= tol_fe and r["dem_unbalanced"] <= tol_dem)
        rows.append(r)
    if disp_mismatch:
        warn("%s: the case's clamp displacement differs from the clamp nodes' in the FE snapshots "
             "(hold: case -> run mm: %s); using the run's (was the run started with --set, or the case "
             "edited since?)" % (run_dir, ", ".join("%d: %.3g -> %.3g" % m for m in disp_mismatch)))

    # sigma_v over the pulling holds (all rows of holds >= 1).
    sv_hist = []
    if stress_col:
        hold_of = {int(s): int(h) for s, h in zip(ic["step"], ic["hold"])}
        last_step = rows[-1]["step"]
        sv_hist = [v / 1e3 for s, v in zip(wc["step"], wc[stress_col])
                   if hold_of.get(int(s), -1) >= 1 and s <= last_step]
    sv_ends = [r["sigma_v_kPa"] for r in rows if r["hold"] >= 1 and not math.isnan(r["sigma_v_kPa"])]
    sv_label = float(np.median(sv_ends)) if sv_ends else (servo_target(case) or NAN) / 1e3
    if label is None:
        label = "%s, $\\sigma_v$ = %.0f kPa" % (os.path.basename(os.path.normpath(run_dir)), sv_label)
    return {
        "dir": run_dir, "label": label, "case_path": case_path, "case": case, "lay": lay,
        "ribs": ribs, "rows": rows, "snaps": snaps, "x_front": x_front, "ic": ic, "wc": wc,
        "stress_col": stress_col, "sv_hist": sv_hist, "sv_target": servo_target(case),
        "run_json": run_json, "status": status, "ends": ends,
    }


def write_table(run):
    rows = run["rows"]
    cols = ["hold", "step", "time_s", "displacement_factor", "clamp_displacement_mm",
            "clamp_displacement_fe_mm", "front_displacement_mm", "clamp_force_N", "clamp_force_kN_per_m",
            "F_total_N", "F_f_N", "F_top_N", "F_bottom_N", "F_bt_N", "F_rest_N", "ratio_Ff_Fbt_to_clamp",
            "ratio_total_to_clamp", "F_f_share", "F_bt_share", "N_top_N", "N_bottom_N", "mu_mobilised",
            "sigma_v_kPa"]
    cols += ["rib%d_bearing_N" % k for k, _ in run["ribs"]]
    cols += ["rib%d_disp_mm" % (k + 1) for k in range(run["lay"]["n_t"])]
    cols += ["interface_contacts", "fe_unbalanced", "fe_resultant", "dem_unbalanced", "converged"]
    path = os.path.join(run["dir"], "pullout.csv")

    def fmt(v):
        if isinstance(v, (int, np.integer)):
            return str(int(v))
        return "nan" if v is None or math.isnan(v) else "%.9g" % v

    with open(path, "w") as f:
        f.write(",".join(cols) + "\n")
        for r in rows:
            f.write(",".join(fmt(r.get(c, NAN)) for c in cols) + "\n")
    return path


# ---------------------------------------------------------------------------------------------
# Interpolation at a frontal displacement
# ---------------------------------------------------------------------------------------------

def bracket(run, u_mm):
    """(i, j, t) with hold-end rows i, j bracketing clamp displacement u_mm (value = (1-t) row i +
    t row j), None beyond the last hold or without FE snapshots."""
    us = [r["clamp_displacement_mm"] for r in run["rows"]]
    ok = [k for k, s in enumerate(run["snaps"]) if s is not None and not math.isnan(us[k])]
    if not ok or u_mm > max(us[k] for k in ok) + 1e-9 or u_mm < min(us[k] for k in ok) - 1e-9:
        return None
    ok.sort(key=lambda k: us[k])
    for a, b in zip(ok, ok[1:] + [ok[-1]]):
        if us[a] - 1e-9 <= u_mm <= us[b] + 1e-9:
            if abs(u_mm - us[a]) < 1e-9 or b == a:
                return a, a, 0.0
            if abs(u_mm - us[b]) < 1e-9:
                return b, b, 0.0
            return a, b, (u_mm - us[a]) / (us[b] - us[a])
    return None


def interp_field(run, u_mm, xkey, ykey):
    br = bracket(run, u_mm)
    if br is None:
        return None
    a, b, t = br
    sa, sb = run["snaps"][a], run["snaps"][b]
    x = sa[xkey]
    ya = sa[ykey]
    yb = np.interp(x, sb[xkey], sb[ykey])
    return x, (1 - t) * ya + t * yb


def interp_rows(run, u_mm, key):
    us = [r["clamp_displacement_mm"] for r in run["rows"]]
    vs = [r.get(key, NAN) for r in run["rows"]]
    if u_mm > max(us) + 1e-9:
        return NAN
    order = np.argsort(us)
    return float(np.interp(u_mm, np.array(us)[order], np.array(vs)[order]))


# ---------------------------------------------------------------------------------------------
# Figures
# ---------------------------------------------------------------------------------------------

LINESTYLES = ["-", "--", ":", "-."]
MARKERS = ["o", "s", "^", "D", "v"]


def run_style(k):
    return LINESTYLES[k % len(LINESTYLES)], MARKERS[k % len(MARKERS)]


def fig_pullout_force(runs, path):
    fig, ax = plt.subplots(figsize=(7, 5))
    width = runs[0]["lay"]["width"]
    for k, run in enumerate(runs):
        u = [r["clamp_displacement_mm"] for r in run["rows"]]
        f = [r["clamp_force_N"] for r in run["rows"]]
        ft = [r["F_total_N"] for r in run["rows"]]
        line, = ax.plot(u, f, marker="o", label=run["label"] + " (clamp)")
        ax.plot(u, ft, ls=":", marker="x", color=line.get_color(), lw=0.9,
                label=run["label"] + " (interface $\\Sigma F_x$)")
    ax.set_xlabel("frontal (clamp) displacement $U_x$ (mm)")
    ax.set_ylabel("pullout force (N)")
    ax.grid(alpha=0.3)
    ax.set_xlim(left=0)
    sec = ax.secondary_yaxis("right", functions=(lambda y: y / width / 1e3, lambda y: y * width * 1e3))
    sec.set_ylabel("pullout force per width (kN/m, width %.3g m)" % width)
    ax.legend(fontsize=8)
    ax.set_title("Pullout force vs frontal displacement (thesis fig. 4-8)")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def ux_colours(n):
    return plt.cm.viridis(np.linspace(0, 0.9, max(n, 1)))


def fig_profiles(runs, path, xkey, ykey, ylabel, title, extra=None):
    fig, ax = plt.subplots(figsize=(7.5, 5))
    cols = ux_colours(len(UX_TARGETS_MM))
    skipped = []
    plotted = 0
    for k, run in enumerate(runs):
        ls, mk = run_style(k)
        xf = run["x_front"]
        for c, u in zip(cols, UX_TARGETS_MM):
            res = interp_field(run, u, xkey, ykey)
            if res is None:
                skipped.append("%s: %g mm" % (os.path.basename(os.path.normpath(run["dir"])), u))
                continue
            x, y = res
            ax.plot(x - xf, y, ls=ls, marker=mk, ms=3, color=c,
                    label="$U_x$ = %g mm%s" % (u, (", " + run["label"]) if len(runs) > 1 else ""))
            plotted += 1
        if extra:
            extra(ax, run, k)
    lay = runs[0]["lay"]
    ax.axvline(0, color="k", lw=0.8)
    ax.text(0, ax.get_ylim()[1], " front wall", va="top", fontsize=7)
    for x0 in lay["trans_x"]:
        ax.axvspan(x0 - runs[0]["x_front"], x0 + lay["w"] - runs[0]["x_front"], color="0.85", lw=0)
    ax.set_xlabel("x from the front wall (m)  (grey: transverse ribs)")
    ax.set_ylabel(ylabel)
    ax.grid(alpha=0.3)
    if plotted:
        ax.legend(fontsize=7)
    ax.set_title(title)
    if skipped:
        ax.text(0.99, 0.01, "beyond the last hold: " + "; ".join(skipped), transform=ax.transAxes,
                ha="right", va="bottom", fontsize=6, color="0.4")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def fig_resistance_split(runs, path):
    fig, ax = plt.subplots(figsize=(7, 5))
    comps = [("clamp_force_N", "clamp force", "k"), ("F_f_N", "$F_f$ (friction)", "tab:blue"),
             ("F_bt_N", "$F_{bt}$ (bearing)", "tab:red"), (None, "$F_f + F_{bt}$", "tab:green")]
    for k, run in enumerate(runs):
        ls, mk = run_style(k)
        u = [r["clamp_displacement_mm"] for r in run["rows"]]
        for key, name, c in comps:
            v = [r[key] if key else r["F_f_N"] + r["F_bt_N"] for r in run["rows"]]
            ax.plot(u, v, ls=ls, marker=mk, ms=4, color=c,
                    label=name + ((", " + run["label"]) if len(runs) > 1 else ""))
    ax.set_xlabel("frontal (clamp) displacement $U_x$ (mm)")
    ax.set_ylabel("force (N)")
    ax.set_xlim(left=0)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)
    ax.set_title("Pullout resistance: friction and bearing (thesis fig. 4-13)"
                 + ("" if len(runs) > 1 else "\n" + runs[0]["label"]), fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def fig_bearing(runs, path):
    fig, ax = plt.subplots(figsize=(7, 5))
    cols = ux_colours(len(UX_TARGETS_MM))
    notes = []
    plotted = 0
    for k, run in enumerate(runs):
        ls, mk = run_style(k)
        if not run["ribs"]:
            notes.append("%s: no rib surfaces" % run["dir"])
            continue
        xr = np.array([run["lay"]["trans_x"][kk - 1] - run["x_front"] for kk, _ in run["ribs"]])
        for c, u in zip(cols, UX_TARGETS_MM):
            b = np.array([interp_rows(run, u, "rib%d_bearing_N" % kk) for kk, _ in run["ribs"]])
            if np.any(np.isnan(b)):
                notes.append("%s: %g mm beyond the last hold" % (os.path.basename(os.path.normpath(run["dir"])), u))
                continue
            tot = b.sum()
            if tot <= 1e-9:
                notes.append("%g mm: no bearing" % u)
                continue
            ax.plot(xr, 100 * np.cumsum(b) / tot, ls=ls, marker=mk, color=c,
                    label="$U_x$ = %g mm (F$_{bt}$ %.0f N)%s" % (u, tot, (", " + run["label"]) if len(runs) > 1 else ""))
            plotted += 1
    ax.set_xlabel("distance of the transverse rib from the front wall (m)")
    ax.set_ylabel("accumulated share of the bearing force (%)")
    ax.set_ylim(0, 105)
    ax.grid(alpha=0.3)
    if plotted:
        ax.legend(fontsize=7, loc="lower right")
    if notes:
        ax.text(0.01, 0.01, "\n".join(notes), transform=ax.transAxes, ha="left", va="bottom", fontsize=6,
                color="0.4")
    ax.set_title("Accumulated bearing resistance per transverse rib (thesis fig. 4-14)", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def measure_for_holds(run):
    """Per completed hold, (measure file, its step, exact) : the file at the hold end, else the
    latest one inside the hold."""
    files = step_files(run["dir"], "measure")
    out = []
    prev_end = -1
    for r in run["rows"]:
        exact = [p for s, p in files if s == r["step"]]
        if exact:
            out.append((exact[0], r["step"], True))
        else:
            inside = [(s, p) for s, p in files if prev_end < s <= r["step"]]
            out.append((inside[-1][1], inside[-1][0], False) if inside else None)
        prev_end = r["step"]
    return out


def grid_cells(path):
    with h5py.File(path, "r") as f:
        if "grid" not in f or "stress" not in f["grid"]:
            return None
        g = f["grid"]
        a = {k: g.attrs[k] for k in g.attrs}
        S = g["stress"][()]
    nx, ny, nz = int(a["nx"]), int(a["ny"]), int(a["nz"])
    S = S.reshape(nz, ny, nx, 6)  # x fastest
    x = a["origin_x"] + (np.arange(nx) + 0.5) * a["spacing_x"]
    zlo, zhi = a["origin_z"], a["origin_z"] + nz * a["spacing_z"]
    return x, S[..., 2].mean(axis=(0, 1)), S[..., 0].mean(axis=(0, 1)), (zlo, zhi)


def fig_soil_stress(runs, path):
    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(7.5, 7), sharex=True)
    any_plotted = False
    band = None
    for k, run in enumerate(runs):
        ls, mk = run_style(k)
        ms = measure_for_holds(run)
        cols = plt.cm.plasma(np.linspace(0, 0.85, max(len(ms), 1)))
        for c, r, m in zip(cols, run["rows"], ms):
            if m is None:
                continue
            cells = grid_cells(m[0])
            if cells is None:
                continue
            x, szz, sxx, band = cells
            lab = "hold %d, $U_x$ %.1f mm%s%s" % (r["hold"], r["clamp_displacement_mm"],
                                                  "" if m[2] else " (step %d)" % m[1],
                                                  (", " + run["label"]) if len(runs) > 1 else "")
            ax1.plot(x - run["x_front"], szz / 1e3, ls=ls, marker=mk, ms=3, color=c, label=lab)
            ax2.plot(x - run["x_front"], sxx / 1e3, ls=ls, marker=mk, ms=3, color=c, label=lab)
            any_plotted = True
    if not any_plotted:
        plt.close(fig)
        return False
    zg = runs[0]["lay"]["origin"][2] + runs[0]["lay"]["t"] / 2
    ax1.set_ylabel("vertical stress $\\sigma_{zz}$ (kPa)")
    ax2.set_ylabel("horizontal stress $\\sigma_{xx}$ (kPa)")
    ax2.set_xlabel("x from the front wall (m)")
    for ax in (ax1, ax2):
        ax.grid(alpha=0.3)
    h, l = ax1.get_legend_handles_labels()
    ncol = 2 if len(l) > 6 else 1
    rows_in = (0.4 + 0.16 * math.ceil(len(l) / ncol))  # legend height, inches
    fig.set_size_inches(7.5, 7 + rows_in)
    fig.legend(h, l, fontsize=6.5, ncol=ncol, loc="lower center")
    ax1.set_title("Soil stress in the measurement cells, z %.0f-%.0f mm above the grid (figs 4-17, 4-18)\n"
                  "Love-Weber, compression positive; (step N): latest measurement inside the hold"
                  % (1e3 * (band[0] - zg), 1e3 * (band[1] - zg)), fontsize=9)
    fig.tight_layout(rect=(0, rows_in / (7 + rows_in), 1, 1))
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return True


def particle_state(path):
    """(ids, positions, displacement or None) from a measure_ or particles_ file."""
    with h5py.File(path, "r") as f:
        if "particles" in f and isinstance(f["particles"], h5py.Group) and "position" in f["particles"]:
            g = f["particles"]
        elif "position" in f and "id" in f:
            g = f
        else:
            return None
        ids = g["id"][()]
        pos = g["position"][()]
        disp = g["displacement"][()] if "displacement" in g else None
        rad = g["radius"][()] if "radius" in g else None
    return ids, pos, disp, rad


def fig_soil_displacement(runs, path, from_hold):
    panels = []
    for run in runs:
        last = run["rows"][-1]
        cur = step_file(run["dir"], "measure", last["step"])
        src = "measure"
        if cur is None:
            cur = step_file(run["dir"], "particles", last["step"])
            src = "particles"
        st = particle_state(cur) if cur else None
        if st is None:
            continue
        ids, pos, disp, rad = st
        ref_note = "from the run's displacement reference"
        h0 = next((r for r in run["rows"] if r["hold"] == from_hold), None)
        ref = None
        if h0 is not None and h0 is not last:
            rp = step_file(run["dir"], "particles", h0["step"]) or step_file(run["dir"], "measure", h0["step"])
            ref = particle_state(rp) if rp else None
        if ref is not None:
            idx = {int(i): n for n, i in enumerate(ref[0])}
            keep = np.array([int(i) in idx for i in ids])
            ids, pos = ids[keep], pos[keep]
            rad = rad[keep] if rad is not None else None
            rows_ref = [idx[int(i)] for i in ids]
            disp = pos - ref[1][rows_ref]
            if rad is None and ref[3] is not None:
                rad = ref[3][rows_ref]
            ref_note = "since the end of hold %d (step %d, $U_x$ %.1f mm)" % (h0["hold"], h0["step"],
                                                                                h0["clamp_displacement_mm"])
        elif disp is None:
            continue
        else:
            print("note: %s: no particle snapshot at the end of hold %d; soil_displacement.png shows the "
                  "displacement from the measurement's reference" % (run["dir"], from_hold))
        panels.append((run, last, pos, disp, rad, ref_note, src))
    if not panels:
        return False
    fig, axes = plt.subplots(len(panels), 1, figsize=(9, 1.5 + 5.0 * len(panels)), squeeze=False)
    for ax, (run, last, pos, disp, rad, ref_note, src) in zip(axes[:, 0], panels):
        lay = run["lay"]
        ymid = lay["origin"][1] + lay["width"] / 2
        r = rad if rad is not None else np.full(len(pos), 0.005)
        dmean = 2 * float(np.mean(r))
        half = max(1.5 * dmean, 0.1 * lay["width"])
        sel = np.abs(pos[:, 1] - ymid) <= half
        p, u, rr = pos[sel], 1e3 * disp[sel], r[sel]
        mag = np.hypot(u[:, 0], u[:, 2])
        xs = p[:, 0] - run["x_front"]
        circles = matplotlib.collections.EllipseCollection(
            2 * rr, 2 * rr, np.zeros(len(rr)), units="xy", offsets=np.c_[xs, p[:, 2]],
            offset_transform=ax.transData, cmap="viridis", alpha=0.8, edgecolor="none")
        circles.set_array(mag)
        vmax = max(float(np.percentile(mag, 98)) if len(mag) else 1.0, 1e-6)
        circles.set_clim(0, vmax)
        ax.add_collection(circles)
        # Arrows: the 98th-percentile displacement drawn one mean grain diameter long.
        ax.quiver(xs, p[:, 2], u[:, 0], u[:, 2], angles="xy", scale_units="xy", scale=vmax / dmean,
                  width=0.0025, color="k")
        cb = fig.colorbar(circles, ax=ax, fraction=0.03)
        cb.set_label("|u| in the x-z plane (mm; colour capped at the 98th percentile)")
        zg = lay["origin"][2] + lay["t"] / 2
        ax.plot([lay["origin"][0] - run["x_front"], lay["origin"][0] + lay["length"] - run["x_front"]], [zg, zg],
                color="r", lw=2, label="geogrid (reference position)")
        for x0 in lay["trans_x"]:
            ax.plot([x0 - run["x_front"]] * 2, [zg - 0.002, zg + 0.002], color="r", lw=2)
        ax.axvline(0, color="k", lw=0.8)
        ax.set_xlim(min(lay["origin"][0] - run["x_front"], xs.min()) - 0.005, xs.max() + dmean)
        ax.set_ylim(p[:, 2].min() - dmean, p[:, 2].max() + dmean)
        ax.set_aspect("equal")
        ax.set_xlabel("x from the front wall (m)")
        ax.set_ylabel("z (m)")
        ax.legend(fontsize=7, loc="upper right")
        ax.set_title("%s: particle displacement at hold %d ($U_x$ %.1f mm) %s\n%d particles with |y - %.3f| < %.3f m "
                     "(%s file); an arrow one mean grain diameter long = %.1f mm"
                     % (run["label"], last["hold"], last["clamp_displacement_mm"], ref_note, int(sel.sum()),
                        ymid, half, src, vmax), fontsize=8)
    fig.suptitle("Soil displacement field around the grid (thesis fig. 4-15)", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return True


def rib_force_extra(ax, run, k):
    # The clamp force shared by the longitudinal ribs, at the clamp's end, per hold <= 25 mm.
    n_l = run["lay"]["n_l"]
    for u in UX_TARGETS_MM:
        v = interp_rows(run, u, "clamp_force_N")
        if not math.isnan(v):
            ax.plot(run["lay"]["clamp_end"] - run["x_front"], v / n_l, marker="*", color="k", ms=7, ls="none")


# ---------------------------------------------------------------------------------------------
# Summary
# ---------------------------------------------------------------------------------------------

def summarize(run):
    lay, rows = run["lay"], run["rows"]
    print("\n== %s  (%s; case %s; status %s)" % (run["dir"], run["label"].replace("$\\sigma_v$", "sigma_v"),
                                                  os.path.relpath(run["case_path"]), run["status"]))
    print("grid: %d longitudinal x %d transverse ribs, width %.3g m; rib fronts at x - x_front = %s m"
          % (lay["n_l"], lay["n_t"], lay["width"], ", ".join("%.3f" % (x - run["x_front"]) for x in lay["trans_x"])))
    nb = len(run["ribs"])
    print("hold  Ux(mm)  clamp(N)  kN/m   F_f(N)  F_bt(N) (F_f+F_bt)/clamp  F_f%   rib1%  rib2%  mu_mob  sv(kPa)  conv")
    for r in rows:
        fb = r["F_bt_N"]
        rb = [r.get("rib%d_bearing_N" % k, NAN) / fb * 100 if fb > 1e-9 else NAN for k, _ in run["ribs"][:2]]
        rb += [NAN] * (2 - len(rb))
        print("%4d  %6.2f  %8.1f  %5.2f  %7.1f  %7.1f  %14.3f  %5.1f  %5.1f  %5.1f  %6.2f  %7.1f  %s"
              % (r["hold"], r["clamp_displacement_mm"], r["clamp_force_N"], r["clamp_force_kN_per_m"], r["F_f_N"],
                 fb, r["ratio_Ff_Fbt_to_clamp"], 100 * r["F_f_share"], rb[0], rb[1], r["mu_mobilised"],
                 r["sigma_v_kPa"], "yes" if r["converged"] else "NO"))
    last = rows[-1]
    if nb and last["F_bt_N"] > 0:
        print("bearing per rib at the last hold (%% of F_bt): %s" % ", ".join(
            "rib%d %.1f" % (k, 100 * last["rib%d_bearing_N" % k] / last["F_bt_N"]) for k, _ in run["ribs"]))
    snap = run["snaps"][-1]
    if snap is not None and len(snap["pxx_x"]):
        drops = []
        for k in range(lay["n_t"]):
            x0, x1 = lay["trans_x"][k], lay["trans_x"][k] + lay["w"]
            before = [p for x, p in zip(snap["pxx_x"], snap["pxx"]) if x < x0]
            after = [p for x, p in zip(snap["pxx_x"], snap["pxx"]) if x > x1]
            if before:
                drops.append((k + 1, lay["n_l"] * (before[-1] - (after[0] if after else 0.0))))
        if drops:
            print("tension drop across each transverse rib at the last hold (N, all longitudinal ribs; "
                  "= what the rib and its junctions take from the soil): %s"
                  % ", ".join("rib%d %.0f" % d for d in drops))
    print("rib displacement at the last hold (mm): %s" % ", ".join(
        "rib%d %.2f" % (k + 1, last["rib%d_disp_mm" % (k + 1)]) for k in range(lay["n_t"])))
    if run["sv_hist"]:
        sv = np.array(run["sv_hist"])
        ends = [r["sigma_v_kPa"] for r in rows if r["hold"] >= 1]
        print("sigma_v (top plate) over holds >= 1: mean %.1f kPa, range %.1f .. %.1f; at hold ends %.1f .. %.1f kPa%s"
              % (sv.mean(), sv.min(), sv.max(), min(ends) if ends else NAN, max(ends) if ends else NAN,
                 "" if run["sv_target"] is None else " (case target %.1f kPa)" % (run["sv_target"] / 1e3)))
    checks(run)


def checks(run):
    """Warnings about the physics / convergence of a run."""
    rows = run["rows"]
    tgt = run["sv_target"]
    pull = [r for r in rows if r["hold"] >= 1]
    ref_sv = float(np.median([r["sigma_v_kPa"] for r in pull])) if pull else (tgt / 1e3 if tgt else NAN)
    for r in rows:
        sv = r["sigma_v_kPa"]
        if not math.isnan(ref_sv) and ref_sv > 0 and (math.isnan(sv) or abs(sv - ref_sv) > 0.05 * ref_sv):
            print("  CHECK hold %d: sigma_v at its end %.1f kPa, not within 5 %% of %.1f kPa%s" % (
                r["hold"], sv, ref_sv,
                " (the consolidation hold ended before the servo plate loaded the soil)" if r["hold"] == 0 else ""))
        if not r["converged"]:
            print("  CHECK hold %d: not converged (FE %.3g%s, DEM %.3g)"
                  % (r["hold"], r["fe_unbalanced"], "" if math.isnan(r["fe_resultant"]) else
                     ", FE resultant %.3g" % r["fe_resultant"], r["dem_unbalanced"]))
        rt = r["ratio_Ff_Fbt_to_clamp"]
        if r["hold"] >= 1 and not math.isnan(rt) and abs(rt - 1) > 0.02:
            print("  CHECK hold %d: (F_f + F_bt)/clamp = %.3f (off by more than 2 %%)" % (r["hold"], rt))
    # sigma_v during the pulling stages: where was the plate while the clamp moved?
    ic, wc, col = run["ic"], run["wc"], run["stress_col"]
    if col and tgt:
        first_pull = next((i for i, h in enumerate(ic["hold"]) if h >= 1), None)
        if first_pull is not None:
            reach = next((s for s, v in zip(wc["step"], wc[col]) if v >= 0.95 * tgt), None)
            if reach is None or reach > ic["step"][first_pull]:
                print("  CHECK sigma_v reached 95 %% of the case's %.0f kPa only at step %s, after the pull began "
                      "(step %d): the first pull step ran under a lower vertical stress"
                      % (tgt / 1e3, "never" if reach is None else "%d" % reach, ic["step"][first_pull]))
    # grid displacement decaying from front to back
    last = rows[-1]
    d = [last["rib%d_disp_mm" % (k + 1)] for k in range(run["lay"]["n_t"])]
    if all(not math.isnan(v) for v in d) and any(d[k + 1] > d[k] + 1e-3 for k in range(len(d) - 1)):
        print("  CHECK last hold: rib displacement does not decay from front to back: %s" % d)
    # ribs that move but carry no bearing
    if run["ribs"] and last["F_bt_N"] > 0:
        idle = [k for k, _ in run["ribs"] if abs(last["rib%d_bearing_N" % k]) < 1e-9
                and last.get("rib%d_disp_mm" % k, 0) > 0.1]
        if idle:
            print("  CHECK last hold: ribs %s moved > 0.1 mm but carry exactly zero bearing (no contact on their "
                  "0.9 mm front faces?)" % ", ".join(str(k) for k in idle))
    pf = [r["clamp_force_N"] for r in pull]
    if any(b < a for a, b in zip(pf, pf[1:])):
        print("  CHECK the pullout force does not grow monotonically: %s" % ", ".join("%.0f" % v for v in pf))


# ---------------------------------------------------------------------------------------------

def main(argv):
    ap = argparse.ArgumentParser(prog="pullout_report.py", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("runs", nargs="+", metavar="OUT_DIR", help="output directory of a pullout run")
    ap.add_argument("--figures", help="figure directory (default: FIRST_OUT_DIR/figures)")
    ap.add_argument("--displacement-from", type=int, default=0, metavar="HOLD",
                    help="soil_displacement.png: displacement since the end of this hold (default 0)")
    ap.add_argument("--label", action="append", help="legend label per run (default: dir name and sigma_v)")
    a = ap.parse_args(argv[1:])
    if a.label and len(a.label) != len(a.runs):
        print("%s: give one --label per OUT_DIR (%d for %d)" % (PROG, len(a.label), len(a.runs)), file=sys.stderr)
        return 2
    runs = []
    try:
        for n, d in enumerate(a.runs):
            if not os.path.isdir(d):
                raise ReportError("%s: not a directory" % d)
            runs.append(load_run(d, a.label[n] if a.label else None))
    except ReportError as e:
        print("%s: %s" % (PROG, e), file=sys.stderr)
        return 2
    except (OSError, KeyError, ValueError) as e:
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
        summarize(run)

    if len(runs) > 1:
        print("\n== clamp force relative to %s, per hold (same clamp displacement)" % runs[0]["dir"])
        base = {r["hold"]: r for r in runs[0]["rows"]}
        for run in runs[1:]:
            parts = []
            for r in run["rows"]:
                b = base.get(r["hold"])
                if b and r["hold"] >= 1 and b["clamp_force_N"] and abs(b["clamp_displacement_mm"] - r["clamp_displacement_mm"]) < 1e-6:
                    parts.append("hold %d %+.1f %%" % (r["hold"], 100 * (r["clamp_force_N"] / b["clamp_force_N"] - 1)))
            print("%s: %s" % (run["dir"], ", ".join(parts) or "no common holds"))

    def fp(name):
        return os.path.join(figdir, name)

    fig_pullout_force(runs, fp("pullout_force.png"))
    written.append(fp("pullout_force.png"))
    if any(s is not None for r in runs for s in r["snaps"]):
        fig_profiles(runs, fp("grid_displacement.png"), "prof_x", "prof_u", "grid displacement $-u_x$ (mm)",
                     "Displacement along the longitudinal ribs (thesis fig. 4-9)")
        fig_profiles(runs, fp("rib_force.png"), "pxx_x", "pxx", "tensile force per longitudinal rib $P_{xx}$ (N)",
                     "Average tensile force along the longitudinal ribs (thesis fig. 4-12)\n"
                     "(*: clamp force / number of ribs)", extra=rib_force_extra)
        written += [fp("grid_displacement.png"), fp("rib_force.png")]
    else:
        print("note: no fe_<step>.h5 at the hold ends: grid_displacement.png and rib_force.png skipped")
    fig_resistance_split(runs, fp("resistance_split.png"))
    fig_bearing(runs, fp("bearing_per_rib.png"))
    written += [fp("resistance_split.png"), fp("bearing_per_rib.png")]
    if fig_soil_stress(runs, fp("soil_stress.png")):
        written.append(fp("soil_stress.png"))
    else:
        print("note: no measure_<step>.h5 with a measurement grid: soil_stress.png skipped")
    if fig_soil_displacement(runs, fp("soil_displacement.png"), a.displacement_from):
        written.append(fp("soil_displacement.png"))
    else:
        print("note: no particle positions at the last hold (measure_/particles_<step>.h5): "
              "soil_displacement.png skipped")
    print("\nwrote:")
    for w in written:
        print("  " + w)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
