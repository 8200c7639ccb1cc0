#!/usr/bin/python3
"""Contact force network around the shaft (thesis fig 3-19, SH12: "when the shaft radius is
reduced, the contact forces within the shear failure zone decrease in the radial direction and
increase in the circumferential direction"), from the particle snapshots at the hold ends.

    /usr/bin/python3 scripts/shaft_network.py DIR [--figure PNG] [--s-mm 3] [--zone 0.2]
                                              [--depth 0.3 0.7] [--slab 0.05]

DIR: a shaft run's output directory (scripts/shaft_report.py reads the same files). The normal
force of every grain-grain contact is rebuilt from the snapshot's positions and radii with the
case's linear law (fdem's default, `contact_model: linear`): fn = K_N delta, K_N the springs
2 E r_a and 2 E r_b in series, delta = r_a + r_b - |x_b - x_a| > 0 (exact for the elastic normal
force; the tangential forces are not in the snapshot and are left out). A Hertz-Mindlin case is
refused. With `measure.force_network: true` the run's own `/force_network` checks it
(--check-network TOL: the same pairs, every fn within K_N |v_rel| dt -- the one step between the
snapshot's positions and the measured forces -- plus TOL times the largest; cli_shaft does).

Printed for the hold at rest (the first) and the hold nearest --s-mm: in the annulus a < r < --zone
(the thesis's failure zone, 0.2 m) and beyond it, over depths --depth (fractions of H), the
directional parts of the normal contact forces
    S_rr = sum fn l (n . e_r)^2 / V,   S_tt = sum fn l (n . e_theta)^2 / V,   S_zz = ... (Pa)
(l the branch length, e_r, e_theta at the contact point: the normal-force part of the Love-Weber
stress in cylindrical axes), their ratio to the rest state, and the contacts' count.
Figure (--figure): plan views of the contacts whose contact point lies in a horizontal slab of
thickness --slab at 0.49H, at rest and at the hold nearest --s-mm, lines between the centres with
width proportional to fn, the failure-zone circle drawn. Needs python3-numpy, -h5py, -matplotlib,
-yaml. Exit 2 on bad input.
"""
import argparse
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from fdem_common import system_python_fallback  # noqa: E402

system_python_fallback(["numpy", "h5py", "matplotlib", "yaml"])
import numpy as np  # noqa: E402
import shaft_report as sr  # noqa: E402

PROG = "shaft_network"
NAN = float("nan")


def read_grains(path):
    import h5py
    with h5py.File(path, "r") as f:
        x = np.asarray(f["position"][...], dtype=float)
        r = np.asarray(f["radius"][...], dtype=float)
        ids = np.asarray(f["id"][...], dtype=np.int64)
        mat = np.asarray(f["material"][...], dtype=np.int64) if "material" in f else np.zeros(len(r), np.int64)
    o = np.argsort(ids, kind="stable")
    return x[o], r[o], mat[o]


def contacts(x, r):
    """Overlapping pairs (i, j, delta) of spheres x, r: a cell list of the largest diameter,
    padded cells, the 13 forward neighbour offsets plus the cell itself."""
    n = len(r)
    if n < 2:
        return np.zeros(0, int), np.zeros(0, int), np.zeros(0)
    h = 2 * r.max()
    lo = x.min(axis=0)
    c = np.floor((x - lo) / h).astype(np.int64)
    dims = c.max(axis=0) + 3
    c += 1  # a border of empty cells
    key = (c[:, 0] * dims[1] + c[:, 1]) * dims[2] + c[:, 2]
    o = np.argsort(key, kind="stable")
    ks = key[o]
    starts = np.r_[0, np.flatnonzero(np.diff(ks)) + 1]
    cells = ks[starts]
    counts = np.diff(np.r_[starts, n])
    kmax = counts.max()
    members = -np.ones((len(cells), kmax), dtype=np.int64)
    slot = np.arange(n) - np.repeat(starts, counts)
    members[np.repeat(np.arange(len(cells)), counts), slot] = o
    offs = [(dx, dy, dz) for dx in (-1, 0, 1) for dy in (-1, 0, 1) for dz in (-1, 0, 1)
            if (dx, dy, dz) > (0, 0, 0)]
    I, J, D = [], [], []

    def add(mi, mj, same):
        a = np.repeat(mi, kmax, axis=1).ravel()
        b = np.tile(mj, (1, kmax)).ravel()
        ok = (a >= 0) & (b >= 0)
        if same:
            ok &= a < b
        a, b = a[ok], b[ok]
        d = r[a] + r[b] - np.linalg.norm(x[b] - x[a], axis=1)
        k = d > 0
        I.append(a[k]), J.append(b[k]), D.append(d[k])

    add(members, members, True)
    for dx, dy, dz in offs:
        nb = cells + (dx * dims[1] + dy) * dims[2] + dz
        pos = np.searchsorted(cells, nb)
        pos = np.minimum(pos, len(cells) - 1)
        hit = cells[pos] == nb
        if hit.any():
            add(members[hit], members[pos[hit]], False)
    return np.concatenate(I), np.concatenate(J), np.concatenate(D)


def network(x, r, young):
    """Contacts with their normal force: dict of i, j, fn, contact point p, unit normal n, branch l."""
    i, j, d = contacts(x, r)
    kn = 2 * young[i] * r[i] * 2 * young[j] * r[j] / (2 * young[i] * r[i] + 2 * young[j] * r[j])
    br = x[j] - x[i]
    ln = np.linalg.norm(br, axis=1)
    nrm = br / ln[:, None]
    p = x[i] + nrm * (r[i] - d / 2)[:, None]
    return {"i": i, "j": j, "fn": kn * d, "delta": d, "p": p, "n": nrm, "l": ln}


def directional(net, sel, vol):
    """S_rr, S_tt, S_zz (Pa) of the selected contacts in the volume vol, and their count."""
    p, n = net["p"][sel], net["n"][sel]
    rr = np.hypot(p[:, 0], p[:, 1])
    er = np.stack([p[:, 0] / rr, p[:, 1] / rr], axis=1)
    nr = n[:, 0] * er[:, 0] + n[:, 1] * er[:, 1]
    nt = -n[:, 0] * er[:, 1] + n[:, 1] * er[:, 0]
    w = net["fn"][sel] * net["l"][sel] / vol
    return float(np.sum(w * nr ** 2)), float(np.sum(w * nt ** 2)), float(np.sum(w * n[:, 2] ** 2)), int(sel.sum())


def analyse(run, s_mm, zone_r, depth, slab):
    case = run["case"]
    mats = case.get("materials") or []
    if str(case.get("contact_model", "linear")) != "linear" or any(
            str(it.get("model", "linear")) != "linear" for it in (case.get("interactions") or [])):
        raise sr.ReportError("%s: not every pair is linear: the normal forces cannot be rebuilt from the overlaps"
                             % run["dir"])
    young_of = np.array([float(m.get("young", "nan")) for m in mats]) if mats else np.array([np.nan])
    rest = run["holds"][0]
    later = [h for h in run["holds"][1:]]
    if not later:
        raise sr.ReportError("%s: one hold only: nothing to compare with the rest state" % run["dir"])
    pick = min(later, key=lambda h: abs(h["s_mm"] - s_mm))
    a, H, Hs = run["a"], run["H"], run["Hs"]
    L = min(float(v) for v in case["packing"]["box"]["max"][:2])
    out = []
    for h in (rest, pick):
        path = sr.snapshot_file(run, h)
        if path is None:
            raise sr.ReportError("%s: no particle snapshot at hold %d's end (particles_%08d.h5)"
                                 % (run["dir"], h["hold"], h["step"]))
        x, r, mat = read_grains(path)
        if mat.max() >= len(young_of) or not np.all(np.isfinite(young_of[mat])):
            raise sr.ReportError("%s: a grain's material has no `young` in case.yaml" % path)
        net = network(x, r, young_of[mat])
        pr = np.hypot(net["p"][:, 0], net["p"][:, 1])
        dep = Hs - net["p"][:, 2]
        dsel = (dep >= depth[0] * H) & (dep < depth[1] * H)
        dz = (depth[1] - depth[0]) * H
        quarter = math.pi / 4
        inner = dsel & (pr > a) & (pr < zone_r)
        outer = dsel & (pr >= zone_r) & (pr < L)
        v_in = quarter * (zone_r ** 2 - a ** 2) * dz
        v_out = quarter * (L ** 2 - zone_r ** 2) * dz
        zc = Hs - 0.49 * H
        in_slab = np.abs(net["p"][:, 2] - zc) < slab / 2
        out.append({"hold": h, "net": net, "x": x, "inner": directional(net, inner, v_in),
                    "outer": directional(net, outer, v_out), "slab": in_slab, "zc": zc})
    return out, (a, L, zone_r)


def report(run, res, geo, depth):
    a, L, zone_r = geo
    print("== %s: normal contact forces rebuilt from the snapshots (linear law), depths %.2fH-%.2fH"
          % (run["dir"], depth[0], depth[1]))
    print("  %-28s %6s %9s %9s %9s %8s %6s | ratio to rest: %5s %5s %5s"
          % ("region", "s(mm)", "S_rr kPa", "S_tt kPa", "S_zz kPa", "contacts", "tt/rr", "rr", "tt", "zz"))
    for key, name in (("inner", "zone %.3f < r < %.3f m" % (a, zone_r)), ("outer", "beyond %.3f < r < %.3f m" % (zone_r, L))):
        base = res[0][key]
        for e in res:
            v = e[key]
            rat = " ".join("%5.2f" % (v[k] / base[k]) if base[k] > 0 else "    -" for k in range(3))
            print("  %-28s %6.2f %9.3f %9.3f %9.3f %8d %6.2f | %s"
                  % (name, e["hold"]["s_mm"], v[0] / 1e3, v[1] / 1e3, v[2] / 1e3, v[3],
                     v[1] / v[0] if v[0] > 0 else NAN, rat))
    i0, i1 = res[0]["inner"], res[1]["inner"]
    fell = i1[0] < i0[0]
    rose = i1[1] > i0[1]
    print("  thesis (fig 3-19): in the zone radial forces fall (%s: %+.0f %%), circumferential forces rise (%s: %+.0f %%; "
          "relative to the radial ones %.2f -> %.2f)"
          % ("yes" if fell else "no", 100 * (i1[0] / i0[0] - 1), "yes" if rose else "no", 100 * (i1[1] / i0[1] - 1),
             i0[1] / i0[0], i1[1] / i1[0]))


def figure(run, res, geo, slab, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.collections import LineCollection
    a, L, zone_r = geo
    fmax = max(float(np.percentile(e["net"]["fn"][e["slab"]], 99.5)) if e["slab"].any() else 1.0 for e in res)
    fig, axes = plt.subplots(1, 2, figsize=(12, 6.2))
    for ax, e in zip(axes, res):
        net, sel = e["net"], e["slab"]
        xa, xb = e["x"][net["i"][sel]], e["x"][net["j"][sel]]
        segs = np.stack([xa[:, :2], xb[:, :2]], axis=1)
        lw = 3.0 * np.clip(net["fn"][sel] / fmax, 0, 1)
        ax.add_collection(LineCollection(segs, linewidths=lw, colors="k"))
        t = np.linspace(0, math.pi / 2, 60)
        ax.fill(np.r_[0, a * np.cos(t)], np.r_[0, a * np.sin(t)], color="0.7")
        ax.plot(zone_r * np.cos(t), zone_r * np.sin(t), "r--", lw=1, label="r = %.2f m (thesis's failure zone)" % zone_r)
        ax.set_xlim(0, L)
        ax.set_ylim(0, L)
        ax.set_aspect("equal")
        ax.set_title("s = %.2f mm: %d contacts in |z - %.3f m| < %.3f m (0.49H)"
                     % (e["hold"]["s_mm"], int(sel.sum()), e["zc"], slab / 2), fontsize=9)
        ax.set_xlabel("x (m)")
        ax.legend(fontsize=7, loc="upper right")
    axes[0].set_ylabel("y (m)")
    fig.suptitle("%s: normal contact forces (line width proportional to fn, full width %.0f N)" % (run["label"], fmax),
                 fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=80)
    plt.close(fig)


def check_network(run, res, tol):
    """The rebuilt normal forces against the run's own /force_network (measure_<step>.h5 at the
    same hold ends, `measure.force_network: true`). The measured forces are the step's, from the
    positions at its start; the snapshot holds the positions at its end: a pair's overlap differs by
    at most |v_b - v_a| dt. So: the same pairs (beyond tol of the largest force), and every pair's
    |fn rebuilt - fn measured| <= K_N |v_rel| dt (1.5 times, for the half-step velocities) + tol
    times the largest; a pair in one network only carries at most that bound (it closed or opened
    during the step). Returns a list of failures."""
    import h5py
    import json
    bad = []
    try:
        with open(os.path.join(run["dir"], "run.json")) as f:
            dt = float(json.load(f)["dt"])
    except (OSError, ValueError, KeyError) as e:
        return ["%s/run.json: no dt (%s)" % (run["dir"], e)]
    for e in res:
        h = e["hold"]
        path = os.path.join(run["dir"], "measure_%08d.h5" % h["step"])
        if not os.path.isfile(path):
            bad.append("%s: missing" % path)
            continue
        with h5py.File(path, "r") as f:
            if "force_network" not in f:
                bad.append("%s: no /force_network (measure.force_network: true)" % path)
                continue
            ids = np.asarray(f["force_network/id"][...], dtype=np.int64).reshape(-1, 2)
            fn = np.asarray(f["force_network/fn"][...], dtype=float).ravel()
        with h5py.File(os.path.join(run["dir"], "particles_%08d.h5" % h["step"]), "r") as f:
            order = np.argsort(np.asarray(f["id"][...], dtype=np.int64), kind="stable")
            gid = np.asarray(f["id"][...], dtype=np.int64)[order]
            vel = np.asarray(f["velocity"][...], dtype=float)[order]
        net = e["net"]
        i, j = net["i"], net["j"]
        kn = net["fn"] / np.maximum(net["delta"], 1e-300)
        bound = 1.5 * kn * np.linalg.norm(vel[j] - vel[i], axis=1) * dt
        mine = {(int(min(gid[a], gid[b])), int(max(gid[a], gid[b]))): (v, w) for a, b, v, w in zip(i, j, net["fn"], bound)}
        theirs = {(int(min(a, b)), int(max(a, b))): v for (a, b), v in zip(ids, fn)}
        fmax = max(theirs.values()) if theirs else 1.0
        only_m = [k for k in mine if k not in theirs and mine[k][0] > mine[k][1] + tol * fmax]
        # A measured pair missing from the rebuilt network opened during the step: its force was
        # at most K_N |v_rel| dt (K_N: the stiffest rebuilt pair's, an upper bound).
        kn_max = float(kn.max()) if len(kn) else 0.0

        def opened_bound(k):
            a, b = np.searchsorted(gid, k[0]), np.searchsorted(gid, k[1])
            if a >= len(gid) or b >= len(gid) or gid[a] != k[0] or gid[b] != k[1]:
                return 0.0
            return 1.5 * kn_max * float(np.linalg.norm(vel[b] - vel[a])) * dt
        only_t = [k for k in theirs if k not in mine and theirs[k] > opened_bound(k) + tol * fmax]
        both = [k for k in mine if k in theirs]
        dev = np.array([abs(mine[k][0] - theirs[k]) for k in both])
        over = [k for k, d in zip(both, dev) if d > mine[k][1] + tol * fmax]
        print("  hold %d: %d contacts rebuilt, %d measured, %d in both; |fn rebuilt - fn measured| / largest (%.3g N): "
              "median %.1e, max %.1e; %d beyond K_N |v_rel| dt + %.0e; %d/%d in one only"
              % (h["hold"], len(mine), len(theirs), len(both), fmax, float(np.median(dev)) / fmax if len(dev) else 0,
                 float(dev.max()) / fmax if len(dev) else 0, len(over), tol, len(only_m), len(only_t)))
        if over or only_m or only_t or not both:
            bad.append("hold %d: the rebuilt network differs from the measured one" % h["hold"])
    return bad


def main(argv):
    ap = argparse.ArgumentParser(prog="shaft_network.py", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("run", metavar="DIR", help="output directory of a shaft run")
    ap.add_argument("--figure", metavar="PNG", help="write the plan views here")
    ap.add_argument("--s-mm", type=float, default=3.0, help="the hold compared with rest (nearest; default 3)")
    ap.add_argument("--zone", type=float, default=0.2, help="outer radius of the failure zone (m; default 0.2)")
    ap.add_argument("--depth", type=float, nargs=2, default=(0.1, 0.9), metavar=("FROM", "TO"),
                    help="depth range as fractions of H (default 0.1 0.9)")
    ap.add_argument("--slab", type=float, default=0.05, help="thickness of the plan-view slab (m; default 0.05)")
    ap.add_argument("--check-network", type=float, metavar="TOL",
                    help="compare the rebuilt forces with the run's /force_network (measure files); exit 1 when "
                         "a pair's fn differs by more than TOL times the largest")
    args = ap.parse_args(argv[1:])
    if not (0 <= args.depth[0] < args.depth[1] <= 1.5) or args.slab <= 0 or args.zone <= 0:
        ap.error("need 0 <= FROM < TO, --slab > 0, --zone > 0")
    ns = argparse.Namespace(unit_weight=None, k0=sr.K0_THESIS, phi=sr.PHI, zone_fraction=sr.ZONE_FRACTION)
    try:
        run = sr.load_run(args.run, ns)
        run["k0"], run["phi"] = ns.k0, ns.phi
        sr.compute(run)
        res, geo = analyse(run, args.s_mm, args.zone, args.depth, args.slab)
    except sr.ReportError as e:
        print("%s: %s" % (PROG, e), file=sys.stderr)
        return 2
    report(run, res, geo, args.depth)
    if args.check_network is not None:
        bad = check_network(run, res, args.check_network)
        for b in bad:
            print("%s: %s" % (PROG, b), file=sys.stderr)
        if bad:
            return 1
    if args.figure:
        figure(run, res, geo, args.slab, args.figure)
        print("wrote %s" % args.figure)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
