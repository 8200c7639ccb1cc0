#!/usr/bin/python3
"""Plot a coupled run's interface.csv: the interface force (z) and the structure's largest
displacement against time, for one or more runs (e.g. the same case with different sub-cycles).

    /usr/bin/python3 scripts/plot_interface.py OUT_DIR [OUT_DIR ...] [--weight W] [-o FILE.png]

--weight W  draws -W (N) as the expected force of a structure carrying weight W at rest.
Default output: OUT_DIR/interface.png of the first run. Needs python3-matplotlib, python3-numpy.
"""
import argparse
import csv
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def read(path):
    with open(os.path.join(path, "interface.csv")) as f:
        rows = list(csv.DictReader(f))
    if not rows:
        sys.exit("plot_interface.py: %s/interface.csv has no rows" % path)
    col = lambda k: [float(r[k]) for r in rows]  # noqa: E731
    return col("time"), col("fz"), col("max_fe_displacement")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("runs", nargs="+", help="output directories of coupled runs")
    ap.add_argument("--weight", type=float, help="weight carried at rest (N); draws -W")
    ap.add_argument("--label", action="append", help="legend label per run (default: directory name)")
    ap.add_argument("-o", "--output", help="PNG file (default: FIRST_RUN/interface.png)")
    a = ap.parse_args()
    labels = a.label or [os.path.basename(os.path.normpath(r)) for r in a.runs]
    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(7, 6), sharex=True)
    for run, lab in zip(a.runs, labels):
        t, fz, u = read(run)
        ax1.plot(t, fz, lw=0.9, label=lab)
        ax2.plot(t, [1e3 * x for x in u], lw=0.9, label=lab)
    if a.weight is not None:
        ax1.axhline(-a.weight, color="k", ls="--", lw=0.8, label="-W = %.4g N" % a.weight)
    ax1.set_ylabel("interface force F_z (N)")
    ax2.set_ylabel("largest FE displacement (mm)")
    ax2.set_xlabel("time (s)")
    for ax in (ax1, ax2):
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    fig.tight_layout()
    out = a.output or os.path.join(a.runs[0], "interface.png")
    fig.savefig(out, dpi=120)
    print(out)


if __name__ == "__main__":
    main()
