"""Helpers shared by fdem's post-processing scripts (scripts/*.py): run under Debian's
/usr/bin/python3 when needed, and read fdem's CSV files."""
import csv
import os
import sys


def system_python_fallback(modules):
    """If `modules` cannot be imported here (e.g. a pyenv/venv python on PATH) but the Debian
    interpreter /usr/bin/python3 (python3-h5py, python3-matplotlib) can, re-run under it."""
    import importlib.util
    if all(importlib.util.find_spec(m) is not None for m in modules):
        return
    system = "/usr/bin/python3"
    if (os.environ.get("FDEM_NO_REEXEC") or not os.path.exists(system)
            or os.path.realpath(sys.executable) == os.path.realpath(system)):
        return
    os.environ["FDEM_NO_REEXEC"] = "1"
    os.execv(system, [system] + sys.argv)


# the columns of fdem's CSV files that hold words, not numbers (holds.csv's `held_by`)
TEXT_COLUMNS = frozenset(["held_by"])


def read_csv(path):
    """Columns of an fdem CSV file as {header: [floats]} (TEXT_COLUMNS as strings); a partly
    written last line is skipped."""
    cols = {}
    with open(path, newline="") as f:
        reader = csv.reader(f)
        header = [h.strip() for h in next(reader)]
        for h in header:
            cols[h] = []
        for row in reader:
            if len(row) != len(header):
                continue  # partly written last line
            try:
                vals = [x.strip() if h in TEXT_COLUMNS else float(x) for h, x in zip(header, row)]
            except ValueError:
                continue
            for h, v in zip(header, vals):
                cols[h].append(v)
    return cols


# --- case files (YAML) -------------------------------------------------------------------------

def load_case(path):
    """A case file as nested dicts/lists, numbers as int/float (Debian's python3-yaml).
    Raises OSError / ValueError."""
    import yaml
    with open(path) as f:
        text = f.read()
    try:
        return _numbers(yaml.safe_load(text))
    except yaml.YAMLError as e:
        raise ValueError(str(e))


def servo_target(case):
    """The stress (Pa) of the first servo wall of a case (walls[].motion.servo.stress), or None."""
    for wdef in case.get("walls") or []:
        m = wdef.get("motion") if isinstance(wdef, dict) else None
        if isinstance(m, dict) and isinstance(m.get("servo"), dict) and "stress" in m["servo"]:
            return float(m["servo"]["stress"])
    return None


def _numbers(v):
    """PyYAML (YAML 1.1) leaves `1.0e8` and `5e-3` as strings; fdem reads them as numbers."""
    if isinstance(v, dict):
        return {k: _numbers(x) for k, x in v.items()}
    if isinstance(v, list):
        return [_numbers(x) for x in v]
    if isinstance(v, str):
        try:
            return float(v) if v.strip() and v.strip().lower() not in ("nan", "inf", "-inf", "+inf", "infinity") else v
        except ValueError:
            return v
    return v


# --- laboratory tests (lab.csv) ----------------------------------------------------------------

def triaxial_peak(c, from_step=None):
    """The peak of a triaxial run's lab.csv columns `c` (read_csv): the axial stage starts at
    `from_step`, or by default at the last row before the peak of q where q is still below 2 % of
    p (the end of the isotropic stage). Returns a dict: k0 (row of the start), s3 (mean lateral
    stress there, Pa), kq (row of the peak of sigma_z / sigma_3), s1 = sigma_z and s3p = sigma_3
    there (Pa), phi (deg, from the peak Mohr circle through the origin: sin phi = (s1 - s3) /
    (s1 + s3)), plane (True for a plane-strain test: the two lateral stresses differ by more than
    10 % at the peak; sigma_3 is then the smaller, else their mean), eps_a_peak (%) and the eps_a,
    eps_v lists (%, compression +, from k0)."""
    import math
    steps = c["step"]
    if from_step is None:
        kq = max(range(len(c["q"])), key=lambda k: c["q"][k])
        k0 = 0
        for k in range(kq + 1):
            if c["p"][k] > 0 and abs(c["q"][k]) < 0.02 * c["p"][k]:
                k0 = k
    else:
        k0 = min(range(len(steps)), key=lambda k: abs(steps[k] - from_step))
    h0, v0 = c["h"][k0], c["lx"][k0] * c["ly"][k0] * c["h"][k0]
    ea = [100 * (h0 - h) / h0 for h in c["h"][k0:]]
    ev = [100 * (v0 - lx * ly * h) / v0 for lx, ly, h in zip(c["lx"][k0:], c["ly"][k0:], c["h"][k0:])]
    kq = max(range(k0, len(c["q"])), key=lambda k: c["q"][k])
    plane = abs(c["sigma_x"][kq] - c["sigma_y"][kq]) > 0.1 * min(c["sigma_x"][kq], c["sigma_y"][kq])

    def s3_at(k):
        return min(c["sigma_x"][k], c["sigma_y"][k]) if plane else 0.5 * (c["sigma_x"][k] + c["sigma_y"][k])
    kq = max(range(k0, len(c["q"])), key=lambda k: c["sigma_z"][k] / s3_at(k) if s3_at(k) > 0 else 0)
    s3p, s1 = s3_at(kq), c["sigma_z"][kq]
    return {"k0": k0, "step0": int(steps[k0]), "s3": s3_at(k0), "kq": kq, "plane": plane,
            "q": s1 - s3p, "s1": s1, "s3p": s3p, "phi": math.degrees(math.asin((s1 - s3p) / (s1 + s3p))),
            "eps_a_peak": ea[kq - k0], "eps_a": ea, "eps_v": ev}


def mohr_coulomb_fit(peaks):
    """Least-squares line t = s sin(phi) + c cos(phi) through the peak circles (s, t) =
    ((s1 + s3)/2, (s1 - s3)/2) of two or more triaxial peaks (triaxial_peak dicts): (phi deg, c Pa),
    or None when the peaks share one mean stress."""
    import math
    s = [0.5 * (p["s1"] + p["s3p"]) for p in peaks]
    t = [0.5 * (p["s1"] - p["s3p"]) for p in peaks]
    n = len(s)
    sx, sy = sum(s), sum(t)
    sxx, sxy = sum(x * x for x in s), sum(x * y for x, y in zip(s, t))
    den = n * sxx - sx * sx
    if not den > 1e-12 * n * sxx:
        return None  # every peak at the same mean stress: no line
    slope = (n * sxy - sx * sy) / den
    icpt = (sy - slope * sx) / n
    phi = math.asin(max(-1.0, min(1.0, slope)))
    return math.degrees(phi), icpt / math.cos(phi)
