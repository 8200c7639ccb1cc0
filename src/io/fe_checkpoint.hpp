#pragma once
// Checkpoint and restart of pure finite-element runs (parallel HDF5): nodal displacements and
// velocities, Gauss-point states, removed elements, the hold and step. Keyed by mesh indices, so a
// checkpoint written on P ranks can be read on any number of ranks.
#include <mpi.h>

#include <cstdint>
#include <string>

#include "fem/fe_model.hpp"

namespace fdem {

struct FeCheckpoint {
  std::int64_t hold = 0;       // the hold being run (hold_done = 0) or last finished (1)
  std::int32_t hold_done = 0;
  std::int64_t step = 0;       // steps done in the whole run (relaxation steps; static: one per hold)
  std::int64_t hold_start = -1;  // the step the hold began (relaxation steps; coupled: DEM steps; -1: not recorded)
  std::int32_t dim = 3;
  fem::FeState state;          // this rank's share when writing; everything when read
};

/// Collective; written to path.tmp and renamed, so a crash never leaves a broken checkpoint.
void write_fe_checkpoint(const std::string& path, MPI_Comm comm, const FeCheckpoint& local);
/// Every rank reads the whole file. Throws InputError if missing or not an FE checkpoint.
FeCheckpoint read_fe_checkpoint(const std::string& path);

}  // namespace fdem
