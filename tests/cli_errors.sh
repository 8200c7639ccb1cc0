#!/usr/bin/env bash
# Bad input through the real command line on 2 ranks: every file in cases/bad/ must fail with
# exit code 2, print the documented message (its first line: "# expected error: ...") exactly
# once, and leave no output directory behind. Also: bad command lines and `fdem check`.
# Usage: cli_errors.sh FDEM_BINARY SOURCE_DIR
set -u
FDEM=$1; SRC=$2
MPIRUN="bash $SRC/scripts/mpirun.sh"
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
fail=0
# one bad case (run two at a time: each is mostly mpirun's start-up)
one_bad() {
  local f=$1 expected loc what out code n b
  b=$(basename "$f" .yaml)
  expected=$(head -1 "$f" | sed -n 's/^# expected error: //p')
  [ -n "$expected" ] || { echo "FAIL $f: no '# expected error:' line"; return 1; }
  # Printed as "FILE:LINE: error: ...WHAT..." (the compiler convention); WHAT may be a part.
  loc=${expected%%: *}; what=${expected#*: }
  out="$tmp/out_$b"
  $MPIRUN -n 2 "$FDEM" run "$f" --out "$out" >"$tmp/$b.stdout" 2>"$tmp/$b.stderr"
  code=$?
  n=$(grep -F -- "$loc: error: " "$tmp/$b.stderr" | grep -cF -- "$what")
  if [ "$code" -ne 2 ]; then echo "FAIL $f: exit code $code, expected 2"; cat "$tmp/$b.stderr"; return 1
  elif [ "$n" -ne 1 ]; then echo "FAIL $f: expected message printed $n times, want once: $expected"; cat "$tmp/$b.stderr"; return 1
  elif [ -e "$out" ]; then echo "FAIL $f: output directory $out was created"; return 1
  else echo "ok   $b: $expected"; fi
}
export -f one_bad; export FDEM MPIRUN tmp
printf '%s\n' "$SRC"/cases/bad/*.yaml | xargs -P 2 -I{} bash -c 'one_bad "$1"' _ {} || fail=1
# Command-line errors.
"$FDEM" run >/dev/null 2>"$tmp/e"; c=$?
[ $c -eq 2 ] && grep -q "no case file given" "$tmp/e" || { echo "FAIL: 'fdem run' without a case: exit $c"; fail=1; }
"$FDEM" run "$SRC/cases/demo/settle.yaml" --bogus >/dev/null 2>"$tmp/e"; c=$?
[ $c -eq 2 ] && grep -q "unknown option '--bogus'" "$tmp/e" || { echo "FAIL: unknown option: exit $c"; fail=1; }
"$FDEM" run "$tmp/does_not_exist.yaml" >/dev/null 2>"$tmp/e"; c=$?
[ $c -eq 2 ] && grep -q "does_not_exist.yaml" "$tmp/e" || { echo "FAIL: missing case file: exit $c"; cat "$tmp/e"; fail=1; }
"$FDEM" check "$SRC/cases/demo/settle.yaml" --set materials.0.young=-5 >/dev/null 2>"$tmp/e"; c=$?
[ $c -eq 2 ] && grep -q "young" "$tmp/e" || { echo "FAIL: --set to a negative modulus: exit $c"; cat "$tmp/e"; fail=1; }
"$FDEM" --version | grep -q "^fdem [0-9]" || { echo "FAIL: --version"; fail=1; }
# --specimen: only for packing cases; a missing or foreign specimen is refused (exit 2, once).
"$FDEM" run "$SRC/cases/demo/settle.yaml" --specimen "$tmp/x.h5" --out "$tmp/sp" >/dev/null 2>"$tmp/e"; c=$?
[ $c -eq 2 ] && grep -q "has no packing section" "$tmp/e" || { echo "FAIL: --specimen without packing: exit $c"; cat "$tmp/e"; fail=1; }
$MPIRUN -n 2 "$FDEM" run "$SRC/cases/specimens/pack_layers_ci.yaml" --specimen "$tmp/none.h5" --out "$tmp/sp" >/dev/null 2>"$tmp/e"; c=$?
n=$(grep -c "none.h5" "$tmp/e")
[ $c -eq 2 ] && [ "$n" -eq 1 ] || { echo "FAIL: --specimen of a missing file: exit $c, printed $n times"; cat "$tmp/e"; fail=1; }
"$FDEM" run "$SRC/cases/examples/inline.yaml" --set time.duration=1e-4 --out "$tmp/other" -q >/dev/null 2>&1 ||
  { echo "FAIL: inline.yaml"; fail=1; }
$MPIRUN -n 2 "$FDEM" run "$SRC/cases/geogrid_pullout/ci.yaml" --specimen "$tmp/other/checkpoint.h5" --out "$tmp/sp" \
  >/dev/null 2>"$tmp/e"; c=$?
[ $c -eq 2 ] && grep -q "packed for another case" "$tmp/e" || { echo "FAIL: --specimen of another case: exit $c"; cat "$tmp/e"; fail=1; }
# Too many ranks for a tiny domain is an input error too (exit 2, once).
$MPIRUN -n 3 "$FDEM" check "$SRC/cases/examples/inline.yaml" --set domain.max=[0.01,0.01,0.01] \
  --set "domain.min=[0,0,0]" >/dev/null 2>"$tmp/e"; c=$?
if [ $c -ne 2 ]; then echo "FAIL: domain too small for 3 ranks: exit $c"; cat "$tmp/e"; fail=1; fi
# Every shipped case passes `fdem check` on 2 ranks.
check_one() { local k; k=$(echo "$1" | tr / _)
  $MPIRUN -n 2 "$FDEM" check "$1" >"$tmp/$k.o" 2>"$tmp/$k.e" || { echo "FAIL: check $1"; cat "$tmp/$k.e"; return 1; }; }
export -f check_one
printf '%s\n' "$SRC"/cases/demo/*.yaml "$SRC"/cases/examples/*.yaml "$SRC"/cases/lab/*.yaml \
  "$SRC"/cases/geogrid_pullout/*.yaml "$SRC"/cases/void/*.yaml "$SRC"/cases/pipe/*.yaml |
  xargs -P 2 -I{} bash -c 'check_one "$1"' _ {} || fail=1
[ $fail -eq 0 ] && echo "all command-line error checks passed"
exit $fail
