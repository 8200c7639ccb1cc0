# The thesis's direct-shear specimen (Tran 2013, §3.4-3.5) packed in YADE 2023.02a (Debian's
# `yade`) with the classes of the thesis's own scripts (appendix, problems 4 and 5: makeCloud,
# FrictMat, Ip2_FrictMat_FrictMat_FrictPhys, Law2_ScGeom_FrictPhys_CundallStrack, NewtonIntegrator
# with local damping, O.dt = 0.5 PWaveTimeStep). docs/cases/specimen_protocol.md.
#
#   OUT=/work/runs/pack_yade_f0 FRICTION=0 BOX=0.06 nice -n 5 yade -n -x scripts/yade/ds_packing.py
#
# Protocol ("the gravitational method", one layer for this small box, thesis l. 1969-2001, 2145):
#   1. a non-overlapping cloud (makeCloud, psdSizes/psdCumm = fdem's sieve curve as generated,
#      distributeMass) holding the solid volume (1 - 0.35) A 25 mm, at solid fraction 0.3 (the
#      cloud's height), in the BOX x BOX section;
#   2. gravity, every friction = FRICTION (0: the thesis's "interparticle friction angle is set to
#      zero"; walls too, as fdem's packing.friction), settle (criterion below);
#   3. the x walls shaken 0.2 mm, 50 Hz, 3 cycles (displacement a sin 2 pi f t), settle again;
#   4. struck off at z = 25 mm (grains whose centre is above removed, as fdem's packing.level),
#      the case's frictions restored (grain 34 deg, floor 45 deg, sides 0), 1000 steps;
#   5. measured as fdem's packing.json: interior box 8 mm (2 d_max) in from the sides and bottom
#      and 12 mm (3 d_max) below the surface (the highest grain top); exact sphere-box volumes.
# Settled: FRICTION 0: the bulk porosity n_b = 1 - V_s/(A 2 zbar_s) changed < 0.002 over the
# window 2 sqrt(dbar/g) (fdem's `porosity` criterion) and kinetic energy per grain < 1e-3 m g d,
# or unbalancedForce < 0.01 (with the same kinetic test); FRICTION > 0: the unbalanced test only
# (fdem's `auto`). MAX_SETTLE steps per settle at most.
import json
import math
import os
import time

import numpy as np
from yade import *  # noqa: F401,F403
from yade import pack, utils

OUT = os.environ.get('OUT', '.')
BOX = float(os.environ.get('BOX', '0.06'))            # box side, m
FRICTION = float(os.environ.get('FRICTION', '0'))     # tan(phi) of every contact while packing
SEED = int(os.environ.get('SEED', '1'))
SHAKE = os.environ.get('SHAKE', 'after')              # 'after' (settle, shake, settle) or 'start'
MAX_SETTLE = int(os.environ.get('MAX_SETTLE', '200000'))
H = 0.025              # specimen height (strike-off), m
TARGET_N = 0.35        # fdem's packing.porosity: sets the cloud's solid volume
CLOUD_FRACTION = 0.3
E, NU, RHO = 3.8e7, 0.25, 2650.0   # Table 3-2; poisson = K_T/K_N for FrictPhys
DAMPING = 0.2
MU_SAND, MU_PLATE = 0.6745, 1.0    # restored after packing: 34 deg, plates 45 deg, sides 0
SHAKE_A, SHAKE_F, SHAKE_CYCLES = 0.0002, 50.0, 3
G = 9.81
os.makedirs(OUT, exist_ok=True)
T0 = time.time()

# --- grading: fdem's sieve curve as fdem generates it (mass shares 16.7/16.6/33.4/33.3 % in the
# classes 1-1.5-2-3-4 mm, NUMBER-uniform in d within a class: mass passing within [a, b] grows as
# d^4), given to makeCloud as a fine psd table in mass
SIEVE = [0.001, 0.0015, 0.002, 0.003, 0.004]
PASS = [0.0, 16.7, 33.3, 66.7, 100.0]
psd_d, psd_c = [SIEVE[0]], [0.0]
for k in range(1, len(SIEVE)):
    a, b = SIEVE[k - 1], SIEVE[k]
    for d in np.linspace(a, b, 9)[1:]:
        psd_d.append(float(d))
        psd_c.append((PASS[k - 1] + (PASS[k] - PASS[k - 1]) * (d ** 4 - a ** 4) / (b ** 4 - a ** 4)) / 100.0)
# number share and mean grain volume of that curve (to get the cloud's solid volume)
w = [(PASS[k] - PASS[k - 1]) / ((SIEVE[k - 1] + SIEVE[k]) * (SIEVE[k - 1] ** 2 + SIEVE[k] ** 2) / 4)
     for k in range(1, len(SIEVE))]
mean_d3 = (PASS[-1] - PASS[0]) / sum(w)   # number-weighted mean of d^3
v_mean = math.pi / 6 * mean_d3
area = BOX * BOX
solid = (1 - TARGET_N) * area * H
num = int(round(solid / v_mean))
cloud_top = solid / (area * CLOUD_FRACTION)

sp = pack.SpherePack()
sp.makeCloud((0, 0, 0), (BOX, BOX, cloud_top), psdSizes=psd_d, psdCumm=psd_c, distributeMass=True,
             num=num, seed=SEED)
print('ds_packing: cloud %d grains (asked %d), solid %.4g m3 (target %.4g), top %.4f m' %
      (len(sp), num, sum(4 / 3 * math.pi * r ** 3 for c, r in sp), solid, cloud_top))

# --- materials (FrictMat, as the thesis's scripts) and bodies
ang = math.atan(FRICTION)
m_sand = O.materials.append(FrictMat(young=E, poisson=NU, frictionAngle=ang, density=RHO, label='sand'))
m_side = O.materials.append(FrictMat(young=E, poisson=NU, frictionAngle=ang, density=7850, label='side'))
m_floor = O.materials.append(FrictMat(young=E, poisson=NU, frictionAngle=ang, density=7850, label='floor'))
T = 0.006                      # wall half-thickness
ztop = cloud_top + 0.01        # side walls reach above the cloud
zc, zh = (ztop - 0.001) / 2, (ztop + 0.001) / 2
floor = O.bodies.append(utils.box(center=(BOX / 2, BOX / 2, -T), extents=(BOX / 2 + 2 * T, BOX / 2 + 2 * T, T),
                                  fixed=True, material=m_floor))
x0 = O.bodies.append(utils.box(center=(-T, BOX / 2, zc), extents=(T, BOX / 2 + 2 * T, zh), fixed=True, material=m_side))
x1 = O.bodies.append(utils.box(center=(BOX + T, BOX / 2, zc), extents=(T, BOX / 2 + 2 * T, zh), fixed=True, material=m_side))
y0 = O.bodies.append(utils.box(center=(BOX / 2, -T, zc), extents=(BOX / 2 + 2 * T, T, zh), fixed=True, material=m_side))
y1 = O.bodies.append(utils.box(center=(BOX / 2, BOX + T, zc), extents=(BOX / 2 + 2 * T, T, zh), fixed=True, material=m_side))
WALLS = [floor, x0, x1, y0, y1]
grains = O.bodies.append([utils.sphere(c, r, material=m_sand) for c, r in sp])

ip2 = Ip2_FrictMat_FrictMat_FrictPhys()
O.engines = [
    ForceResetter(),
    InsertionSortCollider([Bo1_Sphere_Aabb(), Bo1_Box_Aabb()]),
    InteractionLoop([Ig2_Sphere_Sphere_ScGeom(), Ig2_Box_Sphere_ScGeom()], [ip2],
                    [Law2_ScGeom_FrictPhys_CundallStrack()]),
    NewtonIntegrator(damping=DAMPING, gravity=(0, 0, -G)),
    PyRunner(iterPeriod=1, command='shake()', label='shaker', dead=True),
]
O.dt = 0.5 * utils.PWaveTimeStep()
CHECK = 1000
dbar = 2 * float(np.mean([r for c, r in sp]))
mbar = RHO * 4 / 3 * math.pi * float(np.mean([r ** 3 for c, r in sp]))
WINDOW = max(5 * CHECK, int(math.ceil(2 * math.sqrt(dbar / G) / O.dt / CHECK)) * CHECK)
print('ds_packing: dt %.4g s, window %d steps, friction %g, box %g m' % (O.dt, WINDOW, FRICTION, BOX))

shake_state = {'t0': 0.0, 'steps': 0, 'n': 0}


def shake():
    """x walls: velocity a 2 pi f cos(2 pi f t) (at the step's middle), 3 cycles, then at rest."""
    s = shake_state
    if s['n'] >= s['steps']:
        for b in (x0, x1):
            O.bodies[b].state.vel = Vector3(0, 0, 0)
        shaker.dead = True
        return
    t = (s['n'] + 0.5) * O.dt
    v = SHAKE_A * 2 * math.pi * SHAKE_F * math.cos(2 * math.pi * SHAKE_F * t)
    for b in (x0, x1):
        O.bodies[b].state.vel = Vector3(v, 0, 0)
    s['n'] += 1


def start_shaking():
    shake_state['steps'] = int(round(SHAKE_CYCLES / SHAKE_F / O.dt))
    shake_state['n'] = 0
    shaker.dead = False


def spheres():
    return [b for b in O.bodies if b is not None and isinstance(b.shape, Sphere)]


def state_arrays():
    bs = spheres()
    pos = np.array([[b.state.pos[0], b.state.pos[1], b.state.pos[2]] for b in bs])
    r = np.array([b.shape.radius for b in bs])
    ke = sum(0.5 * b.state.mass * b.state.vel.squaredNorm() +
             0.5 * b.state.angVel.dot(Vector3(b.state.inertia[0] * b.state.angVel[0],
                                               b.state.inertia[1] * b.state.angVel[1],
                                               b.state.inertia[2] * b.state.angVel[2])) for b in bs)
    return bs, pos, r, ke


def bulk_porosity(pos, r):
    v = 4 / 3 * math.pi * r ** 3
    zbar = float(np.sum(v * pos[:, 2]) / np.sum(v))
    return 1 - float(np.sum(v)) / (area * 2 * zbar)


def settle(name, by_porosity, history):
    """Run until settled (see the header); returns (steps, ended_by)."""
    start = O.iter
    hist = []
    while True:
        O.run(CHECK, True)
        bs, pos, r, ke = state_arrays()
        kin = ke / len(bs) / (mbar * G * dbar)
        unb = utils.unbalancedForce()
        nb = bulk_porosity(pos, r)
        n = O.iter - start
        hist.append((n, nb))
        history.append({'phase': name, 'iter': O.iter, 'bulk_porosity': nb, 'kinetic_ratio': kin,
                        'unbalanced': unb, 'wall': time.time() - T0})
        if n % 10000 == 0:
            print('ds_packing: %s %d steps, bulk porosity %.4f, kinetic %.2e m g d, unbalanced %.3f, %.0f s' %
                  (name, n, nb, kin, unb, time.time() - T0), flush=True)
        if not shaker.dead:
            continue
        quiet = kin < 1e-3
        if unb < 0.01 and quiet:
            return n, 'unbalanced'
        if by_porosity and n >= WINDOW and quiet:
            j = [k for k, (s, _) in enumerate(hist) if s <= n - WINDOW][-1]
            if abs(nb - hist[j][1]) < 0.002:
                return n, 'porosity'
        if n >= MAX_SETTLE:
            return n, 'max_steps'


def sphere_box_volume(c, r, lo, hi, nq=48):
    """Exact-enough volume of each sphere inside the box [lo, hi]: spheres wholly in or out
    exactly, cut ones by Gauss-Legendre over x and z (clipped to the box) of the y chord in it."""
    vol = np.zeros(len(r))
    inside = np.all(c - r[:, None] >= lo, axis=1) & np.all(c + r[:, None] <= hi, axis=1)
    vol[inside] = 4 / 3 * math.pi * r[inside] ** 3
    cut = ~inside & np.all(c + r[:, None] > lo, axis=1) & np.all(c - r[:, None] < hi, axis=1)
    gx, gw = np.polynomial.legendre.leggauss(nq)
    for i in np.nonzero(cut)[0]:
        ax, bx = max(lo[0], c[i, 0] - r[i]), min(hi[0], c[i, 0] + r[i])
        az, bz = max(lo[2], c[i, 2] - r[i]), min(hi[2], c[i, 2] + r[i])
        if bx <= ax or bz <= az:
            continue
        x = (ax + bx) / 2 + (bx - ax) / 2 * gx
        z = (az + bz) / 2 + (bz - az) / 2 * gx
        X, Z = np.meshgrid(x, z, indexing='ij')
        h2 = r[i] ** 2 - (X - c[i, 0]) ** 2 - (Z - c[i, 2]) ** 2
        h = np.sqrt(np.clip(h2, 0, None))
        chord = np.clip(np.minimum(c[i, 1] + h, hi[1]) - np.maximum(c[i, 1] - h, lo[1]), 0, None)
        W = np.outer(gw, gw) * (bx - ax) / 2 * (bz - az) / 2
        vol[i] = float(np.sum(W * chord))
    return vol


def measure(label):
    bs, pos, r, ke = state_arrays()
    ids = {b.id: k for k, b in enumerate(bs)}
    top = float(np.max(pos[:, 2] + r))
    margin, top_margin = 2 * 0.004, 3 * 0.004
    lo = np.array([margin, margin, margin])
    hi = np.array([BOX - margin, BOX - margin, top - top_margin])
    vin = sphere_box_volume(pos, r, lo, hi)
    n_int = 1 - float(np.sum(vin)) / float(np.prod(hi - lo)) if np.all(hi > lo) else float('nan')
    vol = 4 / 3 * math.pi * r ** 3
    n_whole = 1 - float(np.sum(vol)) / (area * H)
    vslab = sphere_box_volume(pos, r, np.array([0, 0, 0.0]), np.array([BOX, BOX, H]))
    n_slab = 1 - float(np.sum(vslab)) / (area * H)
    # contacts (sphere-sphere, real interactions) per grain; fabric over the interior's sides
    cnt = np.zeros(len(bs), dtype=int)
    inbox = np.all((pos >= lo) & (pos < hi), axis=1)
    F = np.zeros((3, 3))
    sides = 0
    nc = 0
    for I in O.interactions:
        if not I.isReal or I.id1 not in ids or I.id2 not in ids:
            continue
        a, b = ids[I.id1], ids[I.id2]
        nc += 1
        cnt[a] += 1
        cnt[b] += 1
        n = I.geom.normal
        nn = np.outer([n[0], n[1], n[2]], [n[0], n[1], n[2]])
        for k in (a, b):
            if inbox[k]:
                F += nn
                sides += 1
    ci = cnt[inbox]
    npi = int(np.sum(inbox))
    n0, n1 = int(np.sum(ci == 0)), int(np.sum(ci == 1))
    z = int(np.sum(ci)) / npi if npi else float('nan')
    z_mech = (int(np.sum(ci)) - n1) / (npi - n0 - n1) if npi - n0 - n1 > 0 else float('nan')
    z_all = 2 * nc / len(bs)
    a0, a1 = int(np.sum(cnt == 0)), int(np.sum(cnt == 1))
    z_all_mech = (2 * nc - a1) / (len(bs) - a0 - a1) if len(bs) - a0 - a1 > 0 else float('nan')
    F /= max(sides, 1)
    res = {'label': label, 'iter': O.iter, 'grains': len(bs), 'surface_z': top,
           'interior_box': {'min': lo.tolist(), 'max': hi.tolist()},
           'interior': {'particles': npi, 'porosity': n_int, 'void_ratio': n_int / (1 - n_int),
                        'coordination': z, 'coordination_mech': z_mech, 'rattlers_0': n0, 'rattlers_1': n1,
                        'fabric': [F[0, 0], F[1, 1], F[2, 2], F[0, 1], F[0, 2], F[1, 2]]},
           'whole': {'porosity_grains_over_box': n_whole, 'porosity_slab_0_H': n_slab,
                     'coordination': z_all, 'coordination_mech': z_all_mech,
                     'yade_avgNumInteractions': utils.avgNumInteractions(),
                     'yade_avgNumInteractions_skipFree': utils.avgNumInteractions(skipFree=True)},
           'bulk_porosity': bulk_porosity(pos, r), 'unbalanced': utils.unbalancedForce(),
           'wall_time': time.time() - T0}
    print('ds_packing: %s: %d grains, interior n %.4f (e %.3f, %d grains), whole %.4f (slab %.4f), '
          'Z %.2f / mech %.2f, fabric %.3f %.3f %.3f, surface %.4f m' %
          (label, len(bs), n_int, n_int / (1 - n_int), npi, n_whole, n_slab, z, z_mech, F[0, 0], F[1, 1],
           F[2, 2], top), flush=True)
    return res


history = []
report = {'box': BOX, 'friction': FRICTION, 'seed': SEED, 'shake': SHAKE, 'dt': O.dt, 'window': WINDOW,
          'cloud_grains': len(sp), 'cloud_top': cloud_top, 'phases': [], 'measures': []}
by_por = FRICTION == 0
if SHAKE == 'start':
    start_shaking()
    n, how = settle('settle', by_por, history)
    report['phases'].append({'phase': 'shake+settle', 'steps': n, 'ended_by': how})
else:
    n, how = settle('settle1', by_por, history)
    report['phases'].append({'phase': 'settle1', 'steps': n, 'ended_by': how})
    report['measures'].append(measure('settled, before shaking (not struck off)'))
    start_shaking()
    n, how = settle('shake+settle2', by_por, history)
    report['phases'].append({'phase': 'shake+settle2', 'steps': n, 'ended_by': how})
report['measures'].append(measure('settled after shaking (not struck off)'))

# strike-off at H, frictions restored (grain 34 deg, floor 45 deg, sides 0), 1000 steps
removed = 0
for b in spheres():
    if b.state.pos[2] > H:
        O.bodies.erase(b.id)
        removed += 1
O.materials[m_sand].frictionAngle = math.atan(MU_SAND)
O.materials[m_side].frictionAngle = 0.0
O.materials[m_floor].frictionAngle = math.atan(MU_PLATE)
ip2.frictAngle = MatchMaker(matches=[(m_sand, m_floor, math.atan(MU_PLATE))], algo='min')
for I in O.interactions:
    if not I.isReal:
        continue
    walls = {I.id1, I.id2} & set(WALLS)
    tan = MU_SAND if not walls else (MU_PLATE if floor in walls else 0.0)
    I.phys.tangensOfFrictionAngle = tan
O.run(1000, True)
report['phases'].append({'phase': 'struck off, friction restored', 'steps': 1000, 'removed': removed})
final = measure('specimen (struck off at 25 mm, friction restored, 1000 steps)')
report['measures'].append(final)
report['steps_total'] = O.iter
report['wall_time'] = time.time() - T0
report['history'] = history
with open(os.path.join(OUT, 'ds_packing.json'), 'w') as f:
    json.dump(report, f, indent=1)
with open(os.path.join(OUT, 'specimen.txt'), 'w') as f:
    for b in spheres():
        f.write('%d %.9g %.9g %.9g %.9g\n' % (b.id, b.state.pos[0], b.state.pos[1], b.state.pos[2], b.shape.radius))
print('ds_packing: done, %d steps, %.0f s' % (O.iter, time.time() - T0))
