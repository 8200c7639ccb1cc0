#!/usr/bin/python3
"""Realization scatter of pullout runs: the same case packed with different seeds.

    /usr/bin/python3 scripts/pullout_scatter.py OUT_DIR [OUT_DIR ...] [--csv FILE]

Reads OUT_DIR/pullout.csv (written by scripts/pullout_report.py) and OUT_DIR/case.yaml of each
run, groups the runs by the servo stress of their case (walls[*].motion.servo.stress), and prints
per group and per hold (same clamp displacement in every run of the group): the number of runs,
the mean, standard deviation, minimum and maximum of the clamp force per metre of width, the
mean, minimum and maximum of F_f's share and of the share of F_bt on the first two transverse
ribs (SS-1: the first 0.06 m, thesis fig. 4-14), and the holds that did not converge. With two groups it prints, per hold, the ratio
of the higher stress's mean force to the lower's and the range of the per-seed ratios (runs of
the two groups paired by packing.seed where both have it).

A granular specimen is chaotic: another seed, or any change of the floating-point summation
order in the packing, gives another realization of the same specimen. This script says how far
apart those realizations are, so a difference between two cases can be read against it.
--csv FILE writes the per-group, per-hold table. Exit 2 on bad input.
"""
import argparse
import csv
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from fdem_common import load_case, servo_target  # noqa: E402

PROG = "pullout_scatter.py"


class ScatterError(Exception):
    pass


def read_case(path):
    try:
        return load_case(path) or {}
    except OSError as e:
        raise ScatterError("%s: %s" % (path, e.strerror))
    except ValueError as e:
        raise ScatterError("%s: not YAML: %s" % (path, e))


def servo_stress(case, path):
    stress = servo_target(case)
    if stress is None:
        raise ScatterError("%s: no servo wall with a stress" % path)
    return stress


def load(run_dir):
    case_path = os.path.join(run_dir, "case.yaml")
    table = os.path.join(run_dir, "pullout.csv")
    case = read_case(case_path)
    if not os.path.isfile(table):
        raise ScatterError("%s: missing (run scripts/pullout_report.py %s first)" % (table, run_dir))
    rows = {}
    with open(table, newline="") as f:
        reader = csv.DictReader(f)
        need = ("hold", "clamp_displacement_mm", "clamp_force_kN_per_m", "F_f_share", "F_bt_N",
                "rib1_bearing_N", "rib2_bearing_N", "converged")
        missing = [c for c in need if c not in (reader.fieldnames or [])]
        if missing:
            raise ScatterError("%s: no column %s" % (table, ", ".join(missing)))
        for line, r in enumerate(reader, start=2):
            try:
                h = int(r["hold"])
                fbt = float(r["F_bt_N"])
                front = (float(r["rib1_bearing_N"]) + float(r["rib2_bearing_N"])) / fbt if fbt > 0 else float("nan")
                rows[h] = {"u": float(r["clamp_displacement_mm"]), "f": float(r["clamp_force_kN_per_m"]),
                           "share": float(r["F_f_share"]), "front": front, "conv": r["converged"].strip() == "1"}
            except ValueError:
                raise ScatterError("%s:%d: not a number" % (table, line))
    seed = (case.get("packing") or {}).get("seed")
    return {"dir": run_dir, "stress": servo_stress(case, case_path), "seed": seed, "rows": rows}


def stats(values):
    n = len(values)
    mean = sum(values) / n
    sd = math.sqrt(sum((v - mean) ** 2 for v in values) / (n - 1)) if n > 1 else float("nan")
    return mean, sd, min(values), max(values)


def stats_of(values):
    finite = [v for v in values if not math.isnan(v)]
    return stats(finite) if finite else (float("nan"),) * 4


def group_table(runs):
    """Per hold present in every run with the same clamp displacement: the statistics."""
    holds = sorted(set.intersection(*(set(r["rows"]) for r in runs)))
    out = []
    for h in holds:
        us = [r["rows"][h]["u"] for r in runs]
        if max(us) - min(us) > 1e-6:
            raise ScatterError("hold %d: clamp displacement differs between runs (%s mm)"
                               % (h, ", ".join("%g" % u for u in us)))
        f = stats([r["rows"][h]["f"] for r in runs])
        s = stats_of([r["rows"][h]["share"] for r in runs])
        front = stats_of([r["rows"][h]["front"] for r in runs])
        bad = [os.path.basename(os.path.normpath(r["dir"])) for r in runs if not r["rows"][h]["conv"]]
        out.append({"hold": h, "u": us[0], "n": len(runs), "f": f, "share": s, "front": front,
                    "not_converged": bad})
    return out


def main(argv):
    ap = argparse.ArgumentParser(prog=PROG, description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("runs", nargs="+", metavar="OUT_DIR")
    ap.add_argument("--csv", help="write the per-group, per-hold table here")
    a = ap.parse_args(argv[1:])
    try:
        runs = [load(d) for d in a.runs]
        groups = {}
        for r in runs:
            groups.setdefault(r["stress"], []).append(r)
        tables = {s: group_table(g) for s, g in sorted(groups.items())}
    except ScatterError as e:
        print("%s: %s" % (PROG, e), file=sys.stderr)
        return 2
    csv_rows = []
    for s, t in tables.items():
        g = groups[s]
        print("\n== sigma_v %.0f kPa: %d run(s) (seeds %s)" % (s / 1000, len(g),
              ", ".join(str(r["seed"]) for r in g)))
        print("hold  Ux(mm)  kN/m mean    sd   min    max  cv%   F_f% mean  min  max   ribs1-2% mean  min  max"
              "  not converged")
        for e in t:
            m, sd, lo, hi = e["f"]
            sm, _, slo, shi = e["share"]
            cv = 100 * sd / m if m and not math.isnan(sd) else float("nan")
            fm, _, flo, fhi = e["front"]
            print("%4d  %6.2f  %9.2f %5.2f %5.2f %6.2f %4.0f   %9.0f %4.0f %4.0f   %13.0f %4.0f %4.0f  %s"
                  % (e["hold"], e["u"], m, sd, lo, hi, cv, 100 * sm, 100 * slo, 100 * shi,
                     100 * fm, 100 * flo, 100 * fhi, ", ".join(e["not_converged"]) or "-"))
            csv_rows.append([s / 1000, e["hold"], e["u"], e["n"], m, sd, lo, hi, sm, slo, shi,
                             fm, flo, fhi, len(e["not_converged"])])
    if len(tables) == 2:
        (s_lo, t_lo), (s_hi, t_hi) = tables.items()
        lo_by_hold = {e["hold"]: e for e in t_lo}
        by_seed_lo = {r["seed"]: r for r in groups[s_lo] if r["seed"] is not None}
        print("\n== %.0f against %.0f kPa, per hold: ratio of the mean forces (per-seed ratios: min .. max)"
              % (s_hi / 1000, s_lo / 1000))
        for e in t_hi:
            b = lo_by_hold.get(e["hold"])
            if b is None or e["hold"] < 1 or not b["f"][0]:
                continue
            pairs = [r["rows"][e["hold"]]["f"] / by_seed_lo[r["seed"]]["rows"][e["hold"]]["f"]
                     for r in groups[s_hi] if r["seed"] in by_seed_lo
                     and e["hold"] in by_seed_lo[r["seed"]]["rows"]
                     and by_seed_lo[r["seed"]]["rows"][e["hold"]]["f"]]
            rng = " (%d pairs: %.2f .. %.2f)" % (len(pairs), min(pairs), max(pairs)) if pairs else ""
            print("hold %2d  %5.2f mm  %.2f%s" % (e["hold"], e["u"], e["f"][0] / b["f"][0], rng))
    if a.csv:
        try:
            with open(a.csv, "w", newline="") as f:
                w = csv.writer(f)
                w.writerow(["sigma_v_kPa", "hold", "clamp_displacement_mm", "runs", "kN_per_m_mean",
                            "kN_per_m_sd", "kN_per_m_min", "kN_per_m_max", "F_f_share_mean",
                            "F_f_share_min", "F_f_share_max", "ribs12_share_mean", "ribs12_share_min",
                            "ribs12_share_max", "not_converged"])
                for r in csv_rows:
                    w.writerow(["%.9g" % v if isinstance(v, float) else v for v in r])
        except OSError as e:
            print("%s: cannot write %s: %s" % (PROG, a.csv, e.strerror), file=sys.stderr)
            return 2
        print("\nwrote %s" % a.csv)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
