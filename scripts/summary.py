#!/usr/bin/env python3
"""Short human summary of an fdem run directory.

Usage: python3 scripts/summary.py OUTDIR

Reads (each optional; a missing or unreadable one is reported, not fatal):
  OUTDIR/run.json              ranks, steps, dt, wall time, throughput, status
  OUTDIR/history.csv           first/last row: particles, kinetic energy, unbalanced force
  OUTDIR/particles_*.h5        the last snapshot: count, z-range, mean radius (needs h5py)
  OUTDIR/walls.csv             last row: force (and displacement) of each wall
  OUTDIR/holds.csv             per hold: converged, the held walls' stress and settlement
  OUTDIR/lab.csv               a lab test's last row and the peak stress ratio
  OUTDIR/interface.csv         a coupled run's force on the structure at the last row
"""
import csv
import glob
import json
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from fdem_common import system_python_fallback  # noqa: E402



def fmt(v, unit=""):
    """Compact number formatting; None/NaN shown as '-'."""
    if v is None:
        return "-"
    try:
        x = float(v)
    except (TypeError, ValueError):
        return str(v)
    if math.isnan(x):
        return "-"
    if math.isinf(x):
        return ("inf" if x > 0 else "-inf") + (" " + unit if unit else "")
    if x == int(x) and abs(x) < 1e15:
        s = str(int(x))
    elif x != 0 and (abs(x) < 1e-3 or abs(x) >= 1e6):
        s = "%.4g" % x
    else:
        s = "%.6g" % x
    return s + (" " + unit if unit else "")


def read_csv(path):
    """Returns (header, rows as lists of floats) or raises."""
    with open(path, newline="") as f:
        rows = [r for r in csv.reader(f) if r]
    if not rows:
        raise ValueError("empty file")
    header = [h.strip() for h in rows[0]]
    data = []
    for r in rows[1:]:
        try:
            data.append([float(x) for x in r])
        except ValueError:
            continue  # a partly written last line of a killed run
    return header, data


def section_run(out):
    path = os.path.join(out, "run.json")
    print("run.json:")
    if not os.path.exists(path):
        print("  missing")
        return
    try:
        with open(path) as f:
            r = json.load(f)
    except (OSError, ValueError) as e:
        print("  unreadable: %s" % e)
        return
    print("  case %s, fdem %s, status %s" % (r.get("case", "?"), r.get("version", "?"),
                                              r.get("status", "?")))
    steps = r.get("steps")
    start = r.get("start_step", 0) or 0
    print("  ranks %s, steps %s%s, dt %s, simulated time %s" % (
        fmt(r.get("ranks")), fmt(steps),
        (" (restarted at step %s)" % fmt(start)) if start else "",
        fmt(r.get("dt"), "s"), fmt(r.get("simulated_time"), "s")))
    p = r.get("particles") or {}
    print("  particles: initial %s, final %s, removed %s" % (
        fmt(p.get("initial")), fmt(p.get("final")), fmt(p.get("removed"))))
    print("  wall time %s, %s particle-steps/s" % (
        fmt(r.get("wall_time_s"), "s"), fmt(r.get("particle_steps_per_second"))))
    timings = r.get("timings") or {}
    if timings:
        total = sum(v for v in timings.values() if isinstance(v, (int, float))) or 1.0
        parts = ["%s %s (%.0f%%)" % (k, fmt(v, "s"), 100.0 * v / total)
                 for k, v in timings.items() if isinstance(v, (int, float))]
        print("  timings: " + ", ".join(parts))


def section_history(out):
    path = os.path.join(out, "history.csv")
    print("history.csv:")
    if not os.path.exists(path):
        print("  missing")
        return
    try:
        header, data = read_csv(path)
    except (OSError, ValueError) as e:
        print("  unreadable: %s" % e)
        return
    if not data:
        print("  no rows")
        return
    col = {h: i for i, h in enumerate(header)}

    def get(row, name):
        i = col.get(name)
        return row[i] if i is not None and i < len(row) else None

    print("  %d rows" % len(data))
    for label, row in (("first", data[0]), ("last", data[-1])):
        print("  %-5s step %s, t %s: particles %s, kinetic energy %s, unbalanced %s, "
              "contacts %s" % (label, fmt(get(row, "step")), fmt(get(row, "time"), "s"),
                               fmt(get(row, "particles")), fmt(get(row, "kinetic_energy"), "J"),
                               fmt(get(row, "unbalanced")), fmt(get(row, "contacts"))))


def snapshot_step(path):
    name = os.path.basename(path)
    try:
        return int(name[len("particles_"):-len(".h5")])
    except ValueError:
        return -1


def section_snapshot(out):
    files = sorted(glob.glob(os.path.join(out, "particles_*.h5")), key=snapshot_step)
    print("last snapshot:")
    if not files:
        print("  missing (no particles_*.h5)")
        return
    path = files[-1]
    try:
        import h5py  # noqa: imported here so the rest works without it
        import numpy as np
    except ImportError:
        print("  %s (h5py/numpy not available to read it)" % os.path.basename(path))
        return
    try:
        with h5py.File(path, "r") as f:
            step = f.attrs.get("step")
            time = f.attrs.get("time")
            pos = np.asarray(f["position"]) if "position" in f else np.zeros((0, 3))
            rad = np.asarray(f["radius"]) if "radius" in f else np.zeros(0)
            ranks = np.asarray(f["rank"]) if "rank" in f else None
    except (OSError, KeyError) as e:
        print("  %s unreadable: %s" % (os.path.basename(path), e))
        return
    n = pos.shape[0] if pos.ndim == 2 else 0
    print("  %s (%d snapshots): step %s, t %s, %d particles" % (
        os.path.basename(path), len(files), fmt(step), fmt(time, "s"), n))
    if n:
        print("  z from %s to %s m; mean radius %s m (min %s, max %s)" % (
            fmt(pos[:, 2].min()), fmt(pos[:, 2].max()), fmt(rad.mean()), fmt(rad.min()),
            fmt(rad.max())))
        if ranks is not None and ranks.size:
            counts = np.bincount(ranks.astype(np.int64))
            print("  particles per rank: " + " ".join(str(c) for c in counts))


def section_walls(out):
    path = os.path.join(out, "walls.csv")
    if not os.path.exists(path):
        print("walls.csv: missing")
        return
    print("walls.csv:")
    try:
        header, data = read_csv(path)
    except (OSError, ValueError) as e:
        print("  unreadable: %s" % e)
        return
    if not data:
        print("  no rows")
        return
    row = data[-1]
    col = {h: i for i, h in enumerate(header)}
    names = []
    for h in header:
        if h.endswith("_fx"):
            names.append(h[:-3])
    print("  last row: step %s, t %s" % (fmt(row[col["step"]]) if "step" in col else "-",
                                         fmt(row[col["time"]], "s") if "time" in col else "-"))
    for w in names:
        def g(s):
            i = col.get(w + "_" + s)
            return row[i] if i is not None and i < len(row) else None
        print("  %-12s F = (%s, %s, %s) N   u = (%s, %s, %s) m" % (
            w, fmt(g("fx")), fmt(g("fy")), fmt(g("fz")), fmt(g("ux")), fmt(g("uy")),
            fmt(g("uz"))))
    try:
        total = [sum(float(row[col[w + "_f" + c]]) for w in names) for c in "xyz"]
        print("  all walls    F = (%s, %s, %s) N   (at rest this balances the particles' weight)"
              % tuple(fmt(v) for v in total))
    except (KeyError, ValueError, IndexError):
        pass


def csv_rows(out, name):
    """(header, rows) of OUTDIR/NAME, or None when the run has no such file (printed otherwise)."""
    path = os.path.join(out, name)
    if not os.path.exists(path):
        return None
    print("%s:" % name)
    try:
        header, data = read_csv(path)
    except (OSError, ValueError) as e:
        print("  unreadable: %s" % e)
        return None
    if not data:
        print("  no rows")
        return None
    return header, data


def number(x):
    try:
        return float(x)
    except ValueError:
        return None


def section_holds(out):
    """holds.csv (load holds, coupled holds): one line per hold, the held walls' target, stress and
    settlement, and what held it open."""
    path = os.path.join(out, "holds.csv")
    if not os.path.exists(path):
        return
    print("holds.csv:")
    try:
        with open(path, newline="") as f:  # (held_by is text: not read_csv)
            rows = [r for r in csv.reader(f) if r]
    except OSError as e:
        print("  unreadable: %s" % e)
        return
    if len(rows) < 2:
        print("  no rows")
        return
    col = {h.strip(): i for i, h in enumerate(rows[0])}
    walls = [h[:-len("_target")] for h in col if h.endswith("_target")]

    def get(r, name):
        i = col.get(name)
        return number(r[i]) if i is not None and i < len(r) else None

    for r in rows[1:]:
        parts = ["hold %s step %s" % (fmt(get(r, "hold")), fmt(get(r, "step"))),
                 "converged" if get(r, "converged") == 1 else "NOT converged",
                 "unbalanced %s" % fmt(get(r, "unbalanced"))]
        for w in walls:
            if get(r, w + "_stress") is not None and get(r, w + "_settlement") is not None:
                parts.append("%s %s / %s Pa, settlement %s m" % (
                    w, fmt(get(r, w + "_stress")), fmt(get(r, w + "_target")), fmt(get(r, w + "_settlement"))))
        held = r[col["held_by"]] if "held_by" in col and col["held_by"] < len(r) else ""
        if held not in ("", "none"):
            parts.append("held open by " + held)
        print("  " + ", ".join(parts))


def section_lab(out):
    """lab.csv (direct shear, triaxial): the first and last rows and the peak of the stress ratio."""
    got = csv_rows(out, "lab.csv")
    if not got:
        return
    header, data = got
    ratio = next((h for h in header if h in ("tau_over_sigma_n", "q_over_p")), None)
    print("  %d rows; columns %s" % (len(data), ", ".join(header[2:])))
    for label, row in (("last", data[-1]),):
        print("  %-5s " % label + ", ".join("%s %s" % (h, fmt(v)) for h, v in zip(header, row)))
    if ratio:
        i = header.index(ratio)
        k = max(range(len(data)), key=lambda j: data[j][i])
        print("  peak  %s %s at step %s" % (ratio, fmt(data[k][i]), fmt(data[k][0])))


def section_interface(out):
    """interface.csv (coupled runs): the grains' force on the structure at the last row."""
    got = csv_rows(out, "interface.csv")
    if not got:
        return
    header, data = got
    row = data[-1]
    col = {h: i for i, h in enumerate(header)}
    keys = [k for k in ("step", "hold", "fx", "fy", "fz", "interface_contacts", "dem_unbalanced",
                        "fe_unbalanced", "max_fe_displacement") if k in col]
    print("  %d rows; last: " % len(data) + ", ".join("%s %s" % (k, fmt(row[col[k]])) for k in keys))


def main(argv):
    if len(argv) != 2 or argv[1] in ("-h", "--help"):
        print(__doc__.strip())
        return 0 if len(argv) == 2 else 2
    system_python_fallback(["h5py", "numpy"])
    out = argv[1]
    if not os.path.isdir(out):
        print("summary: %s is not a directory" % out, file=sys.stderr)
        return 1
    print("fdem run in %s" % out)
    section_run(out)
    section_history(out)
    section_snapshot(out)
    section_walls(out)
    section_holds(out)
    section_lab(out)
    section_interface(out)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
