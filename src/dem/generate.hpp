#pragma once
// Building the initial particle set from a case's `particles` sources: inline spheres,
// generated non-overlapping random clouds with a size distribution, and the thesis's sphere
// text format. Deterministic: every rank builds the same list (same seed -> same cloud), so the
// result does not depend on the number of ranks.
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "base/vec3.hpp"
#include "dem/particle_source.hpp"

namespace fdem {

struct SphereRecord {
  std::int64_t id = -1;
  Vec3 x;
  double r = 0;
  Vec3 v;
  int mat = -1;
};

/// All particles of the sources, validated (positive radii, inside the domain [domain_min,
/// domain_max], unique ids). Throws InputError (file, line of the source entry, what is wrong).
/// (io/case.hpp has the overload taking a CaseConfig.)
std::vector<SphereRecord> build_particles(const std::vector<ParticleSource>& sources, const Vec3& domain_min,
                                          const Vec3& domain_max);

/// Draw one diameter from a size distribution (after the up-scaling factor).
double sample_diameter(const SizeDistribution& sd, std::mt19937_64& rng);

/// Read the thesis's sphere text format ("id x y z r" per line, '#' comments, blank lines ok).
/// Throws InputError naming the file and line of a malformed record.
std::vector<SphereRecord> read_sphere_file(const std::string& path, double scale, const Vec3& offset,
                                           int material);

}  // namespace fdem
