#!/usr/bin/env bash
# The buried pipe's soil mesh (scripts/pipe_mesh.py, cases/fem/pipe_soil.msh): the committed file is
# what the script writes with its defaults (byte for byte); its cut-out corner nodes are exactly the
# lower half of a 32 x 6 shell pipe's nodes (x, z) = (0.4 + R sin a, R cos a), y = 0.15 j / 6
# (the same doubles: compared as parsed, no tolerance; fdem's cylinder generator gives the bits
# Python's math gives for such expressions); fdem reads its node sets and face sets; and
# cases/fem/pipe_soil_gravity.yaml (static, 2 ranks) balances the soil's weight: bottom reaction
# = gamma x volume (1e-9), and far from the pipe sigma_zz at the bottom = -gamma D within 0.5 %
# (measured 0.22 % less: the pipe 0.3 m away still takes a little of the far soil's weight).
# Usage: cli_pipe_mesh.sh FDEM_BINARY SOURCE_DIR
source "$2/tests/support/cli_common.sh" "$@"
MSH="$SRC/cases/fem/pipe_soil.msh"
CASE="$SRC/cases/fem/pipe_soil_gravity.yaml"

# The committed mesh is the script's output with the defaults; a bad N is refused.
$PY "$SRC/scripts/pipe_mesh.py" -o "$tmp/pipe_soil.msh" >"$tmp/gen.log" 2>&1 || { cat "$tmp/gen.log"; fail "pipe_mesh.py"; }
cat "$tmp/gen.log"
cmp -s "$tmp/pipe_soil.msh" "$MSH" \
  || fail "cases/fem/pipe_soil.msh differs from what scripts/pipe_mesh.py writes (regenerate it with the defaults)"
$PY "$SRC/scripts/pipe_mesh.py" --around 36 -o "$tmp/bad.msh" >"$tmp/o" 2>"$tmp/e" && fail "pipe_mesh.py accepted N = 36"
grep -q "multiple of 8" "$tmp/e" || { cat "$tmp/e"; fail "N = 36: no message about multiples of 8"; }

# Cut-out nodes: every pipe node (i = N/4 .. 3N/4, j = 0 .. M) is a mesh node, exactly, and the
# corners of the "cutout" faces are these nodes and no others.
$PY - "$MSH" <<'PYEOF' || fail "cut-out nodes"
import sys, math
lines = open(sys.argv[1]).read().split("\n")
names = {}
k = lines.index("$PhysicalNames")
for l in lines[k + 2:k + 2 + int(lines[k + 1])]:
    d, t, n = l.split(None, 2)
    names[(int(d), int(t))] = n.strip('"')
k = lines.index("$Nodes")
nblocks = int(lines[k + 1].split()[0]); p = k + 2; xyz = {}
for _ in range(nblocks):
    n = int(lines[p].split()[3]); tags = [int(t) for t in lines[p + 1:p + 1 + n]]
    for t, l in zip(tags, lines[p + 1 + n:p + 1 + 2 * n]):
        xyz[t] = tuple(float(v) for v in l.split())
    p += 1 + 2 * n
k = lines.index("$Entities")
counts = [int(v) for v in lines[k + 1].split()]
ent = {}
for dim in range(4):
    for l in lines[k + 2 + sum(counts[:dim]):k + 2 + sum(counts[:dim + 1])]:
        t = l.split(); first = 4 if dim == 0 else 7
        ent[(dim, int(t[0]))] = [names[(dim, int(v))] for v in t[first + 1:first + 1 + int(t[first])]]
k = lines.index("$Elements")
nblocks = int(lines[k + 1].split()[0]); p = k + 2; faces = {}
for _ in range(nblocks):
    dim, tag, typ, n = (int(v) for v in lines[p].split())
    rows = [[int(v) for v in l.split()[1:]] for l in lines[p + 1:p + 1 + n]]
    for g in ent[(dim, tag)]:
        faces.setdefault(g, []).extend(rows)
    p += 1 + n
N, M, R, L, xc = 32, 6, 0.075, 0.15, 0.4
pipe = set()
for j in range(M + 1):
    for i in range(N // 4, 3 * N // 4 + 1):
        a = 2 * math.pi * i / N
        pipe.add((xc + R * math.sin(a), 0.0 + L * j / M, 0.0 + R * math.cos(a)))
nodes = set(xyz.values())
missing = pipe - nodes
corners = {xyz[t] for f in faces["cutout"] for t in f[:4]}
print("mesh: %d nodes; pipe nodes i = %d..%d, j = 0..%d: %d, found exactly: %d; cut-out face corners: %d"
      % (len(xyz), N // 4, 3 * N // 4, M, len(pipe), len(pipe) - len(missing), len(corners)))
print("springline nodes: z = %r (a = pi/2), %r (a = 3pi/2)" % (R * math.cos(math.pi / 2), R * math.cos(3 * math.pi / 2)))
assert not missing, "pipe nodes not in the mesh: %s" % sorted(missing)[:4]
assert corners == pipe, "cut-out face corners that are not pipe nodes: %s" % sorted(corners - pipe)[:4]
assert sorted(faces) == sorted(["soil", "top", "cutout", "bottom", "xmin", "xmax", "ymin", "ymax"]), sorted(faces)
PYEOF

# fdem's cylinder generator (a shell pipe along +z, 32 x 6 around x = 0.4) makes its nodes with
# the arithmetic above: x = 0.4 + R cos a, y = 0 + R sin a, z = 0 + L j / M bit for bit.
cat >"$tmp/cyl.yaml" <<'EOF'
name: cyl
fem:
  solver: static
  materials:
    - {name: pipe, young: 450.0e6, poisson: 0.46, density: 1200, thickness: 0.004}
  meshes:
    - {name: pipe, material: pipe, cylinder: {base: [0.4, 0, 0], radius: 0.075, length: 0.15, divisions: [32, 6]}}
  restraints:
    - {mesh: pipe, node_set: start, fixed: [x, y, z, rx, ry, rz]}
  loads:
    - {mesh: pipe, pressure: 1.0}
EOF
$MPIRUN -n 1 "$FDEM" run "$tmp/cyl.yaml" --out "$tmp/cyl" -q >"$tmp/cyl.log" 2>&1 || { cat "$tmp/cyl.log"; fail "cylinder run"; }
$PY - "$tmp/cyl/fe_00000000.h5" <<'PYEOF' || fail "cylinder generator vs Python's arithmetic"
import sys, math, h5py
x = h5py.File(sys.argv[1], "r")["nodes/coordinates"][:]
N, M, R, L = 32, 6, 0.075, 0.15
exp = [(0.4 + R * math.cos(2 * math.pi * i / N), 0 + R * math.sin(2 * math.pi * i / N), 0.0 + L * j / M)
       for j in range(M + 1) for i in range(N)]
same = sum(tuple(float(v) for v in p) == e for p, e in zip(x, exp))
print("fdem cylinder nodes equal to Python's doubles: %d of %d" % (same, len(exp)))
assert len(x) == len(exp) and same == len(exp)
PYEOF

# fdem reads the groups: node sets (listed by the error for a missing one) and face sets (all
# 688 boundary quads: 4 interface triangles each when all seven are coupling surfaces).
"$FDEM" check "$CASE" --set 'fem.restraints.0.node_set=nope' >"$tmp/o" 2>"$tmp/e" && fail "check accepted node set 'nope'"
grep -q "(valid: bottom, cutout, soil, top, xmax, xmin, ymax, ymin)" "$tmp/e" || { cat "$tmp/e"; fail "node sets"; }
# (faces.yaml uses $tmp/pipe_soil.msh, the regenerated mesh, byte-identical to the committed one)
cat >"$tmp/faces.yaml" <<'EOF'
name: pipe_soil_faces
domain: {min: [0, 0, -0.1], max: [0.8, 0.15, 0.2]}
time: {dt: auto, steps: 10}
materials:
  - {name: grain, young: 1.0e7, density: 2650, kt_kn: 0.25, friction: 0.5}
particles:
  - inline: {material: grain, spheres: [{id: 1, x: [0.1, 0.07, 0.05], r: 0.005}]}
fem:
  materials:
    - {name: soil, young: 20.0e6, poisson: 0.3, density: 1940, unit_weight: 19000}
  meshes:
    - {name: soil, material: soil, gmsh: pipe_soil.msh}
  restraints:
    - {mesh: soil, node_set: bottom, fixed: [x, y, z]}
coupling:
  material: grain
  surfaces:
    - {mesh: soil, face_set: top, name: top}
    - {mesh: soil, face_set: cutout, name: cutout}
    - {mesh: soil, face_set: bottom, name: bottom}
    - {mesh: soil, face_set: xmin, name: xmin}
    - {mesh: soil, face_set: xmax, name: xmax}
    - {mesh: soil, face_set: ymin, name: ymin}
    - {mesh: soil, face_set: ymax, name: ymax}
EOF
"$FDEM" check "$tmp/faces.yaml" >"$tmp/o" 2>&1 || { cat "$tmp/o"; fail "check of the face sets"; }
grep -q "interface   2752 triangles from 7 surface(s)" "$tmp/o" || { cat "$tmp/o"; fail "face sets: expected 2752 triangles"; }

# The soil under its own weight, static, 2 ranks.
$MPIRUN -n 2 "$FDEM" run "$CASE" --out "$tmp/grav" -q >"$tmp/grav.log" 2>&1 || { cat "$tmp/grav.log"; fail "gravity run"; }
$PY - "$tmp/grav" <<'PYEOF' || fail "gravity case"
import sys, csv, math, glob, h5py, numpy as np
from fe_out import ksp_bounds
d = sys.argv[1]
bound = ksp_bounds(d)[0]
E, nu, gamma, D, W, L, R, N = 20e6, 0.3, 19000.0, 0.1, 0.8, 0.15, 0.075, 32
V = (W * D - N / 4 * R * R * math.sin(2 * math.pi / N)) * L  # box - the polygonal half-disc
rz = float(list(csv.DictReader(open(d + "/reactions.csv")))[-1]["soil_bottom_rz"])
print("bottom reaction %.12f N, gamma V %.12f N (V %.15g m^3): rel. diff %.2e; KSP error bound %.2e"
      % (rz, gamma * V, V, rz / (gamma * V) - 1, bound))
assert abs(rz / (gamma * V) - 1) < 1e-9, "the bottom reaction is not the soil's weight"
# sigma_zz at the bottom nodes far from the pipe (x < 0.1, x > 0.7), from the displacements: u = 0
# on the bottom, so there sigma_zz = (lambda + 2 mu) du_z/dz, and du_z/dz at the bottom of a
# bottom element's vertical edge (corner 0, mid-edge m, corner 1; quadratic u_z) is
# (-3 u_0 + 4 u_m - u_1) / h.
with h5py.File(sorted(glob.glob(d + "/fe_[0-9]*.h5"))[-1], "r") as h:
    X, U = h["nodes/coordinates"][:], h["nodes/displacement"][:]
Mc = E * (1 - nu) / ((1 + nu) * (1 - 2 * nu))
col = {}
for k, (x, y, z) in enumerate(X):
    col.setdefault((x, y), []).append((z, k))
ratios = []
for (x, y), c in col.items():
    c.sort()
    if not (x < 0.1 or x > 0.7) or c[0][0] != -D or len(c) < 3:
        continue
    (z0, k0), (zm, km), (z1, k1) = c[:3]
    if zm != 0.5 * (z0 + z1):  # a mid-layer column (y between layers) has no mid-edge node
        continue
    s = Mc * (-3 * U[k0, 2] + 4 * U[km, 2] - U[k1, 2]) / (z1 - z0)
    ratios.append(s / (-gamma * D))
ratios = np.array(ratios)
print("far field (x < 0.1, x > 0.7): sigma_zz(bottom) / (-gamma D) = %.5f .. %.5f at %d nodes"
      % (ratios.min(), ratios.max(), len(ratios)))
assert len(ratios) == 28, len(ratios)
assert np.all(np.abs(ratios - 1) < 5e-3), "far-field sigma_zz at the bottom is not gamma D within 0.5 %"
PYEOF
