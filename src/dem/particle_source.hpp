#pragma once
// The particle sources of a case (a case file's `particles` entries, docs/case-format.md) and
// size distributions, as the generator (dem/generate.hpp) takes them. Plain data; filled by the
// case reader (io/case_file.cpp), embedded in CaseConfig (io/case.hpp).
#include <cstdint>
#include <string>
#include <vector>

#include "base/vec3.hpp"

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
  /// kSequential: one random sequential addition over the whole box (every rank builds it all);
  /// kCells: the box cut into generation cells (dem/generate.hpp GenerationCells), each filled
  /// from its own random stream, so each rank builds only its block of cells.
  enum Placement { kSequential, kCells } placement = kSequential;
  Vec3 velocity;               // initial velocity (all sources)
  // file: thesis sphere text format, one "id x y z r" per line ('#' comments)
  std::string path;            // resolved relative to the case file
  double scale = 1.0;          // multiplies coordinates and radii
  Vec3 offset;                 // added to coordinates after scaling
};

}  // namespace fdem
