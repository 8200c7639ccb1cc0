#pragma once
// Checkpoint and restart (parallel HDF5): the full state of a DEM run, contact history included.
// A checkpoint written on P ranks can be read on any number of ranks: read_checkpoint returns
// the whole state on every rank, or each rank's share of the particles and contacts (a
// contiguous block of rows, whatever subdomain they lie in), and the caller keeps what its
// subdomain owns (DemEngine: ParticleInput::kShare routes shares to their owners).
#include <mpi.h>

#include <cstdint>
#include <functional>
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
  ParticleStore particles;             // owned particles only (n_owned == size()); read: all, or the share
  /// Write only: when set, the owned prefix [0, n_owned) of this store is written instead of
  /// `particles` (a running engine's store, not copied; it must outlive the write).
  const ParticleStore* particles_view = nullptr;
  std::int64_t particles_total = 0;    // read: the particles in the file (all ranks' shares)
  std::vector<ContactRecord> contacts;
  std::vector<WallState> walls;
  std::int64_t hold = -1, hold_start = -1;  ///< a run with `holds`: the current hold and its first step (-1: none)
  std::vector<Vec3> wall_start;  ///< a run with `holds`: each wall's displacement when the run began (settlements)
  std::vector<Vec3> wall_check;  ///< `holds.creep`: each wall's displacement at the last convergence check (empty: none)
  /// The step at which each phase of each wall's motion schedule starts, walls in order (empty:
  /// no schedules): a phase that starts `after:` a condition has it once the run decided it.
  std::vector<std::int64_t> phase_from;
};

/// Writes more groups into the open checkpoint file before it is closed and renamed (a coupled
/// run's FE state, src/io/fe_checkpoint.cpp): called collectively with the HDF5 file id, the
/// collective transfer property list and the temporary file's name (for messages).
using CheckpointExtra = std::function<void(std::int64_t file, std::int64_t dxpl, const std::string& tmp)>;

/// Collective. Each rank passes its owned particles and the contact records it is responsible
/// for (each contact written by exactly one rank); walls are replicated (rank 0's are written).
/// Written to path + ".tmp" and renamed to `path` once complete (a kill at any moment leaves the
/// previous checkpoint or the new one, never a partial file, under `path`). Every dataset carries
/// a Fletcher32 checksum, the file's metadata HDF5's own checksums.
void write_checkpoint(const std::string& path, MPI_Comm comm, const Checkpoint& local,
                      const CheckpointExtra& extra = {});

/// What each rank reads of a checkpoint's particles and contacts: all of them, or its share
/// (rank k of P: rows [n k / P, n (k + 1) / P) of every particle and contact dataset; walls and
/// attributes are read whole either way).
enum class ReadPart { kWhole, kShare };

/// Collective. Every rank gets the whole checkpoint, or its share of the rows (`part`). Throws
/// InputError naming the file if it is missing, not an fdem checkpoint, of an unsupported format
/// version, truncated or corrupted (checksum mismatch; a share checks only the rows it reads).
Checkpoint read_checkpoint(const std::string& path, MPI_Comm comm, ReadPart part = ReadPart::kWhole);

/// The checkpoint format versions this fdem reads: 1 (no checksums) and 2 (checksums; written).
constexpr std::int32_t kCheckpointVersionMin = 1, kCheckpointVersion = 2;

}  // namespace fdem
