// Finite-element snapshots: one parallel-HDF5 file per snapshot plus an XDMF time series.
//
// <prefix>_<step %08lld>.h5:
//   attributes step (int64), time (double)
//   /nodes/coordinates, /nodes/displacement, /nodes/velocity   N x 3 double
//   /nodes/interface_force   N x 3 double: the particles' force on the node through the coupled
//                            interface, N (0 without coupling; a tied node's is its target's)
//   /nodes/id                                                  N int64 (user ids)
//     Node rows are the nodes' indices in the case's meshes (merged in fem.meshes order:
//     structures.json's node_offset + the node's index in its mesh), whatever the number of
//     ranks and the solver's numbering: each rank writes its owned nodes at their rows
//     (one hyperslab if the rank's numbers are one contiguous range, else a union of hyperslabs,
//     one per run of consecutive numbers).
//   /elements/connectivity  single-type mesh: E x nodes_per_element int64 (global node numbers)
//                           mixed mesh: 1-D int64, XDMF "Mixed" layout (type code, then nodes)
//                           Hex20 nodes in XDMF/VTK order (mid-edge nodes re-ordered from Gmsh's)
//   /elements/stress, /elements/strain   E x 6 double (Voigt xx yy zz xy yz xz: the order VTK
//                                        uses for 6-component symmetric tensors; strain shear
//                                        components are engineering strains, as given)
//   /elements/plastic, /elements/material, /elements/active, /elements/rank   E int32
//   /elements/id, /elements/index                                            E int64
//     Elements are written rank by rank (offset = exclusive prefix sum of the local counts);
//     `index` is each element's index in the case's meshes (merged in fem.meshes order:
//     structures.json's element_offset + its index in its mesh): order by it to read the
//     elements mesh by mesh.
// All dataset writes are collective MPI-IO transfers; ranks without nodes or elements take part
// with empty selections.
//
// <prefix>.xdmf (rewritten by rank 0 after every snapshot, atomically): a Temporal collection of
// Uniform grids (Topology Hexahedron / Hexahedron_20 / Quadrilateral / Mixed, Geometry XYZ from
// the reference coordinates, nodal and cell attributes). No deformed geometry is written: in
// ParaView apply "Warp By Vector" with the nodal displacement to see the deformed mesh.
// Snapshots without nodes or elements are listed as comments only. A restarted run first
// re-lists the snapshots on disk up to its checkpoint's step (adopt_existing: entries rebuilt
// from each file's attributes and dataset shapes), so the time series continues across restarts.
#include "io/fe_output.hpp"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <numeric>
#include <sstream>
#include <stdexcept>
#include <system_error>

#include "fem/element_types.hpp"
#include "io/h5_util.hpp"

namespace fdem {

namespace {

// Element types: fem::kElementTraits (node counts, XDMF codes and names), indexed by the type
// codes in FeOutputData::elem_type.
constexpr int kNumTypes = fem::kElemTypeCount;
int type_nodes(int t) { return fem::kElementTraits[t].nodes; }
int type_xdmf(int t) { return fem::kElementTraits[t].xdmf_code; }

const char* xdmf_topology_name(int code) {
  for (const auto& e : fem::kElementTraits)
    if (e.xdmf_code == code) return e.xdmf_name;
  return "Mixed";
}
int xdmf_nodes_per_element(int code) {
  for (const auto& e : fem::kElementTraits)
    if (e.xdmf_code == code) return e.nodes;
  return 0;
}

// The nodal and cell attributes <prefix>.xdmf lists for each snapshot (dataset in the file,
// attribute name, XDMF type and centre, columns, number type and precision).
// `optional`: absent from older files, which are listed without it.
struct XdmfAttr { const char* ds; const char* name; const char* type; const char* center;
                  int cols; const char* num; int prec; bool optional = false; };
constexpr XdmfAttr kXdmfAttrs[] = {
    {"nodes/displacement", "displacement", "Vector", "Node", 3, "Float", 8},
    {"nodes/velocity", "velocity", "Vector", "Node", 3, "Float", 8},
    {"nodes/interface_force", "interface_force", "Vector", "Node", 3, "Float", 8, true},
    {"nodes/id", "id", "Scalar", "Node", 1, "Int", 8},
    {"elements/stress", "stress", "Tensor6", "Cell", 6, "Float", 8},
    {"elements/strain", "strain", "Tensor6", "Cell", 6, "Float", 8},
    {"elements/plastic", "plastic", "Scalar", "Cell", 1, "Int", 4},
    {"elements/material", "material", "Scalar", "Cell", 1, "Int", 4},
    {"elements/active", "active", "Scalar", "Cell", 1, "Int", 4},
    {"elements/rank", "rank", "Scalar", "Cell", 1, "Int", 4},
    {"elements/id", "id", "Scalar", "Cell", 1, "Int", 8},  // cell data, beside the nodes' id
};

/// Shape of dataset `name` below loc (1-D: dims[1] = 0); false if missing, unreadable or of
/// rank other than 1 or 2.
bool dataset_shape(hid_t loc, const std::string& name, hsize_t dims[2]) {
  using namespace h5;
  if (!exists(loc, name)) return false;
  Handle d(H5Dopen2(loc, name.c_str(), H5P_DEFAULT), H5Dclose);
  if (d.get() < 0) return false;
  Handle sp(H5Dget_space(d), H5Sclose);
  if (sp.get() < 0) return false;
  const int nd = H5Sget_simple_extent_ndims(sp);
  dims[0] = dims[1] = 0;
  return (nd == 1 || nd == 2) && H5Sget_simple_extent_dims(sp, dims, nullptr) >= 0;
}

// Hex20: written node k (XDMF/VTK order) is input node kHex20GmshOfVtk[k] (Gmsh order).
// Gmsh mid-edge nodes 8..19: edges (0,1),(0,3),(0,4),(1,2),(1,5),(2,3),(2,6),(3,7),(4,5),(4,7),
// (5,6),(6,7); VTK: (0,1),(1,2),(2,3),(3,0),(4,5),(5,6),(6,7),(7,4),(0,4),(1,5),(2,6),(3,7).
constexpr int kHex20GmshOfVtk[20] = {0, 1, 2,  3, 4,  5,  6,  7,  8,  11,
                                     13, 9, 16, 18, 19, 17, 10, 12, 14, 15};

std::string xml_escape(const std::string& s) {
  std::string o;
  for (char c : s) {
    switch (c) {
      case '&': o += "&amp;"; break;
      case '<': o += "&lt;"; break;
      case '>': o += "&gt;"; break;
      case '"': o += "&quot;"; break;
      default: o += c;
    }
  }
  return o;
}

/// Local consistency checks of the input; "" if fine.
std::string validate(const FeSnapshotData& d) {
  const std::size_t n = d.node_global.size();
  if (d.n_nodes_global < 0) return "negative n_nodes_global";
  if (d.node_id.size() != n || d.coords.size() != 3 * n || d.displacement.size() != 3 * n ||
      d.velocity.size() != 3 * n)
    return "node arrays have inconsistent sizes (" + std::to_string(n) +
           " global numbers: need as many ids and 3 coordinates/displacements/velocities each)";
  for (std::int64_t g : d.node_global)
    if (g < 0 || g >= d.n_nodes_global)
      return "node global number " + std::to_string(g) + " outside [0, " +
             std::to_string(d.n_nodes_global) + ")";
  {
    std::vector<std::int64_t> s(d.node_global);
    std::sort(s.begin(), s.end());
    const auto dup = std::adjacent_find(s.begin(), s.end());
    if (dup != s.end()) return "node global number " + std::to_string(*dup) + " given twice";
  }
  const std::size_t e = d.elem_id.size();
  if (d.elem_type.size() != e || d.elem_offset.size() != e + 1 || d.stress.size() != 6 * e ||
      d.strain.size() != 6 * e || d.plastic.size() != e || d.material.size() != e ||
      d.active.size() != e)
    return "element arrays have inconsistent sizes (" + std::to_string(e) +
           " element ids: need as many types/plastic/material/active, E+1 offsets and 6 "
           "stress/strain values each)";
  if (d.elem_offset[0] != 0 ||
      d.elem_offset[e] != static_cast<std::int64_t>(d.elem_conn.size()))
    return "element offsets do not span the connectivity array";
  for (std::size_t i = 0; i < e; ++i) {
    const int t = d.elem_type[i];
    if (t < 0 || t >= kNumTypes)
      return "element " + std::to_string(d.elem_id[i]) + ": unknown type " + std::to_string(t);
    if (d.elem_offset[i + 1] - d.elem_offset[i] != type_nodes(t))
      return "element " + std::to_string(d.elem_id[i]) + ": " +
             std::to_string(d.elem_offset[i + 1] - d.elem_offset[i]) + " nodes, its type needs " +
             std::to_string(type_nodes(t));
  }
  for (std::int64_t g : d.elem_conn)
    if (g < 0 || g >= d.n_nodes_global)
      return "element connectivity refers to node " + std::to_string(g) + " outside [0, " +
             std::to_string(d.n_nodes_global) + ")";
  return "";
}

/// Collective: create dataset `name` (total x cols, or 1-D if cols == 1) and write this rank's
/// rows (row-major, `cols` values each; row i goes to file row rows_at[i]). The rows need not be
/// sorted or contiguous but must be distinct: the file selection is one hyperslab per run of
/// consecutive row numbers (one in all for a contiguous range).
template <class T>
void write_rows_at(hid_t loc, const char* name, const T* data, hsize_t cols,
                   const std::vector<std::int64_t>& rows_at, hsize_t total, hid_t dxpl,
                   const std::string& path) {
  using namespace h5;
  const int nd = cols > 1 ? 2 : 1;
  const hsize_t fdims[2] = {total, cols};
  Handle fspace(check(H5Screate_simple(nd, fdims, nullptr), path, "H5Screate_simple"), H5Sclose);
  Handle dset(H5Dcreate2(loc, name, Type<T>::file(), fspace, H5P_DEFAULT, H5P_DEFAULT,
                         H5P_DEFAULT), H5Dclose);
  if (dset.get() < 0) fail(path, std::string("cannot create dataset ") + name);
  if (total == 0) return;  // same on every rank: nothing to write
  const std::size_t n = rows_at.size();
  const hsize_t mdims[2] = {std::max<hsize_t>(n, 1), cols};
  Handle mspace(check(H5Screate_simple(nd, mdims, nullptr), path, "H5Screate_simple"), H5Sclose);
  T dummy{};
  const void* buf = data;
  std::vector<T> sorted;
  if (n == 0) {
    check_status(H5Sselect_none(fspace), path, "H5Sselect_none");
    check_status(H5Sselect_none(mspace), path, "H5Sselect_none");
    buf = &dummy;
  } else {
    // A hyperslab (union) is traversed in file order: hand the data over sorted by row.
    std::vector<std::size_t> perm(n);
    std::iota(perm.begin(), perm.end(), std::size_t{0});
    if (!std::is_sorted(rows_at.begin(), rows_at.end())) {
      std::stable_sort(perm.begin(), perm.end(),
                       [&](std::size_t a, std::size_t b) { return rows_at[a] < rows_at[b]; });
      sorted.resize(n * cols);
      for (std::size_t i = 0; i < n; ++i)
        std::copy(data + perm[i] * cols, data + (perm[i] + 1) * cols, sorted.begin() + i * cols);
      buf = sorted.data();
    }
    H5S_seloper_t op = H5S_SELECT_SET;
    std::size_t i = 0;
    while (i < n) {
      std::size_t j = i + 1;
      while (j < n && rows_at[perm[j]] == rows_at[perm[j - 1]] + 1) ++j;
      if (j < n && rows_at[perm[j]] == rows_at[perm[j - 1]])
        fail(path, std::string("dataset ") + name + ": row " + std::to_string(rows_at[perm[j]]) +
                       " given twice");
      const hsize_t start[2] = {static_cast<hsize_t>(rows_at[perm[i]]), 0};
      const hsize_t count[2] = {static_cast<hsize_t>(j - i), cols};
      check_status(H5Sselect_hyperslab(fspace, op, start, nullptr, count, nullptr), path,
                   "H5Sselect_hyperslab");
      op = H5S_SELECT_OR;
      i = j;
    }
  }
  if (H5Dwrite(dset, Type<T>::mem(), mspace, fspace, dxpl, buf) < 0)
    fail(path, std::string("cannot write dataset ") + name);
}

/// Every rank throws, or none; collective.
void validate_collectively(const FeSnapshotData& d, const std::string& path, int rank, MPI_Comm comm) {
  std::string err = validate(d);
  int ok = err.empty() ? 1 : 0, all_ok = 0;
  MPI_Allreduce(&ok, &all_ok, 1, MPI_INT, MPI_MIN, comm);
  if (!all_ok)
    throw std::runtime_error(path + ": invalid FE snapshot data: " +
                             (ok ? std::string("(error on another rank)")
                                 : "rank " + std::to_string(rank) + ": " + err));
  long long nmin = d.n_nodes_global, nmax = d.n_nodes_global;
  long long nloc = static_cast<long long>(d.node_global.size()), nsum = 0;
  MPI_Allreduce(MPI_IN_PLACE, &nmin, 1, MPI_LONG_LONG, MPI_MIN, comm);
  MPI_Allreduce(MPI_IN_PLACE, &nmax, 1, MPI_LONG_LONG, MPI_MAX, comm);
  MPI_Allreduce(&nloc, &nsum, 1, MPI_LONG_LONG, MPI_SUM, comm);
  if (nmin != nmax)
    throw std::runtime_error(path + ": invalid FE snapshot data: ranks disagree on the number "
                             "of nodes (" + std::to_string(nmin) + " vs " +
                             std::to_string(nmax) + ")");
  if (nsum != nmax)
    throw std::runtime_error(path + ": invalid FE snapshot data: the ranks own " +
                             std::to_string(nsum) + " nodes in all, the mesh has " +
                             std::to_string(nmax) + " (each node must be owned once)");
}

/// The topology kind: one XDMF type over all ranks (`single`), or Mixed; collective.
struct Topology {
  bool mixed = false;
  int single = 0;
};

Topology topology_kind(const FeSnapshotData& d, MPI_Comm comm) {
  constexpr int kCodes[3] = {9, 48, 5};  // bit k of `mask`: XDMF type kCodes[k] present
  int mask = 0;
  for (std::int8_t t : d.elem_type)
    mask |= 1 << (std::find(kCodes, kCodes + 3, type_xdmf(t)) - kCodes);
  MPI_Allreduce(MPI_IN_PLACE, &mask, 1, MPI_INT, MPI_BOR, comm);
  int ntypes = 0, single = 0;
  for (int k = 0; k < 3; ++k)
    if (mask & (1 << k)) { ++ntypes; single = kCodes[k]; }
  const bool mixed = ntypes > 1;
  if (ntypes == 0) single = d.dim == 2 ? 5 : 9;  // no elements: an empty dataset of that shape
  return {mixed, single};
}

/// Connectivity as written: Hex20 re-ordered, with type codes when mixed.
std::vector<std::int64_t> written_connectivity(const FeSnapshotData& d, bool mixed) {
  const std::size_t ne = d.elem_id.size();
  std::vector<std::int64_t> conn;
  conn.reserve(d.elem_conn.size() + (mixed ? ne : 0));
  for (std::size_t i = 0; i < ne; ++i) {
    const int t = d.elem_type[i];
    const std::int64_t* c = d.elem_conn.data() + d.elem_offset[i];
    if (mixed) conn.push_back(type_xdmf(t));
    if (type_xdmf(t) == 48)
      for (int k = 0; k < 20; ++k) conn.push_back(c[kHex20GmshOfVtk[k]]);
    else
      conn.insert(conn.end(), c, c + type_nodes(t));
  }
  return conn;
}

void write_node_group(hid_t fh, const FeSnapshotData& d, hsize_t n_nodes, hid_t dxpl, const std::string& path) {
  using namespace h5;
  Handle g = create_group(fh, "nodes", path);
  write_rows_at<double>(g, "coordinates", d.coords.data(), 3, d.node_global, n_nodes, dxpl,
                        path);
  write_rows_at<double>(g, "displacement", d.displacement.data(), 3, d.node_global, n_nodes,
                        dxpl, path);
  write_rows_at<double>(g, "velocity", d.velocity.data(), 3, d.node_global, n_nodes, dxpl,
                        path);
  const std::vector<double> zeros(d.interface_force.empty() ? d.velocity.size() : 0, 0.0);
  write_rows_at<double>(g, "interface_force", d.interface_force.empty() ? zeros.data() : d.interface_force.data(), 3,
                        d.node_global, n_nodes, dxpl, path);
  write_rows_at<std::int64_t>(g, "id", d.node_id.data(), 1, d.node_global, n_nodes, dxpl,
                              path);
}

/// Collective; erows and crows get the rows of the element and connectivity datasets.
void write_element_group(hid_t fh, const FeSnapshotData& d, const std::vector<std::int64_t>& conn,
                         const Topology& topo, int rank, MPI_Comm comm, hid_t dxpl, const std::string& path,
                         h5::RowRange& erows, h5::RowRange& crows) {
  using namespace h5;
  const std::size_t ne = d.elem_id.size();
  Handle g = create_group(fh, "elements", path);
  erows = row_range(ne, comm);
  if (topo.mixed) {
    crows = row_range(conn.size(), comm);
    write_rows<std::int64_t>(g, "connectivity", conn.data(), 1, crows, dxpl, path);
  } else {
    crows = erows;
    write_rows<std::int64_t>(g, "connectivity", conn.data(),
                             static_cast<hsize_t>(xdmf_nodes_per_element(topo.single)), erows,
                             dxpl, path);
    crows.total *= static_cast<hsize_t>(xdmf_nodes_per_element(topo.single));
  }
  write_rows<double>(g, "stress", d.stress.data(), 6, erows, dxpl, path);
  write_rows<double>(g, "strain", d.strain.data(), 6, erows, dxpl, path);
  write_rows(g, "plastic", d.plastic, erows, dxpl, path);
  write_rows(g, "material", d.material, erows, dxpl, path);
  write_rows(g, "active", d.active, erows, dxpl, path);
  write_rows(g, "id", d.elem_id, erows, dxpl, path);
  std::vector<std::int64_t> index = d.elem_index;
  if (index.size() != ne) index.assign(ne, -1);
  write_rows(g, "index", index, erows, dxpl, path);
  std::vector<std::int32_t> rk(ne, static_cast<std::int32_t>(rank));
  write_rows(g, "rank", rk, erows, dxpl, path);
}

}  // namespace

FeSnapshotWriter::FeSnapshotWriter(std::string dir, std::string prefix, MPI_Comm comm)
    : dir_(std::move(dir)), prefix_(std::move(prefix)), comm_(comm) {
  if (dir_.empty()) dir_ = ".";
  if (prefix_.empty()) prefix_ = "fe";
}

void FeSnapshotWriter::write(std::int64_t step, double time, const FeSnapshotData& d) {
  using namespace h5;
  int rank = 0;
  MPI_Comm_rank(comm_, &rank);
  const std::string file = h5::step_file_name(prefix_, step);
  const std::string path = (std::filesystem::path(dir_) / file).string();

  validate_collectively(d, path, rank, comm_);
  const Topology topo = topology_kind(d, comm_);
  const std::vector<std::int64_t> conn = written_connectivity(d, topo.mixed);

  RowRange erows, crows;
  hsize_t n_nodes = static_cast<hsize_t>(d.n_nodes_global);
  {
    Quiet quiet;
    Handle fh = create_parallel(path, comm_);
    Handle dxpl = collective_dxpl(path);
    write_attr<std::int64_t>(fh, "step", step, path);
    write_attr<double>(fh, "time", time, path);
    write_node_group(fh, d, n_nodes, dxpl, path);
    write_element_group(fh, d, conn, topo, rank, comm_, dxpl, path, erows, crows);
    dxpl.close();
    if (fh.close() < 0) fail(path, "cannot close file");
  }

  // Replace an entry of the same step (a restart rewriting a step), keep the list sorted.
  Entry e{step,
          time,
          static_cast<std::int64_t>(n_nodes),
          static_cast<std::int64_t>(erows.total),
          static_cast<std::int64_t>(crows.total),
          topo.mixed,
          topo.mixed ? 0 : topo.single,
          file};
  auto it = std::find_if(entries_.begin(), entries_.end(),
                         [&](const Entry& x) { return x.step == step; });
  if (it != entries_.end()) *it = e;
  else entries_.push_back(e);
  std::stable_sort(entries_.begin(), entries_.end(),
                   [](const Entry& a, const Entry& b) { return a.step < b.step; });

  h5::on_rank0_or_throw(comm_, [&] { write_xdmf(); },
                        (std::filesystem::path(dir_) / (prefix_ + ".xdmf")).string() + ": cannot write the XDMF file");
}

void FeSnapshotWriter::adopt_existing(std::int64_t max_step) {
  using namespace h5;
  int rank = 0;
  MPI_Comm_rank(comm_, &rank);
  std::vector<Entry> found;
  if (rank == 0) {
    Quiet quiet;
    for (const auto& [s, path] : step_files(dir_, prefix_, max_step)) {
      Handle f(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
      if (f.get() < 0) continue;  // unreadable leftovers are simply not listed
      Entry e{s, 0.0, 0, 0, 0, false, 0, path.filename().string()};
      std::int64_t st = 0;
      if (!read_attr(f, "step", st) || st != s || !read_attr(f, "time", e.time)) continue;
      // Nodes: the rows of the coordinates. Elements: those of the ids; the connectivity is
      // E x nodes-per-element for one element type, 1-D (XDMF Mixed layout) for several.
      hsize_t xd[2], cd[2], id[2];
      if (!dataset_shape(f, "nodes/coordinates", xd) || xd[1] != 3 ||
          !dataset_shape(f, "elements/connectivity", cd) || !dataset_shape(f, "elements/id", id) ||
          id[1] != 0)
        continue;
      e.nodes = static_cast<std::int64_t>(xd[0]);
      e.elems = static_cast<std::int64_t>(id[0]);
      if (cd[1] == 0) {
        e.mixed = true;
        e.conn_len = static_cast<std::int64_t>(cd[0]);
        if (e.elems > 0 && e.conn_len <= e.elems) continue;
      } else {
        e.xdmf_type = cd[1] == 8 ? 9 : cd[1] == 20 ? 48 : cd[1] == 4 ? 5 : 0;
        if (e.xdmf_type == 0 || cd[0] != id[0]) continue;
        e.conn_len = static_cast<std::int64_t>(cd[0] * cd[1]);
      }
      bool ok = true;
      for (const XdmfAttr& a : kXdmfAttrs) {
        hsize_t ad[2];
        const hsize_t rows = static_cast<hsize_t>(a.center[0] == 'N' ? e.nodes : e.elems);
        const bool has = dataset_shape(f, a.ds, ad) && ad[0] == rows &&
                         ad[1] == (a.cols > 1 ? static_cast<hsize_t>(a.cols) : 0);
        if (a.optional) e.interface_force = has;
        else ok = ok && has;
      }
      if (ok) found.push_back(e);
    }
  }
  // Share the list so every rank's entries_ agree.
  long long count = static_cast<long long>(found.size());
  MPI_Bcast(&count, 1, MPI_LONG_LONG, 0, comm_);
  found.resize(static_cast<std::size_t>(count));
  for (Entry& e : found) {
    long long v[7] = {e.step, e.nodes, e.elems, e.conn_len, e.mixed ? 1 : 0, e.xdmf_type, e.interface_force ? 1 : 0};
    MPI_Bcast(v, 7, MPI_LONG_LONG, 0, comm_);
    MPI_Bcast(&e.time, 1, MPI_DOUBLE, 0, comm_);
    e.step = v[0];
    e.nodes = v[1];
    e.elems = v[2];
    e.conn_len = v[3];
    e.mixed = v[4] != 0;
    e.xdmf_type = static_cast<int>(v[5]);
    e.interface_force = v[6] != 0;
    e.file = h5::step_file_name(prefix_, e.step);
  }
  for (const Entry& e : found) {
    auto it = std::find_if(entries_.begin(), entries_.end(),
                           [&](const Entry& x) { return x.step == e.step; });
    if (it == entries_.end()) entries_.push_back(e);
  }
  std::stable_sort(entries_.begin(), entries_.end(),
                   [](const Entry& a, const Entry& b) { return a.step < b.step; });
}

void FeSnapshotWriter::write_xdmf() const {
  const std::string xdmf = (std::filesystem::path(dir_) / (prefix_ + ".xdmf")).string();
  std::ostringstream o;
  o << "<?xml version=\"1.0\" ?>\n"
    << "<!DOCTYPE Xdmf SYSTEM \"Xdmf.dtd\" []>\n"
    << "<Xdmf Version=\"3.0\" xmlns:xi=\"http://www.w3.org/2001/XInclude\">\n"
    << "  <Domain>\n"
    << "    <!-- Reference geometry; for the deformed mesh apply ParaView's Warp By Vector with"
       " the nodal displacement. -->\n"
    << "    <Grid Name=\"" << xml_escape(prefix_)
    << "\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
  for (const Entry& e : entries_) {
    const std::string f = xml_escape(e.file);
    if (e.nodes <= 0 || e.elems <= 0) {
      o << "      <!-- step " << e.step << " (" << f << "): " << e.nodes << " nodes, " << e.elems
        << " elements -->\n";
      continue;
    }
    const std::string nn = std::to_string(e.nodes), ne = std::to_string(e.elems);
    o << "      <Grid Name=\"step_" << e.step << "\" GridType=\"Uniform\">\n"
      << "        <Time Value=\"" << h5::exact(e.time) << "\" />\n";
    if (e.mixed) {
      o << "        <Topology TopologyType=\"Mixed\" NumberOfElements=\"" << ne << "\">\n"
        << "          <DataItem Dimensions=\"" << e.conn_len;
    } else {
      o << "        <Topology TopologyType=\"" << xdmf_topology_name(e.xdmf_type)
        << "\" NumberOfElements=\"" << ne << "\">\n"
        << "          <DataItem Dimensions=\"" << ne << " "
        << xdmf_nodes_per_element(e.xdmf_type);
    }
    o << "\" NumberType=\"Int\" Precision=\"8\" Format=\"HDF\">" << f
      << ":/elements/connectivity</DataItem>\n"
      << "        </Topology>\n"
      << "        <Geometry GeometryType=\"XYZ\">\n"
      << "          <DataItem Dimensions=\"" << nn
      << " 3\" NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">" << f
      << ":/nodes/coordinates</DataItem>\n"
      << "        </Geometry>\n";
    for (const XdmfAttr& a : kXdmfAttrs) {
      if (a.optional && !e.interface_force) continue;
      const std::string& n = a.center[0] == 'N' ? nn : ne;
      o << "        <Attribute Name=\"" << a.name << "\" AttributeType=\"" << a.type
        << "\" Center=\"" << a.center << "\">\n"
        << "          <DataItem Dimensions=\"" << n
        << (a.cols > 1 ? " " + std::to_string(a.cols) : std::string()) << "\" NumberType=\""
        << a.num << "\" Precision=\"" << a.prec << "\" Format=\"HDF\">" << f << ":/" << a.ds
        << "</DataItem>\n"
        << "        </Attribute>\n";
    }
    o << "      </Grid>\n";
  }
  o << "    </Grid>\n  </Domain>\n</Xdmf>\n";

  h5::write_text_atomically(xdmf, o.str());
}

}  // namespace fdem
