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

 private:
  void write_xdmf() const;
  std::string dir_;
  MPI_Comm comm_;
  struct Entry { std::int64_t step; double time; std::int64_t n; std::string file; };
  std::vector<Entry> entries_;
};

}  // namespace fdem
