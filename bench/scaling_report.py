#!/usr/bin/python3
"""The ghost layer and traffic per rank, measured and modelled, and extrapolated to a 10 M-grain
bed on 64-1024 ranks (bench/scaling.sh, docs/performance.md#scaling-out).

    /usr/bin/python3 bench/scaling_report.py RUN_DIR [RUN_DIR ...] [--png FILE] [--json FILE]
        [--rate PARTICLE_STEPS_PER_S] [--latency S] [--bandwidth BYTES_PER_S]

Each RUN_DIR is a run of bench/ghosts.yaml (a uniform static cloud in a box) on some number of
ranks; its run.json "decomposition" gives each rank's owned particles, ghosts and bytes and
messages sent, its case.yaml the box, the sizes and the skin.

The model (stated, then checked against the runs): a rank's ghosts are the grains within the
ghost width w = 2 r_max + skin outside its subdomain on each side that has a neighbour, edges and
corners included (the exchange runs in three sweeps x, y, z): with subdomain sides a_d and
e_d = a_d + w (sides with a neighbour, each), ghosts = n (prod e_d - prod a_d), n the number density.
The process grid is fdem's (the fewest cut areas, partition/decomposition.cpp choose_grid). The
traffic per step is the measured bytes per ghost per step times the ghosts.

The extrapolation: a cube of N = 1e7 grains at porosity 0.4 (d 4-6 mm uniform, as the runs), on
P = 64 ... 1024 ranks; per step and rank the compute time is (N/P + G/2) / rate (rate: one core's
particle-steps per second; an owned-ghost pair is computed on both of its ranks, so a ghost costs
about half an owned grain), the communication time 2 messages per sweep direction with a
neighbour x latency + bytes / bandwidth, plus the step's one global reduction (an allreduce of
log2(P) latencies: exact::StepSums, docs/performance.md#collectives-per-step).
Efficiency = (N / rate) / (P x step time). Every assumption is printed next to the numbers.
"""
import argparse
import json
import math
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "scripts"))
from fdem_common import load_case  # noqa: E402

N_BIG = 1.0e7
POROSITY_BIG = 0.4
RANKS_BIG = (64, 128, 256, 512, 1024)


def choose_grid(P, L, min_width):
    """fdem's process grid: px*py*pz = P with the smallest total cut area, every side >= min_width."""
    best, best_area = None, math.inf
    for px in range(1, P + 1):
        if P % px:
            continue
        for py in range(1, P // px + 1):
            if (P // px) % py:
                continue
            pz = P // px // py
            if any(p > 1 and l / p < min_width for p, l in zip((px, py, pz), L)):
                continue
            area = (px - 1) * L[1] * L[2] + (py - 1) * L[0] * L[2] + (pz - 1) * L[0] * L[1]
            if area < best_area * (1 - 1e-12):
                best, best_area = (px, py, pz), area
    return best


def ghost_volumes(grid, L, w):
    """The ghost-shell volume of every rank (x fastest), as the model above."""
    a = [l / p for l, p in zip(L, grid)]
    out = []
    for k in range(grid[2]):
        for j in range(grid[1]):
            for i in range(grid[0]):
                e = [a[d] + w * ((c > 0) + (c < grid[d] - 1)) for d, c in enumerate((i, j, k))]
                out.append(e[0] * e[1] * e[2] - a[0] * a[1] * a[2])
    return out


def load(d):
    j = json.load(open(os.path.join(d, "run.json")))
    case = load_case(os.path.join(d, "case.yaml"))
    gen = case["particles"][0]["generate"]
    lo, hi = gen["box"]["min"], gen["box"]["max"]
    L = [h - l for h, l in zip(hi, lo)]
    rmax = 0.5 * float(gen["size"]["max"])
    skin = float((case.get("neighbor") or {}).get("skin", 0))
    dec = j["decomposition"]
    return {"dir": d, "P": j["ranks"], "steps": j["steps"] - j.get("start_step", 0), "N": j["particles"]["final"],
            "L": L, "w": 2 * rmax + skin, "grid": dec["grid"], "ranks": dec["ranks"], "size": gen["size"]}


def mean_d3(size):
    lo, hi = float(size["min"]), float(size["max"])
    return (hi ** 4 - lo ** 4) / (4 * (hi - lo))   # E[d^3] of a uniform distribution


def main(argv):
    ap = argparse.ArgumentParser(prog="scaling_report.py", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("runs", nargs="+")
    ap.add_argument("--png")
    ap.add_argument("--json")
    ap.add_argument("--rate", type=float, default=6.0e6, help="one core's particle-steps/s (default 6e6: "
                    "the dense-bed benchmark on 1 rank, docs/performance.md)")
    ap.add_argument("--latency", type=float, default=2e-6, help="per message, s (default 2e-6: an InfiniBand-class network)")
    ap.add_argument("--bandwidth", type=float, default=10e9, help="per rank, bytes/s (default 10e9)")
    a = ap.parse_args(argv[1:])
    runs = sorted((load(d) for d in a.runs), key=lambda r: r["P"])
    out = {"measured": [], "extrapolated": [], "assumptions": {}}
    print("Measured (static cloud, %d grains, box %s m, ghost width %.4f m):"
          % (runs[0]["N"], " x ".join("%g" % x for x in runs[0]["L"]), runs[0]["w"]))
    print("%5s %9s %10s %10s %10s %9s %12s %10s %9s" % ("P", "grid", "owned", "ghosts", "model", "ratio",
                                                       "ghost frac", "B/step", "msg/step"))
    bpg = []
    for r in runs:
        n = r["N"] / (r["L"][0] * r["L"][1] * r["L"][2])
        grid_f = choose_grid(r["P"], r["L"], r["w"])
        if list(grid_f) != list(r["grid"]):
            print("scaling_report: %s: fdem chose grid %s, the model %s" % (r["dir"], r["grid"], grid_f), file=sys.stderr)
            return 1
        model = [n * v for v in ghost_volumes(r["grid"], r["L"], r["w"])]
        g = [q["ghosts"] for q in r["ranks"]]
        own = [q["owned"] for q in r["ranks"]]
        bps = [q["bytes_sent"] / r["steps"] for q in r["ranks"]]
        mps = [q["messages"] / r["steps"] for q in r["ranks"]]
        gm, mm = sum(g) / len(g), sum(model) / len(model)
        if gm > 0:
            bpg.append(sum(bps) / sum(g))
        row = {"P": r["P"], "grid": r["grid"], "owned_mean": sum(own) / len(own), "ghosts_mean": gm, "ghosts_max": max(g),
               "model_mean": mm, "ratio": gm / mm if mm else 1.0, "ghost_fraction": gm / (sum(own) / len(own)),
               "bytes_per_step_max": max(bps), "messages_per_step": max(mps)}
        out["measured"].append(row)
        print("%5d %9s %10.0f %10.0f %10.0f %9s %11.1f%% %10.0f %9.2f"
              % (r["P"], "x".join(map(str, r["grid"])), row["owned_mean"], gm, mm,
                 "%.3f" % row["ratio"] if mm else "-", 100 * row["ghost_fraction"], max(bps), max(mps)))
    bytes_per_ghost = sum(bpg) / len(bpg) if bpg else 0.0
    ratios = [m["ratio"] for m in out["measured"] if m["model_mean"] > 0]
    k = sum(ratios) / len(ratios) if ratios else 1.0
    print("bytes sent per ghost per step (mean over the runs): %.1f; measured / model ghosts: %.3f (mean)"
          % (bytes_per_ghost, k))
    # the 10 M bed
    r0 = runs[0]
    d3 = mean_d3(r0["size"])
    n_big = (1 - POROSITY_BIG) / (math.pi / 6 * d3)
    side = (N_BIG / n_big) ** (1.0 / 3.0)
    L = [side] * 3
    w = r0["w"]
    out["assumptions"] = {"N": N_BIG, "porosity": POROSITY_BIG, "cube_side_m": side, "ghost_width_m": w,
                          "rate_particle_steps_per_s_per_core": a.rate, "latency_s": a.latency,
                          "bandwidth_bytes_per_s": a.bandwidth, "bytes_per_ghost_per_step": bytes_per_ghost,
                          "model_correction": k}
    print("\nExtrapolated: %.0f grains (d %g-%g mm uniform) at porosity %.2f in a cube of %.3f m; ghost width %.4f m;"
          % (N_BIG, 1e3 * float(r0["size"]["min"]), 1e3 * float(r0["size"]["max"]), POROSITY_BIG, side, w))
    print("  one core %.3g particle-steps/s; a ghost costs half an owned grain; %.3g s per message, %.3g bytes/s per "
          "rank; one allreduce per step (log2(P) latencies); %.1f bytes per ghost per step (measured); ghosts = model x "
          "%.3f (measured)"
          % (a.rate, a.latency, a.bandwidth, bytes_per_ghost, k))
    print("%6s %10s %10s %10s %10s %12s %11s %11s %11s %6s" % ("P", "grid", "owned", "ghosts", "ghost frac",
                                                              "MB/step", "compute ms", "comm ms", "step ms", "eff"))
    t1 = N_BIG / a.rate
    for P in RANKS_BIG:
        grid = choose_grid(P, L, w)
        vols = ghost_volumes(grid, L, w)
        G = k * n_big * max(vols)                 # the busiest rank: an interior one
        own = N_BIG / P
        nb = sum(2 if p > 2 else (1 if p == 2 else 0) for p in grid)    # neighbours of an interior rank per sweep
        comp = (own + 0.5 * G) / a.rate
        comm = 2 * nb * a.latency + G * bytes_per_ghost / a.bandwidth + math.log2(P) * a.latency
        step = comp + comm
        eff = t1 / (P * step)
        row = {"P": P, "grid": list(grid), "owned": own, "ghosts": G, "ghost_fraction": G / own,
               "bytes_per_step": G * bytes_per_ghost, "compute_s": comp, "comm_s": comm, "step_s": step, "efficiency": eff}
        out["extrapolated"].append(row)
        print("%6d %10s %10.0f %10.0f %9.1f%% %12.2f %11.2f %11.3f %11.2f %5.0f%%"
              % (P, "x".join(map(str, grid)), own, G, 100 * G / own, G * bytes_per_ghost / 1e6, 1e3 * comp, 1e3 * comm,
                 1e3 * step, 100 * eff))
    if a.json:
        with open(a.json, "w") as f:
            json.dump(out, f, indent=1)
    if a.png:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(1, 2, figsize=(11, 4.2))
        m = out["measured"]
        ax[0].plot([q["P"] for q in m], [100 * q["ghost_fraction"] for q in m], "o", label="measured (static cloud)")
        ax[0].plot([q["P"] for q in m], [100 * q["model_mean"] / q["owned_mean"] for q in m], "x", label="model")
        ax[0].set_xlabel("ranks")
        ax[0].set_ylabel("ghosts / owned grains (%)")
        ax[0].set_title("%d grains: ghost fraction per rank" % runs[0]["N"])
        ax[0].legend()
        e = out["extrapolated"]
        ax[1].semilogx([q["P"] for q in e], [100 * q["efficiency"] for q in e], "o-", base=2, label="efficiency")
        ax[1].semilogx([q["P"] for q in e], [100 * q["ghost_fraction"] for q in e], "s--", base=2, label="ghost fraction")
        ax[1].set_xlabel("ranks")
        ax[1].set_ylabel("%")
        ax[1].set_title("10 M grains, extrapolated (assumptions in the text)")
        ax[1].legend()
        fig.tight_layout()
        fig.savefig(a.png, dpi=110)
        print("wrote %s" % a.png)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
