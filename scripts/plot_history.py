#!/usr/bin/env python3
"""Plot an fdem run's convergence history.

Usage: python3 scripts/plot_history.py OUTDIR

Reads OUTDIR/history.csv (columns step,time,particles,kinetic_energy,unbalanced,contacts) and
writes OUTDIR/history.png: kinetic energy and unbalanced-force ratio against time, log y.
"""
import csv
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from fdem_common import read_csv, system_python_fallback  # noqa: E402



system_python_fallback(["matplotlib"])
import matplotlib  # noqa: E402

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402



def positive(xs, ys):
    """Points with y > 0 (a log axis cannot show the others)."""
    pts = [(x, y) for x, y in zip(xs, ys) if y > 0 and y == y and y != float("inf")]
    return [p[0] for p in pts], [p[1] for p in pts]


def main(argv):
    if len(argv) != 2 or argv[1] in ("-h", "--help"):
        print(__doc__.strip())
        return 0 if len(argv) == 2 else 2
    out = argv[1]
    path = os.path.join(out, "history.csv")
    if not os.path.exists(path):
        print("plot_history: %s is missing" % path, file=sys.stderr)
        return 1
    try:
        h = read_csv(path)
    except (OSError, StopIteration) as e:
        print("plot_history: cannot read %s: %s" % (path, e), file=sys.stderr)
        return 1
    t = h.get("time") or h.get("step") or []
    xlabel = "time (s)" if "time" in h else "step"
    fig, (ax1, ax2) = plt.subplots(2, 1, sharex=True, figsize=(7, 6))
    for ax, key, label in ((ax1, "kinetic_energy", "kinetic energy (J)"),
                           (ax2, "unbalanced", "unbalanced-force ratio")):
        if key in h:
            x, y = positive(t, h[key])
            if x:
                ax.semilogy(x, y, "-", lw=1.2)
            else:
                ax.text(0.5, 0.5, "no positive values", transform=ax.transAxes, ha="center")
        else:
            ax.text(0.5, 0.5, "column %s missing" % key, transform=ax.transAxes, ha="center")
        ax.set_ylabel(label)
        ax.grid(True, which="both", alpha=0.3)
    ax2.set_xlabel(xlabel)
    ax1.set_title("fdem history: %s" % os.path.basename(os.path.normpath(out)))
    fig.tight_layout()
    png = os.path.join(out, "history.png")
    fig.savefig(png, dpi=120)
    print("wrote %s" % png)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
