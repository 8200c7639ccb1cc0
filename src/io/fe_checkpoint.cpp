// FE checkpoints (see fe_checkpoint.hpp).
//
// Layout (format "fdem-fe-checkpoint", version 2; version 1, still read, lacks the checksums):
//   attributes: format, version, hold, hold_done, step, hold_start, dim, damping, has_prev, has_check
//   node N int64, u / v (and u_prev / f_prev if has_prev, u_check if has_check) N x dim double,
//   gp_elem G int64, gp_k G int32, gp_data G x 19 double, removed R int64
// A pure FE run writes it at the root of fe_checkpoint.h5; a coupled run writes it as the group
// /fe of its checkpoint.h5 (src/io/checkpoint.cpp), so the DEM and FE states of a coupled run are
// one file, published by one rename: a kill at any moment leaves a consistent pair.
#include "io/fe_checkpoint.hpp"

#include <cmath>
#include <filesystem>

#include "base/errors.hpp"
#include "io/h5_util.hpp"

namespace fdem {

namespace {
constexpr const char* kFormat = "fdem-fe-checkpoint";
constexpr std::int32_t kVersion = 2, kVersionMin = 1;
constexpr const char* kGroup = "fe";  // in a coupled run's checkpoint.h5

/// Collective: the FE state's attributes and datasets at loc (a file or a group).
void write_fe_state(hid_t loc, MPI_Comm comm, const FeCheckpoint& c, hid_t dxpl, const std::string& tmp) {
  using namespace h5;
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  const fem::FeState& s = c.state;
  const hsize_t dim = static_cast<hsize_t>(c.dim);
  constexpr bool ck = true;  // Fletcher32 on every dataset
  write_attr_string(loc, "format", kFormat, tmp);
  write_attr<std::int32_t>(loc, "version", kVersion, tmp);
  write_attr<std::int64_t>(loc, "hold", c.hold, tmp);
  write_attr<std::int32_t>(loc, "hold_done", c.hold_done, tmp);
  write_attr<std::int64_t>(loc, "step", c.step, tmp);
  write_attr<std::int64_t>(loc, "hold_start", c.hold_start, tmp);
  write_attr<std::int32_t>(loc, "dim", c.dim, tmp);
  if (c.subcycle > 0) write_attr<std::int32_t>(loc, "subcycle", c.subcycle, tmp);
  if (c.mass_scaling > 0) write_attr<double>(loc, "mass_scaling", c.mass_scaling, tmp);
  write_attr<double>(loc, "damping", s.c_last, tmp);
  write_attr<std::int32_t>(loc, "has_prev", s.has_prev, tmp);
  write_attr<std::int32_t>(loc, "has_check", s.has_check, tmp);
  {
    const RowRange rows = row_range(s.node.size(), comm);
    write_rows(loc, "node", s.node, rows, dxpl, tmp, ck);
    write_rows<double>(loc, "u", s.u.data(), dim, rows, dxpl, tmp, ck);
    write_rows<double>(loc, "v", s.v.data(), dim, rows, dxpl, tmp, ck);
    if (s.has_prev) {  // the same on every rank
      write_rows<double>(loc, "u_prev", s.u_prev.data(), dim, rows, dxpl, tmp, ck);
      write_rows<double>(loc, "f_prev", s.f_prev.data(), dim, rows, dxpl, tmp, ck);
    }
    if (s.has_check) write_rows<double>(loc, "u_check", s.u_check.data(), dim, rows, dxpl, tmp, ck);  // (as has_prev)
  }
  {
    const RowRange rows = row_range(s.gp_elem.size(), comm);
    write_rows(loc, "gp_elem", s.gp_elem, rows, dxpl, tmp, ck);
    write_rows(loc, "gp_k", s.gp_k, rows, dxpl, tmp, ck);
    write_rows<double>(loc, "gp_data", s.gp_data.data(), 19, rows, dxpl, tmp, ck);
  }
  {
    // Replicated: rank 0's list.
    long long n = static_cast<long long>(s.removed.size());
    MPI_Bcast(&n, 1, MPI_LONG_LONG, 0, comm);
    RowRange rows;
    rows.total = static_cast<hsize_t>(n);
    rows.local = rank == 0 ? rows.total : 0;
    write_rows(loc, "removed", s.removed, rows, dxpl, tmp, ck);
  }
}

/// Reads the FE state: attributes of loc (the file or the group /fe), datasets `prefix` + name
/// below file (prefix "" or "fe/", so messages name the dataset's full path); errors name `path`.
FeCheckpoint read_fe_state(hid_t file, hid_t loc, const std::string& prefix, const std::string& path,
                           const h5::RowShare& share) {
  using namespace h5;
  const std::string where = prefix.empty() ? "" : "/" + prefix.substr(0, prefix.size() - 1) + ": ";
  auto bad = [&](const std::string& what) { return InputError(path, 0, where + what); };
  std::string format;
  if (!read_attr_string(loc, "format", format) || format != kFormat)
    throw bad("not an fdem FE checkpoint (attribute format is not \"" + std::string(kFormat) + "\")");
  std::int32_t version = 0;
  if (!read_attr(loc, "version", version)) throw bad("FE checkpoint has no version attribute");
  if (version < kVersionMin || version > kVersion)
    throw bad("FE checkpoint format version " + std::to_string(version) + ", this fdem reads " +
              std::to_string(kVersionMin) + "-" + std::to_string(kVersion));
  FeCheckpoint c;
  if (!read_attr(loc, "hold", c.hold) || !read_attr(loc, "hold_done", c.hold_done) ||
      !read_attr(loc, "step", c.step) || !read_attr(loc, "dim", c.dim) ||
      !read_attr(loc, "damping", c.state.c_last))
    throw bad("FE checkpoint lacks its hold/step/dim/damping attributes");
  if (c.dim < 1 || c.dim > 6) throw bad("FE checkpoint has " + std::to_string(c.dim) + " dofs per node");
  if (!read_attr(loc, "hold_start", c.hold_start)) c.hold_start = -1;  // optional (older checkpoints lack it)
  if (!read_attr(loc, "subcycle", c.subcycle)) c.subcycle = 0;        // optional (pure FE; older checkpoints)
  if (!read_attr(loc, "mass_scaling", c.mass_scaling)) c.mass_scaling = 0;  // optional (fem.mass_scaling auto only)
  if (c.mass_scaling < 0 || !std::isfinite(c.mass_scaling)) throw bad("FE checkpoint has a bad mass_scaling");
  auto need = [&](const std::string& e) { if (!e.empty()) throw InputError(path, 0, e); };  // e names the dataset
  hsize_t n = 0, k = 0;
  fem::FeState& s = c.state;
  need(read_rows(file, prefix + "node", 1, s.node, n, share));
  c.node_rows = static_cast<std::int64_t>(n);
  need(read_rows(file, prefix + "u", static_cast<hsize_t>(c.dim), s.u, k, share));
  if (k != n) throw bad("dataset u does not match node");
  need(read_rows(file, prefix + "v", static_cast<hsize_t>(c.dim), s.v, k, share));
  if (k != n) throw bad("dataset v does not match node");
  if (read_attr(loc, "has_prev", s.has_prev) && s.has_prev) {  // optional (older checkpoints lack it)
    need(read_rows(file, prefix + "u_prev", static_cast<hsize_t>(c.dim), s.u_prev, k, share));
    if (k != n) throw bad("dataset u_prev does not match node");
    need(read_rows(file, prefix + "f_prev", static_cast<hsize_t>(c.dim), s.f_prev, k, share));
    if (k != n) throw bad("dataset f_prev does not match node");
  }
  if (read_attr(loc, "has_check", s.has_check) && s.has_check) {  // optional (older checkpoints lack it)
    need(read_rows(file, prefix + "u_check", static_cast<hsize_t>(c.dim), s.u_check, k, share));
    if (k != n) throw bad("dataset u_check does not match node");
  }
  need(read_rows(file, prefix + "gp_elem", 1, s.gp_elem, n, share));
  c.gp_rows = static_cast<std::int64_t>(n);
  need(read_rows(file, prefix + "gp_k", 1, s.gp_k, k, share));
  if (k != n) throw bad("dataset gp_k does not match gp_elem");
  need(read_rows(file, prefix + "gp_data", 19, s.gp_data, k, share));
  if (k != n) throw bad("dataset gp_data does not match gp_elem");
  need(read_rows(file, prefix + "removed", 1, s.removed, n));  // (every rank: the whole list)
  return c;
}

/// True if the open file is an fdem (DEM) checkpoint with the group /fe.
bool is_coupled_checkpoint(hid_t file) {
  std::string format;
  return h5::read_attr_string(file, "format", format) && format == "fdem-checkpoint" &&
         H5Lexists(file, kGroup, H5P_DEFAULT) > 0;
}

}  // namespace

void write_fe_checkpoint(const std::string& path, MPI_Comm comm, const FeCheckpoint& c) {
  using namespace h5;
  const std::string tmp = path + ".tmp";
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  try {
    Quiet quiet;
    Handle file = create_parallel(tmp, comm, true);
    Handle dxpl = collective_dxpl(tmp);
    write_fe_state(file, comm, c, dxpl, tmp);
    dxpl.close();
    if (file.close() < 0) fail(tmp, "cannot close file");
  } catch (...) {
    if (rank == 0) {
      std::error_code ec;
      std::filesystem::remove(tmp, ec);
    }
    throw;
  }
  int ok = 1;
  if (rank == 0) {
    std::error_code ec;
    std::filesystem::rename(tmp, path, ec);
    ok = ec ? 0 : 1;
  }
  MPI_Bcast(&ok, 1, MPI_INT, 0, comm);
  if (!ok) throw std::runtime_error(path + ": cannot rename " + tmp + " to the checkpoint name");
}

void write_coupled_checkpoint(const std::string& path, MPI_Comm comm, const Checkpoint& dem, const FeCheckpoint& fe) {
  write_checkpoint(path, comm, dem, [&](std::int64_t file, std::int64_t dxpl, const std::string& tmp) {
    h5::Handle g = h5::create_group(file, kGroup, tmp);
    write_fe_state(g, comm, fe, dxpl, tmp);
  });
}

bool has_fe_state(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) return false;
  h5::Quiet quiet;
  std::string why;
  h5::Handle file = h5::open_read(path, why);
  return file.get() >= 0 && is_coupled_checkpoint(file);
}

FeCheckpoint read_fe_checkpoint(const std::string& path) { return read_fe_checkpoint(path, h5::RowShare{}); }

FeCheckpoint read_fe_checkpoint(const std::string& path, const h5::RowShare& share) {
  using namespace h5;
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) throw InputError(path, 0, "FE checkpoint file not found");
  Quiet quiet;
  std::string why;
  Handle file = open_read(path, why);
  if (file.get() < 0) throw InputError(path, 0, why + " (cannot read it as an FE checkpoint)");
  if (is_coupled_checkpoint(file)) {
    Handle g(H5Gopen2(file, kGroup, H5P_DEFAULT), H5Gclose);
    if (g.get() < 0) throw InputError(path, 0, "cannot open group /fe (the file is corrupted)");
    return read_fe_state(file, g, std::string(kGroup) + "/", path, share);
  }
  return read_fe_state(file, file, "", path, share);
}

}  // namespace fdem
