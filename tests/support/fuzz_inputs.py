#!/usr/bin/env python3
"""Seeded fuzzing of fdem's input readers (tests/cli_fuzz.sh; docs/verification.md).

Mutates every valid case under cases/ (YAML-aware text mutations), the sphere text files the
cases read, and the FE mesh formats (Gmsh 4.1 .msh and the thesis's node / element / restraint
/ load files, on small cases built from tests/data/mesh/), runs `fdem check` on each mutant and
`fdem run` (1 or 2 ranks, a few seconds) on a sample, and judges each outcome:

  ok     exit 2 with exactly one line containing ': error: ' (the documented message), or
         exit 0 when the mutation is of a kind that can leave the input valid (a deleted
         optional key, a value that is still in range, a truncation at a harmless byte, ...);
  FAIL   a signal / abort / sanitizer report / backtrace, a hang (timeout), exit 1 or any other
         code, a message printed more or less than once, or exit 0 for a mutation that cannot
         leave the input valid (NaN, wrong type, duplicate key, a missing node, ...).

Every mutant has a stable id (base file + index; the random generator is seeded per base file, so
adding a case does not change the mutants of the others). Known failures whose fix belongs to
another part of the code may be listed in XFAIL with a note; they are reported but do not fail
the test. Python 3 standard library only.
"""
import argparse
import concurrent.futures as cf
import os
import random
import re
import resource
import shutil
import signal
import subprocess
import sys
import time

# mutant id -> the finding it reproduces: known failures that do not fail the test while their
# fix is pending (reported as XFAIL; XPASS once fixed). Empty: the 11 findings of the first run
# (issue 14: yes/on booleans, a non-UTF-8 name, empty sphere/restraint/load files, a huge --set
# index, an endless or FIFO case file, unusable --out, a 1e15-element block, a 1e300 skin or
# domain, an unrestrained static solve) are input errors now.
XFAIL = {}

CRASH_MARKERS = ("MPI_ABORT", "Aborted", "Segmentation", "segmentation fault", "terminate called",
                 "Backtrace", "backtrace", "AddressSanitizer", "runtime error:", "core dumped",
                 "Signal:", "LeakSanitizer", "stack-overflow", "PETSC ERROR")

# Mutation kinds that may leave an input valid (exit 0 allowed). All others must be refused.
MAY_BE_HARMLESS = {"delete_key", "huge", "tiny", "negative", "zero", "truncate", "flip", "indent",
                   "delete_line", "coord_huge", "crlf", "huge_int",
                   "extra_token_entities"}

NUM_RE = re.compile(r"(?<![\w.+\-])[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?(?![\w.:])")
KEY_RE = re.compile(r"(?:(?<=^)|(?<=[\s{,]))([A-Za-z_]\w*):(?=\s|$)")
BOOL_RE = re.compile(r"(?<=:\s)(true|false)\b")
FLOWLIST_RE = re.compile(r"\[[^\[\]{}]*\]")


def split_comment(line):
    """(content, comment) of a YAML line; '#' starts a comment at the start or after a blank."""
    q = None
    for i, ch in enumerate(line):
        if q:
            if ch == q:
                q = None
        elif ch in "'\"":
            q = ch
        elif ch == "#" and (i == 0 or line[i - 1] in " \t"):
            return line[:i], line[i:]
    return line, ""


class Mutant:
    def __init__(self, mid, kind, desc, case_path, text_path, data):
        self.id, self.kind, self.desc = mid, kind, desc
        self.case = case_path          # the case file fdem is given
        self.path = text_path          # the mutated file (written from data)
        self.data = data               # bytes


# ---------------------------------------------------------------- YAML case mutations
def yaml_mutations(text, rng):
    """One mutation of a case file's text: (kind, description, new bytes)."""
    lines = text.split("\n")
    content = [split_comment(l)[0] for l in lines]
    nums = [(i, m) for i, c in enumerate(content) for m in NUM_RE.finditer(c)]
    keys = [(i, m) for i, c in enumerate(content) for m in KEY_RE.finditer(c)]
    bools = [(i, m) for i, c in enumerate(content) for m in BOOL_RE.finditer(c)]
    lists = [(i, m) for i, c in enumerate(content) for m in FLOWLIST_RE.finditer(c)
             if re.search(r":\s*$", c[:m.start()])]
    code_lines = [i for i, c in enumerate(content) if c.strip()]

    def with_line(i, new):
        out = list(lines)
        out[i] = new
        return "\n".join(out).encode()

    def replace_num(kind, desc, repl):
        i, m = rng.choice(nums)
        l = lines[i]
        return kind, "line %d: %s '%s' -> %s" % (i + 1, desc, m.group(0), repl[:40]), \
            with_line(i, l[:m.start()] + repl + l[m.end():])

    kinds = ["delete_key", "wrong_type", "huge", "tiny", "negative", "zero", "nan", "inf", "empty",
             "long_string", "list", "map", "dup_key", "truncate", "flip", "deep_nesting", "indent",
             "tab", "huge_int", "bool_yes", "list_to_scalar", "bad_utf8"]
    while True:
        kind = rng.choice(kinds)
        if kind in ("wrong_type", "huge", "tiny", "negative", "zero", "nan", "inf", "long_string",
                    "list", "map", "huge_int", "empty") and not nums:
            continue
        if kind in ("delete_key", "dup_key", "bad_utf8") and not keys:
            continue
        if kind == "bool_yes" and not bools:
            continue
        if kind == "list_to_scalar" and not lists:
            continue
        break
    if kind == "wrong_type":
        return replace_num(kind, "number to string", rng.choice(["abc", "x1", "true", "1.0.0", "0x"]))
    if kind == "huge":
        return replace_num(kind, "huge", rng.choice(["1.0e308", "1.0e300", "1.0e30"]))
    if kind == "tiny":
        return replace_num(kind, "tiny", rng.choice(["1.0e-300", "4.9e-324", "1.0e-30"]))
    if kind == "negative":
        i, m = rng.choice(nums)
        v = m.group(0)
        nv = v[1:] if v.startswith("-") else "-" + v.lstrip("+")
        l = lines[i]
        return kind, "line %d: negate '%s'" % (i + 1, v), with_line(i, l[:m.start()] + nv + l[m.end():])
    if kind == "zero":
        return replace_num(kind, "zero", "0")
    if kind == "nan":
        return replace_num(kind, "NaN", rng.choice([".nan", ".NaN", "nan"]))
    if kind == "inf":
        return replace_num(kind, "infinity", rng.choice([".inf", "-.inf", ".Inf"]))
    if kind == "huge_int":
        return replace_num(kind, "huge integer", rng.choice(["99999999999999999999999", "1000000000000000"]))
    if kind == "long_string":
        return replace_num(kind, "long string", "x" * rng.choice([1000, 100000]))
    if kind == "list":
        return replace_num(kind, "list", rng.choice(["[1, 2]", "[]", "[[1]]"]))
    if kind == "map":
        return replace_num(kind, "map", rng.choice(["{a: 1}", "{}"]))
    if kind == "empty":
        # A block value removed ('key:' -> null) or a flow item emptied ("''").
        i, m = rng.choice(nums)
        l = lines[i]
        repl = "" if re.search(r":\s*$", l[:m.start()]) else "''"
        return kind, "line %d: empty value for '%s'" % (i + 1, m.group(0)), \
            with_line(i, l[:m.start()] + repl + l[m.end():])
    if kind == "deep_nesting":
        n = rng.choice([200, 5000, 100000])
        val = rng.choice(["[" * n + "1" + "]" * n, "{a: " * n + "1" + "}" * n])
        if nums and rng.random() < 0.7:
            i, m = rng.choice(nums)
            l = lines[i]
            return kind, "line %d: '%s' nested %d deep" % (i + 1, m.group(0), n), \
                with_line(i, l[:m.start()] + val + l[m.end():])
        return kind, "appended a key nested %d deep" % n, (text + "\nzzz: " + val + "\n").encode()
    if kind == "list_to_scalar":
        i, m = rng.choice(lists)
        l = lines[i]
        return kind, "line %d: list %s -> 5" % (i + 1, m.group(0)[:30]), \
            with_line(i, l[:m.start()] + "5" + l[m.end():])
    if kind == "bool_yes":
        i, m = rng.choice(bools)
        l = lines[i]
        repl = rng.choice(["yes", "no", "on", "1", "'true'"])
        return kind, "line %d: %s -> %s" % (i + 1, m.group(1), repl), \
            with_line(i, l[:m.start()] + repl + l[m.end():])
    if kind == "bad_utf8":
        # A key's value (or the key itself) gets bytes that are not UTF-8.
        i, m = rng.choice(keys)
        l = lines[i].encode()
        pos = len(lines[i][:m.end()].encode()) + 1
        new = l[:pos] + b"\xff\xfe\xc3(" + l[pos:]
        out = [x.encode() for x in lines]
        out[i] = new
        return kind, "line %d: non-UTF-8 bytes after '%s:'" % (i + 1, m.group(1)), b"\n".join(out)
    if kind == "dup_key":
        i, m = rng.choice(keys)
        l = lines[i]
        c = content[i]
        rest = c[m.end():].strip()
        before = c[:m.start()]
        if before.strip() in ("", "-"):
            # A block key: repeat it (with its scalar or flow value, else '{}') on the next line.
            val = rest if rest else "{}"
            dup = " " * m.start() + m.group(1) + ": " + val
            out = list(lines)
            # after the key's block (lines indented deeper than the key)
            j = i + 1
            if not rest:
                while j < len(lines) and (not content[j].strip() or
                                          len(content[j]) - len(content[j].lstrip()) > m.start()):
                    j += 1
            out.insert(j, dup)
            return kind, "line %d: key '%s' repeated" % (i + 1, m.group(1)), "\n".join(out).encode()
        # A key inside a flow mapping: repeat it right after the '{' that opens the mapping.
        k = before.rfind("{")
        if k < 0:
            return kind, "line %d: key '%s' repeated" % (i + 1, m.group(1)), \
                with_line(i, l + "\n" + " " * m.start() + m.group(1) + ": 1")
        return kind, "line %d: key '%s' repeated in a flow mapping" % (i + 1, m.group(1)), \
            with_line(i, l[:k + 1] + m.group(1) + ": 1, " + l[k + 1:])
    if kind == "delete_key":
        i, m = rng.choice(keys)
        l = lines[i]
        c = content[i]
        before = c[:m.start()]
        rest = c[m.end():]
        out = list(lines)
        if before.strip() == "":
            # block key: drop the line and its children
            j = i + 1
            if not rest.strip():
                while j < len(lines) and (not content[j].strip() or
                                          len(content[j]) - len(content[j].lstrip()) > m.start()):
                    j += 1
            del out[i:j]
            return kind, "line %d: key '%s' deleted" % (i + 1, m.group(1)), "\n".join(out).encode()
        # flow or list-item key: drop 'key: value' up to the next ',' or '}' at this level
        depth, e = 0, m.end()
        while e < len(c):
            ch = c[e]
            if ch in "[{":
                depth += 1
            elif ch in "]}":
                if depth == 0:
                    break
                depth -= 1
            elif ch == "," and depth == 0:
                e += 1
                break
            e += 1
        s = m.start()
        new = l[:s] + l[e:].lstrip()
        if before.strip() == "-" and not new[s:].strip():
            new = l[:s] + "{}"
        return kind, "line %d: key '%s' deleted" % (i + 1, m.group(1)), with_line(i, new)
    data = text.encode()
    if kind == "truncate":
        n = rng.randrange(0, len(data))
        return kind, "truncated at byte %d of %d" % (n, len(data)), data[:n]
    if kind == "flip":
        b = bytearray(data)
        where = []
        for _ in range(rng.randint(1, 3)):
            p = rng.randrange(len(b))
            b[p] ^= rng.randrange(1, 256)
            where.append(p)
        return kind, "bytes flipped at %s" % where, bytes(b)
    if kind in ("indent", "tab"):
        i = rng.choice(code_lines)
        l = lines[i]
        ind = len(l) - len(l.lstrip())
        if kind == "tab":
            return kind, "line %d: indentation by a tab" % (i + 1), with_line(i, "\t" + l.lstrip())
        d = rng.choice([-2, -1, 1, 3])
        if ind + d < 0:
            d = 1
        new = " " * (ind + d) + l.lstrip()
        return kind, "line %d: indentation %d -> %d" % (i + 1, ind, ind + d), with_line(i, new)
    raise AssertionError(kind)


# ---------------------------------------------------------------- text data-file mutations
def table_mutation(text, rng, kinds_extra=()):
    """One mutation of a whitespace-separated table file (spheres, thesis nodes/elements/...)."""
    lines = text.split("\n")
    data = [i for i, l in enumerate(lines) if l.strip() and not l.lstrip().startswith("#")]
    kinds = ["drop_token", "extra_token", "non_numeric", "nan", "inf", "dup_line", "empty_file",
             "truncate", "flip", "binary", "long_line", "huge_id", "bad_id", "delete_line", "crlf",
             "coord_huge"] + list(kinds_extra)
    kind = rng.choice(kinds)

    def with_line(i, new):
        out = list(lines)
        out[i] = new
        return "\n".join(out).encode()
    i = rng.choice(data)
    tok = lines[i].split("#")[0].split()
    if kind == "drop_token":
        return kind, "line %d: last value dropped" % (i + 1), with_line(i, " ".join(tok[:-1]))
    if kind == "extra_token":
        return kind, "line %d: a value added" % (i + 1), with_line(i, " ".join(tok) + " 0.5")
    if kind in ("non_numeric", "nan", "inf", "coord_huge"):
        k = rng.randrange(1, len(tok)) if len(tok) > 1 else 0
        repl = {"non_numeric": rng.choice(["abc", "1.0.0", "0x1g", "--1", "1e", "1,5"]),
                "nan": rng.choice(["nan", "NaN", "-nan"]), "inf": rng.choice(["inf", "-inf", "1e999"]),
                "coord_huge": rng.choice(["1e308", "-1e300", "1e30"])}[kind]
        tok[k] = repl
        return kind, "line %d: value %d -> %s" % (i + 1, k + 1, repl), with_line(i, " ".join(tok))
    if kind == "dup_line":
        out = list(lines)
        out.insert(i + 1, lines[i])
        return kind, "line %d repeated" % (i + 1), "\n".join(out).encode()
    if kind == "delete_line":
        out = list(lines)
        del out[i]
        return kind, "line %d deleted" % (i + 1), "\n".join(out).encode()
    if kind == "empty_file":
        keep = [l for l in lines if l.lstrip().startswith("#")]
        return kind, "every data line removed", ("\n".join(keep) + "\n").encode()
    if kind == "huge_id":
        tok[0] = rng.choice(["99999999999999999999", "1e30", "1e3"])
        return kind, "line %d: id -> %s" % (i + 1, tok[0]), with_line(i, " ".join(tok))
    if kind == "bad_id":
        tok[0] = rng.choice(["-1", "1.5", "x"])
        return kind, "line %d: id -> %s" % (i + 1, tok[0]), with_line(i, " ".join(tok))
    if kind == "long_line":
        return kind, "line %d: 1 MB of digits appended" % (i + 1), with_line(i, " ".join(tok) + " " + "7" * (1 << 20))
    if kind == "crlf":
        return kind, "CRLF line ends", text.replace("\n", "\r\n").encode()
    if kind == "binary":
        return kind, "random binary content", bytes(rng.randrange(256) for _ in range(rng.choice([7, 300, 5000])))
    if kind == "node_out_of_range":
        k = rng.randrange(1, len(tok))
        tok[k] = rng.choice(["0", "999999", "-3", "2147483648"])
        return kind, "line %d: node %d -> %s" % (i + 1, k, tok[k]), with_line(i, " ".join(tok))
    if kind == "dup_node_in_element":
        if len(tok) > 2:
            tok[2] = tok[1]
        return kind, "line %d: element repeats a node" % (i + 1), with_line(i, " ".join(tok))
    b = text.encode()
    if kind == "truncate":
        n = rng.randrange(0, len(b))
        return kind, "truncated at byte %d of %d" % (n, len(b)), b[:n]
    if kind == "flip":
        bb = bytearray(b)
        where = []
        for _ in range(rng.randint(1, 3)):
            p = rng.randrange(len(bb))
            bb[p] ^= rng.randrange(1, 256)
            where.append(p)
        return kind, "bytes flipped at %s" % where, bytes(bb)
    raise AssertionError(kind)


def gmsh_mutation(text, rng):
    """One mutation of a Gmsh 4.1 ASCII file: its $Nodes / $Elements sections, counts, markers."""
    lines = text.split("\n")
    sec, where = None, {"Nodes": [], "Elements": [], "Entities": [], "PhysicalNames": []}
    for i, l in enumerate(lines):
        if l.startswith("$End"):
            sec = None
        elif l.startswith("$"):
            sec = l[1:].strip()
        elif sec in where:
            where[sec].append(i)
    # the structure of the two sections: node coordinate lines and element lines
    coords, elems = [], []
    n = where["Nodes"]
    j = 1
    while j < len(n):
        cnt = int(lines[n[j]].split()[3])
        coords += n[j + 1 + cnt:j + 1 + 2 * cnt]
        j += 1 + 2 * cnt
    e = where["Elements"]
    j = 1
    while j < len(e):
        cnt = int(lines[e[j]].split()[3])
        elems += e[j + 1:j + 1 + cnt]
        j += 1 + cnt
    elems = [i for i in elems if len(lines[i].split()) > 2]
    kinds = ["count_wrong", "count_huge", "node_out_of_range", "nan", "non_numeric", "drop_token",
             "extra_token", "delete_line", "truncate", "flip", "drop_end_marker", "dup_line", "binary",
             "coord_huge", "inf"]
    kind = rng.choice(kinds)

    def with_line(i, new):
        out = list(lines)
        out[i] = new
        return "\n".join(out).encode()
    if kind in ("count_wrong", "count_huge"):
        sec = rng.choice(["Nodes", "Elements"])
        i = where[sec][0]
        tok = lines[i].split()
        k = rng.randrange(len(tok))
        v = int(tok[k])
        tok[k] = str(v + rng.choice([-1, 1])) if kind == "count_wrong" else rng.choice(["1000000000000000", "99999999999999999999", "-1"])
        return kind, "$%s header value %d: %s -> %s" % (sec, k + 1, lines[i].split()[k], tok[k]), \
            with_line(i, " ".join(tok))
    if kind in ("node_out_of_range", "dup_line"):
        i = rng.choice(elems)
        tok = lines[i].split()
        if kind == "dup_line":
            out = list(lines)
            out.insert(i + 1, lines[i])
            return kind, "line %d (an element) repeated" % (i + 1), "\n".join(out).encode()
        k = rng.randrange(1, len(tok))
        tok[k] = rng.choice(["0", "13", "999999", "-3", "99999999999999999999"])
        return kind, "line %d: element node %d -> %s" % (i + 1, k, tok[k]), with_line(i, " ".join(tok))
    if kind in ("nan", "coord_huge", "inf"):
        i = rng.choice(coords)
        tok = lines[i].split()
        k = rng.randrange(3)
        tok[k] = {"nan": "nan", "coord_huge": "1e308", "inf": "inf"}[kind]
        return kind, "line %d: $Nodes coordinate %d -> %s" % (i + 1, k + 1, tok[k]), with_line(i, " ".join(tok))
    if kind in ("non_numeric", "drop_token", "extra_token", "delete_line"):
        sec = rng.choice(["Nodes", "Elements", "Entities", "PhysicalNames"])
        i = rng.choice(where[sec])
        tok = lines[i].split()
        if kind == "non_numeric":
            k = rng.randrange(len(tok))
            tok[k] = rng.choice(["abc", "--2", "1e", "1.0.0"])
            return kind, "line %d ($%s): value %d -> %s" % (i + 1, sec, k + 1, tok[k]), with_line(i, " ".join(tok))
        if kind == "drop_token":
            return kind, "line %d ($%s): last value dropped" % (i + 1, sec), with_line(i, " ".join(tok[:-1]))
        if kind == "extra_token":
            if sec == "Entities":  # entity lines end in lists the reader may not need
                kind = "extra_token_entities"
            return kind, "line %d ($%s): a value added" % (i + 1, sec), with_line(i, lines[i] + " 7")
        out = list(lines)
        del out[i]
        return kind, "line %d ($%s) deleted" % (i + 1, sec), "\n".join(out).encode()
    if kind == "drop_end_marker":
        m = rng.choice(["$EndNodes", "$EndElements", "$EndMeshFormat", "$EndEntities"])
        return kind, "%s removed" % m, text.replace(m + "\n", "", 1).encode()
    if kind == "binary":
        return kind, "random binary content", bytes(rng.randrange(256) for _ in range(rng.choice([7, 300, 5000])))
    b = text.encode()
    if kind == "truncate":
        n = rng.randrange(0, len(b))
        return kind, "truncated at byte %d of %d" % (n, len(b)), b[:n]
    if kind == "flip":
        bb = bytearray(b)
        where_ = []
        for _ in range(rng.randint(1, 3)):
            p = rng.randrange(len(bb))
            bb[p] ^= rng.randrange(1, 256)
            where_.append(p)
        return kind, "bytes flipped at %s" % where_, bytes(bb)
    raise AssertionError(kind)


# ---------------------------------------------------------------- FE cases for the mesh readers
FE_CASES = {
    # name: (yaml text, {placeholder: data file under mesh/})
    "fe_gmsh.yaml": """name: fe_gmsh
fem:
  materials:
    - {name: steel, young: 2.0e11, poisson: 0.3, density: 7800}
  meshes:
    - {name: m, material: steel, gmsh: block2.msh}
  restraints:
    - {mesh: m, node_set: left face, fixed: [x, y, z]}
  loads:
    - {mesh: m, node_set: corner, total: [0, 0, -1000]}
  load_steps: [1.0]
""",
    "fe_thesis_hex8.yaml": """name: fe_thesis_hex8
fem:
  materials:
    - {name: steel, young: 2.0e11, poisson: 0.3, density: 7800}
  meshes:
    - {name: m, material: steel, thesis: {nodes: block2_nodes.txt, elements: block2_elements.txt, element: hex8, dim: 3}}
  restraints:
    - {mesh: m, file: block2_restraints.txt}
  loads:
    - {mesh: m, file: block2_loads.txt}
  load_steps: [1.0]
""",
    "fe_thesis_hex20.yaml": """name: fe_thesis_hex20
fem:
  materials:
    - {name: steel, young: 2.0e11, poisson: 0.3, density: 7800}
  meshes:
    - {name: m, material: steel, thesis: {nodes: hex20_nodes.txt, elements: hex20_elements.txt, element: hex20, dim: 3}}
  restraints:
    - {mesh: m, region: {min: [-0.1, -0.1, -0.1], max: [0.1, 1.1, 1.1]}, fixed: [x, y, z]}
  loads:
    - {mesh: m, region: {min: [1.9, -0.1, -0.1], max: [2.1, 1.1, 1.1]}, total: [0, 0, -1000]}
  load_steps: [1.0]
""",
}


# ---------------------------------------------------------------- running and judging
DATA_LIMIT_GB = 3


def limit_child():
    os.setsid()
    # A mutant asking for 10^15 elements must not take the shared machine's memory with it.
    # (RLIMIT_DATA, not RLIMIT_AS: Open MPI reserves much address space at MPI_Init. An ASan
    # build needs --data-limit-gb 0: its shadow memory counts as data.)
    gb = 1 << 30
    if DATA_LIMIT_GB > 0:
        resource.setrlimit(resource.RLIMIT_DATA, (DATA_LIMIT_GB * gb, DATA_LIMIT_GB * gb))
    resource.setrlimit(resource.RLIMIT_CORE, (0, 0))


ENV = dict(os.environ)
# A singleton (fdem without mpirun) need not start Open MPI's daemon: 0.4 s instead of 0.7 s.
ENV["OMPI_MCA_ess_singleton_isolated"] = "1"


def run_cmd(cmd, cwd, timeout):
    """Run with a time limit; a start-up failure of Open MPI itself (seen once in ~2000 runs on a
    loaded machine, before fdem reads anything) is retried, twice at most, and said."""
    for attempt in range(3):
        rc, text, to, dt = run_once(cmd, cwd, timeout)
        if "An error occurred in MPI_Init" not in text and "before MPI_INIT completed" not in text:
            break
        print("fuzz: Open MPI failed to start (attempt %d): %s" % (attempt + 1, " ".join(cmd)[-120:]))
        sys.stdout.flush()
        time.sleep(1)
    return rc, text, to, dt


def run_once(cmd, cwd, timeout):
    t0 = time.time()
    p = subprocess.Popen(cmd, cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                         stdin=subprocess.DEVNULL, preexec_fn=limit_child, env=ENV)
    try:
        out, err = p.communicate(timeout=timeout)
        timed_out = False
    except subprocess.TimeoutExpired:
        try:
            os.killpg(p.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
        out, err = p.communicate()
        timed_out = True
    return p.returncode, out.decode("utf-8", "replace") + err.decode("utf-8", "replace"), \
        timed_out, time.time() - t0


def judge(kind, rc, text, timed_out, nranks, allow_timeout, running=False):
    """None if the outcome is acceptable, else what is wrong. A run (not a check) of a valid but
    violent mutant (a wall driven into the grains, say) may also stop as diverged: exit 3 with
    one 'the run diverged' (or 'the FE run diverged') message (docs/user-guide.md, "Runs that
    diverge")."""
    if timed_out:
        return None if allow_timeout else "hang (timeout)"
    for m in CRASH_MARKERS:
        if m in text:
            return "crash: '%s' in the output (exit %d)" % (m, rc)
    if rc < 0 or rc >= 128:
        return "killed by a signal / exit %d" % rc
    if rc == 2:
        n = sum(1 for l in text.splitlines() if ": error: " in l)
        if n != 1:
            return "exit 2 with %d lines ': error: ' (want exactly 1) on %d rank(s)" % (n, nranks)
        return None
    if rc == 0:
        return None if kind in MAY_BE_HARMLESS else "exit 0: accepted an input that cannot be valid"
    if rc == 3 and running:
        n = sum(1 for l in text.splitlines() if ": error: the run diverged" in l or ": error: the FE run diverged" in l)
        return None if n == 1 else "exit 3 with %d lines 'the (FE) run diverged' (want exactly 1)" % n
    return "exit %d (want 2 with a message, or 0 for a harmless mutation)" % rc


def main():
    global DATA_LIMIT_GB
    ap = argparse.ArgumentParser()
    ap.add_argument("--fdem", required=True)
    ap.add_argument("--src", required=True)
    ap.add_argument("--work", required=True)
    ap.add_argument("--seed", type=int, default=14)
    ap.add_argument("--per-case", type=int, default=9)
    ap.add_argument("--per-data", type=int, default=16)
    ap.add_argument("--run-sample", type=int, default=24)
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--check-timeout", type=float, default=60)
    ap.add_argument("--run-timeout", type=float, default=8)
    ap.add_argument("--data-limit-gb", type=int, default=DATA_LIMIT_GB, help="per-process data limit (0: none)")
    ap.add_argument("--only", default="", help="run only the mutants whose id contains this")
    ap.add_argument("--keep", action="store_true", help="write every mutant to WORK/ (default: failing ones only)")
    a = ap.parse_args()
    DATA_LIMIT_GB = a.data_limit_gb
    mpirun = ["bash", os.path.join(a.src, "scripts", "mpirun.sh")]
    print("fuzz: seed %d (rerun: %s)" % (a.seed, " ".join(sys.argv)))
    work = os.path.abspath(a.work)
    shutil.copytree(os.path.join(a.src, "cases"), os.path.join(work, "cases"))
    shutil.copytree(os.path.join(a.src, "tests", "data", "mesh"), os.path.join(work, "mesh"),
                    ignore=shutil.ignore_patterns("bad"))
    for name, text in FE_CASES.items():
        with open(os.path.join(work, "mesh", name), "w") as f:
            f.write(text)

    # cases/specimens/{overburden,reuse}_ci.yaml read the sphere file pack_layers_ci.yaml
    # writes: a stand-in, 27 grains inside both domains.
    os.makedirs(os.path.join(work, "out", "specimens"))
    with open(os.path.join(work, "out", "specimens", "pack_layers_ci.txt"), "w") as f:
        f.write("# id x y z r (stand-in for the packing's output)\n")
        for n in range(27):
            f.write("%d %.3f %.3f %.3f 0.002\n" % (n + 1, 0.01 + 0.01 * (n % 3),
                                                   0.01 + 0.01 * (n // 3 % 3), 0.01 + 0.01 * (n // 9)))

    # Base inputs: every case under cases/ but cases/bad, and the mesh cases; each must pass
    # `fdem check` unmutated (cases needing files an earlier run writes are skipped, and said).
    bases = sorted(os.path.relpath(os.path.join(d, f), work)
                   for d, _, fs in os.walk(os.path.join(work, "cases"))
                   for f in fs if f.endswith(".yaml") and "/bad" not in d)
    bases += ["mesh/" + n for n in FE_CASES]
    valid = []

    def check_base(b):
        rc, text, to, dt = run_cmd([a.fdem, "check", b], work, a.check_timeout)
        return b, rc, text, to, dt
    with cf.ThreadPoolExecutor(a.jobs) as ex:
        for b, rc, text, to, dt in ex.map(check_base, bases):
            if rc == 0:
                valid.append(b)
            else:
                print("fuzz: base %s skipped: `fdem check` exit %d unmutated (%s)" %
                      (b, rc, (text.strip().splitlines() or ["timeout"])[-1][:160]))
    if not valid:
        print("FAIL: no valid base case")
        return 1
    print("fuzz: %d valid base cases" % len(valid))

    mutants = []
    # 1. the case files
    for b in valid:
        rng = random.Random("%d:%s" % (a.seed, b))
        text = open(os.path.join(work, b), encoding="utf-8").read()
        for k in range(a.per_case):
            kind, desc, data = yaml_mutations(text, rng)
            stem = b[:-5]
            mutants.append(Mutant("%s#%d" % (b, k), kind, desc, "%s__fuzz%d.yaml" % (stem, k),
                                  "%s__fuzz%d.yaml" % (stem, k), data))
    # 2. the data files, each through a case that reads it
    data_files = [  # (case, file it reads, mutation)
        ("cases/examples/sphere_file.yaml", "cases/examples/spheres.txt", "table"),
        ("cases/coupling/bed_on_coarse_plate.yaml", "cases/coupling/bed_on_coarse_plate_spheres.txt", "table"),
        ("mesh/fe_gmsh.yaml", "mesh/block2.msh", "gmsh"),
        ("mesh/fe_thesis_hex8.yaml", "mesh/block2_nodes.txt", "table"),
        ("mesh/fe_thesis_hex8.yaml", "mesh/block2_elements.txt", "elements"),
        ("mesh/fe_thesis_hex8.yaml", "mesh/block2_restraints.txt", "table"),
        ("mesh/fe_thesis_hex8.yaml", "mesh/block2_loads.txt", "table"),
        ("mesh/fe_thesis_hex20.yaml", "mesh/hex20_nodes.txt", "table"),
        ("mesh/fe_thesis_hex20.yaml", "mesh/hex20_elements.txt", "elements"),
    ]
    for case, df, how in data_files:
        if case not in valid:
            print("FAIL: %s (reads %s) does not pass `fdem check` unmutated" % (case, df))
            return 1
        rng = random.Random("%d:%s" % (a.seed, df))
        text = open(os.path.join(work, df), encoding="utf-8").read()
        ctext = open(os.path.join(work, case), encoding="utf-8").read()
        base = os.path.basename(df)
        stem, ext = os.path.splitext(base)
        for k in range(a.per_data):
            if how == "gmsh":
                kind, desc, data = gmsh_mutation(text, rng)
            elif how == "elements":
                kind, desc, data = table_mutation(text, rng, ("node_out_of_range", "node_out_of_range",
                                                             "dup_node_in_element"))
            else:
                kind, desc, data = table_mutation(text, rng)
            mname = "%s__fuzz%d%s" % (stem, k, ext)
            mcase = "%s__%s__fuzz%d.yaml" % (case[:-5], stem, k)
            mutants.append(Mutant("%s#%d" % (df, k), kind, desc, mcase,
                                  os.path.join(os.path.dirname(df), mname), data))
            mutants[-1].case_text = ctext.replace(base, mname)
    # 3. the command line and the file system: fixed inputs (the tester's reports of issue 14).
    fifo = os.path.join(work, "case_fifo.yaml")
    os.mkfifo(fifo)
    os.makedirs(os.path.join(work, "a_directory.yaml"))
    with open(os.path.join(work, "cases", "examples", "sphere_dir.yaml"), "w") as f:
        f.write(open(os.path.join(work, "cases", "examples", "sphere_file.yaml")).read()
                .replace("path: spheres.txt", "path: ../examples"))
    with open(os.path.join(work, "a_file"), "w") as f:
        f.write("x\n")
    settle = ["cases/demo/settle.yaml"]
    short = ["--set", "time.steps=20"]
    specials = [  # (name, fdem arguments)
        ("set_huge_index", ["check"] + settle + ["--set", "materials.99999999999999999999.young=1"]),
        ("set_index_4e9", ["check"] + settle + ["--set", "materials.4294967296.young=1"]),
        ("set_negative_index", ["check"] + settle + ["--set", "materials.-1.young=1"]),
        ("set_unknown_key", ["check"] + settle + ["--set", "foo.bar=1"]),
        ("set_no_value", ["check"] + settle + ["--set", "time.dt"]),
        ("set_bad_yaml", ["check"] + settle + ["--set", "time.dt=[1,"]),
        ("case_endless_file", ["check", "/dev/zero"]),
        ("case_fifo", ["check", fifo]),
        ("case_directory", ["check", "a_directory.yaml"]),
        ("case_empty", ["check", "/dev/null"]),
        ("sphere_file_is_directory", ["check", "cases/examples/sphere_dir.yaml"]),
        ("out_under_a_file", ["run"] + settle + short + ["--out", "a_file/out", "-q"]),
        ("out_in_proc", ["run"] + settle + short + ["--out", "/proc/fdem_fuzz_out", "-q"]),
        ("restart_missing", ["run"] + settle + short + ["--restart", "no_such_checkpoint.h5", "--out", "o_r", "-q"]),
        ("restart_not_hdf5", ["run"] + settle + short + ["--restart", "a_file", "--out", "o_r2", "-q"]),
        ("block_1e15_elements", ["check", "cases/fem/cantilever.yaml", "--set",
                                 "fem.meshes.0.block.divisions=[100000, 100000, 100000]"]),
        ("skin_huge", ["run"] + settle + short + ["--set", "neighbor.skin=1.0e300", "--out", "o_s", "-q"]),
        ("radius_huge", ["run", "cases/examples/inline.yaml", "--set", "time.steps=20", "--set",
                         "particles.0.inline.spheres.0=[0.5, 0.5, 0.5, 1.0e300]", "--out", "o_rad", "-q"]),
        ("domain_huge", ["run"] + settle + short + ["--set", "domain.max=[1.0e300, 1.0e300, 1.0e300]",
                                                    "--out", "o_dom", "-q"]),
        ("static_unrestrained", ["run", "cases/fem/cantilever.yaml", "--set", "fem.solver=static",
                                 "--set", "fem.restraints=[]", "--out", "o_static", "-q"]),
    ]
    for name, args in specials:
        np_ = 2 if name in ("skin_huge", "domain_huge", "out_under_a_file") else 1
        m = Mutant("cli#" + name, name, "a fixed command line on %d rank(s)" % np_, None, None, None)
        m.cmd, m.np = args, np_
        mutants.append(m)

    if a.only:
        mutants = [m for m in mutants if a.only in m.id]
    for m in mutants:
        if m.path is None:
            continue
        with open(os.path.join(work, m.path), "wb") as f:
            f.write(m.data)
        if hasattr(m, "case_text"):
            with open(os.path.join(work, m.case), "w", encoding="utf-8") as f:
                f.write(m.case_text)
    print("fuzz: %d inputs (%d mutated case files, %d mutated sphere and mesh files, %d command lines)" %
          (len(mutants), sum(1 for m in mutants if m.path and not hasattr(m, "case_text")),
           sum(1 for m in mutants if hasattr(m, "case_text")), sum(1 for m in mutants if not m.path)))

    # Pass 1: `fdem check` on one rank, every mutant.
    def do_check(m):
        np_ = getattr(m, "np", 1)
        cmd = ([a.fdem] if np_ == 1 else mpirun + ["-n", str(np_), a.fdem]) + \
            (m.cmd if hasattr(m, "cmd") else ["check", m.case])
        rc, text, to, dt = run_cmd(cmd, work, a.check_timeout if m.path else min(a.check_timeout, 20))
        return m, rc, text, to, dt, judge(m.kind, rc, text, to, np_, False)
    results = {}
    t0 = time.time()
    with cf.ThreadPoolExecutor(a.jobs) as ex:
        for m, rc, text, to, dt, bad in ex.map(do_check, mutants):
            results[m.id] = (m, rc, text, to, dt, bad, "check")
    tcheck = time.time() - t0

    # Pass 2: `fdem run` on a sample (1 and 2 ranks alternating), a few seconds each: half
    # accepted by check (a still-running case after the timeout is accepted), half refused
    # (the run must refuse them the same way, at once).
    rng = random.Random("%d:run" % a.seed)
    acc = [m for m in mutants if results[m.id][1] == 0 and m.case]
    ref = [m for m in mutants if results[m.id][1] == 2 and m.case]
    sample = rng.sample(acc, min(len(acc), a.run_sample // 2))
    sample += rng.sample(ref, min(len(ref), a.run_sample - len(sample)))

    def do_run(arg):
        j, m = arg
        np_ = 1 + j % 2
        out = os.path.join(work, "out", m.id.replace("/", "_").replace("#", "_"))
        cmd = ([a.fdem] if np_ == 1 else mpirun + ["-n", "2", a.fdem]) + ["run", m.case, "--out", out, "-q"]
        accepted = results[m.id][1] == 0
        # An accepted case may run for hours: stopped after a few seconds. A refused one must
        # stop by itself (the longer limit only guards against a hang on a loaded machine).
        rc, text, to, dt = run_cmd(cmd, work, a.run_timeout if accepted else a.check_timeout)
        bad = judge(m.kind, rc, text, to, np_, accepted, running=accepted)
        if not bad and not accepted and rc == 0:
            bad = "`fdem run` exit 0 where `fdem check` refused the input"
        return m, rc, text, to, dt, bad, "run -n %d" % np_
    t0 = time.time()
    runs = []
    with cf.ThreadPoolExecutor(max(1, a.jobs // 2)) as ex:
        runs = list(ex.map(do_run, enumerate(sample)))
    trun = time.time() - t0

    # Report.
    failures, xfails, xpass = [], [], []
    seen = set()
    for m, rc, text, to, dt, bad, how in list(results.values()) + runs:
        key = m.id
        if bad:
            (xfails if key in XFAIL else failures).append((m, rc, text, bad, how))
        seen.add((key, bool(bad)))
    for key in XFAIL:
        if (key, True) not in seen and any(k == key for k, _ in seen):
            xpass.append(key)
    counts = {}
    for m, rc, *_ in results.values():
        counts[rc] = counts.get(rc, 0) + 1
    print("fuzz: check: %d mutants in %.0f s, exit codes %s" %
          (len(results), tcheck, ", ".join("%s: %d" % (k, v) for k, v in sorted(counts.items()))))
    print("fuzz: run: %d mutants (%d accepted by check) in %.0f s" %
          (len(runs), sum(1 for r in runs if results[r[0].id][1] == 0), trun))
    slow = sorted(results.values(), key=lambda r: -r[4])[:3]
    print("fuzz: slowest checks: %s (limit %.0f s)" %
          (", ".join("%s %.1f s" % (r[0].id, r[4]) for r in slow), a.check_timeout))
    for lst, tag in ((xfails, "XFAIL"), (failures, "FAIL")):
        for m, rc, text, bad, how in lst:
            ls = text.strip().splitlines()
            key = [l for l in ls if re.search(r"error|what\(\)|terminate|ABORT|Sanitizer|runtime error|Signal:", l)]
            tail = "\n      ".join((key[:4] + ["..."] if key else []) + ls[-3:])
            print("%s %s [%s] %s: `fdem %s` -> %s%s\n      %s" %
                  (tag, m.id, m.kind, m.desc, " ".join(m.cmd) if hasattr(m, "cmd") and how == "check"
                   else how + " " + m.case, bad,
                   (" (finding %s)" % XFAIL[m.id]) if m.id in XFAIL else "", tail))
    for key in xpass:
        print("XPASS %s: listed as known failure %s but passes now: remove it from XFAIL" % (key, XFAIL[key]))
    if failures:
        print("fuzz: %d failing input(s); the mutants are in %s (seed %d)" % (len(failures), work, a.seed))
        return 1
    print("fuzz: all %d inputs handled (%d known failures listed in XFAIL)" % (len(results) + len(runs), len(xfails)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
