#pragma once
// CaseConfig: everything a case file (YAML) says, validated, in SI units.
// Filled by read_case() (io/case_file.hpp); docs/case-format.md documents every key.
#include <algorithm>
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "base/vec3.hpp"
#include "dem/generate.hpp"  // SizeDistribution, ParticleSource (the `particles` entries), build_particles
#include "dem/material.hpp"

namespace fdem {

/// A servo-controlled (stress-controlled) wall (docs/case-format.md#servo-walls; the law in
/// dem/walls.hpp ServoParams).
struct ServoConfig {
  double stress = 0;           // sigma0, Pa, compression positive
  bool has_axis = false;
  Vec3 axis;                   // unit direction of compression (planes: default the normal)
  double area = 0;             // m^2; 0: auto (box/facets: projected area)
  std::array<std::string, 4> area_walls;  // area: {between: [[a, b], [c, d]]}: gap(a,b) * gap(c,d)
  std::array<int, 4> area_wall_index{-1, -1, -1, -1};  // resolved after all walls are read
  double gain = 0.5;           // in (0, 1]
  double stiffness = 0;        // N/m; 0: auto (sum of the active contacts' normal stiffnesses)
  double max_velocity = 0;     // m/s, required
  Vec3 velocity;               // prescribed velocity across the axis
};

/// Prescribed motion of a wall.
struct WallMotion {
  enum Kind { kFixed, kVelocity, kFree, kServo } kind = kFixed;
  Vec3 velocity;       // kVelocity: m/s; kFree: initial velocity
  double mass = 0;     // kFree: kg
  std::uint8_t free_dofs = 7;  // kFree: which translations are free (bit 0 x, 1 y, 2 z)
  bool gravity = false;        // kFree: does gravity act on the wall
  ServoConfig servo;           // kServo
  std::int64_t from_step = 0;  // in a motion schedule: the step this motion starts
  // `after:` (a schedule's phase): starts at the first history row where every condition given
  // holds, counted from the previous phase's start, instead of at from_step
  bool after = false;
  double after_unbalanced = 0, after_kinetic = 1e-3, after_servo = 0, after_time = 0;
  std::int64_t after_steps = 0;
  std::string after_stage;  // `after: {stage: name}`: starts with the phase of that name (any wall)
  std::string name;         // a phase's name (`stage` refers to it)
  int line = 0;
};

struct WallConfig {
  enum Kind { kPlane, kBox, kFacets } kind = kPlane;
  std::string name;
  int material = -1;
  int line = 0;
  // plane: a point and the unit normal pointing to the side where the particles are
  Vec3 point, normal;
  // box: solid axis-aligned box (particles outside it touch its faces, edges, corners)
  Vec3 min, max;
  // facets: triangle mesh (vertices, triangles as vertex index triples)
  std::vector<Vec3> vertices;
  std::vector<std::array<int, 3>> triangles;
  WallMotion motion;
  std::vector<WallMotion> schedule;  // `motion` given as a list: phases by from_step (else empty)
  // bands: the force on the wall summed per band of the contacting grains' centres along
  // band_axis, edges band_edges (strictly increasing; empty: no bands)
  Vec3 band_axis;
  std::vector<double> band_edges;
  int node = 0;      // index of its entry in the case file's `walls` list (segments share one)
};

/// A box wall given with `segments: [n1, n2]`: read as n1 * n2 walls <name>_1 ... <name>_n, each
/// its own servo (a loading plate that follows the surface, like the air bags of a pullout box);
/// a `type: container` wall: read as its faces, fixed plane walls facing in.
struct WallGroup {
  std::string name;
  int first = 0, count = 0;  // the segments are walls[first] ... walls[first + count - 1]
  bool container = false;    // a `type: container`: its faces, planes <name>_xmin ... <name>_zmax
};

/// Constraints on particles selected by ids or by a region.
struct ConstraintConfig {
  std::vector<std::int64_t> ids;
  bool has_region = false;
  Vec3 region_min, region_max;
  std::uint8_t blocked = 0;  // Dof bits
  bool has_velocity = false;
  Vec3 velocity;             // prescribed velocity for the blocked translations
  int line = 0;
};

/// Finite elements of a case (key `fem`; docs/case-format.md#fem).
struct FeMaterialConfig {
  std::string name;
  bool mohr_coulomb = false;
  double young = 0, poisson = 0, density = 0, unit_weight = 0;
  double cohesion = 0, friction_deg = 0, dilation_deg = 0;  // Mohr-Coulomb (angles in degrees)
  double hourglass = 0.05;
  double thickness = 0;           // shell4 thickness, m (required for meshes with shells)
  bool nlgeom = false;            // geometrically nonlinear (total Lagrangian); elastic hex8/hex20/quad4
  int line = 0;
};

struct FeMeshConfig {
  enum Kind { kBlock, kGeogrid, kThesis, kGmsh, kCylinder } kind = kBlock;
  std::string name;
  int material = -1;              // index into CaseConfig::fe_materials
  std::string element = "hex8";   // element type name (block, thesis files)
  // block
  Vec3 min, max;
  std::array<int, 3> divisions{1, 1, 1};
  int plate_axis = -1;  // block with element shell4: the direction across the plate
  bool has_void = false;
  Vec3 void_min, void_max;
  // geogrid (fem::GeogridSpec fields)
  double length = 0, width = 0, rib_width = 0, thickness = 0, junction_thickness = 0, clamp_length = 0;
  double clamp_gap = -1;          // < 0: the generator's default
  double side_overhang = 0;       // transverse ribs beyond the outermost longitudinal ribs, m
  int longitudinal_ribs = 0, transverse_ribs = 0, elements_per_rib_width = 1, elements_through_thickness = 1;
  double max_element_length = 0;
  Vec3 origin;
  // cylinder (shell4 pipe along +z from base)
  Vec3 base;
  double radius = 0;
  std::array<int, 2> cyl_divisions{16, 1};  // around, along
  int cyl_axis = 2;                          // 0 x, 1 y, 2 z
  // thesis text files / gmsh
  std::string nodes_file, elements_file, gmsh_file;
  int dim = 3;
  int line = 0;
};

/// A boundary condition on a node set (or on the nodes listed in a thesis-format file).
struct FeNodalConfig {
  int mesh = -1;                  // index into fe_meshes
  std::string node_set;           // or
  bool has_region = false;        // or the nodes inside a box
  Vec3 region_min, region_max;
  std::string file;               // thesis format: restraints "id rx ry rz", loads/displacements "id vx vy vz"
  std::array<bool, 3> fixed{false, false, false};  // restraints
  std::array<bool, 3> fixed_rot{false, false, false};  // restraints of shell rotations
  bool is_pressure = false;       // loads: a pressure on the mesh's shell elements (along their normals)
  double pressure = 0;            // Pa
  Vec3 value;                     // loads: total force over the set (split equally); displacements: per node
  int line = 0;
};

/// fem.ties[]: the nodes of `mesh` (or of its `node_set`) within `tolerance` of a node of `to`
/// become that node (the meshes share it).
struct FeTieConfig {
  int mesh = -1, to = -1;
  std::string node_set;  // empty: every node of `mesh`
  double tolerance = 1e-9;
  int line = 0;
};

struct FeRemovalConfig {
  int mesh = -1;
  std::string element_set;
  int at_hold = 0;                // remove at the start of this hold (0-based)
  int line = 0;
};

struct FeConfig {
  bool present = false;
  bool static_solver = false;     // solver: static (KSP) instead of relaxation
  double damping = -1;            // c (1/s); < 0: adaptive
  double safety = 0.8;            // dt = safety * Gershgorin critical step
  double mass_scaling = 1.0;      // every FE density x this (dynamic relaxation: the static answer keeps)
  bool mass_scaling_auto = false; // `auto`: the smallest scaling whose FE step is the DEM's (coupled runs)
  double tolerance = 1e-4;        // unbalanced-force ratio ending a hold
  std::int64_t max_steps = 1000000;  // per hold
  int check_every = 100;
  bool gravity = false;           // body load unit_weight along the case's gravity direction
  bool distribute = false;        // each rank holds its part of the mesh only (partition/mesh_distribute.hpp)
  std::vector<FeMaterialConfig> materials;
  std::vector<FeMeshConfig> meshes;
  std::vector<FeNodalConfig> restraints, loads, displacements;
  std::vector<double> load_steps, displacement_steps;  // factors per hold
  std::vector<FeRemovalConfig> removals;
  std::vector<FeTieConfig> ties;
  int line = 0;
};

/// One interface surface of the FE-DE coupling (key `coupling.surfaces`; docs/case-format.md#coupling):
/// the faces of `face_set`, or the boundary faces of `element_set`, or (both empty) the whole
/// surface of the mesh.
struct CouplingSurfaceConfig {
  std::string name;               // unique; default: the face set / element set name, or the mesh name
  int mesh = -1;                  // index into fem.meshes
  std::string face_set;           // a face set of that mesh, or
  std::string element_set;        // an element set (its bricks' boundary faces, its shells)
  int material = -1;              // the interface material of this surface (-1: coupling.material)
  int line = 0;
};

/// The FE-DE coupling of a case with particles and finite elements (key `coupling`).
struct CouplingConfig {
  bool present = false;
  int material = -1;              // DEM material (index into CaseConfig::materials) of the interface
  std::vector<CouplingSurfaceConfig> surfaces;
  int subcycle = 0;               // FE step every n DEM steps; 0: automatic
  std::int64_t rigid_steps = 0;   // DEM steps with the structure held rigid
  double tolerance = 0;           // combined convergence tolerance of a hold; 0: fem.tolerance
  double kinetic_ratio = 0;       // a hold also needs the kinetic energy per grain below this x m g d (0: not checked)
  double grain_resultant = 0;     // a hold also needs |sum of the grains' forces + weights| / their weight below this (0: not checked)
  double creep = 0;               // m: an FE part at rest (drift since the last check below this) counts as converged
  double creep_damping = 0;       // > 0: at each check the FE damping is this x the bound tol sum|F| / (M v_creep), at most fem.damping
  std::int64_t ramp_steps = 0;    // DEM steps over which a hold's load/displacement factor moves from the last hold's
  int line = 0;
  /// The interface material of surface i (its own, else `material`).
  int surface_material(std::size_t i) const { return surfaces[i].material >= 0 ? surfaces[i].material : material; }
  /// "'a'" or "'a', 'b'": the names of interface_materials() in `mats`.
  template <class Mats>
  std::string material_names(const Mats& mats) const {
    std::string s;
    for (int m : interface_materials()) s += (s.empty() ? "'" : ", '") + mats[m].name + "'";
    return s;
  }
  /// The interface materials of all surfaces (ascending, unique).
  std::vector<int> interface_materials() const {
    std::vector<int> m;
    for (std::size_t i = 0; i < surfaces.size(); ++i) m.push_back(surface_material(i));
    if (surfaces.empty() && material >= 0) m.push_back(material);
    std::sort(m.begin(), m.end());
    m.erase(std::unique(m.begin(), m.end()), m.end());
    return m;
  }
};

/// Micro-mechanics measurements (key `measure`; docs/case-format.md#measure).
struct MeasureBoxConfig {
  std::string name;
  Vec3 min, max;
  int line = 0;
};
struct MeasureRoseConfig {
  std::string plane;              // "xy", "xz" or "yz"
  int axes[2] = {0, 2};           // the plane's axes (angle from axes[0] towards axes[1])
  int bins = 36;                  // over [0, 180) degrees
};
struct MeasureConfig {
  bool present = false;
  std::int64_t every = 0;         // steps between measurements (> 0)
  std::vector<MeasureBoxConfig> boxes;
  bool has_grid = false;
  Vec3 grid_min, grid_max;
  std::array<int, 3> grid_divisions{1, 1, 1};
  std::vector<MeasureRoseConfig> roses;
  bool force_network = false;     // contact force network segments in measure_<step>.h5
  bool particle_displacements = false;  // per-particle displacements in measure_<step>.h5
  std::int64_t displacement_from = -1;  // step whose positions are the displacement reference (-1: initial)
  int line = 0;
};

/// A laboratory test made of walls (key `lab`; docs/user-guide.md#laboratory-tests): which walls
/// form it, so that lab.csv can report its stresses and strains.
struct LabConfig {
  enum Kind { kNone, kDirectShear, kTriaxial } kind = kNone;
  // direct shear: tau = -sum_w F_w . direction / area over shear_walls (the moving half);
  // sigma_n = -F . axis / area of normal_wall (a servo wall)
  std::vector<int> shear_walls;
  int normal_wall = -1;
  Vec3 direction{1, 0, 0};
  double area = 0;                  // m^2; 0: the normal wall's servo area
  // triaxial: six plane walls xmin, xmax, ymin, ymax, bottom, top (indices into walls)
  std::array<int, 6> box{-1, -1, -1, -1, -1, -1};
  int line = 0;
};

/// Specimen preparation (key `packing`; docs/case-format.md#packing, docs/user-guide.md#making-specimens;
/// the procedure of the thesis, DESIGN.md 4.5). Run by src/app/packing.cpp before the case's own
/// steps (a case with packing and no steps ends after packing).
struct PackingConfig {
  bool present = false;
  enum Method { kLayers, kExpansion } method = kLayers;
  int material = -1;              // particle material (index into materials)
  Vec3 box_min, box_max;          // the specimen's container (inside the walls), m
  int layers = 1;                 // kLayers: number of layers (equal heights)
  double porosity = 0.39;         // target porosity of the final specimen (sizes the clouds)
  SizeDistribution size;
  std::uint64_t seed = 1;         // layer k uses seed + k
  double friction = 0;            // tan(phi) of every contact while packing (restored afterwards)
  bool wall_friction_case = false;  // grain-wall contacts keep the case's friction while packing
  // keep-out cylinders (a shaft, a pile): no cloud grain within r of one
  struct Cylinder {
    Vec3 point, axis;  // a point on the axis, the unit axis
    double radius = 0;
    /// distance of x from the axis
    double axis_distance(const Vec3& x) const {
      const Vec3 d = x - point;
      return norm(d - dot(d, axis) * axis);
    }
  };
  std::vector<Cylinder> exclude;
  double cloud_fraction = 0.2;    // solid fraction of a generated (loose) cloud
  int max_attempts = 1000;        // random placement attempts per particle
  // how each cloud is generated: one sequential addition (every rank builds the whole cloud and
  // keeps its share) or in generation cells (each rank builds only its block: large specimens)
  ParticleSource::Placement placement = ParticleSource::kSequential;
  // lateral shaking of the box: the named walls move together with velocity
  // amplitude * 2 pi f * cos(2 pi f t) along `direction` for `cycles` periods from each layer's start
  std::vector<int> shake_walls;
  double shake_amplitude = 0;     // m
  double shake_frequency = 0;     // Hz
  double shake_cycles = 0;        // periods per layer (0: no shaking)
  Vec3 shake_direction{1, 0, 0};
  // equilibrium of each layer (after the shaking)
  double settle_unbalanced = 0.01;
  double settle_kinetic = 0;      // J per particle; 0: not used
  std::int64_t settle_max_steps = 200000;
  std::int64_t settle_min_steps = 0;
  std::int64_t check_every = 200;
  // what ends a layer (docs/case-format.md#packing): kUnbalanced: the ratio (and settle_kinetic);
  // kPorosity: the bulk porosity changed less than settle_porosity_change over the last
  // settle_window steps with the kinetic energy per grain below settle_kinetic_ratio * m g d
  // (or the ratio criterion, whichever comes first); kAuto: kPorosity when friction == 0
  enum SettleCriterion { kAuto, kUnbalanced, kPorosity } settle_criterion = kAuto;
  double settle_porosity_change = 1e-3;
  std::int64_t settle_window = 0;     // steps; 0: 2 sqrt(d/g) (a grain falls 2 d from rest)
  double settle_kinetic_ratio = 1e-3;
  // kExpansion: growth of the radii from the cloud_fraction cloud to the target porosity
  int expansion_stages = 40;      // radii multiplied by a constant factor at each stage
  std::int64_t stage_steps = 200; // steps of relaxation per stage
  // final settle with the case's friction restored (0: none)
  std::int64_t final_steps = 0;
  // level: grains whose centre lies above box_max.z are removed after the last layer
  bool level = false;
  // report
  double margin = 0;              // interior box: inset from the box's sides and bottom (0: 2 d_max)
  double top_margin = 0;          // interior box: distance below the specimen's surface (0: 3 d_max)
  // structure inserted between layers (coupled cases; designed, see docs/case-format.md#packing)
  int insert_structure_after_layer = 0;  // coupled cases: the structure joins after this layer (0: from the start)
  // per mesh: its interface triangles join after this layer instead (a formation from the start,
  // a grid after the first layer); meshes not listed join after insert_structure_after_layer
  struct StructureJoin {
    int mesh = -1;                 // index in FemConfig::meshes
    int after_layer = 0;
    int line = 0;
  };
  std::vector<StructureJoin> structures;
  // a surcharge layer rained on the finished (levelled) specimen: grains of the packing's sizes
  // in another material (a dense one standing for a uniform pressure, thesis ch. 6)
  struct Surcharge {
    bool present = false;
    int material = -1;             // index in CaseConfig::materials
    double thickness = 0;          // m, at the packing's porosity
    int line = 0;
  } surcharge;
  /// The layer after which mesh `m`'s part of the structure joins.
  int join_layer(int m) const {
    for (const StructureJoin& j : structures)
      if (j.mesh == m) return j.after_layer;
    return insert_structure_after_layer;
  }
  std::string save;               // sphere text file (id x y z r), resolved relative to the case file
  std::string save_file;          // where packing.save was given (case file or "--set ..."), for path errors
  int save_line = 0;              // and its line (0: none)
  std::vector<int> surface_walls; // plane walls (along their normals) and servo boxes (along their
                                  // servo axis) moved onto the specimen after packing
  int line = 0;
};

/// Load holds on walls (`holds`, docs/case-format.md#holds): the servo walls' target stresses
/// change hold by hold; a hold ends when the particles and every held wall have converged.
struct HoldsConfig {
  bool present = false;
  int line = 0;
  struct Wall {
    int wall = -1;                 // index in CaseConfig::walls (a segmented wall: one entry per segment)
    std::vector<double> stress;    // Pa, the target of each hold (a servo wall)
    // a displacement-held wall (a fixed wall moved hold by hold): its displacement along `axis`
    // from the run's start in each hold (m), reached at `velocity` (m/s); empty: a servo wall
    std::vector<double> displacement;
    Vec3 axis;
    double velocity = 0;
    bool moved() const { return !displacement.empty(); }
  };
  std::vector<Wall> walls;
  std::size_t count = 0;           // holds (every wall's list has this length)
  double tolerance = 0.01;         // unbalanced-force ratio and |sigma - target| / target
  std::int64_t check_every = 1000; // steps between convergence checks (counted from the hold's start)
  std::int64_t min_steps = 0;      // a hold runs at least this many steps
  std::int64_t max_steps = 1000000;  // a hold that has not converged ends after this many steps
  int stop_wall = -1;              // the run ends once this wall has moved stop_displacement along its axis
  double stop_displacement = 0;    // m (0: no such stop)
  double creep = 0;                // m: a hold has converged only when every held wall moved less than this
                                   // along its axis since the previous check (0: not checked)
};

struct CaseConfig {
  std::string file;        // path of the case file as given
  std::vector<std::string> overrides;  // the --set overrides applied ("key.path=value")
  std::string resolved_yaml;  // the case file's YAML as run (--set applied), written to case.yaml
  std::string specimen_from;  // --specimen FILE: the packed specimen the run starts from (absolute path)
  std::string name;        // case name (default: file stem)
  Vec3 domain_min, domain_max;
  Vec3 gravity{0, 0, -9.81};
  // time
  double dt = 0;           // fixed step (s); 0: automatic from the critical step
  double dt_safety = 0.3;  // dt = safety * dt_cr when automatic
  std::int64_t steps = 0;  // number of steps (or from duration)
  double duration = 0;     // simulated time (s); used when steps is 0
  double stop_unbalanced = 0;  // stop early when the unbalanced-force ratio drops below (0: never)
  double stop_kinetic_ratio = 1e-3;  // ... and the kinetic energy per grain below this x m g d (0: not checked)
  double damping = 0.2;    // Cundall local damping lambda
  double skin = 0;         // Verlet skin (m); 0: 0.3 * the largest radius... see case-format.md
  std::array<int, 3> grid{0, 0, 0};  // `decomposition.grid`: the process grid; {0,0,0}: auto
  std::pair<std::string, int> grid_at;  // where it was given (file, line)
  std::vector<Material> materials;
  /// Where each material's friction was given (file, line), or its entry when it has none;
  /// ("--set key=value", 0) for an override.
  std::vector<std::pair<std::string, int>> material_at;
  std::vector<PairOverride> interactions;
  ContactModel contact_model = ContactModel::kLinear;  // `contact_model`: of every pair without an `interactions` model
  RollingLaw rolling_law = RollingLaw::kIncremental;   // `rolling_law`: of every material that gives none
  std::vector<ParticleSource> particles;
  std::vector<WallConfig> walls;
  std::vector<std::string> warnings;  // reading's warnings ("--set ...: warning: ..."), printed once by the command line
  std::vector<WallGroup> wall_groups;  // walls split into segments (`segments`)
  std::vector<ConstraintConfig> constraints;
  // output
  std::string out_dir;          // default out/<name>
  std::string out_dir_file;     // where output.dir was given (case file or "--set ..."; empty: default)
  int out_dir_line = 0;         // and its line (0: none)
  std::int64_t snapshot_every = 0;   // steps between particle snapshots (0: first and last)
  std::int64_t history_every = 100;  // steps between CSV history lines
  std::int64_t checkpoint_every = 0; // steps between checkpoints (0: only at the end/signal)
  double progress_interval = 5.0;    // seconds between progress lines
  // restart
  std::string restart_from;     // checkpoint file to start from (particles then come from it)
  std::string restart_file;     // where restart.from was given (case file or "--set ..."), for errors
  int restart_line = 0;         // and its line
  // finite elements
  FeConfig fem;
  // FE-DE coupling (particles + fem)
  CouplingConfig coupling;
  // micro-mechanics measurements
  MeasureConfig measure;
  // laboratory test outputs (lab.csv)
  LabConfig lab;
  // specimen preparation (packing before the run)
  PackingConfig packing;
  // load holds on walls
  HoldsConfig holds;
  bool has_particles() const { return !particles.empty() || !restart_from.empty() || packing.present; }
};

/// All particles of the case (dem/generate.hpp build_particles on its sources and domain).
inline std::vector<SphereRecord> build_particles(const CaseConfig& c) {
  return build_particles(c.particles, c.domain_min, c.domain_max);
}

}  // namespace fdem
