#pragma once
// Checkpoint and restart of pure finite-element runs (parallel HDF5): nodal displacements and
// velocities, Gauss-point states, removed elements, the hold and step. Keyed by mesh indices, so a
// checkpoint written on P ranks can be read on any number of ranks.
#include <mpi.h>

#include <cstdint>
#include <string>

#include "fem/fe_state.hpp"
#include "io/checkpoint.hpp"

namespace fdem {

namespace h5 {
struct RowShare;  // io/h5_util.hpp: part k of P of a dataset's rows
}

struct FeCheckpoint {
  std::int64_t hold = 0;       // the hold being run (hold_done = 0) or last finished (1)
  std::int32_t hold_done = 0;
  std::int64_t step = 0;       // steps done in the whole run (relaxation steps; static: one per hold)
  std::int64_t hold_start = -1;  // the step the hold began (relaxation steps; coupled: DEM steps; -1: not recorded)
  std::int32_t dim = 3;
  std::int32_t subcycle = 0;   // coupled: DEM steps per FE step the run used (0: not recorded, pure FE)
  double mass_scaling = 0;     // coupled, fem.mass_scaling auto: the scaling the run chose (0: not recorded)
  fem::FeState state;          // this rank's share when writing; everything (or a RowShare) when read
  std::int64_t node_rows = 0;  // read: the rows of the node and Gauss-point datasets in the file
  std::int64_t gp_rows = 0;
};

/// Collective; written to path.tmp and renamed, so a crash never leaves a broken checkpoint.
void write_fe_checkpoint(const std::string& path, MPI_Comm comm, const FeCheckpoint& local);
/// Collective: a coupled run's checkpoint, the DEM state (write_checkpoint) with the FE state as
/// the group /fe of the same file -- one file, one rename, so the two are always of one step.
void write_coupled_checkpoint(const std::string& path, MPI_Comm comm, const Checkpoint& dem,
                              const FeCheckpoint& fe);
/// True if `path` is a (coupled) DEM checkpoint that holds the FE state (/fe).
bool has_fe_state(const std::string& path);
/// Every rank reads the whole file: an FE checkpoint, or the /fe group of a coupled run's
/// checkpoint.h5. Throws InputError if missing, not an FE checkpoint, of an unsupported format
/// version, truncated or corrupted (checksum mismatch).
FeCheckpoint read_fe_checkpoint(const std::string& path);
/// The same, but only `share` of the node and Gauss-point rows (hyperslabs; node_rows and gp_rows
/// give the files' counts). For a restart on any number of ranks without a rank reading the
/// whole state: read_fe_checkpoint_for (app/fe_driver.hpp) routes the rows to their owners.
FeCheckpoint read_fe_checkpoint(const std::string& path, const h5::RowShare& share);

}  // namespace fdem
