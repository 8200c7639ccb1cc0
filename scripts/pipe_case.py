#!/usr/bin/env python3
"""Write the buried pipe cases (thesis Tran 2013, appendix A, problem 8; docs/cases/pipe.md).

    python3 scripts/pipe_case.py ci|full DIR

writes DIR/VARIANT.yaml and its soil mesh DIR/VARIANT_soil.msh (scripts/pipe_mesh.py).

The model (the thesis prints only the script, l. 8457-8543; everything marked "inferred" is ours):
- Pipe: D 0.15 m (R 0.075 m, the shells' mid-surface), 4-node shells t 4 mm, elastic E 450 MPa,
  nu 0.46, gamma 15 kN/m^3; axis along y through x = 0.4 m, z = 0 (the springline at the
  DE/FE boundary: inferred), over the whole box length in y, its end rings held in y (plane
  strain: inferred).
- Soil below the springline: FE Hex20, Mohr-Coulomb E 20 MPa, nu 0.3, gamma 19 kN/m^3, c 2 kPa,
  phi 0.6 rad = 34.4 deg, psi 0 (kPa and radians inferred: the script gives c = 2, phi = 0.6), from
  z = -0.1 m to 0 with the lower half of the pipe cut out; its bottom fixed, its sides on rollers
  (inferred). The pipe is tied to it at the cut-out's nodes (fem.ties): the pipe is twice as fine
  as the cut-out, and the cut-out's mid-edge nodes lie on the arc, so every node of a cut-out face
  is a pipe node.
- Soil above the springline: grains, NormalInelasticMat E 1e8 Pa, K_T/K_N 0.3 (YADE's poisson),
  frictionAngle 0.65 rad (tan 0.76), rho 2650, no rolling resistance; sizes not printed by the
  thesis: we choose a normal grading, mean 10 mm, sd 2 mm (full) -- 15 grains across the pipe;
  the CI variant doubles them. Packed in layers (0.05 m; CI 0.0625 m) around the pipe, frictionless, to porosity
  0.38 (inferred), struck off level.
- Interface (the soil's top and the pipe): frictionAngle 0.4 rad (tan 0.42), E 1e8: the pair
  takes the smaller friction, 0.42.
- Box x 0-0.8 m, y 0-0.15 m, z -0.1-0.4 m; rigid side walls, frictionless (inferred); no bottom
  wall (the grains rest on the FE soil's top); a rigid top plate, frictionless, servo-controlled:
  the vertical stress raised 0 -> 500 kPa in 50 kPa holds, each held to the combined DEM + FE
  convergence check. DEM damping 0.1 (the script's).
Variants (the grains are never scaled in the thesis-size run):
  ci    x 0.1-0.7 m, grains 20 mm, cover to z 0.25 m, holds 50 and 100 kPa, a coarser mesh
        (N 16 x M 3 soil faces on the cut-out): a test of the machinery, minutes
  full  the thesis's box and holds, grains 10 mm (~50 000), N 32 x M 6: about an hour on 2 ranks
"""
import os
import subprocess
import sys

R = 0.075          # pipe radius (mid-surface)
CX = 0.4           # pipe axis x
W = 0.15           # box length along y = the pipe's
DEPTH = 0.1        # FE soil below the springline

VARIANTS = {
    "ci": dict(x0=0.1, x1=0.7, top=0.25, layers=4, d=0.020, N=16, M=3, radial=2, side=4,
               stresses=[50e3, 100e3], max_steps=60000, check=500, seed=81),
    "full": dict(x0=0.0, x1=0.8, top=0.40, layers=8, d=0.010, N=32, M=6, radial=4, side=8,
                 stresses=[50e3 * k for k in range(1, 11)], max_steps=400000, check=1000, seed=82),
}


def fmt(v):
    return ("%.6f" % v).rstrip("0").rstrip(".") if abs(v) > 1e-12 else "0"


def vec(v):
    return "[" + ", ".join(fmt(x) for x in v) + "]"


def mesh_args(v):
    return ["--x-min", fmt(v["x0"]), "--x-max", fmt(v["x1"]), "--length", fmt(W), "--depth", fmt(DEPTH),
            "--centre-x", fmt(CX), "--radius", fmt(R), "-N", str(v["N"]), "-M", str(v["M"]),
            "--radial", str(v["radial"]), "--side", str(v["side"])]


def case_yaml(name, v):
    x0, x1, top, d = v["x0"], v["x1"], v["top"], v["d"]
    layers = v["layers"]
    # the top plate starts above the last layer's loose cloud (solid fraction 0.3 from porosity 0.38)
    # (plus a layer: the pipe lifts the layers above it, whose solid volumes count the whole section)
    zp = top + (top / layers) * (1 - 0.38) / 0.3 + 0.01
    sd = 0.2 * d
    stresses = ", ".join("%g" % s for s in v["stresses"])
    return f"""# The buried pipe (thesis appendix A, problem 8), variant '{name}': written by
#   python3 scripts/pipe_case.py {name} cases/pipe
# with its soil mesh {name}_soil.msh (scripts/pipe_mesh.py {' '.join(mesh_args(v))}).
# The model, every inferred value and the variants: scripts/pipe_case.py, docs/cases/pipe.md.
# Run: mpirun -n 2 build/fdem run cases/pipe/{name}.yaml --out out/pipe_{name}
#      (scripts/pipe.sh {name}: the run and its report)
name: pipe_{name}
domain: {{min: {vec([x0 - 0.01, -0.01, -DEPTH - 0.01])}, max: {vec([x1 + 0.01, W + 0.01, zp + 0.02])}}}
gravity: [0, 0, -9.81]
time: {{safety: 0.3, steps: 5000000}}   # an upper bound: the run ends with its last hold
damping: 0.1
rolling_law: total   # the thesis's rolling law (eqs 3-7/3-8; its engine: YADE's NormalInelasticity law), docs/case-format.md#rolling-laws
materials:
  - {{name: sand, young: 1.0e8, density: 2650, kt_kn: 0.3, friction: 0.76}}      # tan 0.65 rad
  - {{name: iface, young: 1.0e8, density: 2650, kt_kn: 0.3, friction: 0.4228}}   # tan 0.4 rad
  - {{name: smooth, young: 1.0e8, density: 7850, kt_kn: 0.3, friction: 0.0}}    # walls, plate
walls:
  - {{name: xmin, type: plane, material: smooth, point: {vec([x0, 0, 0])}, normal: [1, 0, 0]}}
  - {{name: xmax, type: plane, material: smooth, point: {vec([x1, 0, 0])}, normal: [-1, 0, 0]}}
  - {{name: ymin, type: plane, material: smooth, point: [0, 0, 0], normal: [0, 1, 0]}}
  - {{name: ymax, type: plane, material: smooth, point: {vec([0, W, 0])}, normal: [0, -1, 0]}}
  # the top plate: placed on the packed surface, then stress-controlled (PressureControlEngine)
  - name: top
    type: box
    material: smooth
    min: {vec([x0, 0, zp])}
    max: {vec([x1, W, zp + 0.01])}
    motion: {{servo: {{stress: {v["stresses"][0]:g}, axis: [0, 0, -1], max_velocity: 0.05, stiffness: 1.0e7}}}}
packing:
  material: sand
  box: {{min: {vec([x0, 0, 0])}, max: {vec([x1, W, top])}}}
  layers: {layers}
  porosity: 0.38
  size: {{distribution: normal, mean: {fmt(d)}, sd: {fmt(sd)}, min: {fmt(d - 2 * sd)}, max: {fmt(d + 2 * sd)}}}
  seed: {v["seed"]}
  friction: 0
  cloud_fraction: 0.3
  settle: {{criterion: porosity, porosity_change: 0.005, max_steps: 50000, check_every: 500}}
  structures:   # the soil's top and the pipe, from the first layer
    - {{mesh: soil, after_layer: 0}}
    - {{mesh: pipe, after_layer: 0}}
  exclude:      # no grain placed inside the pipe
    - {{point: {vec([CX, 0, 0])}, axis: [0, 1, 0], radius: {fmt(R)}}}
  place_on_surface: [top]
  level: true
  final_steps: 1000
fem:
  gravity: true
  # the shells' stable step is ~10x below the grains' (1.2e-6 s vs 1.3e-5 s in the CI variant);
  # dynamic relaxation's static answer does not depend on the mass (docs/case-format.md)
  mass_scaling: 100
  materials:
    - {{name: soil, model: mohr_coulomb, young: 20.0e6, poisson: 0.3, density: 1940, unit_weight: 19000,
       cohesion: 2000, friction_angle: 34.3775, dilation_angle: 0}}   # c 2 kPa, phi 0.6 rad, psi 0
    - {{name: pvc, young: 450.0e6, poisson: 0.46, density: 1530, unit_weight: 15000, thickness: 0.004}}
  meshes:
    - {{name: soil, material: soil, gmsh: {name}_soil.msh}}
    - name: pipe
      material: pvc
      cylinder: {{base: {vec([CX, 0, 0])}, radius: {fmt(R)}, length: {fmt(W)}, divisions: [{2 * v["N"]}, {2 * v["M"]}], axis: y}}
  ties:
    - {{mesh: pipe, to: soil}}   # the lower half shares the cut-out's nodes
  restraints:
    - {{mesh: soil, node_set: bottom, fixed: [x, y, z]}}
    - {{mesh: soil, node_set: xmin, fixed: [x]}}
    - {{mesh: soil, node_set: xmax, fixed: [x]}}
    - {{mesh: soil, node_set: ymin, fixed: [y]}}
    - {{mesh: soil, node_set: ymax, fixed: [y]}}
    - {{mesh: pipe, node_set: start, fixed: [y]}}
    - {{mesh: pipe, node_set: end, fixed: [y]}}
coupling:
  material: iface
  surfaces:
    - {{mesh: soil, face_set: top, name: soil}}
    - {{mesh: pipe, element_set: all, name: pipe}}
  rigid_steps: 2000
  tolerance: 0.01
holds:
  walls:
    - {{wall: top, stress: [{stresses}]}}
  tolerance: 0.01
  check_every: {v["check"]}
  max_steps: {v["max_steps"]}
measure:
  every: 1000000000
  force_network: true
  particle_displacements: true
output:
  history_every: 1000
  snapshot_every: 0
"""


def main():
    if len(sys.argv) != 3 or sys.argv[1] not in VARIANTS:
        sys.exit("usage: scripts/pipe_case.py ci|full DIR")
    name, out = sys.argv[1], sys.argv[2]
    v = VARIANTS[name]
    os.makedirs(out, exist_ok=True)
    with open(os.path.join(out, name + ".yaml"), "w") as f:
        f.write(case_yaml(name, v))
    here = os.path.dirname(os.path.abspath(__file__))
    subprocess.run([sys.executable, os.path.join(here, "pipe_mesh.py"), "-o", os.path.join(out, name + "_soil.msh")]
                   + mesh_args(v), check=True, stdout=subprocess.DEVNULL)


if __name__ == "__main__":
    main()
