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

/// The generation cells of a `placement: cells` source: the box cut into n[0] x n[1] x n[2]
/// equal cells of edge about 20 largest diameters (at least one per axis). Cell c (linear index,
/// x fastest, then y, then z) is filled from its own random stream (seeded from the source's
/// seed and c) with grains whose centres lie at least their radius inside the cell, so no two
/// cells' grains overlap and any block of cells can be built alone: the cloud does not depend on
/// who builds which cell.
struct GenerationCells {
  Vec3 lo, edge;
  int n[3] = {1, 1, 1};
  std::int64_t count() const { return static_cast<std::int64_t>(n[0]) * n[1] * n[2]; }
};
GenerationCells generation_cells(const ParticleSource& src);

/// The particles of `sources` one rank builds when the case has `placement: cells` sources:
/// every other source's (identical on every rank, as build_particles gives them; `everywhere`
/// marks them) and, of each cells source, the particles of this rank's block of cells (cells
/// [C rank / size, C (rank + 1) / size) of its C). Ids are those build_particles gives (the same
/// on any number of ranks). Validated as build_particles does; an error in this rank's cells
/// (a grain that cannot be placed) is thrown on this rank only.
struct ParticleShareRecords {
  std::vector<SphereRecord> records;
  std::vector<char> everywhere;  // per record: 1 = built on every rank (not a cells source)
};
ParticleShareRecords build_particle_share(const std::vector<ParticleSource>& sources, const Vec3& domain_min,
                                          const Vec3& domain_max, int rank, int size);

/// True if any source has `placement: cells`.
bool has_cell_sources(const std::vector<ParticleSource>& sources);

/// Largest diameter a size distribution gives (after the scale); a normal curve without a
/// maximum: mean + 5 sd.
double largest_diameter(const SizeDistribution& s);

/// Draw one diameter from a size distribution (after the up-scaling factor).
double sample_diameter(const SizeDistribution& sd, std::mt19937_64& rng);

/// Read the thesis's sphere text format ("id x y z r" per line, '#' comments, blank lines ok).
/// Throws InputError naming the file and line of a malformed record.
std::vector<SphereRecord> read_sphere_file(const std::string& path, double scale, const Vec3& offset,
                                           int material);

}  // namespace fdem
