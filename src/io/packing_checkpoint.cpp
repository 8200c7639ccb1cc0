// A packing's checkpoint (see packing_checkpoint.hpp).
//
// Layout: a DEM checkpoint (checkpoint.cpp) with the group /packing:
//   attributes: format "fdem-packing", version 1, layers_done, layers, next_id, steps_total,
//               removed_by_structure, structure_wall, case_walls, elapsed, structure_parts (optional:
//               absent in checkpoints of fdem before packing.structures)
//   layers  L x 17 double: each finished layer's report row (packing.cpp, LayerInfo)
// Version 2 (written only when a signal stopped a layer while it settled; a checkpoint between
// layers stays version 1, readable by an older fdem): the attributes layer_in_progress,
// layer_start_step, layer_shake_steps, layer_before, layer_cloud_top, layer_elapsed and the
// dataset settle_history, H x 2 double (steps into the layer, bulk porosity at that check).
#include "io/packing_checkpoint.hpp"

#include <filesystem>

#include "base/errors.hpp"
#include "io/h5_util.hpp"

namespace fdem {

namespace {
constexpr const char* kGroup = "packing";
constexpr const char* kFormat = "fdem-packing";
constexpr std::int32_t kVersion = 1;         // between layers
constexpr std::int32_t kVersionInLayer = 2;  // a layer stopped while settling
}  // namespace

void write_packing_checkpoint(const std::string& path, MPI_Comm comm, const Checkpoint& dem,
                              const PackingProgress& p) {
  write_checkpoint(path, comm, dem, [&](std::int64_t file, std::int64_t dxpl, const std::string& tmp) {
    using namespace h5;
    Handle g = create_group(file, kGroup, tmp);
    write_attr_string(g, "format", kFormat, tmp);
    write_attr<std::int32_t>(g, "version", p.layer_in_progress > 0 ? kVersionInLayer : kVersion, tmp);
    write_attr<std::int32_t>(g, "layers_done", p.layers_done, tmp);
    write_attr<std::int32_t>(g, "layers", p.layers, tmp);
    write_attr<std::int64_t>(g, "next_id", p.next_id, tmp);
    write_attr<std::int64_t>(g, "steps_total", p.steps_total, tmp);
    write_attr<std::int64_t>(g, "removed_by_structure", p.removed_by_structure, tmp);
    write_attr<std::int32_t>(g, "structure_wall", p.structure_wall, tmp);
    write_attr<std::int32_t>(g, "case_walls", p.case_walls, tmp);
    write_attr<double>(g, "elapsed", p.elapsed, tmp);
    write_attr<std::int32_t>(g, "structure_parts", p.structure_parts, tmp);
    // the rows are the same on every rank: rank 0 writes them
    int rank = 0;
    MPI_Comm_rank(comm, &rank);
    const std::size_t n = rank == 0 ? p.layer_rows.size() : 0;
    const RowRange rows = row_range(n, comm);
    write_rows<double>(g, "layers", n ? p.layer_rows.front().data() : nullptr, kPackingLayerColumns, rows,
                       static_cast<hid_t>(dxpl), tmp, true);
    if (p.layer_in_progress <= 0) return;
    write_attr<std::int32_t>(g, "layer_in_progress", p.layer_in_progress, tmp);
    write_attr<std::int64_t>(g, "layer_start_step", p.layer_start_step, tmp);
    write_attr<std::int64_t>(g, "layer_shake_steps", p.layer_shake_steps, tmp);
    write_attr<std::int64_t>(g, "layer_before", p.layer_before, tmp);
    write_attr<double>(g, "layer_cloud_top", p.layer_cloud_top, tmp);
    write_attr<double>(g, "layer_elapsed", p.layer_elapsed, tmp);
    const std::size_t nh = rank == 0 ? p.settle_history.size() : 0;
    write_rows<double>(g, "settle_history", nh ? p.settle_history.front().data() : nullptr, 2, row_range(nh, comm),
                       static_cast<hid_t>(dxpl), tmp, true);
  });
}

std::optional<PackingProgress> read_packing_progress(const std::string& path) {
  using namespace h5;
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) return std::nullopt;
  Quiet quiet;
  std::string why;
  Handle file = open_read(path, why);
  if (file.get() < 0 || H5Lexists(file, kGroup, H5P_DEFAULT) <= 0) return std::nullopt;
  Handle g(H5Gopen2(file, kGroup, H5P_DEFAULT), H5Gclose);
  std::string format;
  std::int32_t version = 0;
  if (g.get() < 0 || !read_attr_string(g, "format", format) || format != kFormat)
    throw InputError(path, 0, "group /packing is not an fdem packing's progress (the file is corrupted)");
  if (!read_attr(g, "version", version) || (version != kVersion && version != kVersionInLayer))
    throw InputError(path, 0, "packing progress of version " + std::to_string(version) + "; this fdem reads versions " +
                                  std::to_string(kVersion) + " and " + std::to_string(kVersionInLayer));
  PackingProgress p;
  if (!read_attr(g, "layers_done", p.layers_done) || !read_attr(g, "layers", p.layers) ||
      !read_attr(g, "next_id", p.next_id) || !read_attr(g, "steps_total", p.steps_total) ||
      !read_attr(g, "removed_by_structure", p.removed_by_structure) ||
      !read_attr(g, "structure_wall", p.structure_wall) || !read_attr(g, "case_walls", p.case_walls) ||
      !read_attr(g, "elapsed", p.elapsed))
    throw InputError(path, 0, "group /packing lacks some of its attributes (the file is corrupted)");
  if (H5Aexists(g, "structure_parts") > 0 && !read_attr(g, "structure_parts", p.structure_parts))
    throw InputError(path, 0, "group /packing: attribute structure_parts unreadable (the file is corrupted)");
  std::vector<double> v;
  hsize_t nrows = 0;
  const std::string err = read_rows<double>(g, "layers", kPackingLayerColumns, v, nrows);
  if (!err.empty()) throw InputError(path, 0, "packing progress: " + err);
  if (nrows != static_cast<hsize_t>(p.layers_done) && !(nrows == 0 && p.layers_done == 0))
    throw InputError(path, 0, "packing progress: " + std::to_string(nrows) + " layer rows for " +
                                  std::to_string(p.layers_done) + " finished layers (the file is corrupted)");
  p.layer_rows.resize(nrows);
  for (hsize_t i = 0; i < nrows; ++i)
    for (int j = 0; j < kPackingLayerColumns; ++j) p.layer_rows[i][j] = v[i * kPackingLayerColumns + j];
  if (version == kVersion) return p;
  if (!read_attr(g, "layer_in_progress", p.layer_in_progress) || !read_attr(g, "layer_start_step", p.layer_start_step) ||
      !read_attr(g, "layer_shake_steps", p.layer_shake_steps) || !read_attr(g, "layer_before", p.layer_before) ||
      !read_attr(g, "layer_cloud_top", p.layer_cloud_top) || !read_attr(g, "layer_elapsed", p.layer_elapsed))
    throw InputError(path, 0, "group /packing lacks some of the stopped layer's attributes (the file is corrupted)");
  if (p.layer_in_progress != p.layers_done + 1)
    throw InputError(path, 0, "packing progress: layer " + std::to_string(p.layer_in_progress) + " in progress after " +
                                  std::to_string(p.layers_done) + " finished layers (the file is corrupted)");
  hsize_t nh = 0;
  const std::string herr = read_rows<double>(g, "settle_history", 2, v, nh);
  if (!herr.empty()) throw InputError(path, 0, "packing progress: " + herr);
  p.settle_history.resize(nh);
  for (hsize_t i = 0; i < nh; ++i) p.settle_history[i] = {v[2 * i], v[2 * i + 1]};
  return p;
}

}  // namespace fdem
