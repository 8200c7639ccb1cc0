#!/usr/bin/env python3
"""Plot the micro-mechanics measurements of an fdem run (docs/user-guide.md#measurements).

Usage: python3 scripts/plot_measure.py OUTDIR [--steps N,M,...] [--grid-step N]
                                              [--fields szz,sxz,...] [--prefix PATH] [--case FILE]

Rose diagrams (roses.csv): one polar panel per rose (plane), the contact-orientation
histogram at each of --steps (default: the first step with contacts and the last step) as the
fraction of the contacts per bin, mirrored to [180, 360) degrees (n and -n are one line), with
the mean normal force per bin printed for the last step. Writes PREFIX_roses.png.

Stress contours (measure_<step>.h5, the `grid` of the `measure` section): the cell fields on
the vertical plane of the grid (x-z: the cells are averaged over y; a grid with several y cells
shows its middle layer) at --grid-step (default: the last grid file), one panel per field of
--fields (default: szz, sxz, q; also sxx, syy, sxy, syz, p, porosity, Z, Z_mech), stresses in kPa,
compression positive. Writes PREFIX_grid.png.

PREFIX defaults to OUTDIR/measure. Prints the numbers it plots (dominant contact direction,
field ranges). Needs Debian's python3-matplotlib, python3-numpy and python3-h5py.
"""
import csv
import glob
import os
import re
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from fdem_common import system_python_fallback  # noqa: E402



system_python_fallback(["matplotlib", "numpy", "h5py"])
import matplotlib  # noqa: E402

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

PLANES = ["xy", "xz", "yz"]
STRESS = {"sxx": 0, "syy": 1, "szz": 2, "sxy": 3, "sxz": 4, "syz": 5}
SCALAR = {"p": "pressure", "q": "deviatoric", "porosity": "porosity", "Z": "coordination",
          "Z_mech": "coordination_mech", "particles": "particles"}


def read_roses(path):
    """{rose: {step: (theta_min[], theta_max[], count[], mean_fn[])}} and the step times."""
    roses, times = {}, {}
    with open(path, newline="") as f:
        for row in csv.DictReader(f):
            try:
                k, step = int(row["rose"]), int(float(row["step"]))
                vals = [float(row[c]) for c in ("theta_min", "theta_max", "count", "mean_fn")]
            except (KeyError, ValueError):
                continue  # partly written last line
            times[step] = float(row["time"])
            lists = roses.setdefault(k, {}).setdefault(step, ([], [], [], []))
            for lst, v in zip(lists, vals):
                lst.append(v)
    return roses, times


def plot_roses(outdir, steps_wanted, png, case):
    roses, times = read_roses(os.path.join(outdir, "roses.csv"))
    if not roses:
        print("plot_measure: roses.csv has no rows", file=sys.stderr)
        return False
    n = len(roses)
    labels = rose_labels(case, n)
    fig, axes = plt.subplots(1, n, subplot_kw={"projection": "polar"}, figsize=(4.2 * n, 4.4))
    axes = np.atleast_1d(axes)
    for k in sorted(roses):
        data = roses[k]
        steps = sorted(data)
        with_contacts = [s for s in steps if sum(data[s][2]) > 0]
        chosen = steps_wanted or ([with_contacts[0], steps[-1]] if with_contacts else [steps[-1]])
        chosen = [s for s in chosen if s in data]
        ax = axes[k]
        for s in dict.fromkeys(chosen):
            t0, t1, cnt, fn = (np.array(v) for v in data[s])
            total = cnt.sum()
            if total <= 0:
                continue
            frac = cnt / total
            width = np.radians(t1 - t0)
            centre = np.radians(0.5 * (t0 + t1))
            th = np.concatenate([centre, centre + np.pi])
            r = np.concatenate([frac, frac])
            ax.bar(th, r, width=np.concatenate([width, width]), alpha=0.45, edgecolor="k", linewidth=0.4,
                   label="step %d (t %.3g s), %d contacts" % (s, times[s], total))
            kmax = int(np.argmax(cnt))
            mean_fn = np.where(cnt > 0, fn, 0.0)
            print("%s, step %d: %d contacts; most contacts at %.0f-%.0f deg (%.3f of them, isotropic %.3f); "
                  "mean normal force %.3g N (largest %.3g N at %.0f-%.0f deg)"
                  % (labels[k], s, total, t0[kmax], t1[kmax], frac[kmax], 1.0 / len(cnt),
                     float((mean_fn * cnt).sum() / total), mean_fn.max(), t0[int(np.argmax(mean_fn))],
                     t1[int(np.argmax(mean_fn))]))
        ax.set_title(labels[k], fontsize=10)
        ax.set_yticklabels([])
        ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.08))
    fig.tight_layout()
    fig.savefig(png, dpi=80, bbox_inches="tight")
    plt.close(fig)
    print("wrote %s" % png)
    return True


def rose_labels(case, n):
    """Plane names of the roses from the case (--case, else the run's case.yaml), else "rose k"."""
    labels = ["rose %d" % k for k in range(n)]
    if case and os.path.exists(case):
        found = re.findall(r"plane:\s*([xyz]{2})", open(case).read())
        if len(found) == n:
            labels = ["%s plane (angle from %s towards %s)" % (p, p[0], p[1]) for p in found]
    return labels


def grid_field(g, name):
    if name in STRESS:
        return np.asarray(g["stress"])[:, STRESS[name]] / 1e3, "%s (kPa)" % name
    if name in ("p", "q"):
        return np.asarray(g[SCALAR[name]]) / 1e3, "%s (kPa)" % name
    if name in SCALAR:
        return np.asarray(g[SCALAR[name]]), name
    raise KeyError(name)


def plot_grid(outdir, step, fields, png):
    import h5py
    files = sorted(glob.glob(os.path.join(outdir, "measure_[0-9]*.h5")))
    if not files:
        print("plot_measure: no measure_<step>.h5 in %s (no grid in the case?)" % outdir, file=sys.stderr)
        return False
    if step is not None:
        files = [f for f in files if int(re.findall(r"(\d+)\.h5$", f)[0]) == step]
        if not files:
            print("plot_measure: no measure file for step %d" % step, file=sys.stderr)
            return False
    path = files[-1]
    with h5py.File(path, "r") as f:
        if "grid" not in f:
            print("plot_measure: %s has no /grid" % path, file=sys.stderr)
            return False
        g = f["grid"]
        a = g.attrs
        nx, ny, nz = int(a["nx"]), int(a["ny"]), int(a["nz"])
        o = [float(a["origin_x"]), float(a["origin_y"]), float(a["origin_z"])]
        h = [float(a["spacing_x"]), float(a["spacing_y"]), float(a["spacing_z"])]
        fstep, ftime = int(f.attrs["step"]), float(f.attrs["time"])
        npart = np.asarray(g["particles"]).reshape(nz, ny, nx)
        fig, axes = plt.subplots(1, len(fields), figsize=(4.6 * len(fields), 3.6), squeeze=False)
        xe = 1e3 * (o[0] + h[0] * np.arange(nx + 1))
        ze = 1e3 * (o[2] + h[2] * np.arange(nz + 1))
        j = ny // 2
        for ax, name in zip(axes[0], fields):
            v, label = grid_field(g, name)
            v = v.reshape(nz, ny, nx)
            # x-z plane: the y layer j (a grid with ny = 1 is the average over the whole width)
            sl = np.where(npart[:, j, :] > 0, v[:, j, :], np.nan)
            vmax = np.nanmax(np.abs(sl)) if np.isfinite(sl).any() else 1.0
            signed = name in STRESS and name not in ("sxx", "syy", "szz")
            im = ax.pcolormesh(xe, ze, sl, cmap="RdBu_r" if signed else "viridis",
                               vmin=-vmax if signed else None, vmax=vmax if signed else None, shading="flat")
            xc = 0.5 * (xe[:-1] + xe[1:])
            zc = 0.5 * (ze[:-1] + ze[1:])
            if np.isfinite(sl).sum() >= 4 and nx > 1 and nz > 1:
                ax.contour(xc, zc, np.nan_to_num(sl, nan=np.nanmean(sl)), levels=6, colors="k", linewidths=0.5)
            fig.colorbar(im, ax=ax, label=label)
            ax.set_xlabel("x (mm)")
            ax.set_ylabel("z (mm)")
            ax.set_aspect("equal")
            ax.set_title("%s, step %d" % (name, fstep), fontsize=10)
            print("%s at step %d (t %.4g s), y layer %d of %d: %s from %.4g to %.4g, mean %.4g over %d cells with grains"
                  % (os.path.basename(path), fstep, ftime, j, ny, label, np.nanmin(sl), np.nanmax(sl), np.nanmean(sl),
                     int(np.isfinite(sl).sum())))
    fig.tight_layout()
    fig.savefig(png, dpi=80, bbox_inches="tight")
    plt.close(fig)
    print("wrote %s" % png)
    return True


def main(argv):
    args = argv[1:]
    if not args or "-h" in args or "--help" in args:
        print(__doc__.strip())
        return 0 if args else 2
    steps, grid_step, fields, prefix, outdir, case = None, None, ["szz", "sxz", "q"], None, None, None
    k = 0
    while k < len(args):
        a = args[k]
        if a in ("--steps", "--grid-step", "--fields", "--prefix", "--case") and k + 1 >= len(args):
            print("plot_measure: %s needs a value" % a, file=sys.stderr)
            return 2
        if a == "--steps":
            steps = [int(x) for x in args[k + 1].split(",")]; k += 2
        elif a == "--grid-step":
            grid_step = int(args[k + 1]); k += 2
        elif a == "--fields":
            fields = args[k + 1].split(","); k += 2
        elif a == "--case":
            case = args[k + 1]; k += 2
        elif a == "--prefix":
            prefix = args[k + 1]; k += 2
        else:
            outdir = a; k += 1
    bad = [f for f in fields if f not in STRESS and f not in SCALAR]
    if bad:
        print("plot_measure: unknown field(s) %s (valid: %s)" % (", ".join(bad), ", ".join(list(STRESS) + list(SCALAR))),
              file=sys.stderr)
        return 2
    if outdir is None or not os.path.isdir(outdir):
        print("plot_measure: give the output directory of a run with a `measure` section", file=sys.stderr)
        return 2
    prefix = prefix or os.path.join(outdir, "measure")
    case = case or os.path.join(outdir, "case.yaml")  # the case as run
    done = 0
    if os.path.exists(os.path.join(outdir, "roses.csv")):
        done += plot_roses(outdir, steps, prefix + "_roses.png", case)
    if glob.glob(os.path.join(outdir, "measure_[0-9]*.h5")):
        done += plot_grid(outdir, grid_step, fields, prefix + "_grid.png")
    if not done:
        print("plot_measure: nothing to plot in %s (no roses.csv, no measure_<step>.h5 with a grid)" % outdir,
              file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
