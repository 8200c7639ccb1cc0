#!/usr/bin/env python3
"""The direct-shear calibration report (thesis ch. 3.5; docs/cases/direct_shear.md).

Usage: python3 scripts/direct_shear_report.py RUN [RUN ...] [--figures DIR]

Each RUN is the output directory of a direct shear run (lab.csv with a `tau` column and the
case.yaml fdem writes), e.g. the six runs of scripts/direct_shear.sh (two packing seeds x three
normal stresses). Runs are grouped by the packing seed of their case.yaml (packing.seed).

Per run: the target normal stress sigma_0 (the lab's normal wall servo after the last `from_step`
phase), sigma_n while shearing (mean, and the largest deviation of a lab.csv row from sigma_0),
the peak shear stress tau_p and the shear displacement at it, where tau first reaches 95 % of
tau_p, the peak's secant angle atan(tau_p / sigma_n), the residual tau (mean of the last tenth of
the record) and the largest dilation. The specimen: its grains and interior porosity
(packing.json of the run of its seed that packed it).
Mohr-Coulomb fits of the peaks, per seed and all runs together: least squares tau = c + sigma
tan(phi), and through the origin (c = 0). Then the thesis's targets (issue 17, thesis-results.md
DS1-DS6): phi of the fit in 38-41.5 deg (the thesis's DEM over scale factors 2-5; lab 41 deg),
c about 0 (|c| below 10 % of the smallest peak tau), the peaks within 4.5 mm (the thesis's curves
end there), sigma_n within 1 % of sigma_0.
Writes DIR/direct_shear.csv (one row per run), DIR/fits.csv, DIR/curves.png (tau and dilation
against shear displacement) and DIR/envelope.png (peak tau against sigma_n, the fits, the lab's
41 deg) and the residual angle (tau of the last tenth, through the origin). Exit 0, or 2 on a missing or unreadable run. Needs python3-matplotlib, python3-yaml.
"""
import csv
import json
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from fdem_common import load_case, read_csv, system_python_fallback  # noqa: E402

system_python_fallback(["matplotlib", "yaml"])

PHI_RANGE = (38.0, 41.5)   # the thesis's DEM, scale factors 2-5 (l. 2481)
PHI_LAB = 41.0             # Table 3-1, direct shear at Dr 70 %
PEAK_BY_MM = 4.5           # fig 3-7a is plotted to 4.5 mm
SIGMA_TOL = 0.01           # "an error of less than 1 %" (3.5)


class ReportError(Exception):
    pass


def normal_target(case):
    """sigma_0 of the lab's normal wall: the servo stress of its last motion phase."""
    lab = (case.get("lab") or {}).get("direct_shear") or {}
    name = lab.get("normal_wall")
    wall = next((w for w in case.get("walls") or [] if w.get("name") == name), None)
    if wall is None:
        raise ReportError("no lab.direct_shear.normal_wall in case.yaml")
    motion = wall.get("motion")
    phases = motion if isinstance(motion, list) else [motion]
    stress = [p["servo"]["stress"] for p in phases if isinstance(p, dict) and "servo" in p]
    if not stress:
        raise ReportError("the normal wall '%s' has no servo" % name)
    return float(stress[-1])


def read_run(d):
    lab, cy = os.path.join(d, "lab.csv"), os.path.join(d, "case.yaml")
    for p in (lab, cy):
        if not os.path.isfile(p):
            raise ReportError("%s is missing" % p)
    try:
        case = load_case(cy)
        c = read_csv(lab)
    except (OSError, ValueError, StopIteration) as e:
        raise ReportError("%s: %s" % (d, e))
    for col in ("shear_displacement", "normal_displacement", "sigma_n", "tau"):
        if col not in c:
            raise ReportError("%s has no `%s` column (not a direct shear run?)" % (lab, col))
    # shearing starts where the shear walls have moved (before it their displacement is round-off,
    # ~1e-19 m after a packing's shaking)
    k0 = next((k for k, u in enumerate(c["shear_displacement"]) if u > 1e-9), None)
    if k0 is None or len(c["tau"]) - k0 < 5:
        raise ReportError("%s: the run has not sheared (yet)" % lab)
    k0 = max(0, k0 - 1)
    u = [1e3 * (x - c["shear_displacement"][k0]) for x in c["shear_displacement"][k0:]]
    tau = c["tau"][k0:]
    sn = c["sigma_n"][k0 + 1:]
    dil = [1e3 * (x - c["normal_displacement"][k0]) for x in c["normal_displacement"][k0:]]
    s0 = normal_target(case)
    kp = max(range(len(tau)), key=lambda k: tau[k])
    k95 = next(k for k in range(len(tau)) if tau[k] >= 0.95 * tau[kp])
    tail = tau[len(tau) - max(1, len(tau) // 10):]
    sn_mean = sum(sn) / len(sn)
    # a run from another run's specimen (--specimen, named in run.json) has that run's packing seed
    src, case_p = specimen_source(d), case
    if src:
        try:
            case_p = load_case(os.path.join(src, "case.yaml"))
        except (OSError, ValueError):
            pass
    r = {"dir": d, "seed": int((case_p.get("packing") or {}).get("seed", 1)), "sigma0": s0,
         "sigma_n": sn_mean, "sigma_dev_max": max(abs(x / s0 - 1) for x in sn),
         "sigma_dev_mean": sum(abs(x / s0 - 1) for x in sn) / len(sn),
         "tau_peak": tau[kp], "u_peak": u[kp], "u95": u[k95],
         "phi_secant": math.degrees(math.atan(tau[kp] / sn_mean)), "tau_residual": sum(tail) / len(tail),
         "dilation_max": max(dil), "u": u, "tau": tau, "dil": dil}
    r.update(specimen(src or d))
    return r


def specimen_source(d):
    """The folder of the run that packed this run's specimen (run.json's "specimen", written for
    `--specimen FILE`), or None: the run packed its own, or its run.json predates the key."""
    try:
        with open(os.path.join(d, "run.json")) as f:
            path = json.load(f).get("specimen")
    except (OSError, ValueError):
        return None
    return os.path.dirname(path) if path else None


def specimen(d):
    """Grains and interior porosity of the run's specimen from its packing.json (a run started
    from another's specimen.h5 whose run.json does not name it has none: main() takes them from
    the run of the same seed that packed)."""
    try:
        with open(os.path.join(d, "packing.json")) as f:
            pj = json.load(f)
    except (OSError, ValueError):
        return {"porosity": float("nan"), "grains": float("nan")}
    return {"porosity": (pj.get("interior") or {}).get("porosity", float("nan")),
            "grains": pj.get("particles", float("nan"))}


def fit(runs):
    """(phi, c) of the least-squares line through the peaks, and phi through the origin."""
    pts = [(r["sigma_n"], r["tau_peak"]) for r in runs]
    if len({round(p[0]) for p in pts}) < 2:
        return None
    n = len(pts)
    sx = sum(p[0] for p in pts); sy = sum(p[1] for p in pts)
    sxx = sum(p[0] ** 2 for p in pts); sxy = sum(p[0] * p[1] for p in pts)
    slope = (n * sxy - sx * sy) / (n * sxx - sx * sx)
    return {"phi": math.degrees(math.atan(slope)), "c": (sy - slope * sx) / n,
            "phi0": math.degrees(math.atan(sxy / sxx)), "n": n}


def residual_angle(runs):
    """The residual (large-displacement) friction angle: tau_residual = sigma_n tan(phi_r), least
    squares through the origin over all runs."""
    sxy = sum(r["sigma_n"] * r["tau_residual"] for r in runs)
    sxx = sum(r["sigma_n"] ** 2 for r in runs)
    return math.degrees(math.atan(sxy / sxx))


def checks(runs, f):
    """The thesis's targets, each (name, value text, met)."""
    out = []
    if f:
        out.append(("phi of the fit in %.0f-%.1f deg" % PHI_RANGE, "%.1f deg" % f["phi"],
                    PHI_RANGE[0] <= f["phi"] <= PHI_RANGE[1]))
        tmin = min(r["tau_peak"] for r in runs)
        out.append(("c about 0 (|c| < 10 % of the smallest peak tau)", "%.2f kPa (smallest peak %.2f kPa)"
                    % (f["c"] / 1e3, tmin / 1e3), abs(f["c"]) < 0.1 * tmin))
    up = max(r["u_peak"] for r in runs)
    out.append(("peaks within %.1f mm" % PEAK_BY_MM, "%.2f-%.2f mm" % (min(r["u_peak"] for r in runs), up),
                up <= PEAK_BY_MM))
    dm = max(r["sigma_dev_max"] for r in runs)
    out.append(("sigma_n within 1 % of sigma_0 while shearing", "largest row %.2f %%, mean %.2f %%"
                % (100 * dm, 100 * max(r["sigma_dev_mean"] for r in runs)), dm <= SIGMA_TOL))
    return out


def write_tables(runs, fits, figdir):
    cols = ["dir", "seed", "grains", "porosity", "sigma0", "sigma_n", "sigma_dev_max", "sigma_dev_mean",
            "tau_peak", "u_peak", "u95", "phi_secant", "tau_residual", "dilation_max"]
    with open(os.path.join(figdir, "direct_shear.csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(cols)
        for r in runs:
            w.writerow([r[k] for k in cols])
    with open(os.path.join(figdir, "fits.csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["runs", "n", "phi_deg", "c_Pa", "phi_through_origin_deg"])
        for name, ft in fits:
            if ft:
                w.writerow([name, ft["n"], "%.3f" % ft["phi"], "%.1f" % ft["c"], "%.3f" % ft["phi0"]])


def plot(runs, fits, figdir):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    sigmas = sorted({r["sigma0"] for r in runs})
    seeds = sorted({r["seed"] for r in runs})
    colors = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    styles = ["-", "--", ":", "-."]
    fig, (a1, a2) = plt.subplots(2, 1, sharex=True, figsize=(7, 7))
    for r in runs:
        col = colors[sigmas.index(r["sigma0"]) % len(colors)]
        ls = styles[seeds.index(r["seed"]) % len(styles)]
        lab = "sigma_n %.1f kPa, seed %d" % (r["sigma0"] / 1e3, r["seed"])
        a1.plot(r["u"], [t / 1e3 for t in r["tau"]], ls, color=col, label=lab)
        a2.plot(r["u"], r["dil"], ls, color=col)
    a1.axvline(PEAK_BY_MM, color="grey", lw=0.8)
    a1.text(PEAK_BY_MM, a1.get_ylim()[1] * 0.95, " thesis's curves end", fontsize=7, va="top")
    a1.set_ylabel("shear stress tau (kPa)")
    a2.set_ylabel("vertical displacement (mm, + dilation)")
    a2.set_xlabel("shear displacement (mm)")
    a1.legend(fontsize=7)
    for a in (a1, a2):
        a.grid(True, alpha=0.3)
    fig.tight_layout()
    fig.savefig(os.path.join(figdir, "curves.png"), dpi=120)
    plt.close(fig)
    fig, ax = plt.subplots(figsize=(6, 5))
    smax = 1.2 * max(r["sigma_n"] for r in runs) / 1e3
    xs = [0, smax]
    for r in runs:
        mk, col = "os^v"[seeds.index(r["seed"]) % 4], colors[seeds.index(r["seed"]) % len(colors)]
        ax.plot(r["sigma_n"] / 1e3, r["tau_peak"] / 1e3, mk, color=col)
        ax.plot(r["sigma_n"] / 1e3, r["tau_residual"] / 1e3, mk, color=col, mfc="none")
    pr = residual_angle(runs)
    ax.plot(xs, [x * math.tan(math.radians(pr)) for x in xs], ":", color="k", lw=1,
            label="residual (open marks): %.1f deg" % pr)
    ax.plot(xs, [x * math.tan(math.radians(PHI_LAB)) for x in xs], "k--", lw=1, label="lab: 41 deg, c = 0")
    for lo_hi in PHI_RANGE:
        ax.plot(xs, [x * math.tan(math.radians(lo_hi)) for x in xs], color="grey", lw=0.6)
    for name, ft in fits:
        if ft:
            t = math.tan(math.radians(ft["phi"]))
            ax.plot(xs, [ft["c"] / 1e3 + x * t for x in xs], lw=1.2,
                    label="%s: phi %.1f deg, c %.2f kPa" % (name, ft["phi"], ft["c"] / 1e3))
    ax.set_xlim(0, smax)
    ax.set_ylim(0, None)
    ax.set_xlabel("normal stress sigma_n (kPa)")
    ax.set_ylabel("peak shear stress (kPa)")
    ax.set_title("peaks (filled) and residual (open); grey: the thesis's DEM range 38-41.5 deg", fontsize=9)
    ax.legend(fontsize=7)
    ax.grid(True, alpha=0.3)
    fig.tight_layout()
    fig.savefig(os.path.join(figdir, "envelope.png"), dpi=120)
    plt.close(fig)


def main(argv):
    args = argv[1:]
    if not args or "-h" in args or "--help" in args:
        print(__doc__.strip())
        return 0 if args else 2
    figdir, dirs, k = None, [], 0
    while k < len(args):
        if args[k] == "--figures" and k + 1 < len(args):
            figdir = args[k + 1]; k += 2
        else:
            dirs.append(args[k]); k += 1
    try:
        runs = [read_run(d) for d in dirs]
    except ReportError as e:
        print("direct_shear_report: %s" % e, file=sys.stderr)
        return 2
    for r in runs:  # specimens reused by --specimen: from the run of the same seed that packed them
        if math.isnan(r["porosity"]):
            src = next((q for q in runs if q["seed"] == r["seed"] and not math.isnan(q["porosity"])), None)
            if src:
                r["porosity"], r["grains"] = src["porosity"], src["grains"]
    figdir = figdir or os.path.join(dirs[0], "report")
    os.makedirs(figdir, exist_ok=True)
    print("%-34s %5s %6s %7s %8s %8s %7s %8s %7s %7s %7s %7s" % (
        "run", "seed", "n", "sigma0", "sigma_n", "dev max", "tau_p", "u_p (mm)", "u95", "phi_p", "tau_r", "dil"))
    for r in runs:
        print("%-34s %5d %6.3f %7.1f %8.2f %7.2f%% %7.2f %8.2f %7.2f %7.1f %7.2f %7.2f" % (
            os.path.basename(os.path.normpath(r["dir"])), r["seed"], r["porosity"], r["sigma0"] / 1e3,
            r["sigma_n"] / 1e3, 100 * r["sigma_dev_max"], r["tau_peak"] / 1e3, r["u_peak"], r["u95"],
            r["phi_secant"], r["tau_residual"] / 1e3, r["dilation_max"]))
    fits = [("seed %d" % s, fit([r for r in runs if r["seed"] == s])) for s in sorted({r["seed"] for r in runs})]
    if len(fits) > 1:
        fits.append(("all", fit(runs)))
    for name, ft in fits:
        if ft:
            print("Mohr-Coulomb fit, %s (%d runs): phi %.1f deg, c %.2f kPa; through the origin phi %.1f deg"
                  % (name, ft["n"], ft["phi"], ft["c"] / 1e3, ft["phi0"]))
    print("residual friction angle (the mean tau of each record's last tenth, through the origin): %.1f deg"
          % residual_angle(runs))
    overall = fits[-1][1]
    for name, val, ok in checks(runs, overall):
        print("target: %-52s %-40s %s" % (name, val, "met" if ok else "NOT met"))
    write_tables(runs, fits, figdir)
    plot(runs, fits, figdir)
    print("wrote %s/{direct_shear.csv, fits.csv, curves.png, envelope.png}" % figdir)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
