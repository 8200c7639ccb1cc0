#!/usr/bin/env bash
# fem.mass_scaling: auto (docs/case-format.md#fem): the smallest scaling at which the FE stable
# step (with the interface contact stiffness, x fem.safety) is the DEM's own step.
# cases/coupling/sphere_on_plate.yaml, whose unscaled plate clamps the DEM step:
#  - auto on 2 ranks: run.json's coupling.mass_scaling s > 1, the DEM step not clamped and equal
#    to the step of the same case with a plate too heavy to clamp it (fem.mass_scaling 1e6),
#    dt_FE,stable within 1e-6 above it; s = (dt_DEM / dt_FE,stable(s = 1))^2 from the unscaled run;
#  - auto on 1 rank: interface.csv byte for byte the 2-rank run's (s chosen the same way);
#  - fem.mass_scaling given as the number auto chose: interface.csv byte for byte (the same masses);
#  - a run cut at step 1 500 and restarted from its checkpoint: the same interface.csv, and the
#    checkpoint's /fe attribute mass_scaling is s (a restart takes it, not one chosen from the
#    grains it starts with);
#  - auto in a case without coupling: exit 2, the key named.
# Usage: cli_mass_scaling.sh FDEM_BINARY SOURCE_DIR
source "$2/tests/support/cli_common.sh" "$@"
CASE="$SRC/cases/coupling/sphere_on_plate.yaml"
run() { local n=$1 out=$2; shift 2
  $MPIRUN -n "$n" "$FDEM" run "$CASE" --out "$tmp/$out" -q "$@" >"$tmp/$out.log" 2>&1 || { cat "$tmp/$out.log"; fail "run $out"; }; }
run 2 auto2 --set fem.mass_scaling=auto
run 1 auto1 --set fem.mass_scaling=auto
run 1 unscaled
run 1 heavy --set fem.mass_scaling=1e6
s=$($PY -c "import json; print(repr(json.load(open('$tmp/auto2/run.json'))['coupling']['mass_scaling']))")
run 1 given --set fem.mass_scaling=$s
run 2 cut --set fem.mass_scaling=auto --set time.steps=1500 --set output.checkpoint_every=500
$MPIRUN -n 2 "$FDEM" run "$CASE" --out "$tmp/cut" -q --set fem.mass_scaling=auto --restart "$tmp/cut/checkpoint.h5" \
  >"$tmp/cut2.log" 2>&1 || { cat "$tmp/cut2.log"; fail "restart"; }
$PY - "$tmp" <<'PYEOF' || fail "auto mass scaling"
import json, sys
t = sys.argv[1]
c = {d: json.load(open("%s/%s/run.json" % (t, d)))["coupling"] for d in ("auto2", "unscaled", "heavy")}
a, u, h = c["auto2"], c["unscaled"], c["heavy"]
print("unscaled: dt_DEM %.6e (clamped %d), FE stable %.6e; heavy: dt_DEM %.6e; auto: s %.6g, dt_DEM %.6e, FE stable %.6e"
      % (u["dt_dem"], u["dt_dem_clamped"], u["dt_fe_stable"], h["dt_dem"], a["mass_scaling"], a["dt_dem"], a["dt_fe_stable"]))
assert u["dt_dem_clamped"] == 1 and h["dt_dem_clamped"] == 0 and a["dt_dem_clamped"] == 0, (u, h, a)
assert a["dt_dem"] == h["dt_dem"], (a["dt_dem"], h["dt_dem"])
assert 0 <= a["dt_fe_stable"] / a["dt_dem"] - 1 < 1e-6, (a["dt_fe_stable"], a["dt_dem"])
s_expected = (h["dt_dem"] / u["dt_fe_stable"]) ** 2
assert abs(a["mass_scaling"] / s_expected - 1) < 1e-6 and a["mass_scaling"] > 1, (a["mass_scaling"], s_expected)
PYEOF
$PY - "$tmp/cut/checkpoint.h5" "$s" <<'PYEOF' || fail "the checkpoint's mass scaling"
import sys, h5py
with h5py.File(sys.argv[1], "r") as f:
    v = float(f["fe"].attrs["mass_scaling"])
assert v == float(sys.argv[2]), (v, sys.argv[2])
PYEOF
for d in auto1 given cut; do
  cmp "$tmp/auto2/interface.csv" "$tmp/$d/interface.csv" || fail "$d: interface.csv differs from the 2-rank auto run's"
done
cat > "$tmp/fe_only.yaml" <<'YAML'
name: fe_only
fem:
  mass_scaling: auto
  materials:
    - {name: steel, young: 2.0e11, poisson: 0.3, density: 7800}
  meshes:
    - name: bar
      material: steel
      block: {min: [0, 0, 0], max: [1, 0.1, 0.1], divisions: [4, 1, 1]}
  restraints:
    - {mesh: bar, node_set: xmin, fixed: [x, y, z]}
YAML
"$FDEM" check "$tmp/fe_only.yaml" >"$tmp/fe_only.log" 2>&1; rc=$?
[ $rc -eq 2 ] || { cat "$tmp/fe_only.log"; fail "auto without coupling: exit $rc, expected 2"; }
grep -q "fe_only.yaml:3.*fem.mass_scaling: .auto. .*needs a coupled case" "$tmp/fe_only.log" || { cat "$tmp/fe_only.log"; fail "auto without coupling: message"; }
echo "cli_mass_scaling: ok"
