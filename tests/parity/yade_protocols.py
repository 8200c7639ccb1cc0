# Two-body protocols run in YADE 2023.02a (Debian's `yade`), whose histories fdem's contact kernel
# replays in tests/unit_parity_yade.cpp (docs/verification.md#parity-against-yade).
#
#   yade -n -x tests/parity/yade_protocols.py            (PARITY_OUT=<dir>, default: the current dir)
#
# Every body is kinematic (dynamic=False: all six DOFs blocked); its velocity and angular velocity
# are prescribed per phase by a PyRunner at the start of each step. One CSV per protocol, one row
# per step while the two bodies are in contact (the row also when YADE has no interaction).
#
# YADE's step (O.engines below) and what each row holds:
#   setter (PyRunner)   vel/angVel of this step
#   ForceResetter, InsertionSortCollider
#   InteractionLoop     Ig2: the geometry from the positions and orientations at the START of the
#                       step (after the previous step's integration) and the velocities of this step;
#                       Law2: the forces
#   recorder (PyRunner) writes pos/ori (start of step), vel/angVel (this step), the interaction's
#                       geometry and phys, and O.forces of both bodies
#   NewtonIntegrator    pos += vel dt, ori = q(angVel dt) ori
#
# Material mapping (YADE 2023's Ip2_CohFrictMat_CohFrictMat_CohFrictPhys, D = geom radii):
#   kn = 2 Ea Da Eb Db / (Ea Da + Eb Db)   (= fdem's springs 2 E r in series when Da, Db = r)
#   ks = 2 Ea Da Va Eb Db Vb / (Ea Da Va + Eb Db Vb)   (poisson = fdem's kt_kn: ks = kt_kn kn)
#   kr = Da Db ks alphaKr,  ktw = Da Db ks alphaKtw,  maxRollPl = min(etaRoll_a Da, etaRoll_b Db)
#   tan(friction) = tan(min(frictionAngle_a, frictionAngle_b))
# Sphere-sphere (equal radii r): Da = Db = r, so alphaKr = beta_r, etaRoll = eta_r, young = E.
# Facet-sphere: Ig2_Facet_Sphere_ScGeom6D sets radius1 = 2r (the facet), radius2 = r, so the
# facet's young is E/2 (kn = E r, as fdem's wall: 2Er.2Er/(2Er+2Er)), alphaKr = beta_r/2 on both
# (kr = 2r.r.ks.beta_r/2 = beta_r r^2 K_T) and etaRoll = eta_r on both (min(2 eta r, eta r)).
import math
import os

from yade import *  # noqa: F401,F403  (yade -x provides these; explicit for readers)
from yade import utils

OUT = os.environ.get('PARITY_OUT', '.')

R = 0.01          # sphere radius, m
E = 1.0e8         # fdem's Young's modulus of every body, Pa  -> K_N = E r = 1e6 N/m
ALPHA = 0.25      # K_T / K_N
MU = 0.5          # tan(phi)
BETA_R = 0.12     # rolling stiffness factor
ETA_R = 1.0       # rolling limit factor
DT = 1.0e-4       # s
V = 1.0e-3        # normal and sliding speed, m/s
GAP0 = 0.5e-6     # initial gap, m (the contact forms at a definite step)


def mat(young, alpha_kr, alpha_ktw, eta_roll, eta_twist):
    return CohFrictMat(young=young, poisson=ALPHA, frictionAngle=math.atan(MU), density=2600,
                       alphaKr=alpha_kr, alphaKtw=alpha_ktw, etaRoll=eta_roll, etaTwist=eta_twist,
                       momentRotationLaw=True, isCohesive=False, normalCohesion=0, shearCohesion=0)


def vec(v):
    return [v[0], v[1], v[2]]


def rotvec(q):
    axis, angle = q.toAxisAngle()
    if angle > math.pi:
        angle -= 2 * math.pi
    return [axis[0] * angle, axis[1] * angle, axis[2] * angle]


COLUMNS = (['iter', 'real'] +
           [p + c for p in ('pos1_', 'pos2_', 'vel1_', 'vel2_', 'angvel1_', 'angvel2_', 'rot1_', 'rot2_')
            for c in 'xyz'] +
           ['pen'] +
           [p + c for p in ('normal_', 'cp_', 'fn_', 'fs_', 'mb_', 'mt_', 'f1_', 't1_', 'f2_', 't2_')
            for c in 'xyz'])


def run(name, kind, law, phases, twist_stiff=False, ratchet=False):
    """kind: 'ss' (two spheres, id1 = 0 at the origin, id2 = 1) or 'facet' (id1 = 0 the facet in
    z = 0, id2 = 1 the sphere). law: 'incremental' or 'total'. phases: (steps, vel0, angvel0,
    vel1, angvel1) per phase. twist_stiff: YADE's ktw = kr and etaTwist = etaRoll (else ktw = 0).
    ratchet: Ig2_Sphere_Sphere_ScGeom6D's avoidGranularRatcheting (YADE's default True; fdem's
    engine takes the relative velocity at the contact point, as YADE with False)."""
    O.reset()
    ktw = 1.0 if twist_stiff else 0.0
    if kind == 'ss':
        m = mat(E, BETA_R, BETA_R * ktw, ETA_R, ETA_R)
        O.materials.append(m)
        b0 = utils.sphere((0, 0, 0), R, material=m, fixed=True)
        b1 = utils.sphere((2 * R + GAP0, 0, 0), R, material=m, fixed=True)
        O.bodies.append([b0, b1])
    else:
        mf = mat(E / 2, BETA_R / 2, BETA_R / 2 * ktw, ETA_R, ETA_R)
        ms = mat(E, BETA_R / 2, BETA_R / 2 * ktw, ETA_R, ETA_R)
        O.materials.append([mf, ms])
        f = utils.facet([(-0.5, -0.5, 0), (0.5, -0.5, 0), (0, 0.5, 0)], material=mf, fixed=True)
        s = utils.sphere((0, 0, R + GAP0), R, material=ms, fixed=True)
        O.bodies.append([f, s])
    for b in O.bodies:
        b.dynamic = False
    schedule = []
    for (n, v0, w0, v1, w1) in phases:
        schedule += [(v0, w0, v1, w1)] * n
    rows = []
    meta = {}

    def setter():
        k = O.iter
        if k >= len(schedule):
            O.pause()
            return
        v0, w0, v1, w1 = schedule[k]
        O.bodies[0].state.vel = v0
        O.bodies[0].state.angVel = w0
        O.bodies[1].state.vel = v1
        O.bodies[1].state.angVel = w1

    def recorder():
        if O.iter >= len(schedule):
            return
        i = O.interactions[0, 1] if O.interactions.has(0, 1) else None
        real = i is not None and i.isReal
        s0, s1 = O.bodies[0].state, O.bodies[1].state
        row = [O.iter, 1 if real else 0]
        for v in (s0.pos, s1.pos, s0.vel, s1.vel, s0.angVel, s1.angVel):
            row += vec(v)
        row += rotvec(s0.ori) + rotvec(s1.ori)
        if real:
            if (i.id1, i.id2) != (0, 1):
                raise RuntimeError('interaction order %d %d' % (i.id1, i.id2))
            g, p = i.geom, i.phys
            row += [g.penetrationDepth] + vec(g.normal) + vec(g.contactPoint)
            row += vec(p.normalForce) + vec(p.shearForce) + vec(p.moment_bending) + vec(p.moment_twist)
            if not meta:
                meta.update(kn=p.kn, ks=p.ks, kr=p.kr, ktw=p.ktw, maxRollPl=p.maxRollPl,
                            maxTwistPl=p.maxTwistPl, tanphi=p.tangensOfFrictionAngle,
                            refR1=g.refR1, refR2=g.refR2)
        else:
            row += [0.0] * 19
        for b in (0, 1):
            row += vec(O.forces.f(b, True)) + vec(O.forces.t(b, True))
        if len(row) != len(COLUMNS):
            raise RuntimeError('row of %d values, %d columns' % (len(row), len(COLUMNS)))
        rows.append(row)

    O.engines = [
        PyRunner(command='setter()', iterPeriod=1, initRun=True, label='setter'),
        ForceResetter(),
        InsertionSortCollider([Bo1_Sphere_Aabb(), Bo1_Facet_Aabb()]),
        InteractionLoop(
            [Ig2_Sphere_Sphere_ScGeom6D(avoidGranularRatcheting=ratchet, updateRotations=True),
             Ig2_Facet_Sphere_ScGeom6D()],
            [Ip2_CohFrictMat_CohFrictMat_CohFrictPhys(setCohesionNow=False, setCohesionOnNewContacts=False)],
            [Law2_ScGeom6D_CohFrictPhys_CohesionMoment(useIncrementalForm=(law == 'incremental'),
                                                       always_use_moment_law=True)]),
        PyRunner(command='recorder()', iterPeriod=1, initRun=True, label='recorder'),
        NewtonIntegrator(damping=0.0, gravity=(0, 0, 0)),
    ]
    globals()['setter'] = setter
    globals()['recorder'] = recorder
    O.dt = DT
    O.run(len(schedule), True)
    path = os.path.join(OUT, name + '.csv')
    with open(path, 'w') as out:
        out.write('# protocol %s\n# kind %s\n# law %s\n# yade %s\n# avoidGranularRatcheting %d\n'
                  % (name, kind, law, yade.config.version, 1 if ratchet else 0))
        out.write('# dt %r\n# radius %r\n# young %r\n# kt_kn %r\n# friction %r\n# beta_r %r\n# eta_r %r\n'
                  % (DT, R, E, ALPHA, MU, BETA_R, ETA_R))
        for k in sorted(meta):
            out.write('# yade_%s %r\n' % (k, meta[k]))
        out.write(','.join(COLUMNS) + '\n')
        for row in rows:
            out.write(','.join('%d' % x if j < 2 else '%.17g' % x for j, x in enumerate(row)) + '\n')
    print('parity: wrote %s (%d rows)' % (path, len(rows)))


Z = Vector3(0, 0, 0)
X, Y, Zh = Vector3(1, 0, 0), Vector3(0, 1, 0), Vector3(0, 0, 1)
NLOAD = 105               # GAP0 + 1e-5 m at V: overlap 1e-5 m, F_N = 10 N
W = 0.8 / (2 * 300 * DT)  # each sphere's spin when two spheres roll (relative 0.8 rad in 300 steps)
WF = 0.8 / (300 * DT)     # the sphere's spin on the facet
LEVER = R - 0.5e-5        # the contact point's distance from the sphere's centre at F_N = 10 N

# (1) normal load to 2.45e-5 m (24.5 N) and unload past separation
run('normal_ss', 'ss', 'incremental', [(250, Z, Z, -V * X, Z), (260, Z, Z, V * X, Z)])
# (2) sliding past the Coulomb cap (2e-5 m) and back, on a facet (the normal is fixed) and
# between two spheres (the normal turns by y / 2r, up to 3e-3 rad); then unload
slide = [(60, V * X, Z), (120, -V * X, Z), (40, V * Y, Z), (120, V * Zh, Z)]
run('slide_facet', 'facet', 'incremental',
    [(NLOAD, Z, Z, -V * Zh, Z)] + [(n, Z, Z, v, w) for (n, v, w) in slide])
run('slide_ss', 'ss', 'incremental',
    [(NLOAD, Z, Z, -V * X, Z), (60, Z, Z, V * Y, Z), (120, Z, Z, -V * Y, Z), (40, Z, Z, V * Zh, Z),
     (120, Z, Z, V * X, Z)])
# (3) two spheres rolling on each other without slip (opposite spins about z), relative rotation
# 0.8 rad and back to 0: the rolling cap (eta_r r F_N = 0.1 N m) is reached at 0.033 rad
for law in ('incremental', 'total'):
    run('roll_ss_' + law[:3], 'ss', law,
        [(NLOAD, Z, Z, -V * X, Z), (300, Z, W * Zh, Z, -W * Zh), (300, Z, -W * Zh, Z, W * Zh)])
# (4) twist: opposite spins about the normal, 0.8 rad and back (YADE's ktw = kr for the total law)
for law in ('incremental', 'total'):
    run('twist_ss_' + law[:3], 'ss', law,
        [(NLOAD, Z, Z, -V * X, Z), (300, Z, W * X, Z, -W * X), (300, Z, -W * X, Z, W * X)],
        twist_stiff=(law == 'total'))
# (4b) a shear force stored (elastic, 2.5 N), then sphere 0 alone spins about the normal (0.27 rad):
# YADE turns the shear force with the pair's mean spin, fdem does not (a documented difference)
run('twist_spin_ss', 'ss', 'incremental',
    [(NLOAD, Z, Z, -V * X, Z), (100, Z, Z, V * Y, Z), (200, Z, W * X, Z, Z)])
# (5) a sphere rolling on a facet without slip (v = w x lever), 0.8 rad and back
for law in ('incremental', 'total'):
    run('roll_facet_' + law[:3], 'facet', law,
        [(NLOAD, Z, Z, -V * Zh, Z), (300, Z, Z, WF * LEVER * X, WF * Y),
         (300, Z, Z, -WF * LEVER * X, -WF * Y)])
# (2c) the sliding of (2) between two spheres with YADE's default avoidGranularRatcheting = True (a
# documented difference: YADE's relative velocity then scales the translation by (r1 + r2)/(r1 + r2 -
# delta) and takes the full radii as lever arms of the spins)
run('slide_ss_agr', 'ss', 'incremental',
    [(NLOAD, Z, Z, -V * X, Z), (60, Z, Z, V * Y, Z), (120, Z, Z, -V * Y, Z), (40, Z, Z, V * Zh, Z),
     (120, Z, Z, V * X, Z)], ratchet=True)
# (4c) rolling and twist together (axis (x + z)/sqrt 2, 0.8 rad and back), the total law: YADE 2023
# caps bending and twist separately (each at eta r F_N), fdem (the thesis's engine) caps |M| jointly
WD = W / math.sqrt(2)
run('rolltwist_ss_tot', 'ss', 'total',
    [(NLOAD, Z, Z, -V * X, Z), (300, Z, WD * (X + Zh), Z, -WD * (X + Zh)),
     (300, Z, -WD * (X + Zh), Z, WD * (X + Zh))], twist_stiff=True)
