#!/usr/bin/env bash
# The case schema (src/io/case_schema_table.cpp) and what is made from it:
#  - `fdem schema` prints a valid draft-07 JSON Schema; every shipped case (cases/, not cases/bad)
#    validates against it, and the bad cases whose mistake a schema can see (an unknown key, a
#    wrong type, a missing required key, a word not in the list, a number of the wrong sign)
#    do not;
#  - the key tables of docs/case-format.md are the schema's (`--check-docs`), and a drifted
#    table is found and named by its line;
#  - `--markdown` prints a section's table, an unknown section is an error (exit 2).
# Usage: cli_schema.sh FDEM_BINARY SOURCE_DIR
source "$2/tests/support/cli_common.sh" "$@"
"$FDEM" schema >"$tmp/schema.json" || fail "fdem schema"
$PY - "$tmp/schema.json" "$SRC" <<'PYEOF' || fail "JSON Schema"
import sys, json, glob, os, jsonschema
from yaml12 import load  # tests/support: YAML 1.2 numbers, as fdem reads them
schema = json.load(open(sys.argv[1]))
jsonschema.Draft7Validator.check_schema(schema)
v = jsonschema.Draft7Validator(schema)
src = sys.argv[2]
good = sorted(f for f in glob.glob(src + "/cases/**/*.yaml", recursive=True) if "/cases/bad/" not in f)
bad = ["unknown_key", "unknown_contact_model", "wrong_type", "negative_density", "missing_key",
       "packing_bad_settle_criterion", "packing_zero_layers", "servo_negative_stress"]
problems = []
for f in good:
    errs = list(v.iter_errors(load(f)))
    if errs:
        problems.append("%s: %s at %s" % (os.path.relpath(f, src), errs[0].message, list(errs[0].absolute_path)))
for b in bad:
    f = src + "/cases/bad/" + b + ".yaml"
    if not list(v.iter_errors(load(f))):
        problems.append("cases/bad/%s.yaml passes the schema" % b)
print("schema: %d definitions; %d shipped cases valid, %d bad cases refused"
      % (len(schema["definitions"]), len(good), len(bad)))
assert len(good) > 20
assert not problems, "\n".join(problems)
PYEOF
"$FDEM" schema --check-docs "$SRC/docs/case-format.md" || fail "docs/case-format.md's key tables differ from the schema"
# a drifted table: one generated row changed
line=$(grep -n '^| `porosity` ' "$SRC/docs/case-format.md" | head -1 | cut -d: -f1)
[ -n "$line" ] || fail "no porosity row in docs/case-format.md"
sed "${line}s/|/| (edited)/2" "$SRC/docs/case-format.md" >"$tmp/drift.md"
"$FDEM" schema --check-docs "$tmp/drift.md" 2>"$tmp/drift.err" && fail "a drifted table passes --check-docs"
grep -q "drift.md:$line: error: the key tables differ" "$tmp/drift.err" || { cat "$tmp/drift.err"; fail "the drift is not named by its line ($line)"; }
"$FDEM" schema --docs "$tmp/drift.md" | cmp -s - "$SRC/docs/case-format.md" || fail "--docs does not restore the page"
"$FDEM" schema --markdown packing.settle | grep -q '^| `porosity_change` ' || fail "--markdown packing.settle"
"$FDEM" schema --markdown nowhere 2>"$tmp/nw.err"; rc=$?
[ $rc -eq 2 ] && grep -q "no section 'nowhere'" "$tmp/nw.err" || fail "an unknown section: exit $rc, $(cat "$tmp/nw.err")"
echo "cli_schema: ok"
