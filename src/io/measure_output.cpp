#include "io/measure_output.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>

#include "io/h5_util.hpp"

namespace fdem {

MeasureWriter::MeasureWriter(const std::string& dir, const MeasureSpec& spec, MPI_Comm comm, bool append,
                             double keep_up_to)
    : dir_(dir), spec_(spec), comm_(comm) {
  MPI_Comm_rank(comm, &rank_);
  const double keep = append ? keep_up_to : std::numeric_limits<double>::infinity();
  if (!spec.boxes.empty()) {
    csv_ = std::make_unique<CsvWriter>(
        dir + "/measure.csv",
        std::vector<std::string>{"step", "time", "box", "sxx", "syy", "szz", "sxy", "sxz", "syz", "p", "q", "Z",
                                 "Z_mech", "porosity", "fab_xx", "fab_yy", "fab_zz", "fab_xy", "fab_xz", "fab_yz",
                                 "ux", "uy", "uz", "particles", "contacts"},
        comm, append, keep);
    h5::on_rank0_or_throw(
        comm,
        [&] {
          const std::string path = dir + "/measure_boxes.csv";
          std::FILE* f = std::fopen(path.c_str(), "w");
          if (!f) throw std::runtime_error(path + ": cannot write");
          std::fprintf(f, "box,name,min_x,min_y,min_z,max_x,max_y,max_z\n");
          for (std::size_t b = 0; b < spec.boxes.size(); ++b) {
            const MeasureBox& B = spec.boxes[b];
            std::fprintf(f, "%zu,%s,%s,%s,%s,%s,%s,%s\n", b, spec.box_names[b].c_str(), h5::exact(B.lo.x).c_str(),
                         h5::exact(B.lo.y).c_str(), h5::exact(B.lo.z).c_str(), h5::exact(B.hi.x).c_str(), h5::exact(B.hi.y).c_str(),
                         h5::exact(B.hi.z).c_str());
          }
          if (std::fclose(f) != 0) throw std::runtime_error(path + ": cannot write");
        },
        dir + "/measure_boxes.csv: cannot write");
  }
  if (!spec.roses.empty())
    roses_ = std::make_unique<CsvWriter>(
        dir + "/roses.csv",
        std::vector<std::string>{"step", "time", "rose", "bin", "theta_min", "theta_max", "count", "mean_fn"}, comm,
        append, keep);
  if (append && (spec.has_grid || spec.force_network || spec.particle_displacements)) {
    // Keep listing the HDF5 files of the steps up to the restart (rank 0 looks, all agree).
    std::vector<long long> steps;
    if (rank_ == 0) {
      std::error_code ec;
      for (const auto& de : std::filesystem::directory_iterator(dir, ec)) {
        const std::string name = de.path().filename().string();
        long long s = 0;
        if (std::sscanf(name.c_str(), "measure_%lld.h5", &s) == 1 && name == h5::step_file_name("measure", s) && s <= keep_up_to)
          steps.push_back(s);
      }
      std::sort(steps.begin(), steps.end());
    }
    long long n = static_cast<long long>(steps.size());
    MPI_Bcast(&n, 1, MPI_LONG_LONG, 0, comm);
    steps.resize(n);
    MPI_Bcast(steps.data(), static_cast<int>(n), MPI_LONG_LONG, 0, comm);
    for (long long s : steps) {
      Entry e{s, 0.0, 0, h5::step_file_name("measure", s)};
      double ts[2] = {0, 0};
      if (rank_ == 0) {
        h5::Quiet quiet;
        h5::Handle f(H5Fopen((dir + "/" + e.file).c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
        std::int64_t segs = 0;
        if (f.get() >= 0) {
          h5::read_attr(f, "time", ts[0]);
          if (h5::read_attr(f, "segments", segs)) ts[1] = static_cast<double>(segs);
        }
      }
      MPI_Bcast(ts, 2, MPI_DOUBLE, 0, comm);
      e.time = ts[0];
      e.segments = static_cast<std::int64_t>(ts[1]);
      entries_.push_back(e);
    }
  }
}

void MeasureWriter::write(const MeasureResult& r) {
  const double st = static_cast<double>(r.step);
  if (csv_)
    for (std::size_t b = 0; b < r.boxes.size(); ++b) {
      const BoxMeasure& m = r.boxes[b];
      std::vector<double> row{st, r.time, static_cast<double>(b)};
      row.insert(row.end(), m.stress, m.stress + 6);
      row.insert(row.end(), {m.p, m.q, m.z, m.z_mech, m.porosity});
      row.insert(row.end(), m.fabric, m.fabric + 6);
      row.insert(row.end(), m.displacement, m.displacement + 3);
      row.insert(row.end(), {m.particles, m.contacts});
      csv_->row(row);
    }
  if (roses_)
    for (std::size_t k = 0; k < r.rose_count.size(); ++k) {
      const int bins = static_cast<int>(r.rose_count[k].size());
      for (int b = 0; b < bins; ++b) {
        const double c = r.rose_count[k][b];
        roses_->row({st, r.time, static_cast<double>(k), static_cast<double>(b), 180.0 * b / bins,
                     180.0 * (b + 1) / bins, c, c > 0 ? r.rose_fn[k][b] / c : 0.0});
      }
    }
  if (spec_.has_grid || spec_.force_network || spec_.particle_displacements) {
    const std::string file = h5::step_file_name("measure", r.step);
    write_h5(r, file);
    long long segs = static_cast<long long>(r.network.size()), tot = 0;
    MPI_Allreduce(&segs, &tot, 1, MPI_LONG_LONG, MPI_SUM, comm_);
    Entry e{r.step, r.time, tot, file};
    auto it = std::find_if(entries_.begin(), entries_.end(), [&](const Entry& x) { return x.step == r.step; });
    if (it != entries_.end()) *it = e;
    else entries_.push_back(e);
    h5::on_rank0_or_throw(comm_, [&] { write_xdmf(); }, dir_ + ": cannot write the measurement XDMF files");
  }
}

namespace {

/// The /grid group: cell fields, written by rank 0 (every rank holds the same reduced values).
void write_grid_group(hid_t file, const MeasureGrid& G, const MeasureResult& r, int rank, MPI_Comm comm,
                      hid_t dxpl, const std::string& path) {
  using namespace h5;
  Handle g = create_group(file, "grid", path);
  for (int d = 0; d < 3; ++d) {
    const char* on[3] = {"origin_x", "origin_y", "origin_z"};
    const char* sn[3] = {"spacing_x", "spacing_y", "spacing_z"};
    const char* nn[3] = {"nx", "ny", "nz"};
    write_attr<double>(g, on[d], G.lo[d], path);
    write_attr<double>(g, sn[d], G.spacing()[d], path);
    write_attr<std::int64_t>(g, nn[d], G.n[d], path);
  }
  const std::size_t nc = r.cells.size();
  const RowRange rows = row_range(rank == 0 ? nc : 0, comm);
  std::vector<double> s6(rank == 0 ? 6 * nc : 0), f6(s6.size()), u3(rank == 0 ? 3 * nc : 0);
  std::vector<double> pr, q, por, z, zm, np;
  if (rank == 0)
    for (std::size_t c = 0; c < nc; ++c) {
      const BoxMeasure& m = r.cells[c];
      std::copy(m.stress, m.stress + 6, s6.begin() + 6 * c);
      std::copy(m.fabric, m.fabric + 6, f6.begin() + 6 * c);
      std::copy(m.displacement, m.displacement + 3, u3.begin() + 3 * c);
      pr.push_back(m.p); q.push_back(m.q); por.push_back(m.porosity);
      z.push_back(m.z); zm.push_back(m.z_mech); np.push_back(m.particles);
    }
  write_rows<double>(g, "stress", s6.data(), 6, rows, dxpl, path);
  write_rows<double>(g, "fabric", f6.data(), 6, rows, dxpl, path);
  write_rows<double>(g, "displacement", u3.data(), 3, rows, dxpl, path);
  write_rows(g, "pressure", pr, rows, dxpl, path);
  write_rows(g, "deviatoric", q, rows, dxpl, path);
  write_rows(g, "porosity", por, rows, dxpl, path);
  write_rows(g, "coordination", z, rows, dxpl, path);
  write_rows(g, "coordination_mech", zm, rows, dxpl, path);
  write_rows(g, "particles", np, rows, dxpl, path);
}

/// The /force_network group: each rank's segments as two points and a line cell.
void write_force_network_group(hid_t file, const MeasureResult& r, MPI_Comm comm, hid_t dxpl,
                               const std::string& path) {
  using namespace h5;
  Handle g = create_group(file, "force_network", path);
  const std::size_t n = r.network.size();
  const RowRange rows = row_range(n, comm);
  const RowRange prow = row_range(2 * n, comm);
  std::vector<Vec3> pts(2 * n), force(n);
  std::vector<double> fn(n);
  std::vector<std::int64_t> conn(2 * n), ids(2 * n);
  for (std::size_t k = 0; k < n; ++k) {
    const ForceSegment& s = r.network[k];
    pts[2 * k] = s.xa;
    pts[2 * k + 1] = s.xb;
    conn[2 * k] = static_cast<std::int64_t>(prow.offset + 2 * k);
    conn[2 * k + 1] = static_cast<std::int64_t>(prow.offset + 2 * k + 1);
    ids[2 * k] = s.id_a;
    ids[2 * k + 1] = s.id_b;
    fn[k] = s.fn;
    force[k] = s.force;
  }
  write_rows(g, "points", pts, prow, dxpl, path);
  write_rows<std::int64_t>(g, "connectivity", conn.data(), 2, rows, dxpl, path);
  write_rows<std::int64_t>(g, "id", ids.data(), 2, rows, dxpl, path);
  write_rows(g, "fn", fn, rows, dxpl, path);
  write_rows(g, "force", force, rows, dxpl, path);
}

}  // namespace

void MeasureWriter::write_h5(const MeasureResult& r, const std::string& name) {
  using namespace h5;
  const std::string path = dir_ + "/" + name;
  Quiet quiet;
  Handle file = create_parallel(path, comm_);
  Handle dxpl = collective_dxpl(path);
  write_attr<std::int64_t>(file, "step", r.step, path);
  write_attr<double>(file, "time", r.time, path);
  long long segs = static_cast<long long>(r.network.size()), tot = 0;
  MPI_Allreduce(&segs, &tot, 1, MPI_LONG_LONG, MPI_SUM, comm_);
  write_attr<std::int64_t>(file, "segments", tot, path);
  if (spec_.has_grid) write_grid_group(file, spec_.grid, r, rank_, comm_, dxpl, path);
  if (spec_.force_network) write_force_network_group(file, r, comm_, dxpl, path);
  if (spec_.particle_displacements) {
    Handle g = create_group(file, "particles", path);
    const RowRange rows = row_range(r.particle_id.size(), comm_);
    write_rows(g, "id", r.particle_id, rows, dxpl, path);
    write_rows(g, "position", r.particle_x, rows, dxpl, path);
    write_rows(g, "displacement", r.particle_disp, rows, dxpl, path);
  }
  dxpl.close();
  if (file.close() < 0) fail(path, "cannot close file");
}

void MeasureWriter::write_xdmf() const {
  auto head = [](std::ostringstream& o, const char* name) {
    o << "<?xml version=\"1.0\" ?>\n<!DOCTYPE Xdmf SYSTEM \"Xdmf.dtd\" []>\n"
      << "<Xdmf Version=\"3.0\" xmlns:xi=\"http://www.w3.org/2001/XInclude\">\n  <Domain>\n"
      << "    <Grid Name=\"" << name << "\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
  };
  const char* tail = "    </Grid>\n  </Domain>\n</Xdmf>\n";
  if (spec_.has_grid) {
    const MeasureGrid& G = spec_.grid;
    const Vec3 h = G.spacing();
    const std::string cdims = std::to_string(G.n[2]) + " " + std::to_string(G.n[1]) + " " + std::to_string(G.n[0]);
    std::ostringstream o;
    head(o, "measure_grid");
    for (const Entry& e : entries_) {
      o << "      <Grid Name=\"step_" << e.step << "\" GridType=\"Uniform\">\n"
        << "        <Time Value=\"" << h5::exact(e.time) << "\" />\n"
        << "        <Topology TopologyType=\"3DCoRectMesh\" Dimensions=\"" << G.n[2] + 1 << " " << G.n[1] + 1 << " "
        << G.n[0] + 1 << "\" />\n"
        << "        <Geometry GeometryType=\"ORIGIN_DXDYDZ\">\n"
        << "          <DataItem Dimensions=\"3\" NumberType=\"Float\" Precision=\"8\" Format=\"XML\">" << h5::exact(G.lo.z)
        << " " << h5::exact(G.lo.y) << " " << h5::exact(G.lo.x) << "</DataItem>\n"
        << "          <DataItem Dimensions=\"3\" NumberType=\"Float\" Precision=\"8\" Format=\"XML\">" << h5::exact(h.z)
        << " " << h5::exact(h.y) << " " << h5::exact(h.x) << "</DataItem>\n"
        << "        </Geometry>\n";
      struct A { const char* name; const char* type; int cols; };
      static const A attrs[] = {{"stress", "Matrix", 6},      {"fabric", "Matrix", 6},       {"displacement", "Vector", 3},
                                {"pressure", "Scalar", 1},    {"deviatoric", "Scalar", 1},   {"porosity", "Scalar", 1},
                                {"coordination", "Scalar", 1}, {"coordination_mech", "Scalar", 1},
                                {"particles", "Scalar", 1}};
      for (const A& a : attrs)
        o << "        <Attribute Name=\"" << a.name << "\" AttributeType=\"" << a.type << "\" Center=\"Cell\">\n"
          << "          <DataItem Dimensions=\"" << cdims << (a.cols > 1 ? " " + std::to_string(a.cols) : "")
          << "\" NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">" << e.file << ":/grid/" << a.name
          << "</DataItem>\n        </Attribute>\n";
      o << "      </Grid>\n";
    }
    o << tail;
    h5::write_text_atomically(dir_ + "/measure_grid.xdmf", o.str());
  }
  if (spec_.force_network) {
    std::ostringstream o;
    head(o, "force_network");
    for (const Entry& e : entries_) {
      if (e.segments <= 0) {
        o << "      <!-- step " << e.step << " (" << e.file << "): no contacts -->\n";
        continue;
      }
      const std::string n = std::to_string(e.segments), np = std::to_string(2 * e.segments);
      o << "      <Grid Name=\"step_" << e.step << "\" GridType=\"Uniform\">\n"
        << "        <Time Value=\"" << h5::exact(e.time) << "\" />\n"
        << "        <Topology TopologyType=\"Polyline\" NumberOfElements=\"" << n << "\" NodesPerElement=\"2\">\n"
        << "          <DataItem Dimensions=\"" << n << " 2\" NumberType=\"Int\" Precision=\"8\" Format=\"HDF\">"
        << e.file << ":/force_network/connectivity</DataItem>\n        </Topology>\n"
        << "        <Geometry GeometryType=\"XYZ\">\n"
        << "          <DataItem Dimensions=\"" << np << " 3\" NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">"
        << e.file << ":/force_network/points</DataItem>\n        </Geometry>\n"
        << "        <Attribute Name=\"fn\" AttributeType=\"Scalar\" Center=\"Cell\">\n"
        << "          <DataItem Dimensions=\"" << n << "\" NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">" << e.file
        << ":/force_network/fn</DataItem>\n        </Attribute>\n"
        << "        <Attribute Name=\"force\" AttributeType=\"Vector\" Center=\"Cell\">\n"
        << "          <DataItem Dimensions=\"" << n << " 3\" NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">"
        << e.file << ":/force_network/force</DataItem>\n        </Attribute>\n"
        << "      </Grid>\n";
    }
    o << tail;
    h5::write_text_atomically(dir_ + "/force_network.xdmf", o.str());
  }
}

}  // namespace fdem
