#!/usr/bin/env python3
"""One figure for any fdem run directory.

Usage: python3 scripts/plot_run.py OUTDIR [--out FILE.png]

Reads whatever of these OUTDIR has (a missing one just drops its panel) and writes one PNG
(default OUTDIR/run.png), a grid of 1-4 panels:
  history.csv      kinetic energy (J, left axis) and unbalanced-force ratio (right axis) against
                   time (s), log y (non-positive values and NaN dropped);
  walls.csv        the vertical force <wall>_fz (N) of each wall against time (s); of more than
                   8 walls, the 8 with the largest |fz| at the end (band columns <wall>_b<k>_* are
                   parts of a wall, not walls); no panel when every fz is 0 (side walls only);
  holds.csv        the load-settlement curve of each wall with <wall>_stress and
                   <wall>_settlement columns: stress (kPa) against settlement since hold 1 (mm,
                   downward); holds with converged == 0 as open markers (other columns ignored;
                   no panel without such a wall, e.g. coupled runs holding no wall);
  particles_<step>.h5 (the largest step; datasets position, radius, velocity at any depth)
                   a side view (x, z; equal aspect; seen from -y) of the particles as circles of
                   their true radius coloured by speed |v| (scale up to the 99th percentile);
                   of more than 50 000 particles, those within a slab 3 mean diameters thick
                   around the middle y. Walls and FE meshes are not drawn.
Prints one line per panel (or why a file gives none) and one naming the PNG. A directory with
none of these files, an unreadable snapshot or a malformed CSV line (named by file and line; a
partly written last line of a running simulation is skipped) is an error: one line on stderr,
exit code 2.
Needs Debian's python3-matplotlib, python3-numpy and python3-h5py (/usr/bin/python3).
"""
import argparse
import glob
import os
import re
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from fdem_common import TEXT_COLUMNS, system_python_fallback  # noqa: E402

system_python_fallback(["matplotlib", "numpy", "h5py"])
import matplotlib  # noqa: E402

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.collections import EllipseCollection  # noqa: E402
from mpl_toolkits.axes_grid1 import make_axes_locatable  # noqa: E402

MAX_WALLS = 8
MAX_PARTICLES = 50000
SLAB_DIAMETERS = 3.0


class RunError(Exception):
    """A problem with the run directory or one of its files (exit code 2)."""


# --- reading -----------------------------------------------------------------------------------

def read_table(path):
    """Columns of an fdem CSV file as {header: numpy array} (TEXT_COLUMNS as lists of str).
    Unlike fdem_common.read_csv, which skips bad lines, a malformed line raises RunError naming
    the file and line; only a partly written last line (no newline at its end) is skipped."""
    with open(path, newline="") as f:
        text = f.read()
    lines = text.split("\n")
    partial = not text.endswith("\n")
    if lines and lines[-1] == "":
        lines.pop()
    if not lines or not lines[0].strip():
        raise RunError("%s line 1: no header" % path)
    header = [h.strip() for h in lines[0].split(",")]
    rows = []
    for n, line in enumerate(lines[1:], start=2):
        fields = line.rstrip("\r").split(",")
        try:
            if len(fields) != len(header):
                raise ValueError("%d fields, the header has %d" % (len(fields), len(header)))
            rows.append([x.strip() if h in TEXT_COLUMNS else float(x)
                         for h, x in zip(header, fields)])
        except ValueError as e:
            if partial and n == len(lines):
                break  # partly written last line of a running simulation
            raise RunError("%s line %d: malformed (%s)" % (path, n, e))
    cols = {}
    for j, h in enumerate(header):
        vals = [r[j] for r in rows]
        cols[h] = vals if h in TEXT_COLUMNS else np.array(vals, dtype=float)
    return cols


def last_snapshot(outdir):
    """The path and step of the particles_<step>.h5 with the largest step, or (None, None)."""
    best = (None, None)
    for p in glob.glob(os.path.join(outdir, "particles_*.h5")):
        m = re.match(r"particles_(\d+)\.h5$", os.path.basename(p))
        if m and (best[1] is None or int(m.group(1)) > best[1]):
            best = (p, int(m.group(1)))
    return best


def find_dataset(h5, names):
    """The first dataset (at any depth) whose own name is one of `names`, or None."""
    found = []

    def visit(name, obj):
        if not found and hasattr(obj, "shape") and name.rsplit("/", 1)[-1].lower() in names:
            found.append(obj)
    h5.visititems(visit)
    return found[0] if found else None


def read_snapshot(path):
    """Positions (n,3), radii (n,), velocities (n,3) and the step attribute of a snapshot."""
    import h5py
    try:
        with h5py.File(path, "r") as h5:
            pos = find_dataset(h5, ("position", "positions", "pos"))
            rad = find_dataset(h5, ("radius", "radii"))
            vel = find_dataset(h5, ("velocity", "velocities", "vel"))
            if pos is None or rad is None:
                raise RunError("%s: no position/radius datasets" % path)
            x, r = np.asarray(pos[...], float), np.asarray(rad[...], float)
            v = np.asarray(vel[...], float) if vel is not None else np.zeros_like(x)
            step = h5.attrs.get("step")
    except OSError as e:
        raise RunError("%s: cannot read: %s" % (path, e))
    return x.reshape(-1, 3), r.reshape(-1), v.reshape(-1, 3), step


def load_run(outdir):
    """{panel: data} for the files the run has; RunError if it has none of them."""
    data = {}
    for key in ("history", "walls", "holds"):
        path = os.path.join(outdir, key + ".csv")
        if os.path.isfile(path):
            try:
                data[key] = read_table(path)
            except OSError as e:
                raise RunError("%s: cannot read: %s" % (path, e))
    snap, step = last_snapshot(outdir)
    if snap:
        data["particles"] = load_particles(snap, step)
    if not data:
        raise RunError("%s is not an fdem run directory (no history.csv, walls.csv, holds.csv "
                       "or particles_*.h5)" % outdir)
    return data


def unusable(key, cols):
    """Why a CSV file's panel cannot be drawn (a sentence), or None when it can."""
    t = cols.get("time", cols.get("step"))
    if t is None or not len(t):
        return "no rows with a time"
    if key == "history" and "kinetic_energy" not in cols and "unbalanced" not in cols:
        return "no kinetic_energy or unbalanced column"
    if key == "walls" and not wall_names(cols):
        return "no <wall>_fz column"
    if key == "walls" and not any(np.any(cols[n + "_fz"]) for n in wall_names(cols)):
        return "every wall's fz = 0 (walls without a vertical force, e.g. side walls)"
    if key == "holds" and not held_walls(cols):
        return "no <wall>_stress with <wall>_settlement column"
    return None


# --- panels ------------------------------------------------------------------------------------

def positive(t, y):
    """The points with finite y > 0 (a log axis cannot show the others)."""
    keep = np.isfinite(y) & (y > 0) & np.isfinite(t)
    return t[keep], y[keep]


def panel_history(ax, h):
    """Kinetic energy (left axis) and unbalanced-force ratio (right axis) against time."""
    t = h.get("time", h.get("step"))
    said = []
    ax2 = ax.twinx()
    for a, key, label, colour in ((ax, "kinetic_energy", "kinetic energy (J)", "C0"),
                                  (ax2, "unbalanced", "unbalanced-force ratio", "C3")):
        x, y = positive(t, h[key]) if key in h else (np.array([]), np.array([]))
        if len(x):
            a.semilogy(x, y, "-", color=colour, lw=1.2)
            said.append("%s %.3g" % (key, y[-1]))
        a.set_ylabel(label, color=colour)
        a.tick_params(axis="y", colors=colour)
    ax.set_xlabel("time (s)" if "time" in h else "step")
    ax.grid(True, which="both", alpha=0.3)
    ax.set_title("history (%d rows)" % len(t))
    return "history: kinetic energy and unbalanced ratio against time, %d rows to t = %.4g s; last %s" % (
        len(t), t[-1] if len(t) else float("nan"), ", ".join(said) or "no positive values")


def wall_names(cols):
    """The walls of walls.csv: the <name> of every <name>_fz column that is not a band
    (<wall>_b<k>_fz of a wall that has its own <wall>_fz)."""
    names = [h[:-3] for h in cols if h.endswith("_fz")]
    bands = set(n for n in names if re.match(r"(.+)_b\d+$", n)
                and re.match(r"(.+)_b\d+$", n).group(1) in names)
    return [n for n in names if n not in bands]


def panel_walls(ax, w):
    """The vertical force of each wall (the 8 with the largest |fz| at the end) against time."""
    t = w.get("time", w.get("step"))
    names = wall_names(w)
    shown = sorted(names, key=lambda n: -abs(w[n + "_fz"][-1]))[:MAX_WALLS]
    shown = [n for n in names if n in shown]  # the file's order
    for n in shown:
        ax.plot(t, w[n + "_fz"], lw=1.2, label=n)
    ax.set_xlabel("time (s)" if "time" in w else "step")
    ax.set_ylabel("wall force $f_z$ (N)")
    more = "" if len(shown) == len(names) else ", %d of %d with the largest |fz|" % (len(shown), len(names))
    ax.set_title("walls: vertical force%s" % more)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7, ncol=2 if len(shown) > 4 else 1, loc="best")
    ends = ", ".join("%s %.4g N" % (n, w[n + "_fz"][-1]) for n in shown)
    return "walls: fz of %d of %d walls against time; at t = %.4g s: %s" % (
        len(shown), len(names), t[-1], ends)


def held_walls(cols):
    """The walls of holds.csv with both <wall>_stress and <wall>_settlement columns."""
    return [c[:-len("_stress")] for c in cols if c.endswith("_stress")
            and c[:-len("_stress")] + "_settlement" in cols]


def panel_holds(ax, h):
    """Stress (kPa) against settlement since hold 1 (mm, downward) of each held wall."""
    walls = held_walls(h)
    conv = h["converged"] != 0 if "converged" in h else np.ones(len(h[walls[0] + "_stress"]), bool)
    said = []
    for i, wname in enumerate(walls):
        q = h[wname + "_stress"] / 1e3
        s = (h[wname + "_settlement"] - h[wname + "_settlement"][0]) * 1e3
        c = "C%d" % i
        ax.plot(q, s, "-", color=c, lw=1.2, label=wname)
        ax.plot(q[conv], s[conv], "o", color=c, ms=5)
        ax.plot(q[~conv], s[~conv], "o", mfc="white", mec=c, ms=5)
        said.append("%s %.4g kPa, %.4g mm" % (wname, q[-1], s[-1]))
    if not conv.all():
        ax.plot([], [], "o", mfc="white", mec="k", label="not converged")
    ax.invert_yaxis()
    ax.set_xlabel("stress (kPa)")
    ax.set_ylabel("settlement since hold 1 (mm)")
    ax.set_title("holds: load-settlement (%d holds)" % len(conv))
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8, loc="best")
    return "holds: load-settlement of %s, %d holds (%d not converged); last hold: %s" % (
        ", ".join(walls), len(conv), int((~conv).sum()), "; ".join(said))


def slab(x, r):
    """The particles to draw: all, or of more than MAX_PARTICLES those within a slab
    SLAB_DIAMETERS mean diameters thick around the middle y. Returns (mask, note)."""
    if len(r) <= MAX_PARTICLES:
        return np.ones(len(r), bool), ""
    ymid = 0.5 * (x[:, 1].min() + x[:, 1].max())
    half = 0.5 * SLAB_DIAMETERS * 2.0 * r.mean()
    keep = np.abs(x[:, 1] - ymid) <= half
    return keep, "%d in |y - %.4g| <= %.3g m" % (keep.sum(), ymid, half)


def load_particles(path, fstep):
    """The particles of a snapshot to draw, nearest (smallest y) last, with their speeds."""
    x, r, v, step = read_snapshot(path)
    keep, note = slab(x, r)
    x, r, speed = x[keep], r[keep], np.linalg.norm(v[keep], axis=1)
    order = np.argsort(-x[:, 1])  # seen from -y: the nearest particles drawn last
    return {"path": path, "step": int(step) if step is not None else fstep, "n": len(keep),
            "note": note, "x": x[order], "r": r[order], "speed": speed[order]}


def snapshot_aspect(p):
    """Height / width of the drawn particles (1 if none)."""
    x, r = p["x"], p["r"]
    if not len(r):
        return 1.0
    w = (x[:, 0] + r).max() - (x[:, 0] - r).min()
    return ((x[:, 2] + r).max() - (x[:, 2] - r).min()) / w if w > 0 else 1.0


def panel_particles(ax, fig, p):
    """Side view (x, z) of the last snapshot's particles, true radii, coloured by speed (the
    colour scale ends at the 99th percentile; faster particles take its top colour)."""
    x, r, speed = p["x"], p["r"], p["speed"]
    # matplotlib < 3.6 names offset_transform transOffset
    where = {"offset_transform" if matplotlib.__version__ >= "3.6" else "transOffset": ax.transData}
    coll = EllipseCollection(2 * r, 2 * r, np.zeros_like(r), units="xy", offsets=x[:, [0, 2]],
                             cmap="viridis", edgecolors="k", linewidths=0.15, **where)
    coll.set_array(speed)
    top = float(np.percentile(speed, 99)) if len(r) else 1.0
    coll.set_clim(0.0, top if top > 0 else (speed.max() if len(r) and speed.max() > 0 else 1.0))
    ax.add_collection(coll)
    if len(r):
        ax.set_xlim((x[:, 0] - r).min(), (x[:, 0] + r).max())
        ax.set_ylim((x[:, 2] - r).min(), (x[:, 2] + r).max())
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("z (m)")
    ax.set_title("step %d: %d particles%s" % (p["step"], p["n"], " (%s)" % p["note"] if p["note"] else ""),
                 fontsize=9)
    fast = len(r) and speed.max() > coll.get_clim()[1]
    cax = make_axes_locatable(ax).append_axes("right", size="4%", pad=0.08)  # as tall as the view
    fig.colorbar(coll, cax=cax, label="speed |v| (m/s)", extend="max" if fast else "neither")
    return ("particles: %s, step %d, %d particles (%d drawn), radius %.4g-%.4g m, speed 99th "
            "percentile %.3g, max %.3g m/s" % (
                os.path.basename(p["path"]), p["step"], p["n"], len(r), r.min() if len(r) else 0,
                r.max() if len(r) else 0, top, speed.max() if len(r) else 0))


# --- figure ------------------------------------------------------------------------------------

def layout(fig, order, aspect):
    """One axes per panel: 1 x n for up to 2; for 3 with a snapshot, the snapshot spans the right
    column when it is taller than wide, else the bottom row; 1 x 3 without; 2 x 2 for 4."""
    n = len(order)
    if n == 3 and "particles" in order:
        fig.set_size_inches(12.8, 9.6)
        g = fig.add_gridspec(2, 2)
        cells = [g[0, 0], g[1, 0], g[:, 1]] if aspect > 1 else [g[0, 0], g[0, 1], g[1, :]]
        return [fig.add_subplot(c) for c in cells]
    rows, cols = (1, n) if n <= 3 else (2, 2)
    fig.set_size_inches(6.4 * cols, 4.8 * rows)
    return [fig.add_subplot(rows, cols, k + 1) for k in range(n)]


def panels(data):
    """The panels that can be drawn, in order, and a line for each file that cannot."""
    order, lines = [], {}
    for key in ("history", "walls", "holds", "particles"):
        why = unusable(key, data[key]) if key in data and key != "particles" else None
        if why:
            lines[key] = "%s: %s.csv has %s: no panel" % (key, key, why)
        elif key in data:
            order.append(key)
    return order, lines


def plot(data, png, outdir):
    """Draw the available panels into one figure; print a line per panel and save it."""
    order, lines = panels(data)
    if not order:
        raise RunError("nothing to plot in %s: %s" % (outdir, "; ".join(lines.values())))
    fig = plt.figure()
    aspect = snapshot_aspect(data["particles"]) if "particles" in data else 1.0
    for key, ax in zip(order, layout(fig, order, aspect)):
        if key == "particles":
            lines[key] = panel_particles(ax, fig, data[key])
        else:
            lines[key] = {"history": panel_history, "walls": panel_walls,
                          "holds": panel_holds}[key](ax, data[key])
    fig.suptitle("fdem run: %s" % os.path.basename(os.path.normpath(outdir)))
    fig.tight_layout()
    fig.savefig(png, dpi=120)
    plt.close(fig)
    for key in ("history", "walls", "holds", "particles"):
        if key in lines:
            print(lines[key])
    print("wrote %s" % png)


def main(argv):
    head, _, rest = __doc__.split("\n\n", 2)
    ap = argparse.ArgumentParser(description=head + "\n\n" + rest,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("outdir", metavar="OUTDIR")
    ap.add_argument("--out", metavar="FILE.png", help="the PNG (default OUTDIR/run.png)")
    args = ap.parse_args(argv[1:])
    png = args.out or os.path.join(args.outdir, "run.png")
    try:
        if not os.path.isdir(args.outdir):
            raise RunError("%s is not a directory" % args.outdir)
        data = load_run(args.outdir)
        plot(data, png, args.outdir)
    except RunError as e:
        print("plot_run: %s" % e, file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
