#!/usr/bin/env bash
# Every input problem is an input error (issue 14): through the real command line on 2 ranks,
# each bad input below must end with exit code 2, its message (naming the file:line, the key or
# the flag) printed exactly once, no other error line, no crash text (MPI_Abort, terminate,
# backtrace) and no output directory left behind. Also: run.json is valid JSON whatever the
# case name holds.
# Usage: cli_input.sh FDEM_BINARY SOURCE_DIR
set -u
FDEM=$1; SRC=$2
MPIRUN="bash $SRC/scripts/mpirun.sh"
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
fail=0; n_ok=0

# expect_error 'MESSAGE' [fdem arguments...]: run on 2 ranks (a 60 s guard turns a hang into a
# failure) and check the outcome. MESSAGE is a fixed string that must occur in exactly one line.
expect_error() {
  local msg=$1; shift
  rm -rf "$tmp/out"
  timeout -k 5 60 $MPIRUN -n 2 "$FDEM" "$@" >"$tmp/stdout" 2>"$tmp/stderr"
  local code=$?
  local n; n=$(grep -cF -- "$msg" "$tmp/stderr")
  local nerr; nerr=$(grep -c "error" "$tmp/stderr")
  if [ "$code" -ne 2 ]; then
    echo "FAIL [$*]: exit code $code, expected 2"; cat "$tmp/stderr"; fail=1
  elif [ "$n" -ne 1 ] || [ "$nerr" -ne 1 ]; then
    echo "FAIL [$*]: expected '$msg' once and one error line; got $n and $nerr:"; cat "$tmp/stderr"; fail=1
  elif grep -qE "MPI_Abort|terminate called|[Bb]acktrace|core dumped|SIGABRT|SIGSEGV|Signal: " "$tmp/stderr"; then
    echo "FAIL [$*]: crash text in stderr:"; cat "$tmp/stderr"; fail=1
  elif [ -e "$tmp/out" ]; then
    echo "FAIL [$*]: output directory left behind"; fail=1
  else
    n_ok=$((n_ok + 1)); echo "ok   $(grep -F -- "$msg" "$tmp/stderr" | head -c 200)"
  fi
}

INLINE=$SRC/cases/examples/inline.yaml
FEM=$SRC/cases/fem/cantilever.yaml
OUT=(--out "$tmp/out")

# ---- physical ranges and non-finite numbers (docs/case-format.md#ranges)
expect_error "--set materials.0.density=1e308: error: materials[0].density: out of range, got 1e+308; allowed: [1, 100000] kg/m^3" \
  run "$INLINE" "${OUT[@]}" --set materials.0.density=1e308
expect_error "time.dt: out of range, got 1e-300; allowed: [1e-12, 1] s" run "$INLINE" "${OUT[@]}" --set time.dt=1e-300
expect_error "gravity[2]: out of range, got 1e+308" run "$INLINE" "${OUT[@]}" --set "gravity=[0,0,1e308]"
expect_error "walls[0].motion.velocity[2]: out of range, got 1e-300" \
  run "$INLINE" "${OUT[@]}" --set "walls.0.motion={velocity: [0, 0, 1e-300]}"
expect_error "walls[0].motion.velocity[0]: out of range, got 1e+308" \
  run "$INLINE" "${OUT[@]}" --set "walls.0.motion={velocity: [1e308, 0, 0]}"
expect_error "fem.load_steps[0]: expected a number, got '.nan'" run "$FEM" "${OUT[@]}" --set "fem.load_steps=[.nan]"
expect_error "fem.load_steps[1]: expected a number, got '.inf'" run "$FEM" "${OUT[@]}" --set "fem.load_steps=[1, .inf]"
expect_error "fem.loads[0].total[2]: out of range, got 1e+300; allowed: 0 or a magnitude in [1e-12, 1e+12] N" \
  run "$FEM" "${OUT[@]}" --set "fem.loads.0.total=[0,0,1e300]"
# the same in a case file: named by file and line
sed 's/density: 2640/density: 1e-300/' "$INLINE" >"$tmp/tiny_density.yaml"
expect_error "$tmp/tiny_density.yaml:10: error: materials[0].density: out of range, got 1e-300" run "$tmp/tiny_density.yaml" "${OUT[@]}"
# absurd sizes
expect_error "particles[0].inline.spheres[0][3]: out of range, got 1e+10; allowed: [1e-06, 10] m" \
  run "$INLINE" "${OUT[@]}" --set particles.0.inline.spheres.0.3=1e10
expect_error "domain.max[0]: out of range, got 1e+30" run "$INLINE" "${OUT[@]}" --set "domain.max=[1e30,0.1,0.2]"
expect_error "neighbor.skin: out of range, got 1e+10" run "$INLINE" "${OUT[@]}" --set neighbor.skin=1e10

# ---- resource limits, estimated from the keys before anything is allocated
expect_error "fem.meshes[0].block.divisions: about 1e+15 elements; at most 2147483647" \
  run "$FEM" "${OUT[@]}" --set "fem.meshes.0.block.divisions=[100000,100000,100000]"
expect_error "particles[0].generate.count: about 2e+09 particles need about 2048 GB, more than this machine's" \
  run "$SRC/cases/demo/settle.yaml" "${OUT[@]}" --set particles.0.generate.count=2000000000
expect_error "fem.solver: static needs restraints" run "$FEM" "${OUT[@]}" --set fem.solver=static --set "fem.restraints=[]"
expect_error "fem.restraints: no restraint holds the y direction" \
  run "$FEM" "${OUT[@]}" --set fem.solver=static --set "fem.restraints.0.fixed=[x, z]"
D=$(cd "$SRC" && pwd)/tests/data/mesh
printf '# id rx ry rz\n\n' >"$tmp/no_restraints.txt"
cat >"$tmp/block2.yaml" <<EOF
name: block2
fem:
  materials: [{name: steel, young: 2.0e11, poisson: 0.3, density: 7800}]
  meshes: [{name: m, material: steel, thesis: {nodes: $D/block2_nodes.txt, elements: $D/block2_elements.txt}}]
  restraints: [{mesh: m, file: $tmp/no_restraints.txt}]
EOF
expect_error "no_restraints.txt: error: restraints file has no entries" run "$tmp/block2.yaml" "${OUT[@]}"

# ---- strings that are not what they look like
expect_error "fem.gravity: expected true or false, got 'yes'" run "$FEM" "${OUT[@]}" --set fem.gravity=yes
expect_error "measure.force_network: expected true or false, got 'on'" \
  run "$SRC/cases/examples/measure.yaml" "${OUT[@]}" --set measure.force_network=on
expect_error "lab.triaxial.walls[1]: wall 'xmin' is listed twice (also lab.triaxial.walls[0])" \
  run "$SRC/cases/lab/triaxial_ci.yaml" "${OUT[@]}" --set lab.triaxial.walls.1=xmin

# ---- files: empty, directories, FIFOs, devices, missing checkpoints
printf '# id x y z r\n\n# nothing here\n' >"$tmp/empty.txt"
expect_error "empty.txt: error: the sphere file has no spheres" \
  run "$SRC/cases/examples/sphere_file.yaml" "${OUT[@]}" --set "particles.0.file.path=$tmp/empty.txt"
mkdir -p "$tmp/adir"
expect_error "particles[0].file.path: sphere file '$tmp/adir' is a directory" \
  run "$SRC/cases/examples/sphere_file.yaml" "${OUT[@]}" --set "particles.0.file.path=$tmp/adir"
mkfifo "$tmp/fifo.yaml"
expect_error "the case file '$tmp/fifo.yaml' is a FIFO" run "$tmp/fifo.yaml" "${OUT[@]}"
expect_error "particles[0].file.path: sphere file '$tmp/fifo.yaml' is a FIFO" \
  run "$SRC/cases/examples/sphere_file.yaml" "${OUT[@]}" --set "particles.0.file.path=$tmp/fifo.yaml"
expect_error "the case file '/dev/zero' is a device" run /dev/zero "${OUT[@]}"
expect_error "the case file '/dev/urandom' is a device" run /dev/urandom "${OUT[@]}"
{ sed -n '1,/^particles:/p' "$INLINE" | sed '$d'; echo "restart:"; echo "  from: nothing.h5"; } >"$tmp/restart.yaml"
rl=$(grep -n "  from: nothing.h5" "$tmp/restart.yaml" | cut -d: -f1)
expect_error "$tmp/restart.yaml:$rl: error: restart.from: checkpoint '$tmp/nothing.h5' does not exist" run "$tmp/restart.yaml" "${OUT[@]}"

expect_error "--restart $tmp/nothing.h5: error: checkpoint '$tmp/nothing.h5' does not exist" \
  run "$INLINE" "${OUT[@]}" --restart "$tmp/nothing.h5"
expect_error "--specimen $tmp/fifo.yaml: error: specimen '$tmp/fifo.yaml' is a FIFO" \
  run "$SRC/cases/specimens/pack_layers_ci.yaml" "${OUT[@]}" --specimen "$tmp/fifo.yaml"

# ---- --set mistakes
expect_error "--set walls.99999999999999999999.x=1: error: index 99999999999999999999 out of range in walls (size 1)" \
  run "$INLINE" "${OUT[@]}" --set walls.99999999999999999999.x=1
expect_error "--set foo.bar=1: error: unknown key 'foo' at the top level (valid: " run "$INLINE" "${OUT[@]}" --set foo.bar=1

# ---- places to write, checked before any work
touch "$tmp/afile"
expect_error "--out $tmp/afile: error: unusable output directory: '$tmp/afile' exists and is not a directory" \
  run "$INLINE" --out "$tmp/afile"
expect_error "--out $tmp/afile/sub: error: unusable output directory: '$tmp/afile' is a file, not a directory" \
  run "$INLINE" --out "$tmp/afile/sub"
expect_error "--out /proc/fdem_test: error: unusable output directory: cannot create '/proc/fdem_test'" \
  run "$INLINE" --out /proc/fdem_test
# a geogrid whose ribs do not fit: the case file's line and the mesh, before "ok" (issue 59)
expect_error "cases/geogrid_pullout/ci.yaml:90: error: fem.meshes 'grid'.geogrid: no room for 40 transverse ribs" \
  check "$SRC/cases/geogrid_pullout/ci.yaml" --set 'fem.meshes[grid].geogrid.transverse_ribs=40'
grep -q ": ok" "$tmp/stdout" && { echo "FAIL: 'ok' printed for a geogrid that cannot be built"; fail=1; }
# a directory where the run writes its checkpoint (renamed into place at the first checkpoint):
# refused at start-up, before any step (issue 59)
mkdir -p "$tmp/held/checkpoint.h5"
expect_error "--out $tmp/held: error: unusable output directory: '$tmp/held/checkpoint.h5' exists and is not a file (a directory)" \
  run "$INLINE" --out "$tmp/held"
[ ! -e "$tmp/held/run.json" ] || { echo "FAIL: a run.json was written next to the checkpoint.h5 directory"; fail=1; }
PACK=$SRC/cases/specimens/pack_layers_ci.yaml
expect_error "--set packing.save=/proc/fdem_test/s.txt: error: packing.save: unusable path: cannot create '/proc/fdem_test'" \
  run "$PACK" "${OUT[@]}" --set packing.save=/proc/fdem_test/s.txt
expect_error "--set packing.save=$tmp/adir: error: packing.save: unusable path: '$tmp/adir' is a directory" \
  run "$PACK" "${OUT[@]}" --set "packing.save=$tmp/adir"

# ---- a hex20 with a mid-edge node far from the middle of its edge (named: element, file line)
sed 's/^9 1 0 0$/9 1 -3 0/' "$SRC/tests/data/mesh/hex20_nodes.txt" >"$tmp/hex20_nodes.txt"
cp "$SRC/tests/data/mesh/hex20_elements.txt" "$tmp/hex20_elements.txt"
cat >"$tmp/hex20.yaml" <<EOF
name: hex20
fem:
  materials:
    - {name: soil, young: 1.0e7, poisson: 0.3, density: 2000}
  meshes:
    - {name: brick, material: soil, thesis: {nodes: hex20_nodes.txt, elements: hex20_elements.txt, element: hex20}}
EOF
expect_error "$tmp/hex20_elements.txt:1: error: element 7: mid-edge node 9 (id 9) lies 3 from the middle of its edge (length 2)" \
  run "$tmp/hex20.yaml" "${OUT[@]}"

# ---- a case name must be printable UTF-8; run.json is valid JSON whatever the case file's path holds
expect_error "name: is not valid UTF-8 text (byte 255 at 3)" run "$INLINE" "${OUT[@]}" --set "name=$(printf 'abc\377')"
odd=$(printf 'ca"se\\\001\377\376 \303\251t\303\251')
cp "$INLINE" "$tmp/$odd.yaml"
$MPIRUN -n 2 "$FDEM" run "$tmp/$odd.yaml" --out "$tmp/named" -q --set time.duration=2e-4 --set 'name=q"b\s é' >/dev/null 2>"$tmp/e"
c=$?
if [ $c -ne 0 ]; then echo "FAIL: run with odd names: exit $c"; cat "$tmp/e"; fail=1
elif ! python3 -c '
import json, sys
r = json.load(open(sys.argv[1]))
assert r["case"] == "q\"b\\s \u00e9", r["case"]
assert r["case_file"].endswith("/ca\"se\\\x01\ufffd\ufffd \u00e9t\u00e9.yaml"), r["case_file"]
assert r["status"] == "finished", r["status"]
' "$tmp/named/run.json"; then echo "FAIL: run.json is not valid JSON or a name is wrong"; cat "$tmp/named/run.json"; fail=1
else n_ok=$((n_ok + 1)); echo "ok   run.json parses, case name and file escaped"; fi

[ $fail -eq 0 ] && echo "all $n_ok input checks passed"
exit $fail
