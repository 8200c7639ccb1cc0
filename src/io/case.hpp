#pragma once
// CaseConfig: everything a case file (YAML) says, validated, in SI units.
// Filled by read_case() (io/case_file.hpp); docs/case-format.md documents every key.
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "dem/material.hpp"
#include "dem/vec3.hpp"

namespace fdem {

/// A particle size distribution. Sizes are DIAMETERS in the case file (as sieve curves are),
/// stored here as diameters too; the generator halves them.
struct SizeDistribution {
  enum Kind { kConstant, kUniform, kNormal, kSieve } kind = kConstant;
  double d = 0;                    // constant: diameter
  double dmin = 0, dmax = 0;       // uniform: bounds; normal/sieve: optional truncation (0: none)
  double mean = 0, sd = 0;         // normal
  std::vector<double> sieve_d;     // sieve: sieve sizes (ascending), m
  std::vector<double> passing;     // sieve: mass % passing at each size (ascending, last 100)
  double scale = 1.0;              // up-scaling factor applied to every diameter
};

/// One entry of the `particles` list.
struct ParticleSource {
  enum Kind { kInline, kGenerate, kFile } kind = kInline;
  int material = -1;
  std::string source_file;  // the case file this entry came from (for errors)
  int line = 0;             // its line in the case file
  // inline
  struct Sphere { std::int64_t id = -1; Vec3 x; double r = 0; Vec3 v; };
  std::vector<Sphere> spheres;
  // generate: a non-overlapping random cloud in an axis-aligned box
  Vec3 box_min, box_max;
  std::int64_t count = 0;      // number of particles (0: fill to `porosity`)
  double porosity = 0;         // target porosity of the cloud when count is 0
  SizeDistribution size;
  std::uint64_t seed = 1;
  int max_attempts = 100;      // placement attempts per particle before giving up
  Vec3 velocity;               // initial velocity (all sources)
  // file: thesis sphere text format, one "id x y z r" per line ('#' comments)
  std::string path;            // resolved relative to the case file
  double scale = 1.0;          // multiplies coordinates and radii
  Vec3 offset;                 // added to coordinates after scaling
};

/// Prescribed motion of a wall.
struct WallMotion {
  enum Kind { kFixed, kVelocity, kFree } kind = kFixed;
  Vec3 velocity;       // kVelocity: m/s; kFree: initial velocity
  double mass = 0;     // kFree: kg
  std::uint8_t free_dofs = 7;  // kFree: which translations are free (bit 0 x, 1 y, 2 z)
  bool gravity = false;        // kFree: does gravity act on the wall
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

struct CaseConfig {
  std::string file;        // path of the case file as given
  std::string name;        // case name (default: file stem)
  Vec3 domain_min, domain_max;
  Vec3 gravity{0, 0, -9.81};
  // time
  double dt = 0;           // fixed step (s); 0: automatic from the critical step
  double dt_safety = 0.3;  // dt = safety * dt_cr when automatic
  std::int64_t steps = 0;  // number of steps (or from duration)
  double duration = 0;     // simulated time (s); used when steps is 0
  double stop_unbalanced = 0;  // stop early when the unbalanced-force ratio drops below (0: never)
  double damping = 0.2;    // Cundall local damping lambda
  double skin = 0;         // Verlet skin (m); 0: 0.3 * the largest radius... see case-format.md
  std::vector<Material> materials;
  std::vector<PairOverride> interactions;
  std::vector<ParticleSource> particles;
  std::vector<WallConfig> walls;
  std::vector<ConstraintConfig> constraints;
  // output
  std::string out_dir;          // default out/<name>
  std::int64_t snapshot_every = 0;   // steps between particle snapshots (0: first and last)
  std::int64_t history_every = 100;  // steps between CSV history lines
  std::int64_t checkpoint_every = 0; // steps between checkpoints (0: only at the end/signal)
  double progress_interval = 5.0;    // seconds between progress lines
  // restart
  std::string restart_from;     // checkpoint file to start from (particles then come from it)
};

}  // namespace fdem
