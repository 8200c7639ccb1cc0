#!/usr/bin/python3
"""Collect the benchmark runs of bench/run.sh, print the table, write bench/results/latest.{json,md}.

Usage: /usr/bin/python3 bench/report.py --n N --steps S --work bench/work --out bench/results
           [--lig-skipped REASON] [--lammps-skipped REASON] [--settle-info FILE]

Reads WORK/fdem_n1/run.json, WORK/fdem_n2/run.json (particle_steps_per_second, wall_time_s,
timings), WORK/fdem_space_n{1,2}/run.json if present (the same bed, ids in space order), WORK/liggghts_n{1,2}.log and WORK/lammps_n{1,2}.log (the line
`Loop time of X on P procs for S steps with N atoms` -> N*S/X particle-steps/s). fdem's speed per
core is set against each peer's and against the faster of the two at the same rank count.
"""
import argparse
import datetime
import json
import os
import re
import subprocess
import sys

SPACE = "fdem, ids in space order"
LOOP_RE = re.compile(r"Loop time of ([0-9.eE+-]+) on (\d+) procs for (\d+) steps with (\d+) atoms")


def cpu_info():
    model, cores = "unknown", os.cpu_count()
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    model = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    return model, cores


def git_commit():
    try:
        return subprocess.check_output(["git", "rev-parse", "HEAD"], text=True).strip()
    except Exception:
        return "unknown"


def fdem_result(d, ranks):
    path = os.path.join(d, "run.json")
    if not os.path.exists(path):
        return None
    with open(path) as f:
        rj = json.load(f)
    if rj.get("status") != "finished":
        sys.stderr.write(f"warning: {path}: status {rj.get('status')}\n")
    timings = rj.get("timings", {})
    loop = sum(timings.values())
    return {
        "code": "fdem", "ranks": rj.get("ranks", ranks), "steps": rj["steps"] - rj.get("start_step", 0),
        "particles": rj["particles"]["initial"], "particles_final": rj["particles"]["final"],
        "wall_time_s": rj["wall_time_s"], "particle_steps_per_second": rj["particle_steps_per_second"],
        "timings_s": timings, "stage_sum_s": loop, "source": path,
    }


def peer_result(log, ranks, code="LIGGGHTS"):
    """A LIGGGHTS or LAMMPS log: its 'Loop time' line and stage breakdown."""
    if not os.path.exists(log):
        return None
    with open(log, errors="replace") as f:
        text = f.read()
    m = LOOP_RE.search(text)
    if not m:
        return {"code": code, "ranks": ranks, "error": f"no 'Loop time' line in {log}"}
    x, p, s, n = float(m.group(1)), int(m.group(2)), int(m.group(3)), int(m.group(4))
    res = {"code": code, "ranks": p, "steps": s, "particles": n, "particles_final": n,
           "wall_time_s": x, "particle_steps_per_second": n * s / x, "source": log}
    # stage breakdown printed after the loop line: LIGGGHTS "Pair  time (%) = X (...)", LAMMPS
    # "Pair    | min | avg | max | %varavg | %total" (the average taken)
    stages = {}
    for name in ("Pair", "Neigh", "Comm", "Outpt", "Output", "Modify", "Other"):
        mm = re.search(rf"^{name}\s+time \(%\) = ([0-9.eE+-]+)", text, re.M) or \
            re.search(rf"^{name}\s*\|\s*[0-9.eE+-]+\s*\|\s*([0-9.eE+-]+)", text, re.M)
        if mm:
            stages[name.lower()] = float(mm.group(1))
    res["timings_s"] = stages
    mm = re.search(r"Neighbor list builds = (\d+)", text)
    if mm:
        res["neighbor_builds"] = int(mm.group(1))
    return res


def fmt(x, f="{:.3e}"):
    return "–" if x is None else f.format(x)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--n", type=int, required=True)
    ap.add_argument("--steps", type=int, required=True)
    ap.add_argument("--work", default="bench/work")
    ap.add_argument("--out", default="bench/results")
    ap.add_argument("--lig-skipped", default="")
    ap.add_argument("--lammps-skipped", default="")
    ap.add_argument("--settle-info", default="")
    a = ap.parse_args()

    rows = []
    for p in (1, 2):
        r = fdem_result(os.path.join(a.work, f"fdem_n{p}"), p)
        if r:
            rows.append(r)
    for p in (1, 2):  # the same bed, ids renumbered in space order (bench/spheres_space_order.py)
        r = fdem_result(os.path.join(a.work, f"fdem_space_n{p}"), p)
        if r:
            r["code"] = SPACE
            rows.append(r)
    if not a.lig_skipped:
        for p in (1, 2):
            r = peer_result(os.path.join(a.work, f"liggghts_n{p}.log"), p, "LIGGGHTS")
            if r:
                rows.append(r)
    if not a.lammps_skipped:
        for p in (1, 2):
            r = peer_result(os.path.join(a.work, f"lammps_n{p}.log"), p, "LAMMPS")
            if r:
                rows.append(r)

    def get(code, p):
        for r in rows:
            if r["code"] == code and r["ranks"] == p and "error" not in r:
                return r
        return None

    ok = [r for r in rows if "error" not in r]
    for r in ok:
        r["per_core"] = r["particle_steps_per_second"] / r["ranks"]
    for r in ok:
        one = get(r["code"], 1)
        r["parallel_efficiency"] = (r["particle_steps_per_second"] / (r["ranks"] * one["particle_steps_per_second"])
                                    if one else None)
        lig = get("LIGGGHTS", r["ranks"])
        lmp = get("LAMMPS", r["ranks"])
        fdem = r["code"] in ("fdem", SPACE)
        r["fdem_over_liggghts_per_core"] = r["per_core"] / lig["per_core"] if fdem and lig else None
        r["fdem_over_lammps_per_core"] = r["per_core"] / lmp["per_core"] if fdem and lmp else None
        peers = [q for q in (lig, lmp) if q]
        best = max(peers, key=lambda q: q["per_core"]) if peers else None
        r["fdem_over_faster_peer_per_core"] = r["per_core"] / best["per_core"] if fdem and best else None
        r["faster_peer"] = best["code"] if fdem and best else None

    model, cores = cpu_info()
    settle = {}
    if a.settle_info and os.path.exists(a.settle_info):
        with open(a.settle_info) as f:
            settle = json.load(f)
    result = {
        "date": datetime.datetime.now().isoformat(timespec="seconds"),
        "commit": git_commit(), "cpu": model, "cores": cores,
        "particles": a.n, "steps": a.steps, "settle": settle,
        "liggghts_skipped": a.lig_skipped or None, "lammps_skipped": a.lammps_skipped or None, "runs": rows,
    }

    head = ("| code | ranks | particles | steps | wall time (s) | particle-steps/s | per core | "
            "parallel eff. | fdem/LIGGGHTS per core | fdem/LAMMPS per core |")
    lines = [head, "|---|---|---|---|---|---|---|---|---|---|"]

    def ratio_cell(v):
        return "–" if v is None else f"{v:.2f}"
    for r in rows:
        if "error" in r:
            lines.append(f"| {r['code']} | {r['ranks']} | error: {r['error']} | | | | | | | |")
            continue
        eff = r.get("parallel_efficiency")
        lines.append(f"| {r['code']} | {r['ranks']} | {r['particles']} | {r['steps']} | {r['wall_time_s']:.2f} | "
                     f"{r['particle_steps_per_second']:.3e} | {r['per_core']:.3e} | "
                     f"{'–' if eff is None else f'{100 * eff:.1f} %'} | "
                     f"{ratio_cell(r.get('fdem_over_liggghts_per_core'))} | {ratio_cell(r.get('fdem_over_lammps_per_core'))} |")
    table = "\n".join(lines)

    stage_lines = []
    for r in rows:
        if r["code"] in ("fdem", SPACE) and "timings_s" in r:
            tot = r["wall_time_s"]
            parts = ", ".join(f"{k} {v:.2f} s ({100 * v / tot:.0f} %)" for k, v in r["timings_s"].items())
            stage_lines.append(f"- {r['code']} {r['ranks']} rank(s), wall {tot:.2f} s: {parts}; "
                               f"wall time minus the stage sum (setup, I/O): {tot - r['stage_sum_s']:.2f} s"
                               + (" (stage times are the slowest rank's, so their sum can exceed the wall time)"
                                  if r["ranks"] > 1 else ""))
        elif r["code"] in ("LIGGGHTS", "LAMMPS") and r.get("timings_s"):
            tot = r["wall_time_s"]
            parts = ", ".join(f"{k} {v:.2f} s" for k, v in r["timings_s"].items())
            stage_lines.append(f"- {r['code']} {r['ranks']} rank(s), loop {tot:.2f} s: {parts}; "
                               f"neighbour list builds {r.get('neighbor_builds', '?')}")

    print()
    print(f"Dense-state benchmark: {a.n} spheres, {a.steps} steps, {model}, {cores} cores, commit {result['commit'][:10]}")
    if a.lig_skipped:
        print(f"LIGGGHTS skipped: {a.lig_skipped}")
    if a.lammps_skipped:
        print(f"LAMMPS skipped: {a.lammps_skipped}")
    print(table)
    print()
    print("\n".join(stage_lines))
    print("(fdem: wall_time_s from run.json, includes setup, first/last snapshot and final checkpoint;"
          " LIGGGHTS, LAMMPS: 'Loop time', the run loop only)")

    os.makedirs(a.out, exist_ok=True)
    with open(os.path.join(a.out, "latest.json"), "w") as f:
        json.dump(result, f, indent=2)
        f.write("\n")
    with open(os.path.join(a.out, "latest.md"), "w") as f:
        f.write(f"# Dense-state benchmark, {result['date']}\n\n")
        f.write(f"{a.n} spheres, {a.steps} measured steps; {model}, {cores} cores; commit {result['commit']}\n\n")
        if a.lig_skipped:
            f.write(f"LIGGGHTS skipped: {a.lig_skipped}\n\n")
        if a.lammps_skipped:
            f.write(f"LAMMPS skipped: {a.lammps_skipped}\n\n")
        if settle:
            f.write(f"Settled state: {json.dumps(settle)}\n\n")
        f.write(table + "\n\n")
        f.write("\n".join(stage_lines) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
