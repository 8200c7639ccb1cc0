#!/usr/bin/env bash
# The resolved case -- case.yaml of every run, `fdem check --print-case` -- is the case itself:
# --set applied and the schema's defaults filled in (docs/case-format.md#output) change nothing.
#  - every shipped case (cases/, not cases/bad): `fdem check` of its resolved form says what
#    `fdem check` of the case says, and the resolved form validates against `fdem schema`;
#  - a particle run, a packing, a pure FE case and a coupled case give bitwise the same results
#    (history.csv, specimen.txt, fe_history.csv / reactions.csv, interface.csv) from the resolved
#    case as from the case, on 2 ranks; a run's case.yaml is the --print-case text.
# Usage: cli_case_yaml.sh FDEM_BINARY SOURCE_DIR
source "$2/tests/support/cli_common.sh" "$@"
cp -r "$SRC/cases" "$tmp/cases"   # the resolved files sit next to their cases (relative paths)
"$FDEM" schema >"$tmp/schema.json" || fail "fdem schema"
# one case (two at a time: each is a few short fdem processes); prints "checked" or "skipped"
one_case() {
  local f=$1 r="${1%.yaml}.resolved.yaml" k ra rb
  k=$(echo "$f" | tr / _)
  # Two singletons at once: Open MPI gives every isolated singleton job family 0, so they share
  # one session directory and the first to finish removes it under the other (mkdir fails in
  # orte_init). Each process gets its own session directory base.
  export OMPI_MCA_orte_tmpdir_base; OMPI_MCA_orte_tmpdir_base=$(mktemp -d "$tmp/o.XXXX")
  # a case that reads another case's output (out/specimens/...) cannot be checked here
  "$FDEM" check "$tmp/$f" >"$tmp/$k.a" 2>&1; ra=$?
  if [ $ra -ne 0 ] && grep -q "/out/" "$tmp/$k.a"; then echo "($f reads another run's output: skipped)"; return 0; fi
  "$FDEM" check "$tmp/$f" --print-case >"$tmp/$r" 2>"$tmp/$k.err" || { cat "$tmp/$k.err"; echo "FAIL: $f: check --print-case"; return 1; }
  "$FDEM" check "$tmp/$r" >"$tmp/$k.b" 2>&1; rb=$?
  sed -i "s#$r#$f#g" "$tmp/$k.b"
  [ $ra -eq 0 ] && [ $rb -eq 0 ] || { cat "$tmp/$k.b"; echo "FAIL: $f: check exits $ra, its resolved form $rb"; return 1; }
  cmp -s "$tmp/$k.a" "$tmp/$k.b" || { diff "$tmp/$k.a" "$tmp/$k.b" | head -20; echo "FAIL: $f: check of the resolved case differs"; return 1; }
  echo "checked $f"
}
export -f one_case; export FDEM tmp
(cd "$tmp" && find cases -name "*.yaml" -not -path "cases/bad/*" | sort) | xargs -P 2 -I{} bash -c 'one_case "$1"' _ {} \
  >"$tmp/cases.log" 2>&1 || { cat "$tmp/cases.log"; fail "fdem check of the resolved cases"; }
grep -v "^checked " "$tmp/cases.log"
n=$(grep -c "^checked " "$tmp/cases.log")
$PY - "$tmp/schema.json" "$tmp" <<'PYEOF' || fail "the resolved cases against the JSON Schema"
import sys, json, glob, jsonschema
from yaml12 import load  # tests/support: YAML 1.2 numbers, as fdem reads them
v = jsonschema.Draft7Validator(json.load(open(sys.argv[1])))
files = sorted(glob.glob(sys.argv[2] + "/cases/**/*.resolved.yaml", recursive=True))
bad = [(f, e.message) for f in files for e in list(v.iter_errors(load(f)))[:1]]
print("%d resolved cases validate" % (len(files) - len(bad)))
assert files and not bad, bad
PYEOF
echo "check: $n shipped cases, the same from their resolved form"

# name | case | --set | files that must be identical
run_both() {
  local name=$1 case=$2 set=$3; shift 3
  local r="${case%.yaml}.resolved.yaml"
  $MPIRUN -n 2 "$FDEM" run "$tmp/$case" --out "$tmp/$name.a" $set -q >"$tmp/$name.a.log" 2>&1 || { cat "$tmp/$name.a.log"; fail "$name: run"; }
  $MPIRUN -n 2 "$FDEM" run "$tmp/$r" --out "$tmp/$name.b" $set -q >"$tmp/$name.b.log" 2>&1 || { cat "$tmp/$name.b.log"; fail "$name: run of the resolved case"; }
  for out in "$@"; do
    [ -s "$tmp/$name.a/$out" ] || fail "$name: no $out"
    cmp -s "$tmp/$name.a/$out" "$tmp/$name.b/$out" || fail "$name: $out differs between the case and its resolved form"
  done
  # case.yaml is the --print-case text (apart from the header's overrides)
  "$FDEM" check "$tmp/$case" $set --print-case | grep -v '^#' >"$tmp/$name.p"
  grep -v '^#' "$tmp/$name.a/case.yaml" | cmp -s - "$tmp/$name.p" || fail "$name: case.yaml is not the --print-case text"
  echo "$name: $* identical from the resolved case"
}
run_both settle cases/demo/settle.yaml "--set time.steps=2000" history.csv walls.csv
run_both pack cases/specimens/pack_layers_ci.yaml "" specimen.txt
run_both cantilever cases/fem/cantilever.yaml "" fe_history.csv reactions.csv
run_both sphere cases/coupling/sphere_on_plate.yaml "" history.csv interface.csv
echo "cli_case_yaml: ok"
