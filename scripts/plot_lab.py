#!/usr/bin/env python3
"""Plot the laboratory tests of fdem runs (lab.csv, docs/user-guide.md#laboratory-tests).

Usage: python3 scripts/plot_lab.py OUTDIR [OUTDIR ...] [--from-step N] [--png FILE]

Direct shear (lab.csv with a `tau` column): shear stress tau against shear displacement and the
vertical displacement of the top plate (dilation) for every OUTDIR (e.g. one per normal stress);
with two or more runs also the Mohr-Coulomb fit of the peak shear stresses (macro friction angle
and intercept). Triaxial (lab.csv with a `q` column): deviator stress q and volumetric strain
eps_v against axial strain eps_a, both measured from the start of axial loading: --from-step N,
or by default the last row before the peak of q where q is still below 2 % of p (the end of the
isotropic stage); the peak friction angle of each run and, with two or more runs (e.g. one per
confining stress), the Mohr-Coulomb fit of the peak circles. Writes OUTDIR/lab.png (or --png FILE) and prints the key numbers.
Needs Debian's python3-matplotlib.
"""
import csv
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from fdem_common import mohr_coulomb_fit, read_csv, system_python_fallback, triaxial_peak  # noqa: E402



system_python_fallback(["matplotlib"])
import matplotlib  # noqa: E402

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402



def direct_shear(dirs, cols, png):
    fig, (ax1, ax2) = plt.subplots(2, 1, sharex=True, figsize=(7, 7))
    peaks = []
    for d, c in zip(dirs, cols):
        # Shearing: from the last row before the shear displacement starts.
        k0 = max(0, next((k for k, u in enumerate(c["shear_displacement"]) if u > 1e-9), 1) - 1)
        u = [1e3 * (x - c["shear_displacement"][k0]) for x in c["shear_displacement"][k0:]]
        tau = [t / 1e3 for t in c["tau"][k0:]]
        dil = [1e3 * (x - c["normal_displacement"][k0]) for x in c["normal_displacement"][k0:]]
        sn = sum(c["sigma_n"][k0:]) / max(1, len(c["sigma_n"][k0:]))
        label = "%s, sigma_n %.1f kPa" % (os.path.basename(os.path.normpath(d)), sn / 1e3)
        ax1.plot(u, tau, label=label)
        ax2.plot(u, dil, label=label)
        kp = max(range(len(tau)), key=lambda k: tau[k])
        peaks.append((sn, 1e3 * tau[kp], u[kp]))
        print("%s: mean sigma_n %.0f Pa (min %.0f, max %.0f while shearing), peak tau %.0f Pa at %.2f mm,"
              " tau/sigma_n %.3f (%.1f deg)" % (d, sn, min(c["sigma_n"][k0 + 1:] or [sn]), max(c["sigma_n"][k0 + 1:] or [sn]),
                                                1e3 * tau[kp], u[kp], 1e3 * tau[kp] / sn,
                                                math.degrees(math.atan(1e3 * tau[kp] / sn))))
    ax1.set_ylabel("shear stress tau (kPa)")
    ax2.set_ylabel("vertical displacement (mm, + dilation)")
    ax2.set_xlabel("shear displacement (mm)")
    ax1.legend(fontsize=8)
    ax1.grid(True, alpha=0.3)
    ax2.grid(True, alpha=0.3)
    if len(peaks) >= 2:
        # Least-squares line tau = c + sigma tan(phi) through the peaks.
        n = len(peaks)
        sx = sum(p[0] for p in peaks); sy = sum(p[1] for p in peaks)
        sxx = sum(p[0] ** 2 for p in peaks); sxy = sum(p[0] * p[1] for p in peaks)
        slope = (n * sxy - sx * sy) / (n * sxx - sx * sx)
        icpt = (sy - slope * sx) / n
        print("Mohr-Coulomb fit of the peaks: friction angle %.1f deg, intercept %.0f Pa"
              % (math.degrees(math.atan(slope)), icpt))
        ax1.set_title("Mohr-Coulomb: phi %.1f deg, c %.2f kPa" % (math.degrees(math.atan(slope)), icpt / 1e3))
    fig.tight_layout()
    fig.savefig(png, dpi=120)


def triaxial(dirs, cols, png, from_step):
    """One or more triaxial runs (e.g. one per confining stress): q and eps_v against eps_a, the
    peak friction angle of each and, with two or more, the Mohr-Coulomb fit of the peaks."""
    fig, (ax1, ax2) = plt.subplots(2, 1, sharex=True, figsize=(7, 7))
    peaks = []
    for d, c in zip(dirs, cols):
        pk = triaxial_peak(c, from_step)
        peaks.append(pk)
        print("%s: axial loading from step %d (sigma_3 %.0f Pa); peak q %.0f Pa at eps_a %.2f %%"
              " (friction angle %.1f deg); eps_v at the end %.2f %% (compression +)"
              % (d, pk["step0"], pk["s3"], pk["q"], pk["eps_a_peak"], pk["phi"], pk["eps_v"][-1]))
        label = "%s: sigma_3 %.0f kPa, peak phi %.1f deg" % (os.path.basename(os.path.normpath(d)), pk["s3"] / 1e3,
                                                            pk["phi"])
        ax1.plot(pk["eps_a"], [x / 1e3 for x in c["q"][pk["k0"]:]], label=label)
        ax2.plot(pk["eps_a"], pk["eps_v"])
    fit = mohr_coulomb_fit(peaks) if len(peaks) >= 2 else None
    if fit:
        phi, coh = fit
        print("Mohr-Coulomb fit of the peaks (t = s sin phi + c cos phi): friction angle %.1f deg, cohesion %.2f kPa"
              % (phi, coh / 1e3))
        ax1.set_title("Mohr-Coulomb fit of the peaks: phi %.1f deg, c %.2f kPa" % (phi, coh / 1e3))
    ax1.legend(fontsize=8)
    ax1.set_ylabel("deviator stress q (kPa)")
    ax2.set_ylabel("volumetric strain eps_v (%, compression +)")
    ax2.set_xlabel("axial strain eps_a (%)")
    ax1.grid(True, alpha=0.3)
    ax2.grid(True, alpha=0.3)
    fig.tight_layout()
    fig.savefig(png, dpi=120)


def main(argv):
    args = argv[1:]
    if not args or "-h" in args or "--help" in args:
        print(__doc__.strip())
        return 0 if args else 2
    from_step, png, dirs = None, None, []
    k = 0
    while k < len(args):
        if args[k] == "--from-step":
            from_step = float(args[k + 1]); k += 2
        elif args[k] == "--png":
            png = args[k + 1]; k += 2
        else:
            dirs.append(args[k]); k += 1
    cols = []
    for d in dirs:
        path = os.path.join(d, "lab.csv")
        if not os.path.exists(path):
            print("plot_lab: %s is missing (does the case have a `lab` section?)" % path, file=sys.stderr)
            return 1
        cols.append(read_csv(path))
    png = png or os.path.join(dirs[0], "lab.png")
    if all("tau" in c for c in cols):
        direct_shear(dirs, cols, png)
    elif all("q" in c for c in cols):
        triaxial(dirs, cols, png, from_step)
    else:
        print("plot_lab: give one or more direct shear runs, or one or more triaxial runs", file=sys.stderr)
        return 2
    print("wrote %s" % png)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
