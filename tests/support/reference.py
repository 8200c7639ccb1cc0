#!/usr/bin/env python3
"""Reference results: a CI case's headline numbers against tests/reference/<case>.json.

A case's test (tests/cli_*.sh) runs the case, writes the numbers its case page reports to a JSON
object {name: value}, and calls

  reference.py check CASE NUMBERS.json      compare; print a table (number, reference, got,
                                            tolerance, verdict); exit 1 if one is outside its
                                            tolerance, missing, new, or has no sourced tolerance
  reference.py check CASE NUMBERS.json --update
                                            (or FDEM_REFERENCE_UPDATE=1 in the environment, as
                                            `make update-references` sets it) rewrite the
                                            reference's values from this run, keeping each
                                            number's tolerance and its source; a new number gets
                                            no tolerance, which fails the next check until one is
                                            measured: a change of the physics is a reviewed diff
  reference.py pick REPORT.csv NUMBERS.json NAME[=COLUMN] ...
                                            a report's CSV (its first row) as the numbers: each
                                            NAME from COLUMN (default: the same name)
  reference.py spread CASE SEED_1.json SEED_2.json ... [--write FACTOR]
                                            the numbers of the same case packed with other seeds
                                            (FDEM_REFERENCE_SEED=s: the test packs with seed s and
                                            leaves its numbers in FDEM_REFERENCE_KEEP): range and
                                            standard deviation per number; --write sets each
                                            tolerance to FACTOR x the range (at least the floor
                                            below) with the seeds, range and date as its source

Tolerances (docs/verification.md, "Reference results"): a DEM run is chaotic, so a change that only
reorders a floating-point sum (a refactor, another compiler) gives another realisation of the same
packing; the spread over packing seeds is the scale of such a change, and a tolerance of 2 x the
range of 4 packings (the reference's seed and 3 more: about 4 standard deviations; the
difference of two realisations has sqrt(2) of one's) passes a rounding change and fails a change of the physics larger than the packing's own
scatter. Numbers that no dynamics decides (counts fixed by the mesh, closed forms) are "exact".
"""
import argparse
import datetime
import json
import math
import os
import platform
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
# (FDEM_REFERENCE_DIR: another directory, for the tool's own test, tests/cli_reference.sh)
REFERENCE_DIR = os.environ.get("FDEM_REFERENCE_DIR") or os.path.join(os.path.dirname(HERE), "reference")
KINDS = ("abs", "rel", "exact")


def reference_path(case):
    return os.path.join(REFERENCE_DIR, case + ".json")


def load_reference(case):
    path = reference_path(case)
    if not os.path.exists(path):
        return {"case": case, "runs": "", "numbers": []}
    with open(path) as f:
        return json.load(f)


def save_reference(ref):
    with open(reference_path(ref["case"]), "w") as f:
        json.dump(ref, f, indent=2)
        f.write("\n")


def allowed(entry):
    """The largest |got - reference| the entry's tolerance allows (None: no tolerance yet)."""
    tol, kind = entry.get("tolerance"), entry.get("kind")
    if kind == "exact":
        return 0.0
    if tol is None or kind not in KINDS:
        return None
    return tol * abs(entry["value"]) if kind == "rel" else tol


def judge(entry, got):
    """(verdict, allowed difference) of one number."""
    if got is None:
        return "MISSING (the run did not produce it)", None
    if entry.get("value") is None:
        return "NEW (not in the reference)", None
    lim = allowed(entry)
    if lim is None:
        return "NO TOLERANCE (measure one: reference.py spread)", None
    if not (isinstance(got, (int, float)) and math.isfinite(got)):
        return "NOT A NUMBER", lim
    return ("ok" if abs(got - entry["value"]) <= lim else "FAIL"), lim


def fmt(x):
    return "-" if x is None else "%.6g" % x


def tolerance_text(entry, lim):
    if entry.get("kind") == "exact":
        return "exact"
    if lim is None:
        return "-"
    return "+-%s%s" % (fmt(lim), " (%.3g %%)" % (100 * entry["tolerance"]) if entry.get("kind") == "rel" else "")


def print_table(case, rows):
    print("reference results: %s (%s)" % (case, reference_path(case)))
    w = max([len("number")] + [len(r[0]) for r in rows])
    print("  %-*s %14s %14s %22s  %s" % (w, "number", "reference", "got", "tolerance", "verdict"))
    for name, ref, got, tol, verdict in rows:
        print("  %-*s %14s %14s %22s  %s" % (w, name, fmt(ref), fmt(got), tol, verdict))


def check(case, numbers, update, runs=""):
    ref = load_reference(case)
    entries = {e["name"]: e for e in ref["numbers"]}
    names = [e["name"] for e in ref["numbers"]] + [n for n in numbers if n not in entries]
    rows, bad = [], 0
    for name in names:
        entry = entries.get(name, {"name": name, "value": None})
        got = numbers.get(name)
        verdict, lim = judge(entry, got)
        bad += verdict != "ok"
        rows.append((name, entry.get("value"), got, tolerance_text(entry, lim), verdict))
    print_table(case, rows)
    if update:
        kept = []
        for name in names:
            if name not in numbers:
                continue  # a number the case no longer reports leaves the reference
            old = entries.get(name, {"tolerance": None, "kind": None, "source": "not yet measured (reference.py spread)"})
            entry = {"name": name, "value": numbers[name]}
            entry.update({k: v for k, v in old.items() if k not in entry})
            kept.append(entry)
        ref["numbers"] = kept
        if runs:
            ref["runs"] = runs
        ref["updated"] = "%s, %s" % (datetime.date.today().isoformat(), platform.processor() or platform.machine())
        save_reference(ref)
        unsourced = [e["name"] for e in kept if allowed(e) is None]
        print("updated %s%s" % (reference_path(case), "; no tolerance yet for: " + ", ".join(unsourced)
                                if unsourced else ""))
        return 1 if unsourced else 0
    print("%d of %d numbers outside the reference or unjudged" % (bad, len(rows)) if bad else
          "all %d numbers within their tolerances" % len(rows))
    return 1 if bad else 0


def round_up(x):
    """x rounded up to 3 significant digits (a tolerance is read by people)."""
    if x <= 0:
        return x
    scale = 10.0 ** (math.floor(math.log10(x)) - 2)
    return float("%.3g" % (math.ceil(x / scale - 1e-9) * scale))


def spread(case, files, factor):
    runs = []
    for path in files:
        with open(path) as f:
            runs.append(json.load(f))
    ref = load_reference(case)
    entries = {e["name"]: e for e in ref["numbers"]}
    seeds = ", ".join(os.path.basename(p).rsplit("_seed", 1)[-1].replace(".json", "") for p in files)
    print("spread of %s over the reference's run and %d more (%s)" % (case, len(runs), ", ".join(os.path.basename(p) for p in files)))
    print("  %-28s %12s %12s %12s %12s" % ("number", "min", "max", "range", "sd"))
    for name in sorted(set().union(*runs), key=lambda n: list(entries).index(n) if n in entries else 1e9):
        # the reference's own run (the case's seed) is one more member of the set
        vals = [r[name] for r in runs if name in r] + ([entries[name]["value"]] if name in entries else [])
        mean = sum(vals) / len(vals)
        sd = math.sqrt(sum((v - mean) ** 2 for v in vals) / max(1, len(vals) - 1))
        lo, hi = min(vals), max(vals)
        print("  %-28s %12.6g %12.6g %12.6g %12.6g" % (name, lo, hi, hi - lo, sd))
        e = entries.get(name)
        if factor and e is not None and e.get("kind") != "exact":
            floor = 1e-9 * max(1.0, abs(e["value"]))
            e["tolerance"], e["kind"] = round_up(max(factor * (hi - lo), floor)), "abs"
            e["source"] = "%g x the range of %d packings: the case's seed and seeds %s (%.6g .. %.6g; %s)" % (
                factor, len(vals), seeds, lo, hi, datetime.date.today().isoformat())
    if factor:
        save_reference(ref)
        print("wrote the tolerances into %s" % reference_path(case))
    return 0


def pick(csv_path, out_path, specs):
    import csv
    with open(csv_path) as f:
        row = next(csv.DictReader(f))
    numbers = {}
    for spec in specs:
        name, _, col = spec.partition("=")
        col = col or name
        if col not in row:
            print("reference.py pick: %s has no column '%s'" % (csv_path, col), file=sys.stderr)
            return 1
        numbers[name] = float(row[col])
    if os.path.exists(out_path):  # add to the numbers the test wrote itself
        with open(out_path) as f:
            numbers = {**json.load(f), **numbers}
    with open(out_path, "w") as f:
        json.dump(numbers, f, indent=1)
    return 0


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    c = sub.add_parser("check", help="compare a run's numbers with the case's reference")
    c.add_argument("case")
    c.add_argument("numbers")
    c.add_argument("--update", action="store_true", help="rewrite the reference's values from this run")
    c.add_argument("--runs", default="", help="what produces the numbers (kept in the reference by --update)")
    s = sub.add_parser("spread", help="the numbers' spread over packing seeds")
    s.add_argument("case")
    s.add_argument("files", nargs="+")
    s.add_argument("--write", type=float, default=0.0, metavar="FACTOR",
                   help="set each tolerance to FACTOR x the range (2 for four packings)")
    p = sub.add_parser("pick", help="numbers from a report's CSV")
    p.add_argument("csv")
    p.add_argument("out")
    p.add_argument("specs", nargs="+")
    a = ap.parse_args(argv)
    if a.cmd == "pick":
        return pick(a.csv, a.out, a.specs)
    if a.cmd == "spread":
        return spread(a.case, a.files, a.write)
    with open(a.numbers) as f:
        numbers = json.load(f)
    update = a.update or os.environ.get("FDEM_REFERENCE_UPDATE", "") not in ("", "0")
    return check(a.case, numbers, update, a.runs)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
