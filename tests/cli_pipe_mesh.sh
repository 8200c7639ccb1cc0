#!/usr/bin/env bash
# The buried pipe's soil mesh (scripts/pipe_mesh.py, cases/fem/pipe_soil.msh) and the shell pipe
# tied in it (cases/fem/pipe_in_soil.yaml).
#  * The committed mesh is what the script writes with its defaults (byte for byte). All 8 nodes
#    of each cut-out face (corners, and the mid-edge nodes on the arc) are exactly nodes of a
#    64 x 12 shell pipe, (x, z) = (0.4 + R sin a, R cos a), a = 2 pi i / 64, y = 0.15 j / 12 (the
#    same doubles: compared as parsed, no tolerance; fdem's cylinder generator with axis y gives
#    the bits Python's math gives for such expressions): 333 = 33 x 13 - 16 x 6 nodes, the pipe's
#    whole lower half except the faces' centres; the corners are the 32 x 6 pipe's nodes.
#  * fdem reads its node sets and face sets.
#  * cases/fem/pipe_soil_gravity.yaml (static, 2 ranks) balances the soil's weight: the bottom
#    reaction = gamma x the curved mesh's volume (1e-9; measured 1e-12), and far from the pipe
#    sigma_zz at the bottom = -gamma D within 0.5 % (measured 0.22 % less: the pipe 0.3 m away
#    still takes a little of the far soil's weight).
#  * cases/fem/pipe_in_soil.yaml (static, 2 ranks and 1 rank): fdem ties 333 nodes, also with a
#    tolerance of 1e-15 m; (a) the bottom reaction is the soil's and the pipe's weight (1e-9;
#    measured 2e-13); (b) each tied pipe row repeats its soil node's displacement bit for bit
#    (one node: tied pairs do not separate), the free pipe nodes are not soil nodes; (c) 1 and
#    2 ranks agree within the KSP solves' guarantee.
# The pipe in the soil runs with fdem's own solver settings (no PETSC_OPTIONS): with shells fdem
# sets GAMG's smoother safety factor and rigid-body modes (before, CG broke down at once).
# Usage: cli_pipe_mesh.sh FDEM_BINARY SOURCE_DIR
source "$2/tests/support/cli_common.sh" "$@"
MSH="$SRC/cases/fem/pipe_soil.msh"
CASE="$SRC/cases/fem/pipe_soil_gravity.yaml"
PIPE_CASE="$SRC/cases/fem/pipe_in_soil.yaml"

# The committed mesh is the script's output with the defaults; a bad N is refused.
$PY "$SRC/scripts/pipe_mesh.py" -o "$tmp/pipe_soil.msh" >"$tmp/gen.log" 2>&1 || { cat "$tmp/gen.log"; fail "pipe_mesh.py"; }
cat "$tmp/gen.log"
cmp -s "$tmp/pipe_soil.msh" "$MSH" \
  || fail "cases/fem/pipe_soil.msh differs from what scripts/pipe_mesh.py writes (regenerate it with the defaults)"
$PY "$SRC/scripts/pipe_mesh.py" --around 36 -o "$tmp/bad.msh" >"$tmp/o" 2>"$tmp/e" && fail "pipe_mesh.py accepted N = 36"
grep -q "multiple of 8" "$tmp/e" || { cat "$tmp/e"; fail "N = 36: no message about multiples of 8"; }
# --straight-cutout: the cut-out's mid-edge nodes at the chords' midpoints (only its corners are
# pipe nodes, those of a 32 x 6 pipe).
$PY "$SRC/scripts/pipe_mesh.py" --straight-cutout -o "$tmp/straight.msh" >"$tmp/o" 2>&1 || { cat "$tmp/o"; fail "--straight-cutout"; }
grep -q "119 nodes on the pipe (corners of 32 x 6)" "$tmp/o" || { cat "$tmp/o"; fail "--straight-cutout: cut-out nodes"; }

# Cut-out nodes: the 8 nodes of every "cutout" face are nodes of the 2N x 2M = 64 x 12 pipe,
# exactly; they are the pipe's lower-half nodes (i = 16 .. 48, j = 0 .. 12) except the faces'
# centres (i and j odd): 333 nodes. The faces' corners are the N x M = 32 x 6 pipe's nodes.
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
R, L, xc = 0.075, 0.15, 0.4
def pipe(N, M):  # the lower-half nodes of fdem's N x M cylinder (axis y, base [0.4, 0, 0]): (i, j)
    out = {}
    for j in range(M + 1):
        for i in range(N // 4, 3 * N // 4 + 1):
            a = 2 * math.pi * i / N
            out[(xc + R * math.sin(a), 0.0 + L * j / M, 0.0 + R * math.cos(a))] = (i, j)
    return out
fine, coarse = pipe(64, 12), pipe(32, 6)
nodes = set(xyz.values())
on_cut = {xyz[t] for f in faces["cutout"] for t in f}
corners = {xyz[t] for f in faces["cutout"] for t in f[:4]}
free = sorted(fine[q] for q in set(fine) - nodes)
print("mesh: %d nodes; %d cut-out faces, their nodes: %d, all nodes of the 64 x 12 pipe: %s; the pipe's lower half: "
      "%d nodes, %d in the mesh, %d not (all face centres: %s); face corners = the 32 x 6 pipe's %d nodes: %s"
      % (len(xyz), len(faces["cutout"]), len(on_cut), on_cut <= set(fine), len(fine), len(fine) - len(free), len(free),
         all(i % 2 and j % 2 for i, j in free), len(coarse), corners == set(coarse)))
print("springline nodes: z = %r (a = pi/2), %r (a = 3pi/2)" % (R * math.cos(math.pi / 2), R * math.cos(3 * math.pi / 2)))
assert on_cut <= set(fine), "cut-out nodes that are not pipe nodes: %s" % sorted(on_cut - set(fine))[:4]
assert len(on_cut) == 333 and on_cut == set(fine) & nodes, "the cut-out's nodes are not the pipe's nodes in the mesh"
assert free == [(i, j) for i in range(17, 48, 2) for j in range(1, 12, 2)], "pipe nodes off the soil: %s" % free[:4]
assert corners == set(coarse), "cut-out face corners that are not the 32 x 6 pipe's nodes"
assert sorted(faces) == sorted(["soil", "top", "cutout", "bottom", "xmin", "xmax", "ymin", "ymax"]), sorted(faces)
PYEOF

# fdem's cylinder generator (the shell pipe of pipe_in_soil.yaml: axis y, base [0.4, 0, 0],
# 64 x 12) makes its nodes with the arithmetic above: x = 0.4 + R sin a, y = 0 + L j / M,
# z = 0 + R cos a, bit for bit.
cat >"$tmp/cyl.yaml" <<'EOF'
name: cyl
fem:
  solver: static
  materials:
    - {name: pipe, young: 450.0e6, poisson: 0.46, density: 1530, thickness: 0.004}
  meshes:
    - {name: pipe, material: pipe, cylinder: {axis: y, base: [0.4, 0, 0], radius: 0.075, length: 0.15, divisions: [64, 12]}}
  restraints:
    - {mesh: pipe, node_set: start, fixed: [x, y, z, rx, ry, rz]}
  loads:
    - {mesh: pipe, pressure: 1.0}
EOF
$MPIRUN -n 1 "$FDEM" run "$tmp/cyl.yaml" --out "$tmp/cyl" -q >"$tmp/cyl.log" 2>&1 || { cat "$tmp/cyl.log"; fail "cylinder run"; }
$PY - "$tmp/cyl/fe_00000000.h5" <<'PYEOF' || fail "cylinder generator vs Python's arithmetic"
import sys, math, h5py
x = h5py.File(sys.argv[1], "r")["nodes/coordinates"][:]
N, M, R, L = 64, 12, 0.075, 0.15
exp = [(0.4 + R * math.sin(2 * math.pi * i / N), 0.0 + L * j / M, 0.0 + R * math.cos(2 * math.pi * i / N))
       for j in range(M + 1) for i in range(N)]
same = sum(tuple(float(v) for v in p) == e for p, e in zip(x, exp))
print("fdem cylinder nodes (axis y, 64 x 12) equal to Python's doubles: %d of %d" % (same, len(exp)))
assert len(x) == len(exp) and same == len(exp)
PYEOF

# fdem reads the groups: node sets (listed by the error for a missing one) and face sets (all
# 688 boundary quads: 8 interface triangles each (Hex20 faces) when all seven are coupling surfaces).
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
grep -q "interface   5504 triangles from 7 surface(s)" "$tmp/o" || { cat "$tmp/o"; fail "face sets: expected 5504 triangles"; }

# The soil under its own weight, static, 2 ranks.
$MPIRUN -n 2 "$FDEM" run "$CASE" --out "$tmp/grav" -q >"$tmp/grav.log" 2>&1 || { cat "$tmp/grav.log"; fail "gravity run"; }
$PY - "$tmp/grav" <<'PYEOF' || fail "gravity case"
import sys, csv, math, glob, h5py, numpy as np
from fe_out import ksp_bounds
d = sys.argv[1]
bound = ksp_bounds(d)[0]
E, nu, gamma, D, W, L, R, N = 20e6, 0.3, 19000.0, 0.1, 0.8, 0.15, 0.075, 32
# box - the polygonal half disc - N/2 parabolic segments, 2/3 chord x sagitta (each cut-out edge is
# the parabola through its chord's ends and the arc's midpoint; fdem integrates it exactly)
V = (W * D - N / 4 * R * R * math.sin(2 * math.pi / N)
     - N / 2 * 2 / 3 * (2 * R * math.sin(math.pi / N)) * R * (1 - math.cos(math.pi / N))) * L
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

# The shell pipe (64 x 12) tied in the soil's cut-out: 333 nodes tied, also with 1e-15 m.
"$FDEM" check "$PIPE_CASE" >"$tmp/o" 2>&1 || { cat "$tmp/o"; fail "check of pipe_in_soil.yaml"; }
grep -q "ties        pipe -> soil: 333 nodes" "$tmp/o" || { cat "$tmp/o"; fail "pipe_in_soil: expected 333 tied nodes"; }
"$FDEM" check "$PIPE_CASE" --set fem.ties.0.tolerance=1e-15 >"$tmp/o" 2>&1 || { cat "$tmp/o"; fail "check, tolerance 1e-15"; }
grep -q "ties        pipe -> soil: 333 nodes" "$tmp/o" || { cat "$tmp/o"; fail "pipe_in_soil, tolerance 1e-15 m: expected 333 tied nodes"; }
# Static, under gravity, on 2 ranks and on 1.
$MPIRUN -n 2 "$FDEM" run "$PIPE_CASE" --out "$tmp/pipe2" -q >"$tmp/pipe2.log" 2>&1 \
  || { cat "$tmp/pipe2.log"; fail "pipe in soil, 2 ranks"; }
$MPIRUN -n 1 "$FDEM" run "$PIPE_CASE" --out "$tmp/pipe1" -q >"$tmp/pipe1.log" 2>&1 \
  || { cat "$tmp/pipe1.log"; fail "pipe in soil, 1 rank"; }
$PY - "$tmp/pipe2" "$tmp/pipe1" <<'PYEOF' || fail "pipe in soil"
import sys, csv, json, math, glob, h5py, numpy as np
from fe_out import ksp_bounds, agree_within_ksp, displacement
d2, d1 = sys.argv[1:3]
W, D, L, R, N, M = 0.8, 0.1, 0.15, 0.075, 32, 6      # the soil (N x M: its cut-out's divisions)
gs, gp, t = 19000.0, 15000.0, 0.004                   # unit weights, the pipe's thickness
NA, NL = 2 * N, 2 * M                                 # the pipe: 64 x 12
Vs = (W * D - N / 4 * R * R * math.sin(2 * math.pi / N)
      - N / 2 * 2 / 3 * (2 * R * math.sin(math.pi / N)) * R * (1 - math.cos(math.pi / N))) * L
meshes = {m["name"]: m for m in json.load(open(d2 + "/structures.json"))["meshes"]}
s0, p0 = meshes["soil"]["node_offset"], meshes["pipe"]["node_offset"]
assert meshes["soil"]["nodes"] == 4189 and meshes["pipe"]["nodes"] == (NL + 1) * NA
with h5py.File(sorted(glob.glob(d2 + "/fe_[0-9]*.h5"))[-1], "r") as h:
    X, U = h["nodes/coordinates"][:], h["nodes/displacement"][:]
P = X[p0:p0 + (NL + 1) * NA].reshape(NL + 1, NA, 3)   # pipe node (i, j): row p0 + j NA + i
A = sum(0.5 * np.linalg.norm(np.cross(P[j + 1, (i + 1) % NA] - P[j, i], P[j + 1, i] - P[j, (i + 1) % NA]))
        for j in range(NL) for i in range(NA))       # the facets' (flat rectangles') area
# (a) the bottom carries the soil's and the pipe's weight.
rz = float(list(csv.DictReader(open(d2 + "/reactions.csv")))[-1]["soil_bottom_rz"])
weight = gs * Vs + gp * t * A
print("bottom reaction %.12f N; weight: soil gamma V %.12f N + pipe gamma t A %.12f N (A %.15g m^2) = %.12f N: "
      "rel. diff %.2e" % (rz, gs * Vs, gp * t * A, A, weight, rz / weight - 1))
assert abs(rz / weight - 1) < 1e-9, "the bottom reaction is not the soil's and the pipe's weight"
# (b) tied pipe nodes are soil nodes: their rows repeat the soil node's, bit for bit, displacement
# included (so a tied pair never separates); the other pipe nodes are no soil node's.
soil = {tuple(X[s0 + k]): s0 + k for k in range(meshes["soil"]["nodes"])}
tied, gap, centre_gap = 0, 0.0, []
for j in range(NL + 1):
    for i in range(NA):
        r = p0 + j * NA + i
        s = soil.get(tuple(X[r]))
        lower = NA // 4 <= i <= 3 * NA // 4
        if s is not None:
            assert lower and not (i % 2 and j % 2), "pipe node (%d, %d) is a soil node" % (i, j)
            assert np.array_equal(U[r], U[s]), "tied pipe node (%d, %d): displacement %s, its soil node's %s" % (i, j, U[r], U[s])
            gap = max(gap, float(np.linalg.norm((X[r] + U[r]) - (X[s] + U[s]))))
            tied += 1
        else:
            assert not lower or (i % 2 and j % 2), "lower-half pipe node (%d, %d) is not tied" % (i, j)
            if lower:  # a face centre: the soil face's (Quad8) displacement there vs the pipe node's
                u = lambda a, b: U[p0 + b * NA + a]
                us = (-0.25 * (u(i - 1, j - 1) + u(i + 1, j - 1) + u(i + 1, j + 1) + u(i - 1, j + 1))
                      + 0.5 * (u(i, j - 1) + u(i + 1, j) + u(i, j + 1) + u(i - 1, j)))
                centre_gap.append(float(np.linalg.norm(U[r] - us)))
umax = float(np.sqrt((U ** 2).sum(axis=1)).max())
print("tied pipe rows: %d, displacements identical to their soil nodes'; largest distance of a tied pair after "
      "deformation %r m; free face centres %d: pipe node vs the soil face's centre up to %.3e m (%.2e of the largest "
      "displacement %.4e m)" % (tied, gap, len(centre_gap), max(centre_gap), max(centre_gap) / umax, umax))
assert tied == 333 and gap == 0.0 and len(centre_gap) == 96
# (c) 1 rank vs 2 ranks.
b2, b1 = ksp_bounds(d2)[0], ksp_bounds(d1)[0]
f2, f1 = (sorted(glob.glob(d + "/fe_[0-9]*.h5"))[-1] for d in (d2, d1))
agree_within_ksp(displacement(f1), displacement(f2), b1 + b2, "pipe in soil: 1 rank vs 2 ranks")
PYEOF
