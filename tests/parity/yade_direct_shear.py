# The direct-shear CI box (cases/lab/direct_shear_packed_ci.yaml) in YADE 2023.02a (Debian's `yade`),
# sheared from a packing fdem made: the same grains at the same positions, the same box, materials,
# servo and protocol (docs/verification.md, "One assembly: the direct-shear CI box in both codes").
#
#   SPECIMEN=/work/runs/dsci_s1/specimen.txt OUT=/work/runs/yade_ds_13.6 SIGMA=13600 \
#     nice -n 5 yade -n -x tests/parity/yade_direct_shear.py
#
# Environment: SPECIMEN (fdem's specimen.txt: id x y z r, m), OUT (directory; lab.csv is written
# there), SIGMA (sigma_n, Pa; default 13600), CONSOL (consolidation steps, 8000), SHEAR (shearing
# steps, 18000: 9 mm at 0.1 m/s), RATCHET (1: Ig2_Sphere_Sphere_ScGeom6D's avoidGranularRatcheting,
# YADE's default; 0, the default here: fdem's relative velocity at the contact point), FDEM_ROLL
# (a diagnostic, default 0: every FDEM_ROLL steps a PyRunner after the InteractionLoop gives every
# grain-grain contact fdem's kr = beta_r rbar^2 ks and maxRollPl = eta_r rbar, rbar = (r_a + r_b)/2,
# instead of YADE's r_a r_b and min(r_a, r_b); a new contact keeps YADE's values until then).
#
# What the specimen gives: positions and radii only (fdem's specimen.h5 also holds the velocities,
# spins and contact histories after the packing's final steps: YADE starts at rest, without
# shear histories). The top plate is placed as fdem's packing.place_on_surface does: its face on
# the highest grain top, max(z + r) over the grains within a radius of its footprint.
#
# Mapping (docs/verification.md#parity-against-yade; YADE's Ip2_CohFrictMat_CohFrictMat_CohFrictPhys
# with D_a, D_b the geometry's radii):
#   grains  CohFrictMat(young=E, poisson=kt_kn, frictionAngle=atan 0.6745, alphaKr=beta_r 0.05,
#           etaRoll=eta_r 1, alphaKtw=0): two grains of radii r_a, r_b get kn = 2E r_a r_b/(r_a+r_b)
#           and ks = kt_kn kn as fdem; kr = r_a r_b ks beta_r and maxRollPl = eta_r min(r_a, r_b)
#           where fdem takes rbar = (r_a + r_b)/2 (K_r = beta_r rbar^2 K_T, M_lim = eta_r rbar F_N):
#           equal for equal radii only (here r_b/r_a up to 1.6: K_r 0.95, M_lim 0.77 of fdem's).
#   walls   boxes (Ig2_Box_Sphere_ScGeom6D sets radius1 = radius2 = the sphere's r, as fdem's walls
#           take r for both springs): young = E gives kn = E r = fdem's wall. fdem's incremental pair
#           of a grain and a wall material without rolling values takes the mean: beta_r 0.025,
#           eta_r 0.5 (run.json's pairs); YADE takes the harmonic mean of alphaKr (0 if one is 0)
#           and min(etaRoll D): the walls' alphaKr = 1/60 (2*0.05*(1/60)/(0.05+1/60) = 0.025) and
#           etaRoll = 0.5 (min(1 r, 0.5 r)).
#   friction  YADE's default is min(frictionAngle_a, frictionAngle_b): grain-plate would be 34 deg;
#           fdem's `interactions` entry gives the grain-rough pair tan phi = 1.0, here a MatchMaker
#           on frictAngle for the (sand, rough) material pair; the side boxes 0.
#   floor   fdem's plane z = 0: a box whose top face is z = 0 and wide enough (the same contact).
#   servo   fdem's law (src/dem/walls.cpp servo_step): every step after the forces,
#           dz = 0.5 (sigma0 A - F_z) / K, K = sum kn n_z^2 over the plate's contacts, |dz| <= v_max dt
#           (no contact: v_max dt), A = 0.06 x 0.06; the plate's velocity (dz/dt along -z, plus the
#           shear velocity) is set before NewtonIntegrator moves it (fdem: walls.integrate, disp +=
#           dt vel). v_max 0.4 m/s while consolidating, 0.1 m/s while shearing.
#   step    fdem's order: the walls' motion phase of step k is set before step k's forces, lab.csv's
#           row k holds step k-1's forces and the positions after it (rows every 500 steps).
import math
import os
import time

from yade import *  # noqa: F401,F403
from yade import utils

SPECIMEN = os.environ.get('SPECIMEN', '/work/runs/dsci_s1/specimen.txt')
OUT = os.environ.get('OUT', '.')
SIGMA = float(os.environ.get('SIGMA', '13600'))
CONSOL = int(os.environ.get('CONSOL', '8000'))
SHEAR = int(os.environ.get('SHEAR', '18000'))
RATCHET = os.environ.get('RATCHET', '0') == '1'
FDEM_ROLL = int(os.environ.get('FDEM_ROLL', '0'))   # > 0: every FDEM_ROLL steps, fdem's rolling values
EVERY = 500
os.makedirs(OUT, exist_ok=True)

E, KT_KN, RHO = 3.8e7, 0.25, 2650.0
MU_SAND, MU_ROUGH = 0.6745, 1.0
BETA_R, ETA_R = 0.05, 1.0
DT, DAMPING, G = 5.0e-6, 0.2, 9.81
V_SHEAR = 0.1
AREA = 0.06 * 0.06
GAIN = 0.5
VMAX_CONSOL, VMAX_SHEAR = 0.4, 0.1
PLATE = ((0.0, 0.0, 0.084), (0.06, 0.06, 0.088))   # the case's top plate, before it is placed


def cmat(mu, alpha_kr, eta_roll, rho):
    return CohFrictMat(young=E, poisson=KT_KN, frictionAngle=math.atan(mu), density=rho,
                       alphaKr=alpha_kr, alphaKtw=0.0, etaRoll=eta_roll, etaTwist=eta_roll,
                       momentRotationLaw=True, isCohesive=False, normalCohesion=0, shearCohesion=0)


sand = O.materials.append(cmat(MU_SAND, BETA_R, ETA_R, RHO))
# the walls' rolling values: fdem's pair mean (beta_r/2, eta_r/2) through YADE's harmonic mean / min
AKR_WALL = 1.0 / 60.0
rough = O.materials.append(cmat(MU_ROUGH, AKR_WALL, 0.5, 7850.0))
smooth = O.materials.append(cmat(0.0, AKR_WALL, 0.5, 7850.0))

# --- grains: fdem's specimen.txt
spheres = []
with open(SPECIMEN) as f:
    for line in f:
        line = line.split('#')[0].split()
        if len(line) != 5:
            continue
        x, y, z, r = (float(v) for v in line[1:])
        spheres.append((x, y, z, r))
NWALL = 10
ALLBITS = (1 << (NWALL + 1)) - 1
sid = O.bodies.append([utils.sphere((x, y, z), r, material=sand, mask=ALLBITS) for (x, y, z, r) in spheres])

# --- walls: each box its own mask bit (boxes never pair with each other; every grain pairs with all)
surface = max(z + r for (x, y, z, r) in spheres
              if PLATE[0][0] - r <= x <= PLATE[1][0] + r and PLATE[0][1] - r <= y <= PLATE[1][1] + r)
WALLS = [
    ('floor', rough, (-0.05, -0.05, -0.01), (0.11, 0.11, 0.0)),
    ('low_x0', smooth, (-0.012, -0.012, -0.001), (0.0, 0.072, 0.0125)),
    ('low_x1', smooth, (0.06, -0.012, -0.001), (0.072, 0.072, 0.0125)),
    ('low_y0', smooth, (-0.012, -0.012, -0.001), (0.072, 0.0, 0.0125)),
    ('low_y1', smooth, (-0.012, 0.06, -0.001), (0.072, 0.072, 0.0125)),
    ('up_x0', smooth, (-0.012, -0.012, 0.0125), (0.0, 0.072, 0.09)),
    ('up_x1', smooth, (0.06, -0.012, 0.0125), (0.072, 0.072, 0.09)),
    ('up_y0', smooth, (-0.012, -0.012, 0.0125), (0.072, 0.0, 0.09)),
    ('up_y1', smooth, (-0.012, 0.06, 0.0125), (0.072, 0.072, 0.09)),
    ('top', rough, (PLATE[0][0], PLATE[0][1], surface), (PLATE[1][0], PLATE[1][1], surface + PLATE[1][2] - PLATE[0][2])),
]
wid = {}
for k, (name, m, lo, hi) in enumerate(WALLS):
    c = tuple(0.5 * (lo[d] + hi[d]) for d in range(3))
    e = tuple(0.5 * (hi[d] - lo[d]) for d in range(3))
    wid[name] = O.bodies.append(utils.box(c, e, fixed=True, material=m, mask=1 << (k + 1)))
SHEAR_WALLS = [wid[n] for n in ('up_x0', 'up_x1', 'up_y0', 'up_y1', 'top')]
TOP = wid['top']
X0_UPX0 = O.bodies[wid['up_x0']].state.pos[0]
Z0_TOP = O.bodies[TOP].state.pos[2]
ZCASE_TOP = Z0_TOP - (surface - PLATE[0][2])   # the case's plate position (normal_displacement 0)

frict = MatchMaker(matches=((sand, rough, math.atan(MU_ROUGH)),), algo='min')

O.engines = [
    PyRunner(command='schedule()', iterPeriod=1, initRun=True, label='sched'),
    ForceResetter(),
    InsertionSortCollider([Bo1_Sphere_Aabb(), Bo1_Box_Aabb()]),
    InteractionLoop(
        [Ig2_Sphere_Sphere_ScGeom6D(avoidGranularRatcheting=RATCHET, updateRotations=True),
         Ig2_Box_Sphere_ScGeom6D()],
        [Ip2_CohFrictMat_CohFrictMat_CohFrictPhys(setCohesionNow=False, setCohesionOnNewContacts=False,
                                                  frictAngle=frict)],
        [Law2_ScGeom6D_CohFrictPhys_CohesionMoment(useIncrementalForm=True, always_use_moment_law=True)]),
    PyRunner(command='servo()', iterPeriod=1, initRun=True, label='servoR'),
] + ([PyRunner(command='fdem_roll()', iterPeriod=FDEM_ROLL, initRun=True, label='froll')] if FDEM_ROLL > 0 else []) + [
    NewtonIntegrator(damping=DAMPING, gravity=(0, 0, -G)),
    PyRunner(command='record()', iterPeriod=1, initRun=True, label='rec'),
]
O.dt = DT

rows = []
state = {'vx': 0.0}


def schedule():
    vx = V_SHEAR if O.iter >= CONSOL else 0.0
    if vx != state['vx']:
        state['vx'] = vx
        for b in SHEAR_WALLS[:4]:
            O.bodies[b].state.vel = Vector3(vx, 0, 0)


NS = len(sid)   # grains are bodies 0 .. NS-1, the walls after them


def fdem_roll():
    for i in O.interactions:
        if i.id1 >= NS or i.id2 >= NS or not i.isReal:
            continue
        g, p = i.geom, i.phys
        rbar = 0.5 * (g.refR1 + g.refR2)
        p.kr = BETA_R * rbar * rbar * p.ks
        p.maxRollPl = ETA_R * rbar


def servo():
    vmax = VMAX_SHEAR if O.iter >= CONSOL else VMAX_CONSOL
    cap = vmax * DT
    fz = O.forces.f(TOP)[2]        # the grains push the plate up: +z
    k = 0.0
    for i in O.interactions.withBody(TOP):
        if i.isReal:
            nz = i.geom.normal[2]
            k += i.phys.kn * nz * nz
    missing = SIGMA * AREA - fz    # F0 - F along the axis -z
    dz = GAIN * missing / k if k > 0 else (cap if SIGMA > 0 else 0.0)
    dz = max(-cap, min(cap, dz))
    O.bodies[TOP].state.vel = Vector3(state['vx'], 0, -dz / DT)


def record():
    step = O.iter + 1
    if step % EVERY:
        return
    fx = sum(O.forces.f(b)[0] for b in SHEAR_WALLS)
    sig = O.forces.f(TOP)[2] / AREA
    tau = -fx / AREA
    zt = O.bodies[TOP].state.pos[2]
    rows.append((step, step * DT, O.bodies[wid['up_x0']].state.pos[0] - X0_UPX0, zt - ZCASE_TOP, sig, tau,
                 tau / sig if sig > 0 else 0.0, zt - 0.5 * (PLATE[1][2] - PLATE[0][2]),
                 sum(1 for i in O.interactions.withBody(TOP) if i.isReal)))
    if step % 2000 == 0:
        print('yade_direct_shear: step %d  sigma_n %.1f  tau %.1f  plate z %.6f  (%.0f s)'
              % (step, sig, tau, rows[-1][7], time.time() - T0), flush=True)


# the row at step 0, as fdem's (no forces yet)
rows.append((0, 0.0, 0.0, Z0_TOP - ZCASE_TOP, 0.0, 0.0, 0.0, surface, 0))
T0 = time.time()
print('yade_direct_shear: %d grains from %s, plate face at %.9f m, sigma_n %g Pa, %d + %d steps, '
      'avoidGranularRatcheting %s, fdem rolling values every %d steps' % (len(sid), SPECIMEN, surface, SIGMA, CONSOL, SHEAR, RATCHET, FDEM_ROLL), flush=True)
O.run(CONSOL + SHEAR, True)
with open(os.path.join(OUT, 'lab.csv'), 'w') as out:
    out.write('step,time,shear_displacement,normal_displacement,sigma_n,tau,tau_over_sigma_n,plate_z,plate_contacts\n')
    for r in rows:
        out.write('%d,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%d\n' % r)
print('yade_direct_shear: wrote %s (%d rows, %.0f s, yade %s)' % (os.path.join(OUT, 'lab.csv'), len(rows),
                                                                  time.time() - T0, yade.config.version), flush=True)
