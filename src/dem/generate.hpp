#pragma once
// Building the initial particle set from a case's `particles` sources: inline spheres,
// generated non-overlapping random clouds with a size distribution, and the thesis's sphere
// text format. Deterministic: every rank builds the same list (same seed -> same cloud), so the
// result does not depend on the number of ranks.
#include <cstdint>
#include <limits>
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
///
/// With `files`, each sphere-file source takes `files->records[i]` (this rank's part of the file,
/// read by the caller with read_sphere_file(..., part, ...)) instead of reading the whole file;
/// the caller has checked the explicit ids of every source over every rank (unique) and gives
/// their maximum (app/particle_input.hpp does both).
struct ParticleShareRecords {
  std::vector<SphereRecord> records;  // the sources' records in source order
  std::vector<char> everywhere;  // per record: 1 = built on every rank (not a cells source or a file part)
  std::vector<std::size_t> count;  // per source: its records here
  std::vector<std::vector<std::int64_t>> lines;  // per source: a file source's records' lines
};
struct FileShares {
  std::vector<std::vector<SphereRecord>> records;  // per source: a file source's part (moved out)
  std::vector<std::vector<std::int64_t>> lines;    // their lines in the file (moved out)
  std::int64_t max_explicit_id = -1;               // over every source and rank
};
ParticleShareRecords build_particle_share(const std::vector<ParticleSource>& sources, const Vec3& domain_min,
                                          const Vec3& domain_max, int rank, int size, FileShares* files = nullptr);

/// True if any source has `placement: cells`.
bool has_cell_sources(const std::vector<ParticleSource>& sources);

/// Largest diameter a size distribution gives (after the scale); a normal curve without a
/// maximum: mean + 5 sd.
double largest_diameter(const SizeDistribution& s);

/// Draw one diameter from a size distribution (after the up-scaling factor).
double sample_diameter(const SizeDistribution& sd, std::mt19937_64& rng);

/// Read the thesis's sphere text format ("id x y z r" per line, '#' comments, blank lines ok).
/// Throws InputError naming the file and line of a malformed record, or of a file without spheres.
std::vector<SphereRecord> read_sphere_file(const std::string& path, double scale, const Vec3& offset,
                                           int material);

/// A byte range [begin, end) of a text file that starts and ends at line starts, the number of
/// its first line, and the newlines in it. Part k of n (sphere_file_part) starts at the first
/// line start at or after byte size k / n: the n parts cover the file, each line in exactly one;
/// first_line is 1 there (the caller numbers them: 1 + the newlines of the parts before).
struct FilePart {
  std::uint64_t begin = 0, end = std::numeric_limits<std::uint64_t>::max();
  std::int64_t first_line = 1, newlines = 0;
};
FilePart sphere_file_part(const std::string& path, int part, int parts);

/// The spheres of one part of a sphere file (none is no error here), their lines appended to
/// `lines` if given. Reads only the part's bytes.
std::vector<SphereRecord> read_sphere_file(const std::string& path, double scale, const Vec3& offset, int material,
                                           const FilePart& part, std::vector<std::int64_t>* lines);

}  // namespace fdem
