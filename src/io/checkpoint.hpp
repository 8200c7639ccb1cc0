#pragma once
// Checkpoint and restart (parallel HDF5): the full state of a DEM run, contact history included.
// A checkpoint written on P ranks can be read on any number of ranks: read_checkpoint returns
// the whole state on every rank and the caller keeps what its subdomain owns.
#include <mpi.h>

#include <cstdint>
#include <string>
#include <vector>

#include "dem/contact_history.hpp"
#include "dem/particles.hpp"

namespace fdem {

/// State of one wall: displacement from its initial position, velocity.
struct WallState {
  Vec3 disp, vel;
};

struct Checkpoint {
  std::int64_t step = 0;
  double time = 0, dt = 0;
  ParticleStore particles;             // owned particles only (n_owned == size())
  std::vector<ContactRecord> contacts;
  std::vector<WallState> walls;
};

/// Collective. Each rank passes its owned particles and the contact records it is responsible
/// for (each contact written by exactly one rank); walls are replicated (rank 0's are written).
void write_checkpoint(const std::string& path, MPI_Comm comm, const Checkpoint& local);

/// Collective. Every rank gets the whole checkpoint. Throws InputError if the file is missing
/// or not an fdem checkpoint.
Checkpoint read_checkpoint(const std::string& path, MPI_Comm comm);

}  // namespace fdem
