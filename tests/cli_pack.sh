#!/usr/bin/env bash
# Multi-layer gravitational packing end to end on 2 ranks (cases/specimens/pack_layers_ci.yaml,
# frictionless, 4 layers, ~2 700 grains): the case ends after packing; packing.json reports every
# layer; the interior porosity (box 2 d_max from the walls and bottom, 3 d_max below the
# surface) and every layer's band of it lie within +-0.02 of the target 0.37; the size
# distribution matches the requested one; the saved sphere file is reused by
# cases/specimens/reuse_ci.yaml (a servo plate on top) which runs; each layer's progress line gives
# the interior porosity so far or says the bed has no interior yet (never nan).
# Usage: cli_pack.sh FDEM_BINARY SOURCE_DIR
source "$2/tests/support/cli_common.sh" "$@"

$MPIRUN -n 2 "$FDEM" run "$SRC/cases/specimens/pack_layers_ci.yaml" --out "$tmp/pack" \
  --set packing.save="$tmp/spec.txt" >"$tmp/pack.log" 2>&1 || { cat "$tmp/pack.log"; fail "packing failed"; }
cat "$tmp/pack.log"
for f in packing.json specimen.txt specimen.h5; do [ -f "$tmp/pack/$f" ] || fail "no $f"; done
[ -f "$tmp/spec.txt" ] || fail "packing.save not written"
[ ! -f "$tmp/pack/history.csv" ] || fail "a packing-only case ran steps after packing"
$PY - "$tmp/pack/packing.json" <<'PYEOF' || fail "packing report"
import json, sys
d = json.load(open(sys.argv[1]))
target = d["target_porosity"]
n = d["interior"]["porosity"]
print(f"interior porosity {n:.4f} (target {target}), Z {d['interior']['coordination']:.3f}, K0 {d['interior']['k0']:.3f}")
assert abs(n - target) <= 0.02, f"interior porosity {n} not within 0.02 of {target}"
assert len(d["layers"]) == 4
for l in d["layers"]:
    assert l["added"] > 400, l
    if "porosity" in l:
        print(f"layer {l['layer']}: band porosity {l['porosity']:.4f}")
        assert abs(l["porosity"] - target) <= 0.02, l
assert sum(l["added"] for l in d["layers"]) == d["particles"]
g = d["grading"]
for a, b in zip(g["requested_passing"], g["generated_passing"]):
    assert abs(a - b) < 3.0, g
assert abs(g["generated"]["cu"] - g["requested"]["cu"]) < 0.05, g
fab = d["interior"]["fabric"]
assert abs(fab[0] + fab[1] + fab[2] - 1) < 1e-9
PYEOF
grep -q "interior box" "$tmp/pack.log" || fail "no report on stdout"
# every layer's progress line gives the interior porosity so far, or says why there is none yet
# (a first layer thinner than the interior's margins): never "nan"
[ "$(grep -c '^fdem packing: layer' "$tmp/pack.log")" = 4 ] || fail "not one progress line per layer"
! grep '^fdem packing: layer' "$tmp/pack.log" | grep -qi "nan" || fail "a layer's progress line prints nan"
grep '^fdem packing: layer' "$tmp/pack.log" | grep -qE "interior porosity 0\.[0-9]{4}" || fail "no layer gives its interior porosity"

# Reuse: the saved specimen under a servo plate.
$MPIRUN -n 2 "$FDEM" run "$SRC/cases/specimens/reuse_ci.yaml" --out "$tmp/reuse" -q --set time.steps=1000 \
  --set particles.0.file.path="$tmp/spec.txt" >"$tmp/reuse.log" 2>&1 || { cat "$tmp/reuse.log"; fail "reuse failed"; }
n1=$(grep -vc '^#' "$tmp/spec.txt")
n2=$($PY -c "import json;print(json.load(open('$tmp/reuse/run.json'))['particles']['initial'])")
[ "$n1" = "$n2" ] || fail "reuse loaded $n2 particles, the specimen has $n1"

# A packing stopped by SIGTERM (polled at the settle checks, on the run loop of every run): exit
# 128 + 15, the message once, no specimen (a partial packing is none), the bed of the settling
# layer in OUT/checkpoint.h5, which `fdem check` reads. (A singleton run: mpirun reports its own
# code for a signalled job.)
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
"$FDEM" run "$SRC/cases/specimens/pack_layers_ci.yaml" --out "$tmp/stop" \
  --set packing.settle.max_steps=10000000 --set packing.settle.porosity_change=1e-12 >"$tmp/stop.log" 2>&1 &
pid=$!
for i in $(seq 1 600); do grep -q "layer(s), box" "$tmp/stop.log" && break; sleep 0.1; done
grep -q "layer(s), box" "$tmp/stop.log" || { kill -KILL $pid; cat "$tmp/stop.log"; fail "packing did not start in 60 s"; }
sleep 2  # (the first layer settles for ever: its criterion cannot be met)
kill -TERM $pid
wait $pid; code=$?
cat "$tmp/stop.log"
[ $code -eq 143 ] || fail "a packing stopped by SIGTERM exited with $code, not 143"
[ "$(grep -c 'holds the bed in layer 1 of 4, settling at its step' "$tmp/stop.log")" = 1 ] || fail "the stop message is not printed once"
for f in specimen.h5 specimen.txt packing.json; do [ ! -f "$tmp/stop/$f" ] || fail "an interrupted packing wrote $f"; done
"$FDEM" check "$SRC/cases/specimens/pack_layers_ci.yaml" --restart "$tmp/stop/checkpoint.h5" >"$tmp/stopcheck.log" 2>&1 ||
  { cat "$tmp/stopcheck.log"; fail "fdem check of a settling layer's checkpoint"; }
grep -q "resumes     in layer 1 of 4, settling" "$tmp/stopcheck.log" || { cat "$tmp/stopcheck.log"; fail "check does not say the packing resumes in layer 1"; }

# A packing stopped in a later layer (the signal sent as layer 1's checkpoint appears, so it lands
# in layer 2's shaking -- noticed at its first settle check -- or settling): OUT/checkpoint.h5
# holds the bed as it is in that layer and the layer's progress, the message says so once;
# --restart goes on settling that layer at its step, here on another number of ranks, and ends
# with the specimen of the unstopped packing above: specimen.txt byte for byte (ids, positions and
# radii at 17 digits) and packing.json but for its wall-clock times.
"$FDEM" run "$SRC/cases/specimens/pack_layers_ci.yaml" --out "$tmp/res" --set packing.save="$tmp/spec.txt" \
  >"$tmp/res.log" 2>&1 &
pid=$!
for i in $(seq 1 1200); do [ -f "$tmp/res/checkpoint.h5" ] && break; sleep 0.1; done
kill -TERM $pid
wait $pid; code=$?
cat "$tmp/res.log"
[ $code -eq 143 ] || fail "the packing was not stopped after its first layer (exit $code, not 143)"
[ "$(grep -c 'go on with --restart' "$tmp/res.log")" = 1 ] || fail "the stop message does not name the checkpoint once"
grep -q "holds the bed in layer [234] of 4, settling at its step" "$tmp/res.log" || fail "the packing was not stopped while a layer settled"
for f in specimen.h5 specimen.txt packing.json; do [ ! -f "$tmp/res/$f" ] || fail "an interrupted packing wrote $f"; done
"$FDEM" check "$SRC/cases/specimens/pack_layers_ci.yaml" --restart "$tmp/res/checkpoint.h5" >"$tmp/rescheck.log" 2>&1 ||
  { cat "$tmp/rescheck.log"; fail "fdem check of a packing's checkpoint"; }
grep -q "resumes     in layer [234] of 4, settling" "$tmp/rescheck.log" || { cat "$tmp/rescheck.log"; fail "check does not say where the packing resumes"; }
# a checkpoint that does not fit the case: exit 2 naming the file and the key
"$FDEM" run "$SRC/cases/specimens/pack_layers_ci.yaml" --out "$tmp/res" --restart "$tmp/res/checkpoint.h5" \
  --set packing.layers=5 >"$tmp/resbad.log" 2>&1; code=$?
cat "$tmp/resbad.log"
[ $code -eq 2 ] && grep -q "res/checkpoint.h5.*packing.layers 5" "$tmp/resbad.log" || fail "a checkpoint of 4 layers resumed a packing of 5 (exit $code)"
$MPIRUN -n 3 "$FDEM" run "$SRC/cases/specimens/pack_layers_ci.yaml" --out "$tmp/res" --restart "$tmp/res/checkpoint.h5" \
  --set packing.save="$tmp/spec.txt" >"$tmp/res2.log" 2>&1 || { cat "$tmp/res2.log"; fail "the resumed packing failed"; }
grep -q "resuming from.*goes on settling at its step" "$tmp/res2.log" || fail "the packing did not resume in its layer"
cmp "$tmp/pack/specimen.txt" "$tmp/res/specimen.txt" || fail "the resumed packing's specimen differs from the unstopped one's"
$PY - "$tmp/pack/packing.json" "$tmp/res/packing.json" <<'PYEOF' || fail "the resumed packing's report differs"
import json, sys
def strip(d):
    if isinstance(d, dict): return {k: strip(v) for k, v in d.items() if k not in ("wall_time", "rank_balance")}  # (the ranks differ)
    if isinstance(d, list): return [strip(x) for x in d]
    return d
a, b = (strip(json.load(open(f))) for f in sys.argv[1:3])
assert a == b, [k for k in a if a[k] != b[k]]
print("resumed packing: specimen and report identical to the unstopped packing's")
PYEOF
# A stop while the surcharge settles (after levelling: not a layer) goes back to the checkpoint
# after the last layer, and --restart pours the surcharge again: the unstopped run's specimen.
# Both start from the first packing's checkpoint after its layer 4 (a packing-only case leaves it).
SUR='packing.surcharge={material: sand, thickness: 0.01}'
mkdir -p "$tmp/sur" "$tmp/surs"
cp "$tmp/pack/checkpoint.h5" "$tmp/sur/layer4.h5"
cp "$tmp/pack/checkpoint.h5" "$tmp/surs/checkpoint.h5"
"$FDEM" run "$SRC/cases/specimens/pack_layers_ci.yaml" --out "$tmp/sur" --set "$SUR" --restart "$tmp/sur/layer4.h5" \
  >"$tmp/sur.log" 2>&1 || { cat "$tmp/sur.log"; fail "the surcharge after layer 4 failed"; }
"$FDEM" run "$SRC/cases/specimens/pack_layers_ci.yaml" --out "$tmp/surs" --set "$SUR" --restart "$tmp/surs/checkpoint.h5" \
  >"$tmp/surs.log" 2>&1 &
pid=$!
for i in $(seq 1 1200); do grep -q "resuming from" "$tmp/surs.log" && break; sleep 0.05; done
sleep 0.3  # (the surcharge settles for ~11 000 steps)
kill -TERM $pid
wait $pid; code=$?
cat "$tmp/surs.log"
[ $code -eq 143 ] || fail "the packing was not stopped while its surcharge settled (exit $code)"
grep -q "holds the bed after layer 4 of 4" "$tmp/surs.log" || fail "a stop in the surcharge does not go back to layer 4's checkpoint"
"$FDEM" run "$SRC/cases/specimens/pack_layers_ci.yaml" --out "$tmp/surs" --set "$SUR" --restart "$tmp/surs/checkpoint.h5" \
  >"$tmp/surs2.log" 2>&1 || { cat "$tmp/surs2.log"; fail "the packing stopped in its surcharge did not resume"; }
cmp "$tmp/sur/specimen.txt" "$tmp/surs/specimen.txt" || fail "the resumed surcharge's specimen differs from the unstopped one's"
echo "ok: packed, reported, reused ($n1 particles); a signal stops a packing with its settling layer saved, resumed to the unstopped specimen, also in its surcharge"
