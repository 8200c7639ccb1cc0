#pragma once
// The particles a rank starts a run with, without any rank holding all of them (issue 20):
// `placement: cells` clouds are built cell block by cell block (dem/generate.hpp), sphere files
// read in byte ranges, one per rank, and every check that needs all the particles -- unique ids,
// the next automatic id, the count of a file, overlapping input particles -- made over the ranks,
// with the messages a 1-rank run gives.
#include <mpi.h>

#include <cstdint>
#include <string>

#include "dem/generate.hpp"
#include "io/case.hpp"

namespace fdem {

/// The message of two input particles that overlap by `ratio` of the smaller radius.
std::string input_overlap_message(std::int64_t id_a, const Vec3& xa, double ra, std::int64_t id_b, const Vec3& xb,
                                  double rb, double ratio);

/// True if the case's particles start shared (each rank its part): a `placement: cells` cloud or
/// a sphere file among its sources.
bool shared_particle_input(const CaseConfig& c);

/// Collective. This rank's records of the case's particles: of a cells cloud, its block of
/// cells; of a sphere file, the lines in its byte range [size k / P, size (k + 1) / P) (cut at line
/// starts); every other source's records with `everywhere` set (the caller keeps them on rank 0).
/// Ids are those of a 1-rank read. Throws the same InputError on every rank for a bad line, a
/// duplicate id, a file without spheres, a particle outside the domain, or two input particles
/// that overlap by more than HealthLimits::kMaxInputOverlap of the smaller radius (naming the
/// later one's file and line).
ParticleShareRecords read_particle_share(const CaseConfig& c, MPI_Comm comm);

}  // namespace fdem
