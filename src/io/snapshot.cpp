// Particle snapshots: one parallel-HDF5 file per snapshot plus an XDMF time series.
//
// particles_<step %08lld>.h5:
//   attributes step (int64), time (double)
//   /position, /velocity, /angular_velocity, /displacement (x - x0), /force   N x 3 double
//   /radius N double, /id N int64, /rank N int32, /material N int32
// Each rank writes its owned particles (indices [0, n_owned)) as one block at the offset given
// by an exclusive prefix sum over the ranks, with collective MPI-IO transfers.
//
// particles.xdmf (rewritten by rank 0 after every snapshot, atomically): a Temporal collection
// of Uniform grids, each a Polyvertex topology over the positions of one snapshot, with the
// other datasets as point attributes. Snapshots with no particles are listed as comments only
// (zero-sized DataItems upset some XDMF readers).
#include "io/snapshot.hpp"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <system_error>

#include "io/h5_util.hpp"

namespace fdem {

SnapshotWriter::SnapshotWriter(std::string dir, MPI_Comm comm)
    : dir_(std::move(dir)), comm_(comm) {
  if (dir_.empty()) dir_ = ".";
  xdmf_ = (std::filesystem::path(dir_) / "particles.xdmf").string();
}

std::string SnapshotWriter::file_for(std::int64_t step) const {
  return (std::filesystem::path(dir_) / h5::step_file_name("particles", step)).string();
}

void SnapshotWriter::write(std::int64_t step, double time, const ParticleStore& p) {
  using namespace h5;
  int rank = 0;
  MPI_Comm_rank(comm_, &rank);
  const std::string path = file_for(step);
  const std::size_t n = std::min(p.n_owned, p.size());
  RowRange rows;
  {
    Quiet quiet;
    Handle file = create_parallel(path, comm_);
    Handle dxpl = collective_dxpl(path);
    write_attr<std::int64_t>(file, "step", step, path);
    write_attr<double>(file, "time", time, path);

    rows = row_range(n, comm_);
    write_rows(file, "position", p.x, rows, dxpl, path);
    write_rows(file, "radius", p.r, rows, dxpl, path);
    write_rows(file, "velocity", p.v, rows, dxpl, path);
    write_rows(file, "angular_velocity", p.w, rows, dxpl, path);
    {
      std::vector<Vec3> d(n);
      for (std::size_t i = 0; i < n; ++i) d[i] = p.x[i] - p.x0[i];
      write_rows(file, "displacement", d, rows, dxpl, path);
    }
    write_rows(file, "force", p.f, rows, dxpl, path);
    write_rows(file, "id", p.id, rows, dxpl, path);
    {
      std::vector<std::int32_t> rk(n, static_cast<std::int32_t>(rank));
      write_rows(file, "rank", rk, rows, dxpl, path);
    }
    write_rows(file, "material", p.mat, rows, dxpl, path);
    dxpl.close();
    if (file.close() < 0) fail(path, "cannot close file");
  }

  // Replace an entry of the same step (a restart rewriting a step), keep the list sorted.
  Entry e{step, time, static_cast<std::int64_t>(rows.total), h5::step_file_name("particles", step)};
  auto it = std::find_if(entries_.begin(), entries_.end(),
                         [&](const Entry& x) { return x.step == step; });
  if (it != entries_.end()) *it = e;
  else entries_.push_back(e);
  std::stable_sort(entries_.begin(), entries_.end(),
                   [](const Entry& a, const Entry& b) { return a.step < b.step; });

  h5::on_rank0_or_throw(comm_, [&] { write_xdmf(); }, xdmf_ + ": cannot write the XDMF file");
}

void SnapshotWriter::adopt_existing(std::int64_t max_step) {
  using namespace h5;
  int rank = 0;
  MPI_Comm_rank(comm_, &rank);
  std::vector<Entry> found;
  if (rank == 0) {
    Quiet quiet;
    for (const auto& [s, path] : step_files(dir_, "particles", max_step)) {
      Handle f(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
      if (f.get() < 0) continue;  // unreadable leftovers are simply not listed
      Entry e{s, 0.0, 0, path.filename().string()};
      std::int64_t st = 0;
      if (!read_attr(f, "step", st) || st != s || !read_attr(f, "time", e.time)) continue;
      if (H5Lexists(f, "position", H5P_DEFAULT) <= 0) continue;
      Handle d(H5Dopen2(f, "position", H5P_DEFAULT), H5Dclose);
      if (d.get() < 0) continue;
      Handle sp(H5Dget_space(d), H5Sclose);
      hsize_t dims[2] = {0, 0};
      if (sp.get() < 0 || H5Sget_simple_extent_ndims(sp) != 2 ||
          H5Sget_simple_extent_dims(sp, dims, nullptr) < 0)
        continue;
      e.n = static_cast<std::int64_t>(dims[0]);
      found.push_back(e);
    }
  }
  // Share the list so every rank's entries_ agree.
  long long count = static_cast<long long>(found.size());
  MPI_Bcast(&count, 1, MPI_LONG_LONG, 0, comm_);
  found.resize(static_cast<std::size_t>(count));
  for (Entry& e : found) {
    long long sn[2] = {e.step, e.n};
    MPI_Bcast(sn, 2, MPI_LONG_LONG, 0, comm_);
    MPI_Bcast(&e.time, 1, MPI_DOUBLE, 0, comm_);
    e.step = sn[0];
    e.n = sn[1];
    e.file = h5::step_file_name("particles", e.step);
  }
  for (const Entry& e : found) {
    auto it = std::find_if(entries_.begin(), entries_.end(),
                           [&](const Entry& x) { return x.step == e.step; });
    if (it == entries_.end()) entries_.push_back(e);
  }
  std::stable_sort(entries_.begin(), entries_.end(),
                   [](const Entry& a, const Entry& b) { return a.step < b.step; });
}

void SnapshotWriter::write_xdmf() const {
  std::ostringstream o;
  o << "<?xml version=\"1.0\" ?>\n"
    << "<!DOCTYPE Xdmf SYSTEM \"Xdmf.dtd\" []>\n"
    << "<Xdmf Version=\"3.0\" xmlns:xi=\"http://www.w3.org/2001/XInclude\">\n"
    << "  <Domain>\n"
    << "    <Grid Name=\"particles\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
  struct Attr { const char* name; const char* type; int cols; const char* num; int prec; };
  static const Attr kAttrs[] = {
      {"radius", "Scalar", 1, "Float", 8},
      {"velocity", "Vector", 3, "Float", 8},
      {"angular_velocity", "Vector", 3, "Float", 8},
      {"displacement", "Vector", 3, "Float", 8},
      {"force", "Vector", 3, "Float", 8},
      {"id", "Scalar", 1, "Int", 8},
      {"rank", "Scalar", 1, "Int", 4},
      {"material", "Scalar", 1, "Int", 4},
  };
  for (const Entry& e : entries_) {
    if (e.n <= 0) {
      o << "      <!-- step " << e.step << " (" << e.file << "): no particles -->\n";
      continue;
    }
    const std::string n = std::to_string(e.n);
    o << "      <Grid Name=\"step_" << e.step << "\" GridType=\"Uniform\">\n"
      << "        <Time Value=\"" << h5::exact(e.time) << "\" />\n"
      << "        <Topology TopologyType=\"Polyvertex\" NumberOfElements=\"" << n
      << "\" NodesPerElement=\"1\" />\n"
      << "        <Geometry GeometryType=\"XYZ\">\n"
      << "          <DataItem Dimensions=\"" << n
      << " 3\" NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">" << e.file
      << ":/position</DataItem>\n"
      << "        </Geometry>\n";
    for (const Attr& a : kAttrs) {
      o << "        <Attribute Name=\"" << a.name << "\" AttributeType=\"" << a.type
        << "\" Center=\"Node\">\n"
        << "          <DataItem Dimensions=\"" << n << (a.cols == 3 ? " 3" : "")
        << "\" NumberType=\"" << a.num << "\" Precision=\"" << a.prec
        << "\" Format=\"HDF\">" << e.file << ":/" << a.name << "</DataItem>\n"
        << "        </Attribute>\n";
    }
    o << "      </Grid>\n";
  }
  o << "    </Grid>\n  </Domain>\n</Xdmf>\n";

  h5::write_text_atomically(xdmf_, o.str());
}

}  // namespace fdem
