#!/usr/bin/env python3
"""Check the layering of src/ (README.md#layout): every `#include "folder/..."` must point to the
same folder or to a folder its layer may use; no #include cycles between files; no MPI in the
DEM kernels (src/dem) or the element kernels (src/fem/element*); dem and fem never include io.

    check_layers.py [SRC_DIR]            check SRC_DIR (default: the src/ next to this script)
    check_layers.py --self-test SRC_DIR  prove the check fails on injected violations

Exit 0 when clean, 1 with one line per violation ("file:line: error: ...") otherwise. Run by
every build (CMake target check_layers) and by ctest (tests check_layers, check_layers_selftest).
"""
import os
import re
import shutil
import sys
import tempfile

# The layers, lowest first, and the folders each may include (besides itself). This is the link
# graph of CMakeLists.txt (fdem_<folder> libraries), transitively closed.
ALLOWED = {
    "base": set(),
    "dem": {"base"},
    "fem": {"base"},
    "partition": {"base", "dem", "fem"},
    "coupling": {"base", "dem", "fem", "partition"},
    "io": {"base", "dem", "fem"},
    "app": {"base", "dem", "fem", "partition", "coupling", "io"},
}
# Where MPI must not appear (the kernels are plain computations over local data).
NO_MPI = [("dem", ""), ("fem", "element")]  # (folder, file-name prefix)

INCLUDE = re.compile(r'^\s*#\s*include\s*"([^"]+)"')
SOURCE_EXT = (".hpp", ".h", ".cpp", ".cc", ".hh")


def strip_comment(line):
    i = line.find("//")
    return line if i < 0 else line[:i]


def check(src):
    src = os.path.abspath(src)
    errors = []
    shown = os.path.relpath(src)
    if shown.startswith(".."):
        shown = src
    # the table itself must be a DAG (an edge a -> b: a includes b)
    for a, deps in ALLOWED.items():
        for b in deps:
            if a in ALLOWED.get(b, set()):
                errors.append(f"{__file__}: error: ALLOWED has a cycle between '{a}' and '{b}'")
    files = {}  # "folder/name" -> [(line number, included "folder/name")]
    for root, _, names in os.walk(src):
        for name in sorted(names):
            if not name.endswith(SOURCE_EXT):
                continue
            path = os.path.join(root, name)
            rel = os.path.relpath(path, src).replace(os.sep, "/")
            folder = rel.split("/")[0] if "/" in rel else ""
            where = f"{shown}/{rel}"
            if folder not in ALLOWED:
                errors.append(f"{where}:1: error: folder '{folder or '.'}' is not a known layer; "
                              f"add it to ALLOWED in scripts/check_layers.py and to CMakeLists.txt")
                continue
            incs = []
            with open(path, encoding="utf-8", errors="replace") as f:
                lines = f.read().split("\n")
            no_mpi = any(folder == d and name.startswith(p) for d, p in NO_MPI)
            for ln, line in enumerate(lines, 1):
                m = INCLUDE.match(line)
                if m:
                    target = m.group(1)
                    tfolder = target.split("/")[0] if "/" in target else folder
                    if "/" not in target:
                        target = f"{folder}/{target}"
                    incs.append((ln, target))
                    if tfolder != folder and tfolder in ALLOWED and tfolder not in ALLOWED[folder]:
                        if folder in ALLOWED[tfolder]:
                            how = f"which is above it ('{tfolder}' uses '{folder}': a cycle)"
                        else:
                            how = "which it does not link (a sibling or unrelated layer)"
                        if tfolder == "io" and folder in ("dem", "fem"):
                            how += "; case-format types belong in io, physics specs in dem / fem"
                        may = ", ".join(sorted(ALLOWED[folder])) or "nothing but itself"
                        errors.append(f"{where}:{ln}: error: layer '{folder}' includes \"{m.group(1)}\" of layer "
                                      f"'{tfolder}', {how} ('{folder}' may include: {may})")
                if no_mpi:
                    code = strip_comment(line)
                    if "MPI_" in code or re.search(r"#\s*include\s*<mpi\.h>", code):
                        errors.append(f"{where}:{ln}: error: MPI in '{folder}/{name}': the {folder} kernels "
                                      f"must not use MPI (reduce in partition/ or the engine)")
            files[rel] = incs
    # file-level #include cycles (among files of src/)
    state = {}  # 1: on the stack, 2: done
    stack = []

    def visit(f):
        state[f] = 1
        stack.append(f)
        for ln, t in files.get(f, []):
            if t not in files:
                continue
            if state.get(t) == 1:
                cyc = stack[stack.index(t):] + [t]
                errors.append(f"{shown}/{f}:{ln}: error: #include cycle: " + " -> ".join(cyc))
            elif t not in state:
                visit(t)
        stack.pop()
        state[f] = 2

    for f in sorted(files):
        if f not in state:
            visit(f)
    return errors


def self_test(src):
    """Each injected violation must make check() fail, naming the file and line."""
    ok = True
    base_errors = check(src)
    if base_errors:
        print("self-test: the unmodified tree already fails:\n" + "\n".join(base_errors))
        return False
    cases = [
        ("upward include", "dem/particles.hpp", '#include "io/case.hpp"\n', "dem/particles.hpp:"),
        ("sideways include", "fem/mesh.hpp", '#include "dem/particles.hpp"\n', "fem/mesh.hpp:"),
        ("partition above coupling", "partition/halo.hpp", '#include "coupling/coupler.hpp"\n', "partition/halo.hpp:"),
        ("base includes a layer", "base/vec3.hpp", '#include "dem/material.hpp"\n', "base/vec3.hpp:"),
        ("MPI in dem", "dem/walls.cpp", "static int bad_rank() { int r; MPI_Comm_rank(MPI_COMM_WORLD, &r); return r; }\n",
         "dem/walls.cpp:"),
        ("MPI in fem/element", "fem/element.cpp", "#include <mpi.h>\n", "fem/element.cpp:"),
        ("file cycle", "dem/vec3_cycle_a.hpp", '#include "dem/vec3_cycle_b.hpp"\n', "#include cycle"),
    ]
    for what, rel, text, expect in cases:
        tmp = tempfile.mkdtemp(prefix="fdem_layers_")
        try:
            copy = os.path.join(tmp, "src")
            shutil.copytree(src, copy)
            path = os.path.join(copy, rel)
            if what == "file cycle":
                with open(os.path.join(copy, "dem/vec3_cycle_b.hpp"), "w") as f:
                    f.write('#pragma once\n#include "dem/vec3_cycle_a.hpp"\n')
                with open(path, "w") as f:
                    f.write("#pragma once\n" + text)
            else:
                with open(path) as f:
                    body = f.read()
                # after the first line (#pragma once or the first include): a line number > 1
                first, rest = body.split("\n", 1)
                with open(path, "w") as f:
                    f.write(first + "\n" + text + rest)
            errs = check(copy)
            hit = [e for e in errs if expect in e]
            if hit:
                print(f"self-test: {what}: fails as it must: {hit[0].replace(copy, 'src')}")
            else:
                print(f"self-test: {what}: NOT detected (errors: {errs})")
                ok = False
        finally:
            shutil.rmtree(tmp)
    return ok


def main(argv):
    if len(argv) >= 2 and argv[1] == "--self-test":
        src = argv[2] if len(argv) > 2 else os.path.join(os.path.dirname(__file__), "..", "src")
        return 0 if self_test(src) else 1
    src = argv[1] if len(argv) > 1 else os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "src")
    errors = check(src)
    for e in errors:
        print(e, file=sys.stderr)
    if errors:
        print(f"check_layers: {len(errors)} layering violation(s); the allowed graph is in "
              f"scripts/check_layers.py (ALLOWED) and README.md#layout", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
