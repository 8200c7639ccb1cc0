#pragma once
// A packing's progress in its checkpoint (docs/user-guide.md#making-specimens): after every
// finished layer the packing writes OUT/checkpoint.h5 -- the bed so far as an ordinary DEM
// checkpoint (write_checkpoint) plus the group /packing with what the packer needs to go on:
// layers done, the next particle id, steps so far, whether the structure has joined, and each
// finished layer's report row. A packing stopped by a signal while a layer settles writes the
// same file with the bed as it is and the layer's progress (`layer_in_progress`). `fdem run CASE
// --restart OUT/checkpoint.h5` resumes the packing at the next layer, or in the stopped layer's
// settling at its step, and the specimen it ends with is the one of an uninterrupted packing.
#include <mpi.h>

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "io/checkpoint.hpp"

namespace fdem {

/// Number of values of a finished layer's report row (PackingProgress::layers).
constexpr int kPackingLayerColumns = 17;

struct PackingProgress {
  std::int32_t layers_done = 0;           ///< layers finished (the next one is layers_done + 1)
  std::int32_t layers = 0;                ///< layers of the packing that wrote it (checked on resume)
  std::int64_t next_id = 0;               ///< id of the next generated grain
  std::int64_t steps_total = 0;           ///< packing steps so far
  std::int64_t removed_by_structure = 0;  ///< grains removed where they overlapped the structure
  std::int32_t structure_wall = -1;       ///< index of the structure's first wall once a part has joined, else -1
  std::int32_t case_walls = 0;            ///< the case's own walls (the structure's are after them)
  std::int32_t structure_parts = -1;      ///< parts of the structure joined (-1: not recorded, an older
                                          ///< checkpoint: all of it when structure_wall >= 0)
  double elapsed = 0;                     ///< wall-clock seconds of the packing so far
  std::vector<std::array<double, kPackingLayerColumns>> layer_rows;  ///< one per finished layer

  /// A layer stopped while settling (0: none, the checkpoint is between layers): its index
  /// (layers_done + 1) and what its settling needs to go on as if never stopped.
  std::int32_t layer_in_progress = 0;
  std::int64_t layer_start_step = 0;    ///< the engine's step when the layer's shaking began
  std::int64_t layer_shake_steps = 0;   ///< steps of its shaking (done: a stop is polled while it settles)
  std::int64_t layer_before = 0;        ///< grains before its cloud was added
  double layer_cloud_top = 0;           ///< top of its cloud (m)
  double layer_elapsed = 0;             ///< wall-clock seconds spent in the layer so far
  std::vector<std::array<double, 2>> settle_history;  ///< (steps into the layer, bulk porosity) at each check
};

/// Collective: the packing's checkpoint (the bed's state `dem` and the group /packing), written
/// to path.tmp and renamed (a kill at any moment leaves the previous layer's or this one's).
void write_packing_checkpoint(const std::string& path, MPI_Comm comm, const Checkpoint& dem,
                              const PackingProgress& progress);

/// The packing progress of checkpoint `path`, or nothing if it is not a packing's checkpoint
/// (a run's, or not a checkpoint at all: read_checkpoint says what is wrong with those).
/// Throws InputError naming the file if the group /packing is there but unreadable.
std::optional<PackingProgress> read_packing_progress(const std::string& path);

}  // namespace fdem
