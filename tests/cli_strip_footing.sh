#!/usr/bin/env bash
# The strip footing on geogrid-reinforced sand, CI size (cases/strip_footing/ci_n*.yaml; thesis
# ch. 5; docs/cases/strip_footing.md): packing with the grid inserted and the surface struck off,
# the footing placed on it and loaded to 20, 40 and 60 kPa in held increments.
#  - packing.level: no grain centre above the box's top (0.15 m), grains removed (packing.json);
#  - N = 1 on 2 ranks: three holds, each converged, the footing's stress within 2 % of its
#    target, the settlement growing with the pressure, the footing moved less than holds.creep in
#    the last check interval (walls.csv); at each hold's end the floor carries the
#    footing's load plus the grains' weight (frictionless walls: within 1 %); the grid's interface
#    forces balance its restraints' reactions (it is held only in y, on its symmetry planes:
#    F_interface + R = 0 in x, y and z within 2 % of the faces' summed force magnitudes; the holds
#    converge the FE's residual to 1 % of its nodal forces); holds.csv's held_by `none` for every
#    converged hold, and the grid's part (the thesis's rolling law, fem.damping 1000,
#    coupling.creep 5 um, creep_damping 0.5: interface.csv's fe_damping 1000 at the start, never
#    above, below 500 while the grid's load is small) balanced as a whole (resultant < 1 %) with
#    its norm < 1 % or its drift since the previous check (its nodes' RMS displacement) < 5 um (a
#    few rib nodes chatter about their places against the grains at rest);
#  - N = 1 on 1 rank, from the 2-rank run's specimen, cut 750 steps into hold 2 and continued on 2
#    ranks from its checkpoint (which carries the grid's displacements at the last check, the
#    reference of coupling.creep's drift): holds.csv, interface.csv and reactions.csv byte for byte
#    the 2-rank run's (the packing's rank independence: cli_pack, cli_coupled_pack);
#  - holds.creep (a hold ends only when the footing has stopped sinking): N = 0 from its specimen,
#    cut 750 steps into hold 2 on 2 ranks and restarted on 1: holds.csv byte for byte the
#    uninterrupted one's;
#  - N = 0 on 2 ranks: the same holds and floor checks without a grid;
#  - scripts/footing_report.py on both: footing.csv with the same pressures, the reaction balance
#    it computes within 1 % of 1, the figures written.
# Usage (ctest): cli_strip_footing.sh FDEM_BINARY SOURCE_DIR
source "$2/tests/support/cli_common.sh" "$@"
D="$SRC/cases/strip_footing"
$MPIRUN -n 2 "$FDEM" run "$D/ci_n1.yaml" --out "$tmp/n1" "${ref_seed[@]}" >"$tmp/n1.log" 2>&1 || { tail -30 "$tmp/n1.log"; fail "N = 1, 2 ranks"; }
grep -E "^hold .* at step|levelled|inserted" "$tmp/n1.log"
$MPIRUN -n 2 "$FDEM" run "$D/ci_n0.yaml" --out "$tmp/n0" "${ref_seed[@]}" >"$tmp/n0.log" 2>&1 || { tail -30 "$tmp/n0.log"; fail "N = 0, 2 ranks"; }
grep -E "^hold .* at step|levelled" "$tmp/n0.log"
for n in 0 1; do
  $PY - "$tmp/n$n" "$n" <<'PYEOF' || fail "N = $n: holds / equilibrium"
import csv, json, math, sys
d, n = sys.argv[1], int(sys.argv[2])
def rows(f):
    return list(csv.DictReader(open(d + "/" + f)))
walls = {int(float(r["step"])): r for r in rows("walls.csv")}
W = 0.0
for line in open(d + "/specimen.txt"):
    if not line.startswith("#") and line.strip():
        W += 2650 * 4 / 3 * math.pi * float(line.split()[4]) ** 3 * 9.81
# packing.level: the specimen struck off at the box's top (z = 0.15 m): no grain centre above it
pk = json.load(open(d + "/packing.json"))
assert pk["level"]["z"] == 0.15 and pk["level"]["grains_removed"] > 0, pk.get("level")
zmax = max(float(l.split()[3]) for l in open(d + "/specimen.txt") if l.strip() and not l.startswith("#"))
assert zmax <= 0.1505, zmax  # (final_steps may lift a grain by a hair)
h = rows("holds.csv")
assert [r["hold"] for r in h] == ["1", "2", "3"], h
prev = 0.0
uz = {s: float(w["footing_uz"]) for s, w in walls.items()}
for r, t in zip(h, [20000, 40000, 60000]):
    s_ = int(r["step"])
    creep = abs(uz[s_] - uz[s_ - 500])  # walls.csv every 500 steps = holds.check_every
    assert creep < 5e-6, (r["hold"], creep)
    s, q, u = int(r["step"]), float(r["footing_stress"]), float(r["footing_settlement"])
    assert r["converged"] == "1" and abs(q - t) / t < 0.02, r
    assert r["held_by"] == "none", r  # (a converged hold: nothing held it open)
    assert u > prev, (u, prev)
    prev = u
    floor, footing = -float(walls[s]["bottom_fz"]), float(walls[s]["footing_fz"])
    ratio = floor / (footing + W)
    print("N = %d hold %s: q %.1f Pa (target %d), s %.3f mm; floor %.3f N = footing %.3f N + weight %.3f N (%.5f)"
          % (n, r["hold"], q, t, 1e3 * u, floor, footing, W, ratio))
    assert abs(ratio - 1) < 0.01
if n == 1:
    # the grid's part at each hold's end (holds.csv): balanced as a whole, and either its residual
    # norm below the tolerance or at rest by coupling.creep (drift since the last check < 5 um)
    for r in h:
        res, nrm, v, u = (float(r["grid_" + k]) for k in ("resultant", "unbalanced", "speed", "drift"))
        print("  grid, hold %s: resultant %.4f, norm %.4f, RMS speed %.3f mm/s, drift %.3f um"
              % (r["hold"], res, nrm, 1e3 * v, 1e6 * u))
        assert res < 0.01 and (nrm < 0.01 or u < 5e-6), r
    # coupling.creep_damping 0.5: fem.damping (1000 1/s) until the first check, then never above it,
    # and below it while the grid's load is small (the footing's load reaches the grid in hold 1)
    c = [float(r["fe_damping"]) for r in rows("interface.csv")]
    print("  FE damping: first %.1f, least %.1f, last %.1f 1/s" % (c[0], min(c), c[-1]))
    assert c[0] == 1000 and max(c) <= 1000 and min(c) < 500, (c[0], min(c), max(c))
    iface = {int(float(r["step"])): r for r in rows("interface.csv")}
    reac = {int(float(r["step"])): r for r in rows("reactions.csv")}
    for r in h:
        s = int(r["step"])
        i, R = iface[s], reac[s]
        scale = sum(math.sqrt(sum(float(i[f + "_f" + c]) ** 2 for c in "xyz")) for f in ("top", "bottom", "rest"))
        for c in "xyz":
            F = float(i["f" + c])
            Rc = float(R["grid_ymin_r" + c]) + float(R["grid_ymax_r" + c])
            print("  grid, hold %s: interface f%s %.4f N + reactions %.4f N = %.4f N (|F| of the top, bottom and other faces summed: %.2f N)"
                  % (r["hold"], c, F, Rc, F + Rc, scale))
            # a hold ends when the FE's residual resultant is below holds.tolerance (1 %) of the sum
            # of its nodal forces' magnitudes (>= the faces' sum): static up to that, not exactly
            assert abs(F + Rc) < 0.02 * scale, (c, F, Rc, scale)
PYEOF
done
# holds.creep across a restart: N = 0 cut inside hold 2 on 2 ranks (the checkpoint carries the
# footing's position at the last check), continued on 1 rank: the same holds.csv
cut=$($PY -c "import csv; h=list(csv.DictReader(open('$tmp/n0/holds.csv'))); print(int(h[0]['step']) + 750)")
$MPIRUN -n 2 "$FDEM" run "$D/ci_n0.yaml" --out "$tmp/n0c" -q --specimen "$tmp/n0/specimen.h5" --set time.steps=$cut >"$tmp/n0c.log" 2>&1 ||
  { tail -30 "$tmp/n0c.log"; fail "N = 0 cut"; }
$MPIRUN -n 1 "$FDEM" run "$D/ci_n0.yaml" --out "$tmp/n0c" -q --restart "$tmp/n0c/checkpoint.h5" >"$tmp/n0c2.log" 2>&1 ||
  { tail -30 "$tmp/n0c2.log"; fail "N = 0 restart"; }
cmp "$tmp/n0/holds.csv" "$tmp/n0c/holds.csv" || { cat "$tmp/n0c/holds.csv"; fail "N = 0: the restarted run's holds.csv differs"; }
# N = 1 on 1 rank from the 2-rank run's specimen, cut 750 steps into hold 2 (past a check: the
# checkpoint carries the grid's displacements at it, coupling.creep's reference) and continued on 2
cut=$($PY -c "import csv; print(int(csv.DictReader(open('$tmp/n1/holds.csv')).__next__()['step']) + 750)")
$MPIRUN -n 1 "$FDEM" run "$D/ci_n1.yaml" --out "$tmp/n1r1" -q --specimen "$tmp/n1/specimen.h5" --set time.steps=$cut \
  >"$tmp/n1r1.log" 2>&1 || { tail -30 "$tmp/n1r1.log"; fail "N = 1, 1 rank"; }
$MPIRUN -n 2 "$FDEM" run "$D/ci_n1.yaml" --out "$tmp/n1r1" -q --restart "$tmp/n1r1/checkpoint.h5" >"$tmp/n1r2.log" 2>&1 ||
  { tail -30 "$tmp/n1r2.log"; fail "N = 1 restart"; }
for f in holds.csv interface.csv reactions.csv; do  # (less the cut run's last row, at step $cut)
  grep -v -E "^([^,]*,)?$cut," "$tmp/n1r1/$f" | cmp "$tmp/n1/$f" - ||
    fail "N = 1: $f differs between 2 ranks and 1 rank cut at step $cut, continued on 2"
done
$PY "$SRC/scripts/footing_report.py" "$tmp/n0" "$tmp/n1" --figures "$tmp/fig" >"$tmp/report.log" 2>&1 ||
  { cat "$tmp/report.log"; fail "footing_report.py"; }
for p in pressure_settlement grid_profiles grid_max sigma_v_depth; do
  [ -s "$tmp/fig/$p.png" ] || fail "footing_report.py wrote no $p.png"
done
$PY - "$tmp" <<'PYEOF' || fail "footing.csv"
import csv, json, sys
numbers = {}
for n in (0, 1):
    r = list(csv.DictReader(open("%s/n%d/footing.csv" % (sys.argv[1], n))))
    assert [round(float(x["q_kPa"])) for x in r] == [20, 40, 60], r
    for x in r:
        assert abs(float(x["reaction_balance"]) - 1) < 0.01, x
        numbers["n%d_settlement_%d_kPa_mm" % (n, round(float(x["q_kPa"])))] = float(x["settlement_mm"])
        if n == 1:
            numbers["n1_grid_max_down_%d_kPa_mm" % round(float(x["q_kPa"]))] = float(x["grid_max_down_mm"])
    pk = json.load(open("%s/n%d/packing.json" % (sys.argv[1], n)))
    numbers["n%d_grains" % n] = pk["particles"]
# the case page's headline numbers: the settlements (N = 0 and 1) and the grid's, against the reference
json.dump(numbers, open(sys.argv[1] + "/numbers.json", "w"), indent=1)
PYEOF
reference_check strip_footing_ci "$tmp/numbers.json"
echo "strip footing (ci): passed"
