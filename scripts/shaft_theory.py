#!/usr/bin/python3
"""Analytical active earth pressure on a cylindrical shaft in dry sand (thesis fig 3-17):
p / (a gamma) against the depth h / a for a smooth shaft of radius a, soil friction phi and the
earth pressure coefficient on radial planes lambda (sigma_theta = lambda sigma_v).

    /usr/bin/python3 scripts/shaft_theory.py --check        # the limits below, asserted; exit 1 if not
    /usr/bin/python3 scripts/shaft_theory.py --phi 41 [--lam 0.344]   # a table against h/a

Two families, both written out here from their mechanics (docs/cases/shaft.md#analytical-solutions):

Prater (1977): a Coulomb wedge whose sliding surface is a cone rising at alpha from the shaft's foot
at depth z to the surface. Per radian about the axis, with c = cot alpha:
  weight   W = gamma (a c z^2 / 2 + c^2 z^3 / 6)
  hoop     T = lambda gamma c z^3 / 6   (the radial planes' sigma_theta = lambda gamma y over the
             wedge's section; the two faces dtheta apart push the wedge away from the shaft)
  thrust   P(z) = max over alpha of  W tan(alpha - phi) - T
and the pressure p(z) = P'(z) / a (the maximising alpha held, the envelope theorem), set to 0 where
P falls with depth. Limits: z << a gives Rankine's Ka gamma z; a -> infinity gives Coulomb's (= Rankine's,
smooth vertical wall) thrust Ka gamma z^2 / 2 per unit length; with lambda = K0 = 1 - sin phi, p falls
to 0 at h/a 8.5 for phi 33-41 deg (the thesis: "zero earth pressure at h/a of about 9").

Slip-line family (Berezantzev 1958, lambda = 1; Cheng & Hu 2005's general lambda): with
t = tan(45 - phi/2), b = a + h t (the radius at which the slip line through the wall point at depth
h reaches the surface) and eta = 2 lambda tan(phi) tan(45 + phi/2),
  p = gamma a t / (eta - 1) [1 - (a / b)^(eta - 1)]        (eta = 1: gamma a t ln(b / a))
This is the closed form as it is usually quoted for Berezantzev (lambda = 1); the lambda in eta is
our reading of Cheng & Hu's generalisation, not checked against their paper. Limits: at the surface
p -> Ka gamma h; lambda = 0 (no hoop stress) gives Rankine's Ka gamma h at every depth; for
eta > 1 p tends to gamma a t / (eta - 1) with depth (Berezantzev's nearly uniform pressure), for
eta < 1 it keeps growing (Cheng & Hu with lambda = K0: "a continuing increase with depth").
Terzaghi's (1943) solution is not drawn.
"""
import argparse
import math
import sys


def _rad(deg):
    return math.radians(deg)


def rankine_ka(phi):
    return math.tan(_rad(45 - phi / 2)) ** 2


def prater_thrust(z, a, phi, lam, n=4000):
    """P(z) / gamma per radian and the maximising alpha (deg): a grid over alpha in (phi, 90),
    refined once around the best."""
    tphi = _rad(phi)

    def val(al):
        c = 1 / math.tan(al)
        return (a * c * z * z / 2 + c * c * z ** 3 / 6) * math.tan(al - tphi) - lam * c * z ** 3 / 6

    lo, hi = tphi + 1e-9, _rad(90) - 1e-9
    best = None
    for _ in range(3):
        step = (hi - lo) / n
        cand = max((val(lo + k * step), lo + k * step) for k in range(n + 1))
        best = cand if best is None or cand[0] > best[0] else best
        lo, hi = max(tphi + 1e-9, best[1] - 2 * step), min(_rad(90) - 1e-9, best[1] + 2 * step)
    return best[0], math.degrees(best[1])


def prater_p(h, phi, lam, a=1.0):
    """p / (a gamma) at depth h a (h = depth / a) by Prater's cone: the derivative of the maximum
    thrust at the maximising alpha, 0 where the thrust falls with depth."""
    z = h * a
    _, al = prater_thrust(z, a, phi, lam)
    c = 1 / math.tan(_rad(al))
    dP = (a * c * z + c * c * z * z / 2) * math.tan(_rad(al - phi)) - lam * c * z * z / 2
    return max(dP / a, 0.0) / a


def slipline_p(h, phi, lam):
    """p / (a gamma) at depth h a: Berezantzev (lam = 1) / Cheng & Hu (general lam)."""
    t = math.tan(_rad(45 - phi / 2))
    eta = 2 * lam * math.tan(_rad(phi)) * math.tan(_rad(45 + phi / 2))
    rb = 1 + h * t  # b / a
    if abs(eta - 1) < 1e-12:
        return t * math.log(rb)
    return t / (eta - 1) * (1 - rb ** (1 - eta))


def curves(phi, lam_k0, h_max, n=60):
    """{label: (h list, p/(a gamma) list)}: the three the thesis draws besides Terzaghi's."""
    hs = [h_max * k / n for k in range(n + 1)]
    return {
        "Berezantzev (lambda = 1)": (hs, [slipline_p(h, phi, 1.0) for h in hs]),
        "Cheng & Hu (lambda = K0 %.2f)" % lam_k0: (hs, [slipline_p(h, phi, lam_k0) for h in hs]),
        "Prater (lambda = K0 %.2f)" % lam_k0: (hs, [prater_p(h, phi, lam_k0) for h in hs]),
    }


def check():
    """The limits the docstring names; returns a list of failures (empty: all hold)."""
    bad = []

    def near(name, got, want, rel):
        ok = abs(got - want) <= rel * abs(want)
        print("%-58s %10.5g  expected %10.5g  %s" % (name, got, want, "ok" if ok else "FAILED"))
        if not ok:
            bad.append(name)

    for phi in (30.0, 41.0):
        ka = rankine_ka(phi)
        k0 = 1 - math.sin(_rad(phi))
        near("Prater, phi %g: p/(a gamma) at h/a 0.01 vs Ka h" % phi, prater_p(0.01, phi, k0), ka * 0.01, 0.02)
        # a wall much wider than deep: Coulomb's thrust Ka z^2 / 2 per unit length of wall
        z, a = 1.0, 1e5
        near("Prater, phi %g: plane limit thrust / (a z^2/2) vs Ka" % phi,
             prater_thrust(z, a, phi, k0)[0] / (a * z * z / 2), ka, 1e-3)
        near("Prater, phi %g: Coulomb angle vs 45 + phi/2" % phi, prater_thrust(z, a, phi, k0)[1], 45 + phi / 2, 1e-3)
        near("slip line, phi %g, lambda 1: p at h/a 0.001 vs Ka h" % phi, slipline_p(1e-3, phi, 1.0), ka * 1e-3, 2e-3)
        near("slip line, phi %g, lambda 0: p at h/a 10 vs Ka h (Rankine)" % phi, slipline_p(10, phi, 0.0), ka * 10, 1e-9)
        t = math.tan(_rad(45 - phi / 2))
        eta = 2 * math.tan(_rad(phi)) * math.tan(_rad(45 + phi / 2))
        near("Berezantzev, phi %g: p at h/a 1e6 vs t / (eta - 1)" % phi, slipline_p(1e6, phi, 1.0), t / (eta - 1), 1e-3)
    # the thesis: Prater with lambda = K0 gives zero pressure at h/a about 9 (phi 41, Table 3-1)
    phi = 41.0
    k0 = 1 - math.sin(_rad(phi))
    h0 = next(h / 10 for h in range(1, 200) if prater_p(h / 10, phi, k0) <= 0)
    near("Prater, phi 41, lambda K0: first h/a with p = 0 (thesis about 9)", h0, 9.0, 0.1)
    # Cheng & Hu with lambda = K0 (eta < 1) keeps increasing with depth
    inc = all(slipline_p(h + 1, phi, k0) > slipline_p(h, phi, k0) for h in range(15))
    print("%-58s %10s  %s" % ("Cheng & Hu, phi 41: increasing over h/a 0-15", inc, "ok" if inc else "FAILED"))
    if not inc:
        bad.append("Cheng & Hu increasing")
    return bad


def main(argv):
    ap = argparse.ArgumentParser(prog="shaft_theory.py", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--check", action="store_true", help="assert the limits; exit 1 if one fails")
    ap.add_argument("--phi", type=float, default=41.0, metavar="DEG", help="soil friction angle (default 41)")
    ap.add_argument("--lam", type=float, metavar="L", help="lambda for Prater and Cheng & Hu (default 1 - sin phi)")
    ap.add_argument("--h-max", type=float, default=15.0, metavar="H", help="deepest h/a of the table (default 15)")
    args = ap.parse_args(argv[1:])
    if args.check:
        bad = check()
        print("all limits hold" if not bad else "%d limit(s) FAILED" % len(bad))
        return 1 if bad else 0
    if not (0 < args.phi < 90):
        ap.error("--phi must lie in (0, 90)")
    lam = args.lam if args.lam is not None else 1 - math.sin(_rad(args.phi))
    cs = curves(args.phi, lam, args.h_max, n=int(round(args.h_max)))
    names = list(cs)
    print("h/a " + " | ".join(names))
    hs = cs[names[0]][0]
    for i, h in enumerate(hs):
        print("%4.1f " % h + " ".join("%8.3f" % cs[k][1][i] for k in names))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
