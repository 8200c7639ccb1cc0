#!/usr/bin/env bash
# The make targets a user reads about exist, and scripts/install-deps.sh helps off Debian:
#  - README.md's table of make targets (rows "| `make X` | ... |") names only targets the Makefile
#    defines; every target in the Makefile's .PHONY is in that table, and every rule's target is in
#    .PHONY; each row's time column is a measured time (a number and a unit) or "not measured";
#  - every `make X` mentioned in README.md, docs/**/*.md (inline code, code blocks) and the comments
#    of cases/**/*.yaml (commands: "#   make X", "(make X)", "or: make X", `make X`) names a
#    target of the Makefile (options such as make -C and variables such as make NP=4 are skipped);
#  - scripts/install-deps.sh on a PATH without dpkg-query and apt-get (nor cmake): exit 2, on
#    stderr that this is not Debian/Ubuntu, the libraries fdem needs and the plain CMake command;
#    with cmake, pkg-config and mpicxx on that PATH (a module environment): exit 0.
# No build, no run: a second. The fdem binary (argument 1) is not used.
# Usage: cli_make_targets.sh FDEM_BINARY SOURCE_DIR
source "$2/tests/support/cli_common.sh" "$@"

# 1, 2. The Makefile's rules and .PHONY (make's own database: -q runs no recipe), then the Python
# check of the README table and of every mention.
# Without make (it is one of the Debian packages install-deps.sh installs), the Makefile itself.
if command -v make >/dev/null 2>&1; then
  env -u MAKEFLAGS -u MFLAGS -u MAKELEVEL make --no-print-directory -C "$SRC" -pRrq : >"$tmp/db.txt" 2>/dev/null
else
  { echo "# Files"; grep -v -E '^[^:#]*[:+?]?=' "$SRC/Makefile"; echo "# Finished Make data base"; } >"$tmp/db.txt"
fi
# the data base lists rules after "# Files"; a target line is "name: prerequisites"
awk '/^# Files/,/^# Finished Make data base/' "$tmp/db.txt" | grep -E '^[A-Za-z0-9_][A-Za-z0-9_.-]*:' |
  grep -v -E '^(Makefile|GNUmakefile|makefile):' | cut -d: -f1 | sort -u >"$tmp/rules.txt"
grep -E '^\.PHONY:' "$tmp/db.txt" | head -1 | cut -d: -f2- | tr ' ' '\n' | grep -v '^$' | sort -u >"$tmp/phony.txt"
[ -s "$tmp/rules.txt" ] && [ -s "$tmp/phony.txt" ] || fail "could not read the Makefile's rules and .PHONY (make -pRrq)"

$PY - "$SRC" "$tmp/rules.txt" "$tmp/phony.txt" <<'PYEOF' || fail "make targets in README.md, docs/ or cases/ do not match the Makefile"
import glob, os, re, sys
src, rules_f, phony_f = sys.argv[1:4]
rules = set(open(rules_f).read().split())
phony = set(open(phony_f).read().split())
errors = []

# (i) README's table against the Makefile
readme = open(os.path.join(src, "README.md")).read().splitlines()
table = []
for n, line in enumerate(readme, 1):
    m = re.match(r"^\|\s*`make ([^`]+)`\s*\|", line)
    if not m:
        continue
    name = m.group(1).strip()
    cells = [c.strip() for c in line.strip().strip("|").split("|")]
    table.append(name)
    if name not in rules:
        errors.append(f"README.md:{n}: the table names `make {name}`: no such target in the Makefile")
    if len(cells) < 4:
        errors.append(f"README.md:{n}: `make {name}`: want 4 columns (target, what, time, source), got {len(cells)}")
    elif not ("not measured" in cells[2] or re.search(r"\d\s*(s|min|h)\b", cells[2])):
        errors.append(f"README.md:{n}: `make {name}`: time '{cells[2]}' is neither a measured time nor 'not measured'")
if not table:
    errors.append("README.md: no table of make targets (rows starting with | `make X` |)")
for name in sorted(set(t for t in table if table.count(t) > 1)):
    errors.append(f"README.md: `make {name}` is in the table twice")
for name in sorted(phony - set(table)):
    errors.append(f"Makefile: .PHONY target '{name}' is not in README.md's table of make targets")
for name in sorted(rules - phony):
    errors.append(f"Makefile: rule '{name}' is not in .PHONY")

# (ii) every `make X` mentioned
def check(where, token):
    token = token.rstrip(".,;:)'\"")
    if not token or token.startswith("-") or "=" in token or "$" in token:
        return 0  # make -C dir, make -n, make NP=4 ..., make $(TARGET): not a target name
    if token not in rules:
        errors.append(f"{where}: `make {token}` names no target of the Makefile")
    return 1

SPAN = re.compile(r"`make\s+([^`\s]+)[^`]*`")          # `make X ...`
CMD = re.compile(r"(?:^\s*(?:\$\s+)?|[;(]\s*|&&\s*|\|\|\s*|\bor:\s*)make\s+(\S+)")  # a command
mentions = 0
docs = [os.path.join(src, "README.md")] + sorted(glob.glob(os.path.join(src, "docs", "**", "*.md"), recursive=True))
for path in docs:
    rel = os.path.relpath(path, src)
    fenced = False
    for n, line in enumerate(open(path, encoding="utf-8", errors="replace"), 1):
        if line.lstrip().startswith("```"):
            fenced = not fenced
            continue
        if fenced:
            for m in CMD.finditer(line):
                mentions += check(f"{rel}:{n}", m.group(1))
        else:
            for m in SPAN.finditer(line):
                mentions += check(f"{rel}:{n}", m.group(1))
for path in sorted(glob.glob(os.path.join(src, "cases", "**", "*.yaml"), recursive=True)):
    rel = os.path.relpath(path, src)
    for n, line in enumerate(open(path, encoding="utf-8", errors="replace"), 1):
        if "#" not in line:
            continue
        comment = line[line.index("#") + 1:]
        seen = set()
        for m in SPAN.finditer(comment):
            seen.add(m.start(1)); mentions += check(f"{rel}:{n}", m.group(1))
        # a command in a comment: indented ("#   make X"), in parentheses, after "or:"
        for m in re.finditer(r"(?:^\s{2,}|\(\s*|\bor:\s*)make\s+(\S+)", comment):
            if m.start(1) not in seen:
                mentions += check(f"{rel}:{n}", m.group(1))

if errors:
    print("\n".join(errors))
    sys.exit(1)
print(f"make targets: README table {len(table)} targets = Makefile .PHONY {len(phony)}; "
      f"{mentions} `make X` mentions in README.md, docs/ and cases/ all name a target")
PYEOF

# 3. install-deps.sh off Debian. A PATH of only what the script uses besides dpkg-query and
# apt-get (grep, id); bash itself is started by its full path.
BASH_BIN=$(command -v bash)
mkdir -p "$tmp/nodeb" "$tmp/modules"
for t in grep id; do ln -s "$(command -v $t)" "$tmp/nodeb/$t"; done
env PATH="$tmp/nodeb" "$BASH_BIN" "$SRC/scripts/install-deps.sh" >"$tmp/d.out" 2>"$tmp/d.err"; c=$?
[ $c -eq 2 ] || { cat "$tmp/d.err"; fail "install-deps.sh without dpkg-query/apt-get/cmake: exit $c, want 2"; }
[ ! -s "$tmp/d.out" ] || { cat "$tmp/d.out"; fail "install-deps.sh off Debian writes to stdout (want stderr)"; }
for w in "not a Debian/Ubuntu system" "C++17" "CMake >= 3.18" "MPI" "PETSc" "parallel HDF5" "METIS" "Eigen" \
         "yaml-cpp" "GoogleTest" "libpetsc-real-dev" "cmake -S . -B build" "README.md#building-elsewhere" \
         "not on the PATH: cmake pkg-config mpicxx"; do
  grep -qF -- "$w" "$tmp/d.err" || { cat "$tmp/d.err"; fail "install-deps.sh off Debian does not say '$w'"; }
done
# a module environment: cmake, pkg-config and mpicxx found (stand-ins: only looked up, never run)
cp -a "$tmp/nodeb/." "$tmp/modules/"
for t in cmake pkg-config mpicxx; do printf '#!/bin/sh\nexit 1\n' >"$tmp/modules/$t"; chmod +x "$tmp/modules/$t"; done
env PATH="$tmp/modules" "$BASH_BIN" "$SRC/scripts/install-deps.sh" >/dev/null 2>"$tmp/m.err"; c=$?
[ $c -eq 0 ] || { cat "$tmp/m.err"; fail "install-deps.sh off Debian with cmake, pkg-config, mpicxx on the PATH: exit $c, want 0"; }
grep -qF "PETSc" "$tmp/m.err" || { cat "$tmp/m.err"; fail "install-deps.sh in a module environment does not list what fdem needs"; }
echo "install-deps.sh off Debian: exit 2 naming the libraries; exit 0 with cmake, pkg-config, mpicxx on the PATH"
echo "cli_make_targets: ok"
