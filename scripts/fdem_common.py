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


def read_csv(path):
    """Columns of an fdem CSV file as {header: [floats]}; a partly written last line is skipped."""
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
                vals = [float(x) for x in row]
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
