#include "io/fe_checkpoint.hpp"

#include <filesystem>

#include "io/errors.hpp"
#include "io/h5_util.hpp"

namespace fdem {

namespace {
constexpr const char* kFormat = "fdem-fe-checkpoint";
constexpr std::int32_t kVersion = 1;
}  // namespace

void write_fe_checkpoint(const std::string& path, MPI_Comm comm, const FeCheckpoint& c) {
  using namespace h5;
  const std::string tmp = path + ".tmp";
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  const fem::FeState& s = c.state;
  const hsize_t dim = static_cast<hsize_t>(c.dim);
  try {
    Quiet quiet;
    Handle file = create_parallel(tmp, comm);
    Handle dxpl = collective_dxpl(tmp);
    write_attr_string(file, "format", kFormat, tmp);
    write_attr<std::int32_t>(file, "version", kVersion, tmp);
    write_attr<std::int64_t>(file, "hold", c.hold, tmp);
    write_attr<std::int32_t>(file, "hold_done", c.hold_done, tmp);
    write_attr<std::int64_t>(file, "step", c.step, tmp);
    write_attr<std::int64_t>(file, "hold_start", c.hold_start, tmp);
    write_attr<std::int32_t>(file, "dim", c.dim, tmp);
    write_attr<double>(file, "damping", s.c_last, tmp);
    write_attr<std::int32_t>(file, "has_prev", s.has_prev, tmp);
    {
      const RowRange rows = row_range(s.node.size(), comm);
      write_rows(file, "node", s.node, rows, dxpl, tmp);
      write_rows<double>(file, "u", s.u.data(), dim, rows, dxpl, tmp);
      write_rows<double>(file, "v", s.v.data(), dim, rows, dxpl, tmp);
      if (s.has_prev) {  // the same on every rank
        write_rows<double>(file, "u_prev", s.u_prev.data(), dim, rows, dxpl, tmp);
        write_rows<double>(file, "f_prev", s.f_prev.data(), dim, rows, dxpl, tmp);
      }
    }
    {
      const RowRange rows = row_range(s.gp_elem.size(), comm);
      write_rows(file, "gp_elem", s.gp_elem, rows, dxpl, tmp);
      write_rows(file, "gp_k", s.gp_k, rows, dxpl, tmp);
      write_rows<double>(file, "gp_data", s.gp_data.data(), 19, rows, dxpl, tmp);
    }
    {
      // Replicated: rank 0's list.
      long long n = static_cast<long long>(s.removed.size());
      MPI_Bcast(&n, 1, MPI_LONG_LONG, 0, comm);
      RowRange rows;
      rows.total = static_cast<hsize_t>(n);
      rows.local = rank == 0 ? rows.total : 0;
      write_rows(file, "removed", s.removed, rows, dxpl, tmp);
    }
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

FeCheckpoint read_fe_checkpoint(const std::string& path) {
  using namespace h5;
  auto bad = [&](const std::string& what) { return InputError(path, 0, what); };
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) throw bad("FE checkpoint file not found");
  Quiet quiet;
  Handle file(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
  if (file.get() < 0) throw bad("not an HDF5 file (cannot open it as an FE checkpoint)");
  std::string format;
  if (!read_attr_string(file, "format", format) || format != kFormat)
    throw bad("not an fdem FE checkpoint (attribute format is not \"" + std::string(kFormat) + "\")");
  std::int32_t version = 0;
  if (!read_attr(file, "version", version) || version != kVersion) throw bad("unsupported FE checkpoint version");
  FeCheckpoint c;
  if (!read_attr(file, "hold", c.hold) || !read_attr(file, "hold_done", c.hold_done) ||
      !read_attr(file, "step", c.step) || !read_attr(file, "dim", c.dim) ||
      !read_attr(file, "damping", c.state.c_last))
    throw bad("FE checkpoint lacks its hold/step/dim/damping attributes");
  if (!read_attr(file, "hold_start", c.hold_start)) c.hold_start = -1;  // optional (older checkpoints lack it)
  auto need = [&](const std::string& e) { if (!e.empty()) throw bad(e); };
  hsize_t n = 0, k = 0;
  fem::FeState& s = c.state;
  need(read_rows(file.get(), "node", 1, s.node, n));
  need(read_rows(file.get(), "u", static_cast<hsize_t>(c.dim), s.u, k));
  if (k != n) throw bad("dataset u does not match node");
  need(read_rows(file.get(), "v", static_cast<hsize_t>(c.dim), s.v, k));
  if (k != n) throw bad("dataset v does not match node");
  if (read_attr(file, "has_prev", s.has_prev) && s.has_prev) {  // optional (older checkpoints lack it)
    need(read_rows(file.get(), "u_prev", static_cast<hsize_t>(c.dim), s.u_prev, k));
    if (k != n) throw bad("dataset u_prev does not match node");
    need(read_rows(file.get(), "f_prev", static_cast<hsize_t>(c.dim), s.f_prev, k));
    if (k != n) throw bad("dataset f_prev does not match node");
  }
  need(read_rows(file.get(), "gp_elem", 1, s.gp_elem, n));
  need(read_rows(file.get(), "gp_k", 1, s.gp_k, k));
  if (k != n) throw bad("dataset gp_k does not match gp_elem");
  need(read_rows(file.get(), "gp_data", 19, s.gp_data, k));
  if (k != n) throw bad("dataset gp_data does not match gp_elem");
  need(read_rows(file.get(), "removed", 1, s.removed, n));
  return c;
}

}  // namespace fdem
