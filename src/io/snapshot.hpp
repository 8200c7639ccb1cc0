#pragma once
// Particle snapshots: parallel HDF5 (collective writes, one file per snapshot) plus an XDMF
// sidecar (a temporal collection over all snapshots) that ParaView opens as points carrying
// id, radius, velocity, displacement, force, angular velocity and owning rank.
#include <mpi.h>

#include <cstdint>
#include <string>
#include <vector>

#include "dem/particles.hpp"

namespace fdem {

class SnapshotWriter {
 public:
  /// `dir` must exist. Files: dir/particles_<step>.h5 and dir/particles.xdmf.
  SnapshotWriter(std::string dir, MPI_Comm comm);
  /// Collective: write the owned particles of every rank.
  void write(std::int64_t step, double time, const ParticleStore& p);

  /// Collective, for restarts: take over the snapshots already in `dir` with step <= max_step
  /// (rank 0 reads their step/time/count attributes) so that particles.xdmf keeps listing them.
  /// Files of later steps (written after the checkpoint the run restarts from) are ignored and
  /// are overwritten when the run reaches those steps again.
  void adopt_existing(std::int64_t max_step);

  /// Path of the snapshot file of `step`.
  std::string file_for(std::int64_t step) const;
  const std::string& xdmf_path() const { return xdmf_; }

 private:
  void write_xdmf() const;
  std::string dir_;
  std::string xdmf_;
  MPI_Comm comm_;
  struct Entry { std::int64_t step; double time; std::int64_t n; std::string file; };
  std::vector<Entry> entries_;
};

}  // namespace fdem
