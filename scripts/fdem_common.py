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

def _yaml_scalar(s):
    s = s.strip()
    if len(s) >= 2 and s[0] == s[-1] and s[0] in "'\"":
        return s[1:-1]
    low = s.lower()
    if low in ("true", "yes", "on"):
        return True
    if low in ("false", "no", "off"):
        return False
    if low in ("", "~", "null"):
        return None
    for conv in (int, float):
        try:
            return conv(s)
        except ValueError:
            pass
    return s


def _yaml_strip_comment(line):
    quote = None
    for i, ch in enumerate(line):
        if quote:
            if ch == quote:
                quote = None
        elif ch in "'\"":
            quote = ch
        elif ch == "#" and (i == 0 or line[i - 1] in " \t"):
            return line[:i].rstrip()
    return line.rstrip()


def _yaml_split_key(s):
    """'key: value' -> (key, value) when s is a mapping entry (outside brackets/quotes), else None."""
    depth, quote = 0, None
    for i, ch in enumerate(s):
        if quote:
            if ch == quote:
                quote = None
        elif ch in "'\"":
            quote = ch
        elif ch in "[{":
            depth += 1
        elif ch in "]}":
            depth -= 1
        elif ch == ":" and depth == 0 and (i + 1 == len(s) or s[i + 1] in " \t"):
            return _yaml_scalar(s[:i]), s[i + 1:].strip()
    return None


def _yaml_flow(s):
    """A flow value ({...}, [...] or a scalar)."""
    pos = [0]

    def ws():
        while pos[0] < len(s) and s[pos[0]] in " \t\n":
            pos[0] += 1

    def value():
        ws()
        ch = s[pos[0]] if pos[0] < len(s) else ""
        if ch == "{":
            pos[0] += 1
            out = {}
            while True:
                ws()
                if s[pos[0]] == "}":
                    pos[0] += 1
                    return out
                k = scalar(":")
                pos[0] += 1  # ':'
                out[k] = value()
                ws()
                if s[pos[0]] == ",":
                    pos[0] += 1
        if ch == "[":
            pos[0] += 1
            out = []
            while True:
                ws()
                if s[pos[0]] == "]":
                    pos[0] += 1
                    return out
                out.append(value())
                ws()
                if s[pos[0]] == ",":
                    pos[0] += 1
        return scalar(",]}")

    def scalar(stops):
        ws()
        start = pos[0]
        if pos[0] < len(s) and s[pos[0]] in "'\"":
            q = s[pos[0]]
            end = s.index(q, pos[0] + 1)
            pos[0] = end + 1
            return s[start + 1:end]
        while pos[0] < len(s) and s[pos[0]] not in stops:
            if s[pos[0]] == ":" and ":" in stops and not (pos[0] + 1 < len(s) and s[pos[0] + 1] not in " \t"):
                break
            pos[0] += 1
        return _yaml_scalar(s[start:pos[0]])

    v = value()
    ws()
    if pos[0] != len(s):
        raise ValueError("unexpected text after a value: %r" % s[pos[0]:])
    return v


def parse_simple_yaml(text):
    """The YAML subset of fdem's case files (block mappings and sequences, flow {...} / [...],
    plain or quoted scalars, # comments); no anchors, tags or multi-line strings."""
    lines = []
    for raw in text.splitlines():
        line = _yaml_strip_comment(raw.replace("\t", "    "))
        if line.strip() in ("", "---"):
            continue
        lines.append([len(line) - len(line.lstrip(" ")), line.strip()])
    # Join flow values spanning several lines.
    merged = []
    for ind, s in lines:
        if merged and merged[-1][2] > 0:
            merged[-1][1] += " " + s
            merged[-1][2] += s.count("[") + s.count("{") - s.count("]") - s.count("}")
            continue
        merged.append([ind, s, s.count("[") + s.count("{") - s.count("]") - s.count("}")])
    lines = [(ind, s) for ind, s, _ in merged]

    def block(i, ind):
        if lines[i][1].startswith("- ") or lines[i][1] == "-":
            out = []
            while i < len(lines) and lines[i][0] == ind and (lines[i][1].startswith("- ") or lines[i][1] == "-"):
                rest = lines[i][1][1:].strip()
                if not rest:
                    v, i = block(i + 1, lines[i + 1][0])
                    out.append(v)
                    continue
                kv = _yaml_split_key(rest) if rest[0] not in "[{" else None
                if kv is None:
                    out.append(_yaml_flow(rest))
                    i += 1
                    continue
                # A mapping whose first key is on the dash line: re-read it at the key's indent.
                sub = ind + 1 + (len(lines[i][1][1:]) - len(lines[i][1][1:].lstrip(" ")))
                lines[i] = (sub, rest)
                v, i = block(i, sub)
                out.append(v)
            return out, i
        out = {}
        while i < len(lines) and lines[i][0] == ind:
            kv = _yaml_split_key(lines[i][1])
            if kv is None:
                raise ValueError("expected 'key: value': %r" % lines[i][1])
            k, v = kv
            i += 1
            if v:
                out[k] = _yaml_flow(v)
            elif i < len(lines) and (lines[i][0] > ind or (lines[i][0] == ind and lines[i][1].startswith("-"))):
                out[k], i = block(i, lines[i][0])
            else:
                out[k] = None
        return out, i

    if not lines:
        return None
    value, i = block(0, lines[0][0])
    if i != len(lines):
        raise ValueError("bad indentation near %r" % lines[i][1])
    return value


def load_case(path):
    """A case file as nested dicts/lists, numbers as int/float: PyYAML when installed (Debian
    python3-yaml; anchors work), else parse_simple_yaml. Raises OSError / ValueError."""
    with open(path) as f:
        text = f.read()
    try:
        import yaml
    except ImportError:
        return parse_simple_yaml(text)
    return _numbers(yaml.safe_load(text))


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


def apply_override(case, assignment):
    """Apply one `key=value` override as `fdem run --set` does (dotted path, list indices as
    numbers, value in YAML flow syntax), in place."""
    key, sep, val = assignment.partition("=")
    if not sep or not key:
        raise ValueError("override %r: expected key=value" % assignment)
    parts = key.strip().split(".")
    node = case
    for p in parts[:-1]:
        node = node[int(p)] if isinstance(node, list) else node.setdefault(p, {})
    last = parts[-1]
    value = _yaml_flow(val.strip())
    if isinstance(node, list):
        node[int(last)] = value
    else:
        node[last] = value
