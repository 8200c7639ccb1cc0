#!/usr/bin/python3
"""The buried pipe (thesis Tran 2013, appendix A, problem 8; docs/cases/pipe.md): equilibrium, the
pipe's diameter changes against the modified Iowa formula, the earth pressure on the pipe against
the angle, the deformed shape and the FE soil's plastic zone, at every hold's end of a run of
cases/pipe/*.yaml (scripts/pipe_case.py).

    /usr/bin/python3 scripts/pipe_report.py DIR [--figures FIGDIR] [--csv FILE] [--check]

Reads from DIR: case.yaml (the pipe's `cylinder`, the materials, the box), holds.csv (the hold
ends and the plate's stress), interface.csv, structures.json (the meshes' node ranges),
fe_<step>.h5 and particles_<step>.h5 at every hold's end.
Printed per hold (--csv: one row per hold):
 1 equilibrium: the plate's force + the grains' weight sum(m g) against -fz of the interface
   (soil + pipe; the side walls are frictionless), and the pipe's share of it.
 2 the diameter changes dD_v = u_z(crown) - u_z(invert), dD_h = u_x(right springline) -
   u_x(left), mean over the pipe's rings (mm; from the start of the run: the packing's weight
   included), and the vertical stress at the crown sigma_v = plate stress + the grains' weight
   over the box's area.
 3 the modified Iowa formula (Spangler 1941; Watkins & Spangler 1958), a sanity band, not a target:
   dX = D_L K W_c r^3 / (E I + 0.061 E' r^3), D_L = 1, K = 0.1, W_c = sigma_v D (the prism load,
   N/m), E I = E t^3 / 12 per unit length, r the mid-surface radius, E' the modulus of soil reaction
   taken between M_s / 2 and 3 M_s / 2, M_s the fill's constrained modulus measured in the run
   (the plate's settlement between the first and the last hold over the fill's height).
 4 the earth pressure on the pipe against the angle theta from the crown (clockwise seen along
   +y, so 90 deg is the springline at +x): p = -(F . e_r) / (R dtheta W) from
   nodes/interface_force summed over the rings (the grains act on the upper half only; the lower
   half is tied to the FE soil).
 5 the FE soil's plastic zone: the soil elements with a yielded Gauss point (elements/plastic).
Figures (--figures): pipe_diameter.png (dD against sigma_v with the Iowa band), pipe_pressure.png
(p against theta per hold), pipe_shape.png (the deformed mid ring, magnified), pipe_plastic.png
(the soil elements' centres in x-z, yielded ones filled).
--check: every hold converged; plate + weight within 2 % of -fz; dD_v < 0 < dD_h growing with the
stress. Exit 1 when one fails. Needs Debian's python3-numpy, -h5py, -matplotlib, -yaml. Exit 2 on
bad input.
"""
import argparse
import json
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from fdem_common import load_case, read_csv, system_python_fallback  # noqa: E402

system_python_fallback(["numpy", "h5py", "matplotlib", "yaml"])
import numpy as np  # noqa: E402
import h5py  # noqa: E402

G = 9.81


def die(msg):
    print("pipe_report.py: " + msg, file=sys.stderr)
    sys.exit(2)


def model(run):
    """The pipe's and the box's numbers from the run's case.yaml."""
    try:
        case = load_case(os.path.join(run, "case.yaml"))
        fem = case["fem"]
        pipe = next(m for m in fem["meshes"] if "cylinder" in m)
        cyl = pipe["cylinder"]
        mat = next(m for m in fem["materials"] if m["name"] == pipe["material"])
        box = case["packing"]["box"]
        grains = {m["name"]: m for m in case["materials"]}
        sand = grains[case["packing"]["material"]]
    except (OSError, ValueError, KeyError, StopIteration, TypeError) as e:
        die("%s/case.yaml: not a buried-pipe case (%s)" % (run, e))
    if cyl.get("axis", "z") != "y":
        die("%s/case.yaml: the pipe's axis must be y" % run)
    area = (box["max"][0] - box["min"][0]) * (box["max"][1] - box["min"][1])
    return dict(name=pipe["name"], base=np.array(cyl["base"], float), R=float(cyl["radius"]),
                W=float(cyl["length"]), n_around=int(cyl["divisions"][0]), E=float(mat["young"]),
                t=float(mat["thickness"]), area=area, density=float(sand["density"]),
                fill_height=box["max"][2] - box["min"][2])


def node_rows(run, name):
    try:
        with open(os.path.join(run, "structures.json")) as f:
            meshes = json.load(f)["meshes"]
        m = next(m for m in meshes if m["name"] == name)
    except (OSError, ValueError, KeyError, StopIteration) as e:
        die("%s/structures.json: no mesh '%s' (%s)" % (run, name, e))
    return m["node_offset"], m["node_offset"] + m["nodes"]


def pipe_rings(X, m):
    """Angle index (0 = crown, clockwise seen along +y) of every pipe node."""
    dx, dz = X[:, 0] - m["base"][0], X[:, 2] - m["base"][2]
    r = np.hypot(dx, dz)
    if np.max(np.abs(r - m["R"])) > 1e-6 * m["R"]:
        die("the pipe's nodes are not on its cylinder (radius %g)" % m["R"])
    theta = np.mod(np.arctan2(dx, dz), 2 * math.pi)
    k = np.rint(theta / (2 * math.pi / m["n_around"])).astype(int) % m["n_around"]
    return k, theta


def hold_state(run, step, m, rows):
    path = os.path.join(run, "fe_%08d.h5" % step)
    try:
        with h5py.File(path, "r") as f:
            X = f["nodes/coordinates"][:]
            U = f["nodes/displacement"][:]
            F = f["nodes/interface_force"][:] if "nodes/interface_force" in f else None
            plastic = f["elements/plastic"][:]
            mat = f["elements/material"][:]
            conn = f["elements/connectivity"][:]
    except (OSError, KeyError) as e:
        die("%s: %s" % (path, e))
    if F is None:
        die("%s: no nodes/interface_force (a run of fdem before December 2026)" % path)
    a, b = rows
    Xp, Up, Fp = X[a:b], U[a:b], F[a:b]
    k, theta = pipe_rings(Xp, m)
    n = m["n_around"]
    uz = np.array([Up[k == i, 2].mean() for i in range(n)])
    ux = np.array([Up[k == i, 0].mean() for i in range(n)])
    crown, right, invert, left = 0, n // 4, n // 2, 3 * n // 4
    dDv = uz[crown] - uz[invert]
    dDh = ux[right] - ux[left]
    # earth pressure: the radial component of the interface force per angle, summed over the rings
    th = 2 * math.pi * np.arange(n) / n
    er = np.stack([np.sin(th), np.zeros(n), np.cos(th)], axis=1)
    Fr = np.array([(Fp[k == i] @ er[i]).sum() for i in range(n)])
    p = -Fr / (m["R"] * 2 * math.pi / n * m["W"])
    # the mid ring's deformed shape
    y = Xp[:, 1]
    ymid = y[np.argmin(np.abs(y - m["base"][1] - m["W"] / 2))]
    ring = np.abs(y - ymid) < 1e-9
    order = np.argsort(theta[ring])
    shape = (Xp[ring][order], Up[ring][order])
    # the soil's elements (hexahedra) and their centres
    cents, yielded = soil_elements(X, conn, mat, plastic, rows)
    return dict(dDv=dDv, dDh=dDh, p=p, theta=th, shape=shape, cents=cents, yielded=yielded,
                pipe_fz=Fp[:, 2].sum())


def soil_elements(X, conn, mat, plastic, pipe_rows):
    """Centres and yielded flags of the solid elements (XDMF mixed topology: type code, nodes)."""
    cents, yielded = [], []
    if conn.ndim == 2:
        for e, c in enumerate(conn):
            cents.append(X[c].mean(axis=0)); yielded.append(plastic[e] > 0)
        return np.array(cents), np.array(yielded)
    sizes = {48: 20, 9: 8, 5: 4}  # Hexahedron_20, Hexahedron, Quadrilateral
    i, e = 0, 0
    while i < len(conn):
        code = int(conn[i])
        if code not in sizes:
            die("unexpected XDMF element code %d" % code)
        nn = sizes[code]
        c = conn[i + 1:i + 1 + nn]
        if code != 5 and not (pipe_rows[0] <= c[0] < pipe_rows[1]):
            cents.append(X[c[:8]].mean(axis=0)); yielded.append(plastic[e] > 0)
        i += 1 + nn
        e += 1
    return np.array(cents), np.array(yielded)


def grain_weight(run, step, density):
    path = os.path.join(run, "particles_%08d.h5" % step)
    try:
        with h5py.File(path, "r") as f:
            r = f["radius"][:]
    except (OSError, KeyError) as e:
        die("%s: %s" % (path, e))
    return float((4.0 / 3.0 * math.pi * r ** 3).sum() * density * G)


def iowa(sigma_v, m, E_prime):
    r = m["R"]
    EI = m["E"] * m["t"] ** 3 / 12
    return 1.0 * 0.1 * sigma_v * 2 * r * r ** 3 / (EI + 0.061 * E_prime * r ** 3)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("run")
    ap.add_argument("--figures")
    ap.add_argument("--csv")
    ap.add_argument("--check", action="store_true")
    a = ap.parse_args()
    run = a.run
    m = model(run)
    rows = node_rows(run, m["name"])
    try:
        holds = read_csv(os.path.join(run, "holds.csv"))
        iface = read_csv(os.path.join(run, "interface.csv"))
    except (OSError, StopIteration) as e:
        die("%s: %s" % (run, e))
    stress_col = next((h for h in holds if h.endswith("_stress")), None)
    settle_col = next((h for h in holds if h.endswith("_settlement")), None)
    if not holds.get("step") or stress_col is None:
        die("%s/holds.csv: no finished hold with a servo wall" % run)
    istep = {int(s): i for i, s in enumerate(iface["step"])}
    out, fails = [], []
    for h in range(len(holds["step"])):
        step = int(holds["step"][h])
        if step not in istep:
            die("%s/interface.csv: no row at step %d" % (run, step))
        j = istep[step]
        s = hold_state(run, step, m, rows)
        w = grain_weight(run, step, m["density"])
        plate = holds[stress_col][h] * m["area"]
        fz = -iface["fz"][j]
        sigma_v = holds[stress_col][h] + w / m["area"]
        row = dict(hold=h + 1, step=step, converged=int(holds["converged"][h]), target=holds[stress_col.replace(
            "_stress", "_target")][h], plate_stress=holds[stress_col][h], sigma_v=sigma_v, plate_force=plate,
            weight=w, interface_fz=fz, balance=(plate + w) / fz - 1, pipe_share=-s["pipe_fz"] / fz,
            dDv_mm=1e3 * s["dDv"], dDh_mm=1e3 * s["dDh"], settlement_mm=1e3 * holds[settle_col][h] if settle_col else 0,
            yielded=int(s["yielded"].sum()), soil_elements=len(s["yielded"]),
            p_crown_kPa=s["p"][0] / 1e3, p_springline_kPa=0.5 * (s["p"][len(s["p"]) // 4] + s["p"][3 * len(s["p"]) // 4]) / 1e3)
        row["_state"] = s
        out.append(row)
    # the fill's constrained modulus from the plate's settlement between the first and last hold
    Ms = float("nan")
    if len(out) > 1 and settle_col:
        ds = (out[-1]["settlement_mm"] - out[0]["settlement_mm"]) / 1e3
        if ds > 0:
            Ms = (out[-1]["plate_stress"] - out[0]["plate_stress"]) * m["fill_height"] / ds
    print("pipe_report: %s  D %.3f m, t %.1f mm, E %.3g MPa; fill's constrained modulus M_s %.3g MPa "
          "(plate settlement between the holds)" % (run, 2 * m["R"], 1e3 * m["t"], m["E"] / 1e6, Ms / 1e6))
    print("  hold  plate(kPa)  sigma_v(kPa)  (plate+W)/-fz-1  pipe share  dD_v(mm)  dD_h(mm)  "
          "Iowa dX(mm) [E'=1.5Ms .. 0.5Ms]  p crown/springline (kPa)  yielded soil elements")
    for r in out:
        lo, hi = iowa(r["sigma_v"], m, 1.5 * Ms), iowa(r["sigma_v"], m, 0.5 * Ms)
        r["iowa_lo_mm"], r["iowa_hi_mm"] = 1e3 * lo, 1e3 * hi
        print("  %4d  %9.1f  %12.1f  %+14.4f  %10.3f  %8.3f  %8.3f  %7.3f .. %7.3f  %9.1f / %6.1f  %d/%d%s" % (
            r["hold"], r["plate_stress"] / 1e3, r["sigma_v"] / 1e3, r["balance"], r["pipe_share"], r["dDv_mm"],
            r["dDh_mm"], r["iowa_lo_mm"], r["iowa_hi_mm"], r["p_crown_kPa"], r["p_springline_kPa"], r["yielded"],
            r["soil_elements"], "" if r["converged"] else "  (not converged)"))
    if a.csv:
        keys = [k for k in out[0] if not k.startswith("_")]
        os.makedirs(os.path.dirname(os.path.abspath(a.csv)), exist_ok=True)
        with open(a.csv, "w") as f:
            f.write(",".join(keys) + "\n")
            for r in out:
                f.write(",".join("%.10g" % r[k] for k in keys) + "\n")
    if a.figures:
        figures(a.figures, out, m, Ms)
    if a.check:
        prev = None
        for r in out:
            if not r["converged"]:
                fails.append("hold %d did not converge" % r["hold"])
            if abs(r["balance"]) > 0.02:
                fails.append("hold %d: plate + weight differs from -fz by %.2f %%" % (r["hold"], 100 * r["balance"]))
            if not (r["dDv_mm"] < 0 < r["dDh_mm"]):
                fails.append("hold %d: dD_v %.3f mm, dD_h %.3f mm: not an oval" % (r["hold"], r["dDv_mm"], r["dDh_mm"]))
            if prev and not (r["dDv_mm"] < prev["dDv_mm"] and r["dDh_mm"] > prev["dDh_mm"]):
                fails.append("hold %d: the diameter changes do not grow with the stress" % r["hold"])
            prev = r
        for f in fails:
            print("pipe_report: check failed: " + f)
        if fails:
            sys.exit(1)
        print("pipe_report: checks passed (%d holds)" % len(out))


def figures(d, out, m, Ms):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    os.makedirs(d, exist_ok=True)
    sv = np.array([r["sigma_v"] for r in out]) / 1e3
    fig, ax = plt.subplots(figsize=(5, 4))
    ax.plot(sv, [r["dDv_mm"] for r in out], "o-", label="vertical $\\Delta D_v$")
    ax.plot(sv, [r["dDh_mm"] for r in out], "s-", label="horizontal $\\Delta D_h$")
    s = np.linspace(0, sv.max() * 1.05, 50)
    if math.isfinite(Ms):
        lo, hi = iowa(s * 1e3, m, 1.5 * Ms) * 1e3, iowa(s * 1e3, m, 0.5 * Ms) * 1e3
        ax.fill_between(s, lo, hi, color="0.85", label="Iowa, E' = 0.5-1.5 $M_s$")
        ax.fill_between(s, -hi, -lo, color="0.85")
    ax.axhline(0, color="k", lw=0.5)
    ax.set_xlabel("vertical stress at the crown $\\sigma_v$ (kPa)")
    ax.set_ylabel("diameter change (mm)")
    ax.legend(fontsize=8)
    fig.tight_layout(); fig.savefig(os.path.join(d, "pipe_diameter.png"), dpi=120); plt.close(fig)

    fig, ax = plt.subplots(figsize=(5, 4))
    for r in out:
        s = r["_state"]
        deg = np.degrees(s["theta"])
        o = np.argsort(np.where(deg > 180, deg - 360, deg))
        dd = np.where(deg > 180, deg - 360, deg)[o]
        keep = np.abs(dd) <= 90
        ax.plot(dd[keep], s["p"][o][keep] / 1e3, ".-", label="%.0f kPa" % (r["plate_stress"] / 1e3))
    ax.set_xlabel("angle from the crown (deg; +90 = springline at +x)")
    ax.set_ylabel("radial earth pressure (kPa)")
    ax.legend(fontsize=7, title="plate")
    fig.tight_layout(); fig.savefig(os.path.join(d, "pipe_pressure.png"), dpi=120); plt.close(fig)

    fig, ax = plt.subplots(figsize=(4.5, 4.5))
    X, U = out[-1]["_state"]["shape"]
    umax = np.abs(U).max()
    mag = 0.1 * m["R"] / umax if umax > 0 else 1
    cx, cz = m["base"][0], m["base"][2]
    ax.plot(np.append(X[:, 0], X[0, 0]) - cx, np.append(X[:, 2], X[0, 2]) - cz, "k--", lw=0.8, label="undeformed")
    for r in out:
        X, U = r["_state"]["shape"]
        xx, zz = X[:, 0] + mag * U[:, 0] - cx, X[:, 2] + mag * U[:, 2] - cz
        ax.plot(np.append(xx, xx[0]), np.append(zz, zz[0]), lw=1, label="%.0f kPa" % (r["plate_stress"] / 1e3))
    ax.set_aspect("equal")
    ax.set_title("mid ring, displacements x %.0f" % mag, fontsize=9)
    ax.legend(fontsize=7)
    fig.tight_layout(); fig.savefig(os.path.join(d, "pipe_shape.png"), dpi=120); plt.close(fig)

    fig, ax = plt.subplots(figsize=(6, 2.8))
    s = out[-1]["_state"]
    c, y = s["cents"], s["yielded"]
    # the share of the elements along y that yielded, per (x, z) column of the mesh
    key = np.round(c[:, [0, 2]], 6)
    cols, inv = np.unique(key, axis=0, return_inverse=True)
    inv = inv.reshape(-1)
    share = np.array([y[inv == i].mean() for i in range(len(cols))])
    sc = ax.scatter(cols[:, 0], cols[:, 1], c=share, cmap="Reds", vmin=0, vmax=1, s=18, edgecolors="0.4")
    fig.colorbar(sc, ax=ax, label="share of elements along y yielded")
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)"); ax.set_ylabel("z (m)")
    ax.set_title("FE soil's plastic zone at %.0f kPa (element centres)" % (out[-1]["plate_stress"] / 1e3), fontsize=9)
    fig.tight_layout(); fig.savefig(os.path.join(d, "pipe_plastic.png"), dpi=120); plt.close(fig)


if __name__ == "__main__":
    main()
