#!/usr/bin/env python3
"""The FE soil mesh under a buried pipe (Tran 2013, appendix problem 8) as a Gmsh .msh 4.1 ASCII file.

The soil is the box x in [x_min, x_max], y in [0, L], z in [-D, 0] (defaults 0-0.8 m, 0-0.15 m,
-0.1-0 m) minus the lower half of the pipe, {(x - xc)^2 + z^2 < R^2, z < 0} (xc = 0.4 m,
R = 0.075 m): the soil below the pipe's springline. Elements: 20-node serendipity hexahedra
(Gmsh type 17; node order = fdem's, src/fem/element_types.hpp: the 8 corners, then mid-edge node
8 + k on the edge between corners kHex20Edge[k]). Every mid-edge node is at the midpoint of its
straight edge except on the cut-out, where they lie on the pipe's circle (below).

Pipe nodes: the soil is made to be tied (fdem's fem.ties) to a shell4 pipe, a `cylinder` mesh
with axis y, base [xc, 0, 0] and n_around x n_along elements, whose nodes are at
    a = 2 * pi * i / n_around,   x = xc + R * sin(a),   z = 0.0 + R * cos(a),   y = 0.0 + L * j / n_along
(src/fem/mesh_generate.cpp make_cylinder_shell). The cut-out is the lower half of an N x M
division (N/2 element edges around, M layers along y); its nodes are those of a pipe TWICE as
fine, n_around = 2N, n_along = 2M:
  * the cut-out's corner nodes: the pipe's nodes with i even and j even (= the nodes i/2, j/2 of
    an N x M pipe, bit for bit: the factor 2 is exact in the angle and in y);
  * the cut-out's mid-edge nodes ON THE ARC: around the pipe (between the corners at angles
    2 pi i / N and 2 pi (i + 1) / N) the pipe node 2i + 1 at angle 2 pi (2i + 1) / (2N), not the
    chord's midpoint; along y the mid-layer y = L (2j + 1) / (2M) (the pipe's ring 2j + 1).
So all 8 nodes of each cut-out face are nodes of the 2N x 2M pipe; only the pipe's node at each
face's centre (i and j odd) has no soil partner. With N 32 and M 6 the pipe is 64 x 12 and
(N + 1)(2M + 1) - (N/2) M = 429 - 96 = 333 of its nodes are soil nodes. The coordinates are the
same floating-point expressions, evaluated in the same order with the C library's sin and cos
(Python's math module), written with repr() (the shortest string that reads back to the same
double). Note that cos(pi/2) and cos(3pi/2) are not 0 in floating point: the two springline nodes
of every ring lie at z = 4.6e-18 and z = -1.4e-17, not on z = 0 (a harmless sliver; it keeps them
equal to the pipe's). --straight-cutout puts the cut-out's mid-edge nodes at the chords'
midpoints instead (the cut-out is then the polygon of an N x M pipe's facets, whose corners only
are soil nodes: tying it leaves the soil's mid-edge nodes free, an incompatible joint).

An element next to the cut-out thus has one curved (parabolic) edge, its other edges straight
with midpoint nodes; its Jacobian stays positive (checked at the 2x2x2 Gauss points and the 8
corners of every element: the smallest det J is 0.75 of its element's mean). Its det J is a
polynomial of degree at most 2 in each natural coordinate, so fdem's 2x2x2 rule (stiffness)
and 3x3x3 (body load) integrate the volume exactly: the mesh volume is the box minus the
polygonal half disc minus N/2 parabolic segments of 2/3 x chord x sagitta, times L (the script
checks it against Gauss rules of order 2, 3 and 8 to 1e-13).

Mesh structure (a 2-D mesh of the x-z section, extruded in y with M layers):
  * ring: a mapped block between the half circle and the rectangle [xc - D, xc + D] x [-D, 0]
    (half-width = the soil depth D). Each cut-out corner node (angle a) is joined by a straight
    ray from the pipe axis, divided into --radial equal parts, to the point where that ray meets
    the rectangle. The rectangle's bottom corners lie on the rays at 45 degrees from the
    vertical, a = 3pi/4 and 5pi/4, which are node angles only when N is a multiple of 8
    (checked): the ring then has N/8 divisions on each vertical side (x = xc -+ D) and N/4 along
    the bottom z = -D.
  * two structured side blocks, x_min .. xc - D and xc + D .. x_max, with --side divisions in x
    (uniform, or geometric with --side-ratio = outermost / innermost element width) and, in z,
    the ring's nodes on x = xc -+ D (their inner column of nodes is the ring's).
Defaults (N 32, M 6, --radial 4, --side 8, --side-ratio 3): 128 hex20 per layer, 768 in all
(4189 nodes); next to the pipe the elements are 14.7 mm around (one facet) by 6.3 - 16.6 mm
radially and 25 mm along y, about one or two of the 5 - 10 mm grains above; the side blocks'
elements are 20 - 33 mm high (the ring's nodes on x = xc -+ D) and 20 mm wide next to the ring,
growing to 61 mm at x_min and x_max.

Physical groups (fdem: element/node sets and face sets, docs/mesh-formats.md): volume "soil"
(element and node set); surfaces of 8-node quadrangles (Gmsh type 16, node order: 4 corners
counter-clockwise seen from outside, then the mid-edge nodes of edges 01, 12, 23, 30), which fdem
turns into face sets and node sets: "top" (z = 0, the cut-out excluded), "cutout", "bottom"
(z = -D), "xmin", "xmax", "ymin", "ymax". Node and element tags are 1, 2, ...: nodes layer by
layer (y_0: section corners then edge midpoints; the mid-layer y_{j+1/2}: corners only; y_1 ...),
hexahedra layer by layer, then the faces group by group.

Usage (the committed cases/fem/pipe_soil.msh is made with the defaults; cases/fem/pipe_in_soil.yaml
ties a 64 x 12 shell pipe to it):
    /usr/bin/python3 scripts/pipe_mesh.py -o cases/fem/pipe_soil.msh
It prints one summary line: nodes, elements, cut-out nodes, the pipe nodes among them, the exact
mesh volume (box - polygonal half disc - parabolic segments, x L) and the volume by Gauss rules.
Only the standard library and numpy are used.
"""
import argparse
import math
import sys

import numpy as np

# fdem's Hex20 node order (src/fem/element_types.hpp): mid-edge node 8 + k between these corners.
HEX20_EDGE = [(0, 1), (0, 3), (0, 4), (1, 2), (1, 5), (2, 3), (2, 6), (3, 7), (4, 5), (4, 7), (5, 6), (6, 7)]
# Local faces of a brick (docs/mesh-formats.md "Local faces"): corners counter-clockwise seen from outside.
HEX_FACES = [(0, 4, 7, 3), (1, 2, 6, 5), (0, 1, 5, 4), (3, 7, 6, 2), (0, 3, 2, 1), (4, 5, 6, 7)]
SURFACES = ["top", "cutout", "bottom", "xmin", "xmax", "ymin", "ymax"]


def parse_args(argv):
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("-o", "--output", default="pipe_soil.msh", help="the .msh file to write (default %(default)s)")
    p.add_argument("--x-min", type=float, default=0.0, help="box x from (m, default %(default)s)")
    p.add_argument("--x-max", type=float, default=0.8, help="box x to (m, default %(default)s)")
    p.add_argument("--length", type=float, default=0.15, help="box y from 0 to this (m): the pipe's length (default %(default)s)")
    p.add_argument("--depth", type=float, default=0.1, help="box z from -depth to 0 (m), also the ring's half-width (default %(default)s)")
    p.add_argument("--centre-x", type=float, default=0.4, help="x of the pipe axis, which runs along y at z = 0 (m, default %(default)s)")
    p.add_argument("--radius", type=float, default=0.075, help="pipe (cut-out) radius R (m, default %(default)s)")
    p.add_argument("--around", "-N", type=int, default=32, help="N: the pipe's elements around, a multiple of 8 (default %(default)s)")
    p.add_argument("--along", "-M", type=int, default=6, help="M: the pipe's elements along y = the soil's layers (default %(default)s)")
    p.add_argument("--radial", type=int, default=4, help="ring divisions from the cut-out to the rectangle (default %(default)s)")
    p.add_argument("--side", type=int, default=8, help="x divisions of each side block (default %(default)s)")
    p.add_argument("--side-ratio", type=float, default=3.0,
                   help="side blocks: outermost / innermost element width, geometric grading (1: uniform; default %(default)s)")
    p.add_argument("--straight-cutout", action="store_true",
                   help="the cut-out's mid-edge nodes at the chords' midpoints (the polygon of an N x M pipe's facets), "
                        "not on the arc of a 2N x 2M pipe's nodes")
    a = p.parse_args(argv)
    err = []
    if a.around < 8 or a.around % 8:
        err.append("--around (N) must be a positive multiple of 8: the ring's corners at 45 degrees must be node angles")
    if a.along < 1 or a.radial < 1 or a.side < 1:
        err.append("--along, --radial and --side must be at least 1")
    if not (a.radius > 0 and a.depth > a.radius and a.length > 0):
        err.append("need 0 < radius < depth and length > 0")
    if not (a.x_min < a.centre_x - a.depth and a.centre_x + a.depth < a.x_max):
        err.append("the ring [centre-x - depth, centre-x + depth] must lie strictly inside [x-min, x-max]")
    if not a.side_ratio > 0:
        err.append("--side-ratio must be positive")
    if err:
        p.error("; ".join(err))
    return a


def graded(lo, hi, n, ratio):
    """n + 1 points from lo to hi (both exact); element widths in geometric progression, the last
    `ratio` times the first (ratio 1: uniform, lo + (hi - lo) * k / n)."""
    if ratio == 1.0:
        w = [float(k) for k in range(n + 1)]
    else:
        q = ratio ** (1.0 / (n - 1)) if n > 1 else 1.0
        w = [0.0]
        for k in range(n):
            w.append(w[-1] + q ** k)
    pts = [lo + (hi - lo) * w[k] / w[n] for k in range(n + 1)]
    pts[0], pts[-1] = lo, hi
    return pts


class Section:
    """The 2-D mesh of the x-z section: corner points and quadrilaterals (corner indices ordered
    so that (q1 - q0) x (q3 - q0) points along +y: extruded along +y they make positive bricks)."""

    def __init__(self):
        self.pts = []       # (x, z)
        self.quads = []     # 4 point indices

    def point(self, x, z):
        self.pts.append((x + 0.0, z + 0.0))  # (+ 0.0: no -0.0 in the file)
        return len(self.pts) - 1

    def quad(self, q):
        (x0, z0), (x1, z1), (x3, z3) = self.pts[q[0]], self.pts[q[1]], self.pts[q[3]]
        cy = (z1 - z0) * (x3 - x0) - (x1 - x0) * (z3 - z0)  # y component of (q1 - q0) x (q3 - q0)
        if cy < 0:
            q = [q[0], q[3], q[2], q[1]]
        self.quads.append(list(q))


def build_section(a):
    N, D, R, xc = a.around, a.depth, a.radius, a.centre_x
    S = Section()
    half, eighth = N // 2, N // 8
    # Ring: s = 0 .. N/2 is the pipe's i = N/4 + s; r = 0 (cut-out) .. radial (rectangle).
    ring = [[None] * (a.radial + 1) for _ in range(half + 1)]
    cut = []
    for s in range(half + 1):
        i = N // 4 + s
        ang = 2 * math.pi * i / N                                 # as the pipe's generator
        cx, cz = xc + R * math.sin(ang), 0.0 + R * math.cos(ang)  # the pipe node (exact)
        # The ray's end on the rectangle, from the angle k * 2pi/N off the downward vertical
        # (exact at the corners |k| = N/8, the bottom k = 0 and the springline |k| = N/4).
        k = s - N // 4
        if abs(k) <= eighth:  # bottom side z = -D
            off = 0.0 if k == 0 else D if abs(k) == eighth else D * math.tan(2 * math.pi * abs(k) / N)
            qx, qz = (xc + off if k < 0 else xc - off), -D
        else:                 # a vertical side x = xc -+ D
            kk = abs(k)
            qz = 0.0 if kk == N // 4 else -D / math.tan(2 * math.pi * kk / N)
            qx = xc + D if k < 0 else xc - D
        for r in range(a.radial + 1):
            if r == 0:
                x, z = cx, cz
            elif r == a.radial:
                x, z = qx, qz
            else:
                x, z = cx + (qx - cx) * r / a.radial, cz + (qz - cz) * r / a.radial
                if abs(k) == N // 4:
                    z = 0.0  # the springline rays lie on the surface z = 0
            ring[s][r] = S.point(x, z)
        cut.append(ring[s][0])
    ring_outer = [ring[s][a.radial] for s in range(half + 1)]
    for s in range(half):
        for r in range(a.radial):
            S.quad([ring[s][r], ring[s + 1][r], ring[s + 1][r + 1], ring[s][r + 1]])
    # Side blocks: their inner columns are the ring's rectangle nodes on x = xc -+ D.
    right_col = [ring[s][a.radial] for s in range(0, eighth + 1)]            # z from 0 down to -D
    left_col = [ring[s][a.radial] for s in range(half, half - eighth - 1, -1)]  # z from 0 down to -D
    for col, x_in, x_out in ((left_col, xc - D, a.x_min), (right_col, xc + D, a.x_max)):
        xs = graded(x_in, x_out, a.side, a.side_ratio)  # from the ring outwards
        grid = [col] + [[S.point(xs[m], S.pts[p][1]) for p in col] for m in range(1, a.side + 1)]
        for m in range(a.side):
            for n in range(len(col) - 1):
                S.quad([grid[m][n], grid[m + 1][n], grid[m + 1][n + 1], grid[m][n + 1]])
    return S, cut, ring_outer


def build_mesh(a):
    S, cut, ring_outer = build_section(a)
    N, M, L = a.around, a.along, a.length
    ys = [0.0 + L * j / M for j in range(M + 1)]  # as the pipe's generator
    # Section edges (their midpoints are mid-edge nodes on every layer).
    edges = {}
    for q in S.quads:
        for c in range(4):
            e = tuple(sorted((q[c], q[(c + 1) % 4])))
            if e not in edges:
                edges[e] = len(edges)
    # The mid-edge points of the section's edges: the straight edge's midpoint, except on the
    # cut-out (unless --straight-cutout): the node k = 2i + 1 of a pipe with 2N around, between
    # the cut-out corners i and i + 1 (pipe_node(2N, 2i) == pipe_node(N, i) bit for bit).
    mids = {}
    for (p, q) in edges:
        (xp, zp), (xq, zq) = S.pts[p], S.pts[q]
        mids[(p, q)] = (0.5 * (xp + xq), 0.5 * (zp + zq))
    if not a.straight_cutout:
        for s in range(len(cut) - 1):
            mids[tuple(sorted((cut[s], cut[s + 1])))] = pipe_section_node(a, 2 * N, 2 * (N // 4 + s) + 1)
    npt, ned = len(S.pts), len(edges)
    per_full = npt + ned
    stride = per_full + npt  # a full layer, then a mid-layer of corner points only
    coords = []
    for j in range(M + 1):
        for (x, z) in S.pts:
            coords.append((x, ys[j], z))
        for e in edges:
            x, z = mids[e]
            coords.append((x, ys[j], z))
        if j < M:
            # the mid-layer: the y-edges' midpoints, or the ring j' = 2j + 1 of a pipe with 2M along
            ym = 0.5 * (ys[j] + ys[j + 1]) if a.straight_cutout else 0.0 + L * (2 * j + 1) / (2 * M)
            for (x, z) in S.pts:
                coords.append((x, ym, z))
    X = np.array(coords)

    def corner(p, j):
        return j * stride + p

    def mid(p, q, j):
        return j * stride + npt + edges[tuple(sorted((p, q)))]

    def vert(p, j):  # on the y edge from layer j to j + 1
        return j * stride + per_full + p

    hexes = []
    for j in range(M):
        for q in S.quads:
            c = [corner(p, j) for p in q] + [corner(p, j + 1) for p in q]
            n = list(c)
            for (u, v) in HEX20_EDGE:
                if u < 4 and v < 4:
                    n.append(mid(q[u], q[v], j))
                elif u >= 4 and v >= 4:
                    n.append(mid(q[u - 4], q[v - 4], j + 1))
                else:
                    n.append(vert(q[u], j))
            hexes.append(n)
    return S, X, hexes, cut, ring_outer, ys


def pipe_section_node(a, n_around, i):
    """(x, z) of ring node i of fdem's cylinder with axis y, base [centre-x, 0, 0] and n_around
    elements around (src/fem/mesh_generate.cpp make_cylinder_shell: x[z] += R cos(a),
    x[x] += R sin(a), a = 2 pi i / n_around), the same doubles."""
    ang = 2 * math.pi * i / n_around
    return a.centre_x + a.radius * math.sin(ang), 0.0 + a.radius * math.cos(ang)


def boundary_faces(X, hexes, a):
    """The faces that belong to one brick only, as 8-node quads, by group."""
    count = {}
    for n in hexes:
        for fc in HEX_FACES:
            key = tuple(sorted(n[c] for c in fc))
            count[key] = count.get(key, 0) + 1
    edge_of = {frozenset(uv): 8 + k for k, uv in enumerate(HEX20_EDGE)}
    groups = {g: [] for g in SURFACES}
    tol = 1e-9 * max(a.x_max - a.x_min, a.length, a.depth)
    for e, n in enumerate(hexes):
        for fc in HEX_FACES:
            if count[tuple(sorted(n[c] for c in fc))] != 1:
                continue
            quad8 = [n[c] for c in fc] + [n[edge_of[frozenset((fc[c], fc[(c + 1) % 4]))]] for c in range(4)]
            P = X[quad8[:4]]
            if np.all(np.abs(P[:, 1]) < tol):
                g = "ymin"
            elif np.all(np.abs(P[:, 1] - a.length) < tol):
                g = "ymax"
            elif np.all(np.abs(P[:, 2]) < tol):
                g = "top"
            elif np.all(np.abs(P[:, 2] + a.depth) < tol):
                g = "bottom"
            elif np.all(np.abs(P[:, 0] - a.x_min) < tol):
                g = "xmin"
            elif np.all(np.abs(P[:, 0] - a.x_max) < tol):
                g = "xmax"
            elif np.all(np.abs(np.hypot(P[:, 0] - a.centre_x, P[:, 2]) - a.radius) < tol):
                g = "cutout"
            else:
                raise RuntimeError("boundary face of element %d not on any side: %s" % (e + 1, P))
            groups[g].append(quad8)
    return groups


def check(a, S, X, hexes, groups, cut, ring_outer, ys):
    """Self-checks: the cut-out corners are the pipe's nodes (and, on the arc, all 8 nodes of each
    cut-out face are nodes of the 2N x 2M pipe), the ring's corners are on node rays, the section's
    quads are oriented for positive bricks, every brick's Jacobian is positive at its 2x2x2 Gauss
    points and corners, the areas of the sides. Returns the smallest det J / mean det J."""
    N, M = a.around, a.along
    for s, p in enumerate(cut):
        i = N // 4 + s
        ang = 2 * math.pi * i / N
        assert S.pts[p] == (a.centre_x + a.radius * math.sin(ang), 0.0 + a.radius * math.cos(ang)), (i, S.pts[p])
    assert ys == [0.0 + a.length * j / a.along for j in range(a.along + 1)]
    # The rectangle's bottom corners are ring nodes on the rays of the pipe nodes i = 3N/8, 5N/8.
    r_out = [S.pts[p] for p in ring_outer]
    assert r_out[N // 8] == (a.centre_x + a.depth, -a.depth) and r_out[3 * N // 8] == (a.centre_x - a.depth, -a.depth)
    for q in S.quads:
        (x0, z0), (x1, z1), (x3, z3) = S.pts[q[0]], S.pts[q[1]], S.pts[q[3]]
        assert (z1 - z0) * (x3 - x0) - (x1 - x0) * (z3 - z0) > 0
    g = 1 / math.sqrt(3)
    det = jacobians(X, hexes, np.vstack([g * HEX_CORNER, HEX_CORNER]))
    det_ratio = float(np.min(det / det.mean(axis=1, keepdims=True)))
    assert np.all(det > 0), "a brick with det J <= 0 at a Gauss point or corner: %s" % np.argwhere(det <= 0)[:4]
    # The cut-out faces' nodes: all 8 on the pipe with 2N x 2M elements, node (k, l) at angle
    # 2 pi k / 2N, y = L l / 2M (k even, l even: the corners; a face's centre, k and l odd, is not
    # a soil node); with --straight-cutout the corners only, on the N x M pipe.
    fine = not a.straight_cutout
    n_ar, n_al = (2 * N, 2 * M) if fine else (N, M)
    pipe = {}
    for l in range(n_al + 1):
        for k in range(n_ar // 4, 3 * n_ar // 4 + 1):
            x, z = pipe_section_node(a, n_ar, k)
            pipe[(x, 0.0 + a.length * l / n_al, z)] = (k, l)
    on_cut = {tuple(X[n]) for f in groups["cutout"] for n in (f if fine else f[:4])}
    assert on_cut <= set(pipe), "cut-out nodes not on the pipe: %s" % sorted(on_cut - set(pipe))[:4]
    free = {kl for p, kl in pipe.items() if p not in on_cut}
    assert free == ({(k, l) for k in range(n_ar // 4 + 1, 3 * n_ar // 4, 2) for l in range(1, n_al, 2)} if fine else set()), \
        "pipe nodes not in the soil: %s" % sorted(free)[:4]
    # Areas of the section's boundary: top + cut-out chords + bottom etc.
    area = {g: 0.0 for g in groups}
    for g, fs in groups.items():
        for f in fs:
            P = X[f[:4]]
            area[g] += 0.5 * np.linalg.norm(np.cross(P[2] - P[0], P[3] - P[1]))
    W, L, D, R = a.x_max - a.x_min, a.length, a.depth, a.radius
    chord = 2 * R * math.sin(math.pi / N)
    expect = {"top": (W - 2 * R) * L, "bottom": W * L, "xmin": D * L, "xmax": D * L,
              "cutout": N // 2 * chord * L, "ymin": None, "ymax": None}
    for g, v in expect.items():
        if v is not None:
            assert abs(area[g] - v) < 1e-12 * v, (g, area[g], v)
    return det_ratio, len(on_cut)


HEX_CORNER = np.array([(-1, -1, -1), (1, -1, -1), (1, 1, -1), (-1, 1, -1), (-1, -1, 1), (1, -1, 1), (1, 1, 1), (-1, 1, 1)], float)


def hex20_dshape(P):
    """Derivatives of fdem's 20 serendipity shape functions (src/fem/element.cpp Hex20Shape) at
    the natural points P (n x 3): n x 20 x 3."""
    P = np.asarray(P, float)
    dN = np.zeros((len(P), 20, 3))
    for a in range(8):
        c = HEX_CORNER[a]
        p = 1 + c * P                                   # n x 3
        s = P @ c - 2
        dN[:, a, 0] = 0.125 * c[0] * p[:, 1] * p[:, 2] * (s + p[:, 0])
        dN[:, a, 1] = 0.125 * c[1] * p[:, 0] * p[:, 2] * (s + p[:, 1])
        dN[:, a, 2] = 0.125 * c[2] * p[:, 0] * p[:, 1] * (s + p[:, 2])
    for k, (u, v) in enumerate(HEX20_EDGE):
        c = 0.5 * (HEX_CORNER[u] + HEX_CORNER[v])
        f = np.where(c == 0, 1 - P * P, 1 + c * P)
        df = np.where(c == 0, -2 * P, c + 0 * P)
        dN[:, 8 + k, 0] = 0.25 * df[:, 0] * f[:, 1] * f[:, 2]
        dN[:, 8 + k, 1] = 0.25 * f[:, 0] * df[:, 1] * f[:, 2]
        dN[:, 8 + k, 2] = 0.25 * f[:, 0] * f[:, 1] * df[:, 2]
    return dN


def jacobians(X, hexes, P):
    """det J of every brick (rows) at the natural points P (columns)."""
    XE = X[np.array(hexes)]                             # e x 20 x 3
    J = np.einsum("eai,gaj->egij", XE, hex20_dshape(P))  # dx_i / dxi_j
    return np.linalg.det(J)


def gauss_volume(X, hexes, n):
    """The mesh's volume by the n x n x n Gauss-Legendre rule of every brick's Jacobian (fdem
    integrates a Hex20's stiffness with n = 2 and its body load with n = 3)."""
    g, w = np.polynomial.legendre.leggauss(n)
    P = np.array([(a, b, c) for a in g for b in g for c in g])
    W = np.array([wa * wb * wc for wa in w for wb in w for wc in w])
    return float(np.sum(jacobians(X, hexes, P) @ W))


def section_area(S):
    """The section's area: the shoelace sum of its quadrilaterals (what the bricks integrate)."""
    tot = 0.0
    for q in S.quads:
        P = [S.pts[p] for p in q]
        tot += 0.5 * sum(P[k][1] * P[(k + 1) % 4][0] - P[k][0] * P[(k + 1) % 4][1] for k in range(4))
    return tot


def write_msh(path, X, hexes, groups):
    lines = ["$MeshFormat", "4.1 0 8", "$EndMeshFormat", "$PhysicalNames", str(len(SURFACES) + 1),
             '3 1 "soil"']
    lines += ['2 %d "%s"' % (k + 1, g) for k, g in enumerate(SURFACES)]
    lines += ["$EndPhysicalNames", "$Entities", "0 0 %d 1" % len(SURFACES)]
    r = repr
    for k, g in enumerate(SURFACES):
        P = X[sorted({n for f in groups[g] for n in f})]
        lo, hi = P.min(axis=0), P.max(axis=0)
        lines.append("%d %s %s %s %s %s %s 1 %d 0" % (k + 1, r(lo[0]), r(lo[1]), r(lo[2]), r(hi[0]), r(hi[1]), r(hi[2]), k + 1))
    lo, hi = X.min(axis=0), X.max(axis=0)
    lines.append("1 %s %s %s %s %s %s 1 1 %d %s" % (r(lo[0]), r(lo[1]), r(lo[2]), r(hi[0]), r(hi[1]), r(hi[2]), len(SURFACES),
                                                    " ".join(str(k + 1) for k in range(len(SURFACES)))))
    lines.append("$EndEntities")
    n = len(X)
    lines += ["$Nodes", "1 %d 1 %d" % (n, n), "3 1 0 %d" % n]
    lines += [str(t + 1) for t in range(n)]
    lines += ["%s %s %s" % (r(float(x)), r(float(y)), r(float(z))) for x, y, z in X]
    lines.append("$EndNodes")
    nface = sum(len(f) for f in groups.values())
    ne = len(hexes) + nface
    lines += ["$Elements", "%d %d 1 %d" % (1 + len(SURFACES), ne, ne), "3 1 17 %d" % len(hexes)]
    tag = 0
    for h in hexes:
        tag += 1
        lines.append("%d %s" % (tag, " ".join(str(v + 1) for v in h)))
    for k, g in enumerate(SURFACES):
        lines.append("2 %d 16 %d" % (k + 1, len(groups[g])))
        for f in groups[g]:
            tag += 1
            lines.append("%d %s" % (tag, " ".join(str(v + 1) for v in f)))
    lines.append("$EndElements")
    with open(path, "w", newline="\n") as fh:
        fh.write("\n".join(lines) + "\n")
    return nface


def main(argv=None):
    a = parse_args(sys.argv[1:] if argv is None else argv)
    S, X, hexes, cut, ring_outer, ys = build_mesh(a)
    groups = boundary_faces(X, hexes, a)
    det_ratio, cut_nodes = check(a, S, X, hexes, groups, cut, ring_outer, ys)
    nface = write_msh(a.output, X, hexes, groups)
    W, L, D, R, N = a.x_max - a.x_min, a.length, a.depth, a.radius, a.around
    half_disc = N / 4 * R * R * math.sin(2 * math.pi / N)  # N/2 triangles (R^2/2) sin(2pi/N)
    # On the arc, each cut-out edge is a parabola through the chord's ends and the arc's midpoint:
    # it takes a parabolic segment, 2/3 chord x sagitta, more from the soil than the chord.
    segments = 0.0 if a.straight_cutout else N / 2 * 2 / 3 * (2 * R * math.sin(math.pi / N)) * R * (1 - math.cos(math.pi / N))
    volume = (W * D - half_disc - segments) * L
    v_poly = section_area(S) * L
    v2, v3, v8 = (gauss_volume(X, hexes, n) for n in (2, 3, 8))
    assert abs(v_poly - (W * D - half_disc) * L) < 1e-13 * volume, (v_poly, (W * D - half_disc) * L)
    for v in (v2, v3, v8):  # det J is of degree 2 at most in each natural coordinate: 2x2x2 is exact
        assert abs(v - volume) < 1e-13 * volume, (v, volume)
    print("%s: %d nodes, %d hex20 + %d quad8 faces, cut-out: %d corner nodes (%d x %d), %d nodes on the pipe (%s); "
          "volume %r m^3 (box %r - half-disc polygon %r - parabolic segments %r, x %r); Gauss 2x2x2 %r, 3x3x3 %r, "
          "8x8x8 %r; min det J / element mean %.3f"
          % (a.output, len(X), len(hexes), nface, len(cut) * (a.along + 1), len(cut), a.along + 1, cut_nodes,
             "corners of %d x %d" % (N, a.along) if a.straight_cutout else "%d x %d, face centres free" % (2 * N, 2 * a.along),
             volume, W * D * L, half_disc, segments, L,
             v2, v3, v8, det_ratio))


if __name__ == "__main__":
    main()
