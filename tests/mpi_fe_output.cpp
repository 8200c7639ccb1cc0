// fdem-test-ranks: 1 2
// FE snapshots: synthetic meshes (a Hex8 block, a mixed Hex8/Hex20/Hex8R/Quad4 mesh, a Hex20
// mesh) are partitioned over the ranks and written twice; rank 0 then reopens the files with
// serial HDF5 and checks every node at its global row, every element's connectivity, fields and
// writing rank, the Hex20 node re-ordering (geometrically: each written mid-edge node must lie
// at the middle of the corresponding XDMF/VTK edge), and the XDMF file (text and XML parse);
// a restarted writer (adopt_existing) writes the XDMF an uninterrupted one would.
#include <gtest/gtest.h>

#include "support/mpi_tempdir.hpp"
#include <hdf5.h>
#include <mpi.h>
#include <unistd.h>

#include <array>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "io/fe_output.hpp"

using namespace fdem;

namespace {

int rank_of() { int r; MPI_Comm_rank(MPI_COMM_WORLD, &r); return r; }
int size_of() { int s; MPI_Comm_size(MPI_COMM_WORLD, &s); return s; }

// TempDir: tests/support/mpi_tempdir.hpp


enum : int { kHex8 = 0, kHex8R = 1, kHex20 = 2, kQuad4 = 3 };
int nodes_of(int t) { return t == kHex20 ? 20 : t == kQuad4 ? 4 : 8; }
int xdmf_code(int t) { return t == kHex20 ? 48 : t == kQuad4 ? 5 : 9; }

// Corner numbering of a brick: 0 (0,0,0) 1 (1,0,0) 2 (1,1,0) 3 (0,1,0), 4..7 the same at z = 1.
const int kCorner[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                           {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
// Mid-edge nodes 8..19 of the 20-node brick, as corner pairs.
const int kGmshEdges[12][2] = {{0, 1}, {0, 3}, {0, 4}, {1, 2}, {1, 5}, {2, 3},
                               {2, 6}, {3, 7}, {4, 5}, {4, 7}, {5, 6}, {6, 7}};
const int kVtkEdges[12][2] = {{0, 1}, {1, 2}, {2, 3}, {3, 0}, {4, 5}, {5, 6},
                              {6, 7}, {7, 4}, {0, 4}, {1, 5}, {2, 6}, {3, 7}};

/// The whole mesh (known to every rank) and its partition.
struct Mesh {
  struct El {
    int type;
    std::vector<int> nodes;  // mesh node indices, Gmsh order
    std::int64_t id;
    int owner = 0;
  };
  std::vector<std::array<double, 3>> X;  // by mesh node index
  std::vector<El> el;
  std::vector<int> node_owner;           // by mesh node index
  std::vector<std::int64_t> gnum;        // mesh node index -> global number
  int dim = 3;

  std::int64_t node_uid(int m) const { return 100 + 7 * m; }
  int n_nodes() const { return static_cast<int>(X.size()); }

  /// Element owners from `owner_of(element index)`; a node belongs to the lowest rank among
  /// its elements; global numbers rank by rank (within a rank: mesh order).
  void partition(const std::function<int(int)>& owner_of) {
    node_owner.assign(X.size(), 1 << 30);
    for (std::size_t e = 0; e < el.size(); ++e) {
      el[e].owner = owner_of(static_cast<int>(e));
      for (int m : el[e].nodes) node_owner[m] = std::min(node_owner[m], el[e].owner);
    }
    for (int& o : node_owner) if (o == 1 << 30) o = 0;
    gnum.assign(X.size(), -1);
    std::int64_t g = 0;
    for (int r = 0; r < size_of(); ++r)
      for (int m = 0; m < n_nodes(); ++m)
        if (node_owner[m] == r) gnum[m] = g++;
  }
};

/// A bx x by x bz block of Hex8 elements (element ids 1000 + e) with coordinates
/// (1.0 ix, 0.5 iy, 2.0 iz) + 0.25.
Mesh hex_block(int bx, int by, int bz) {
  Mesh M;
  auto idx = [&](int i, int j, int k) { return i + (bx + 1) * (j + (by + 1) * k); };
  for (int k = 0; k <= bz; ++k)
    for (int j = 0; j <= by; ++j)
      for (int i = 0; i <= bx; ++i) M.X.push_back({1.0 * i + 0.25, 0.5 * j + 0.25, 2.0 * k + 0.25});
  for (int k = 0; k < bz; ++k)
    for (int j = 0; j < by; ++j)
      for (int i = 0; i < bx; ++i) {
        Mesh::El e{kHex8, {}, 1000 + static_cast<std::int64_t>(M.el.size())};
        for (const auto& c : kCorner) e.nodes.push_back(idx(i + c[0], j + c[1], k + c[2]));
        M.el.push_back(e);
      }
  return M;
}

/// One element per entry of `types`, side by side along x, each with its own nodes
/// (Hex20 nodes in Gmsh order; Quad4 in the z = 0 plane). Element ids 500 + 3 e.
Mesh separate_elements(const std::vector<int>& types) {
  Mesh M;
  for (std::size_t e = 0; e < types.size(); ++e) {
    const double x0 = 3.0 * e;
    Mesh::El el{types[e], {}, 500 + 3 * static_cast<std::int64_t>(e)};
    auto add = [&](double x, double y, double z) {
      el.nodes.push_back(M.n_nodes());
      M.X.push_back({x0 + 1.5 * x, 0.75 * y, 1.25 * z});
    };
    const int corners = types[e] == kQuad4 ? 4 : 8;
    for (int c = 0; c < corners; ++c) add(kCorner[c][0], kCorner[c][1], kCorner[c][2]);
    if (types[e] == kHex20)
      for (const auto& ed : kGmshEdges)
        add(0.5 * (kCorner[ed[0]][0] + kCorner[ed[1]][0]),
            0.5 * (kCorner[ed[0]][1] + kCorner[ed[1]][1]),
            0.5 * (kCorner[ed[0]][2] + kCorner[ed[1]][2]));
    M.el.push_back(el);
  }
  return M;
}

// Field values, derived from global node numbers / element ids and the step.
std::array<double, 3> disp_of(std::int64_t g, int step) {
  return {0.001 * g, -1.0 * g, step + 0.5 * g};
}
std::array<double, 3> vel_of(std::int64_t g, int step) {
  return {1.0 * g, 2.0 * g, 3.0 * g + step};
}
double stress_of(std::int64_t id, int k, int step) { return 10.0 * id + k + 0.5 * step; }
double strain_of(std::int64_t id, int k, int step) { return -(id + 0.1 * k) * 1e-3 - step; }
std::int32_t plastic_of(std::int64_t id) { return static_cast<std::int32_t>(id % 3); }
std::int32_t material_of(std::int64_t id) { return static_cast<std::int32_t>(id % 2 + 1); }
std::int32_t active_of(std::int64_t id) { return id % 5 != 0; }

/// This rank's share. Owned nodes are listed in reverse order if `reverse_nodes`.
FeSnapshotData local_data(const Mesh& M, int step, bool reverse_nodes = false) {
  const int r = rank_of();
  FeSnapshotData d;
  d.dim = M.dim;
  d.n_nodes_global = M.n_nodes();
  std::vector<int> owned;
  for (int m = 0; m < M.n_nodes(); ++m)
    if (M.node_owner[m] == r) owned.push_back(m);
  if (reverse_nodes) std::reverse(owned.begin(), owned.end());
  for (int m : owned) {
    const std::int64_t g = M.gnum[m];
    d.node_global.push_back(g);
    d.node_id.push_back(M.node_uid(m));
    const auto u = disp_of(g, step), v = vel_of(g, step);
    for (int k = 0; k < 3; ++k) {
      d.coords.push_back(M.X[m][k]);
      d.displacement.push_back(u[k]);
      d.velocity.push_back(v[k]);
    }
  }
  for (const Mesh::El& e : M.el) {
    if (e.owner != r) continue;
    d.elem_id.push_back(e.id);
    d.elem_type.push_back(static_cast<std::int8_t>(e.type));
    for (int m : e.nodes) d.elem_conn.push_back(M.gnum[m]);
    d.elem_offset.push_back(static_cast<std::int64_t>(d.elem_conn.size()));
    for (int k = 0; k < 6; ++k) {
      d.stress.push_back(stress_of(e.id, k, step));
      d.strain.push_back(strain_of(e.id, k, step));
    }
    d.plastic.push_back(plastic_of(e.id));
    d.material.push_back(material_of(e.id));
    d.active.push_back(active_of(e.id));
  }
  return d;
}

template <class T>
std::vector<T> read_ds(hid_t f, const char* name, hid_t mtype, std::vector<hsize_t>& dims) {
  dims.clear();
  hid_t d = H5Dopen2(f, name, H5P_DEFAULT);
  EXPECT_GE(d, 0) << name;
  if (d < 0) return {};
  hid_t s = H5Dget_space(d);
  const int nd = H5Sget_simple_extent_ndims(s);
  dims.assign(nd, 0);
  H5Sget_simple_extent_dims(s, dims.data(), nullptr);
  hsize_t n = 1;
  for (hsize_t x : dims) n *= x;
  std::vector<T> out(n);
  if (n) EXPECT_GE(H5Dread(d, mtype, H5S_ALL, H5S_ALL, H5P_DEFAULT, out.data()), 0) << name;
  H5Sclose(s);
  H5Dclose(d);
  return out;
}

/// The connectivity the file must hold for element e: global numbers, Hex20 in VTK order
/// (found geometrically: the Gmsh node at the middle of each VTK edge).
std::vector<std::int64_t> expected_conn(const Mesh& M, const Mesh::El& e) {
  std::vector<std::int64_t> c;
  for (int m : e.nodes) c.push_back(M.gnum[m]);
  if (e.type != kHex20) return c;
  std::vector<std::int64_t> v(c.begin(), c.begin() + 8);
  for (const auto& ve : kVtkEdges) {
    int found = -1;
    for (int k = 0; k < 12; ++k) {
      const auto& ge = kGmshEdges[k];
      if ((ge[0] == ve[0] && ge[1] == ve[1]) || (ge[0] == ve[1] && ge[1] == ve[0])) found = k;
    }
    EXPECT_GE(found, 0);
    v.push_back(c[8 + found]);
  }
  return v;
}

/// Rank 0: checks one snapshot file against the mesh. Returns the connectivity rows as read
/// (per element, type code stripped) in file order.
std::vector<std::vector<std::int64_t>> check_file(const std::string& file, const Mesh& M,
                                                  int step, double time, bool mixed) {
  std::vector<std::vector<std::int64_t>> rows;
  hid_t h = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  EXPECT_GE(h, 0) << file;
  if (h < 0) return rows;
  std::int64_t st = -1;
  double t = -1;
  hid_t a = H5Aopen(h, "step", H5P_DEFAULT);
  H5Aread(a, H5T_NATIVE_INT64, &st);
  H5Aclose(a);
  a = H5Aopen(h, "time", H5P_DEFAULT);
  H5Aread(a, H5T_NATIVE_DOUBLE, &t);
  H5Aclose(a);
  EXPECT_EQ(st, step);
  EXPECT_EQ(t, time);

  const hsize_t N = M.X.size(), E = M.el.size();
  std::vector<hsize_t> dims;
  const auto X = read_ds<double>(h, "/nodes/coordinates", H5T_NATIVE_DOUBLE, dims);
  EXPECT_EQ(dims, (std::vector<hsize_t>{N, 3}));
  const auto U = read_ds<double>(h, "/nodes/displacement", H5T_NATIVE_DOUBLE, dims);
  EXPECT_EQ(dims, (std::vector<hsize_t>{N, 3}));
  const auto V = read_ds<double>(h, "/nodes/velocity", H5T_NATIVE_DOUBLE, dims);
  EXPECT_EQ(dims, (std::vector<hsize_t>{N, 3}));
  const auto NID = read_ds<std::int64_t>(h, "/nodes/id", H5T_NATIVE_INT64, dims);
  EXPECT_EQ(dims, (std::vector<hsize_t>{N}));
  if (X.size() == 3 * N && U.size() == 3 * N && V.size() == 3 * N && NID.size() == N) {
    for (int m = 0; m < M.n_nodes(); ++m) {
      const std::int64_t g = M.gnum[m];
      const auto u = disp_of(g, step), v = vel_of(g, step);
      for (int k = 0; k < 3; ++k) {
        EXPECT_EQ(X[3 * g + k], M.X[m][k]) << "node " << m << " row " << g;
        EXPECT_EQ(U[3 * g + k], u[k]) << "node " << m << " row " << g;
        EXPECT_EQ(V[3 * g + k], v[k]) << "node " << m << " row " << g;
      }
      EXPECT_EQ(NID[g], M.node_uid(m));
    }
  }

  const auto EID = read_ds<std::int64_t>(h, "/elements/id", H5T_NATIVE_INT64, dims);
  EXPECT_EQ(dims, (std::vector<hsize_t>{E}));
  const auto RK = read_ds<std::int32_t>(h, "/elements/rank", H5T_NATIVE_INT32, dims);
  EXPECT_EQ(dims, (std::vector<hsize_t>{E}));
  const auto S = read_ds<double>(h, "/elements/stress", H5T_NATIVE_DOUBLE, dims);
  EXPECT_EQ(dims, (std::vector<hsize_t>{E, 6}));
  const auto EPS = read_ds<double>(h, "/elements/strain", H5T_NATIVE_DOUBLE, dims);
  EXPECT_EQ(dims, (std::vector<hsize_t>{E, 6}));
  const auto PL = read_ds<std::int32_t>(h, "/elements/plastic", H5T_NATIVE_INT32, dims);
  EXPECT_EQ(dims, (std::vector<hsize_t>{E}));
  const auto MAT = read_ds<std::int32_t>(h, "/elements/material", H5T_NATIVE_INT32, dims);
  EXPECT_EQ(dims, (std::vector<hsize_t>{E}));
  const auto ACT = read_ds<std::int32_t>(h, "/elements/active", H5T_NATIVE_INT32, dims);
  EXPECT_EQ(dims, (std::vector<hsize_t>{E}));
  const auto C = read_ds<std::int64_t>(h, "/elements/connectivity", H5T_NATIVE_INT64, dims);
  const std::vector<hsize_t> cdims = dims;
  H5Fclose(h);
  if (EID.size() != E || RK.size() != E || S.size() != 6 * E || EPS.size() != 6 * E ||
      PL.size() != E || MAT.size() != E || ACT.size() != E) {
    ADD_FAILURE() << file << ": element datasets have the wrong sizes";
    return rows;
  }

  // Connectivity rows in file order.
  if (mixed) {
    hsize_t L = 0;
    for (const auto& e : M.el) L += 1 + nodes_of(e.type);
    EXPECT_EQ(cdims, (std::vector<hsize_t>{L}));
    std::size_t p = 0;
    for (hsize_t i = 0; i < E && p < C.size(); ++i) {
      const int code = static_cast<int>(C[p++]);
      const int n = code == 48 ? 20 : code == 5 ? 4 : code == 9 ? 8 : 0;
      EXPECT_NE(n, 0) << "bad type code " << code;
      if (n == 0 || p + n > C.size()) break;
      rows.emplace_back(C.begin() + p, C.begin() + p + n);
      rows.back().insert(rows.back().begin(), code);  // keep the code for the check below
      p += n;
    }
    EXPECT_EQ(p, C.size());
  } else {
    const hsize_t npe = E ? nodes_of(M.el[0].type) : 8;
    EXPECT_EQ(cdims, (std::vector<hsize_t>{E, npe}));
    for (hsize_t i = 0; i < E && (i + 1) * npe <= C.size(); ++i)
      rows.emplace_back(C.begin() + i * npe, C.begin() + (i + 1) * npe);
  }
  EXPECT_EQ(rows.size(), E);

  // Elements: each id once, in rank order, with its connectivity and fields.
  std::map<std::int64_t, const Mesh::El*> by_id;
  for (const auto& e : M.el) by_id[e.id] = &e;
  std::map<std::int64_t, int> seen;
  for (hsize_t i = 0; i < E && i < rows.size(); ++i) {
    auto it = by_id.find(EID[i]);
    if (it == by_id.end()) { ADD_FAILURE() << "unknown element id " << EID[i]; continue; }
    const Mesh::El& e = *it->second;
    ++seen[e.id];
    if (i > 0) EXPECT_LE(RK[i - 1], RK[i]) << "elements not in rank order";
    EXPECT_EQ(RK[i], e.owner) << "element " << e.id;
    std::vector<std::int64_t> got = rows[i];
    if (mixed) {
      EXPECT_EQ(got[0], xdmf_code(e.type)) << "element " << e.id;
      got.erase(got.begin());
      rows[i] = got;
    }
    EXPECT_EQ(got, expected_conn(M, e)) << "element " << e.id;
    for (int k = 0; k < 6; ++k) {
      EXPECT_EQ(S[6 * i + k], stress_of(e.id, k, step)) << "element " << e.id;
      EXPECT_EQ(EPS[6 * i + k], strain_of(e.id, k, step)) << "element " << e.id;
    }
    EXPECT_EQ(PL[i], plastic_of(e.id));
    EXPECT_EQ(MAT[i], material_of(e.id));
    EXPECT_EQ(ACT[i], active_of(e.id));
  }
  EXPECT_EQ(seen.size(), static_cast<std::size_t>(E));
  for (const auto& [id, n] : seen) EXPECT_EQ(n, 1) << "element " << id;

  // Hex20, geometrically: written node 8 + k is the middle of VTK edge k of the written corners.
  for (hsize_t i = 0; i < rows.size(); ++i) {
    if (rows[i].size() != 20) continue;
    for (int k = 0; k < 12; ++k)
      for (int c = 0; c < 3; ++c) {
        const double mid = 0.5 * (X[3 * rows[i][kVtkEdges[k][0]] + c] +
                                  X[3 * rows[i][kVtkEdges[k][1]] + c]);
        EXPECT_DOUBLE_EQ(X[3 * rows[i][8 + k] + c], mid) << "hex20 VTK mid-edge node " << 8 + k;
      }
  }
  return rows;
}

std::string slurp(const std::string& path) {
  std::ifstream f(path);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

bool has(const std::string& s, const std::string& what) {
  return s.find(what) != std::string::npos;
}

/// XML well-formedness with Python's minidom (skipped if /usr/bin/python3 is missing).
void expect_xml_parses(const std::string& path) {
  if (!std::filesystem::exists("/usr/bin/python3")) return;
  const std::string cmd =
      "/usr/bin/python3 -c 'import sys, xml.dom.minidom; xml.dom.minidom.parse(sys.argv[1])' '" +
      path + "'";
  EXPECT_EQ(std::system(cmd.c_str()), 0) << path << " is not well-formed XML";
}

std::string h5(const std::string& dir, const std::string& prefix, int step) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "_%08d.h5", step);
  return dir + "/" + prefix + buf;
}

}  // namespace

TEST(FeOutput, Hex8BlockRoundRobinTwoSnapshots) {
  fdem::testing::TempDir dir("fdem_feout");
  ASSERT_FALSE(dir.path.empty());
  Mesh M = hex_block(3, 2, 1);
  M.el[5].type = kHex8R;  // Hex8R is a Hexahedron too: still a single-type mesh
  const int P = size_of();
  M.partition([&](int e) { return e % P; });
  ASSERT_EQ(M.n_nodes(), 24);
  FeSnapshotWriter w(dir.path, "block", MPI_COMM_WORLD);
  ASSERT_NO_THROW(w.write(5, 0.5, local_data(M, 5)));
  ASSERT_NO_THROW(w.write(10, 1.25, local_data(M, 10)));
  if (rank_of() != 0) return;
  check_file(h5(dir.path, "block", 5), M, 5, 0.5, false);
  check_file(h5(dir.path, "block", 10), M, 10, 1.25, false);

  const std::string xp = dir.path + "/block.xdmf";
  const std::string x = slurp(xp);
  ASSERT_FALSE(x.empty());
  EXPECT_TRUE(has(x, "Version=\"3.0\""));
  EXPECT_TRUE(has(x, "CollectionType=\"Temporal\""));
  EXPECT_TRUE(has(x, "block_00000005.h5:/elements/connectivity"));
  EXPECT_TRUE(has(x, "block_00000010.h5:/elements/connectivity"));
  EXPECT_TRUE(has(x, "block_00000010.h5:/nodes/coordinates"));
  EXPECT_TRUE(has(x, "TopologyType=\"Hexahedron\" NumberOfElements=\"6\""));
  EXPECT_FALSE(has(x, "Mixed"));
  EXPECT_TRUE(has(x, "Dimensions=\"6 8\""));
  EXPECT_TRUE(has(x, "Dimensions=\"24 3\""));
  EXPECT_TRUE(has(x, "GeometryType=\"XYZ\""));
  EXPECT_TRUE(has(x, "<Time Value=\"1.25\""));
  EXPECT_TRUE(has(x, "AttributeType=\"Tensor6\" Center=\"Cell\""));
  EXPECT_TRUE(has(x, "block_00000005.h5:/elements/stress"));
  EXPECT_TRUE(has(x, "block_00000005.h5:/nodes/displacement"));
  EXPECT_TRUE(has(x, "Name=\"displacement\" AttributeType=\"Vector\" Center=\"Node\""));
  EXPECT_TRUE(has(x, "Name=\"rank\" AttributeType=\"Scalar\" Center=\"Cell\""));
  EXPECT_FALSE(std::filesystem::exists(xp + ".tmp"));
  expect_xml_parses(xp);
}

TEST(FeOutput, NonContiguousUnsortedNodeNumbers) {
  // Elements by halves; natural numbering (global = mesh index), so each rank's owned nodes are
  // several runs of numbers, handed over in reverse order.
  fdem::testing::TempDir dir("fdem_feout");
  ASSERT_FALSE(dir.path.empty());
  Mesh M = hex_block(3, 2, 1);
  const int P = size_of();
  M.partition([&](int e) { return e < 3 ? 0 : std::min(1, P - 1); });
  for (int m = 0; m < M.n_nodes(); ++m) M.gnum[m] = m;
  FeSnapshotWriter w(dir.path, "fe", MPI_COMM_WORLD);
  ASSERT_NO_THROW(w.write(0, 0.0, local_data(M, 0, true)));
  ASSERT_NO_THROW(w.write(1, 0.1, local_data(M, 1, true)));
  if (rank_of() != 0) return;
  check_file(h5(dir.path, "fe", 0), M, 0, 0.0, false);
  check_file(h5(dir.path, "fe", 1), M, 1, 0.1, false);
}

TEST(FeOutput, MixedMeshAndHex20Order) {
  fdem::testing::TempDir dir("fdem_feout");
  ASSERT_FALSE(dir.path.empty());
  Mesh M = separate_elements({kHex8, kHex20, kHex8R, kQuad4, kHex20});
  const int P = size_of();
  M.partition([&](int e) { return e % P; });
  FeSnapshotWriter w(dir.path, "mixed", MPI_COMM_WORLD);
  ASSERT_NO_THROW(w.write(3, 0.3, local_data(M, 3)));
  ASSERT_NO_THROW(w.write(4, 0.4, local_data(M, 4)));
  if (rank_of() != 0) return;
  const auto rows = check_file(h5(dir.path, "mixed", 3), M, 3, 0.3, true);
  check_file(h5(dir.path, "mixed", 4), M, 4, 0.4, true);

  // The first Hex20 (id 503), explicitly: VTK mid-edge k <- Gmsh node 8 + {0,3,5,1,8,10,11,9,2,4,6,7}[k].
  const Mesh::El& e = M.el[1];
  ASSERT_EQ(e.id, 503);
  const int gmsh_of_vtk[12] = {0, 3, 5, 1, 8, 10, 11, 9, 2, 4, 6, 7};
  std::vector<std::int64_t> want;
  for (int k = 0; k < 8; ++k) want.push_back(M.gnum[e.nodes[k]]);
  for (int k = 0; k < 12; ++k) want.push_back(M.gnum[e.nodes[8 + gmsh_of_vtk[k]]]);
  bool found = false;
  for (const auto& r : rows)
    if (r.size() == 20 && r[0] == want[0]) { EXPECT_EQ(r, want); found = true; }
  EXPECT_TRUE(found);

  const std::string xp = dir.path + "/mixed.xdmf";
  const std::string x = slurp(xp);
  // Flat length: (1+8) + (1+20) + (1+8) + (1+4) + (1+20) = 65.
  EXPECT_TRUE(has(x, "TopologyType=\"Mixed\" NumberOfElements=\"5\""));
  EXPECT_TRUE(has(x, "<DataItem Dimensions=\"65\" NumberType=\"Int\" Precision=\"8\" "
                     "Format=\"HDF\">mixed_00000003.h5:/elements/connectivity"));
  EXPECT_TRUE(has(x, "mixed_00000004.h5:/elements/connectivity"));
  EXPECT_TRUE(has(x, "Dimensions=\"" + std::to_string(M.n_nodes()) + " 3\""));
  expect_xml_parses(xp);
}

TEST(FeOutput, Hex20OnlyMesh) {
  fdem::testing::TempDir dir("fdem_feout");
  ASSERT_FALSE(dir.path.empty());
  Mesh M = separate_elements({kHex20, kHex20, kHex20});
  const int P = size_of();
  M.partition([&](int e) { return (e + 1) % P; });
  FeSnapshotWriter w(dir.path, "h20", MPI_COMM_WORLD);
  ASSERT_NO_THROW(w.write(7, 7.0, local_data(M, 7)));
  if (rank_of() != 0) return;
  check_file(h5(dir.path, "h20", 7), M, 7, 7.0, false);
  const std::string x = slurp(dir.path + "/h20.xdmf");
  EXPECT_TRUE(has(x, "TopologyType=\"Hexahedron_20\" NumberOfElements=\"3\""));
  EXPECT_TRUE(has(x, "Dimensions=\"3 20\""));
  expect_xml_parses(dir.path + "/h20.xdmf");
}

TEST(FeOutput, RankWithoutElements) {
  fdem::testing::TempDir dir("fdem_feout");
  ASSERT_FALSE(dir.path.empty());
  Mesh M = hex_block(3, 2, 1);
  M.partition([](int) { return 0; });  // all elements and nodes on rank 0
  FeSnapshotWriter w(dir.path, "fe", MPI_COMM_WORLD);
  // 1) The last rank has nothing at all.
  ASSERT_NO_THROW(w.write(1, 1.0, local_data(M, 1)));
  // 2) The last rank owns the odd-numbered nodes but no elements.
  const int last = size_of() - 1;
  for (int m = 0; m < M.n_nodes(); ++m)
    if (M.gnum[m] % 2 == 1) M.node_owner[m] = last;
  ASSERT_NO_THROW(w.write(2, 2.0, local_data(M, 2)));
  if (rank_of() != 0) return;
  check_file(h5(dir.path, "fe", 1), M, 1, 1.0, false);
  check_file(h5(dir.path, "fe", 2), M, 2, 2.0, false);
  const std::string x = slurp(dir.path + "/fe.xdmf");
  EXPECT_TRUE(has(x, "fe_00000001.h5:/nodes/coordinates"));
  EXPECT_TRUE(has(x, "fe_00000002.h5:/nodes/coordinates"));
  expect_xml_parses(dir.path + "/fe.xdmf");
}

TEST(FeOutput, EmptyMeshAndRewrittenStep) {
  fdem::testing::TempDir dir("fdem_feout");
  ASSERT_FALSE(dir.path.empty());
  FeSnapshotWriter w(dir.path, "empty", MPI_COMM_WORLD);
  ASSERT_NO_THROW(w.write(0, 0.0, FeSnapshotData{}));
  Mesh M = hex_block(1, 1, 1);
  M.partition([](int) { return 0; });
  ASSERT_NO_THROW(w.write(1, 0.5, local_data(M, 1)));
  ASSERT_NO_THROW(w.write(1, 0.5, local_data(M, 1)));  // same step again: listed once
  if (rank_of() != 0) return;
  std::vector<hsize_t> dims;
  hid_t h = H5Fopen(h5(dir.path, "empty", 0).c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(h, 0);
  read_ds<double>(h, "/nodes/coordinates", H5T_NATIVE_DOUBLE, dims);
  EXPECT_EQ(dims, (std::vector<hsize_t>{0, 3}));
  read_ds<std::int64_t>(h, "/elements/connectivity", H5T_NATIVE_INT64, dims);
  EXPECT_EQ(dims, (std::vector<hsize_t>{0, 8}));
  H5Fclose(h);
  check_file(h5(dir.path, "empty", 1), M, 1, 0.5, false);
  const std::string x = slurp(dir.path + "/empty.xdmf");
  EXPECT_TRUE(has(x, "<!-- step 0 (empty_00000000.h5): 0 nodes, 0 elements -->"));
  const auto first = x.find("<Grid Name=\"step_1\"");
  EXPECT_NE(first, std::string::npos);
  EXPECT_EQ(x.find("<Grid Name=\"step_1\"", first + 1), std::string::npos);
  expect_xml_parses(dir.path + "/empty.xdmf");
}

TEST(FeOutput, RestartAdoptsSnapshotsUpToItsStep) {
  // A run writes steps 0 (empty), 3 (mixed mesh), 4 and 8 (Hex20 mesh) and stops; restarted from
  // step 5, its writer takes over 0, 3 and 4 -- not 8, nor the leftovers that are not the
  // writer's files --, rewrites 4 and goes on to 6. Its XDMF must be the one of a run that wrote
  // 0, 3, 4 and 6 without a break, to the byte.
  fdem::testing::TempDir a("fdem_feout"), b("fdem_feout");
  ASSERT_FALSE(a.path.empty());
  ASSERT_FALSE(b.path.empty());
  const int P = size_of();
  Mesh mixed = separate_elements({kHex8, kHex20, kQuad4});
  mixed.partition([&](int e) { return e % P; });
  Mesh h20 = separate_elements({kHex20, kHex20});
  h20.partition([&](int e) { return (e + 1) % P; });
  const double t3 = 0.1 * 3, t4 = 1.0 / 3.0, t6 = 0.7;
  {
    FeSnapshotWriter w(a.path, "fe", MPI_COMM_WORLD);
    ASSERT_NO_THROW(w.write(0, 0.0, FeSnapshotData{}));
    ASSERT_NO_THROW(w.write(3, t3, local_data(mixed, 3)));
    ASSERT_NO_THROW(w.write(4, t4 + 1, local_data(mixed, 4)));  // rewritten after the restart
    ASSERT_NO_THROW(w.write(8, 0.8, local_data(h20, 8)));
  }
  if (rank_of() == 0) {
    namespace fs = std::filesystem;
    std::ofstream(a.path + "/fe_00000002.h5") << "not an HDF5 file";
    fs::copy_file(h5(a.path, "fe", 3), a.path + "/fe_00000001.h5");  // its step attribute says 3
    fs::copy_file(h5(a.path, "fe", 3), a.path + "/fe_5.h5");         // not a name the writer uses
    fs::copy_file(h5(a.path, "fe", 3), a.path + "/fe_x_00000005.h5");
  }
  MPI_Barrier(MPI_COMM_WORLD);
  {
    FeSnapshotWriter w(a.path, "fe", MPI_COMM_WORLD);
    ASSERT_NO_THROW(w.adopt_existing(5));
    ASSERT_NO_THROW(w.write(4, t4, local_data(h20, 4)));
    ASSERT_NO_THROW(w.write(6, t6, local_data(h20, 6)));
  }
  {
    FeSnapshotWriter w(b.path, "fe", MPI_COMM_WORLD);
    ASSERT_NO_THROW(w.write(0, 0.0, FeSnapshotData{}));
    ASSERT_NO_THROW(w.write(3, t3, local_data(mixed, 3)));
    ASSERT_NO_THROW(w.write(4, t4, local_data(h20, 4)));
    ASSERT_NO_THROW(w.write(6, t6, local_data(h20, 6)));
  }
  if (rank_of() != 0) return;
  const std::string xa = slurp(a.path + "/fe.xdmf"), xb = slurp(b.path + "/fe.xdmf");
  EXPECT_TRUE(has(xb, "<!-- step 0 (fe_00000000.h5): 0 nodes, 0 elements -->"));
  EXPECT_TRUE(has(xb, "TopologyType=\"Mixed\" NumberOfElements=\"3\""));
  EXPECT_TRUE(has(xb, "TopologyType=\"Hexahedron_20\" NumberOfElements=\"2\""));
  // The steps listed (grids, and comments for empty snapshots), then the whole text.
  auto steps = [](const std::string& x) {
    std::vector<long long> v;
    for (std::size_t p = x.find("step"); p != std::string::npos; p = x.find("step", p + 1))
      if (p + 5 < x.size() && (x[p + 4] == '_' || x[p + 4] == ' ')) v.push_back(std::atoll(&x[p + 5]));
    return v;
  };
  EXPECT_EQ(steps(xb), (std::vector<long long>{0, 3, 4, 6}));
  EXPECT_EQ(steps(xa), steps(xb));
  EXPECT_TRUE(xa == xb) << "the restarted writer's XDMF differs from the uninterrupted one's";
  expect_xml_parses(a.path + "/fe.xdmf");
}

TEST(FeOutput, InvalidInputThrowsOnEveryRank) {
  fdem::testing::TempDir dir("fdem_feout");
  ASSERT_FALSE(dir.path.empty());
  Mesh M = hex_block(2, 1, 1);
  M.partition([](int) { return 0; });
  FeSnapshotWriter w(dir.path, "bad", MPI_COMM_WORLD);
  {
    FeSnapshotData d = local_data(M, 0);
    if (rank_of() == 0) d.elem_type[0] = 7;  // unknown type on rank 0 only
    try {
      w.write(0, 0.0, d);
      ADD_FAILURE() << "no exception";
    } catch (const std::runtime_error& e) {
      EXPECT_TRUE(has(e.what(), "bad_00000000.h5")) << e.what();
      if (rank_of() == 0) EXPECT_TRUE(has(e.what(), "unknown type 7")) << e.what();
    }
  }
  {
    // One rank: a node missing overall. More ranks: rank 0 claims one node twice.
    FeSnapshotData d = local_data(M, 0);
    if (size_of() == 1) {
      d.node_global.pop_back();
      d.node_id.pop_back();
      for (int k = 0; k < 3; ++k) {
        d.coords.pop_back(); d.displacement.pop_back(); d.velocity.pop_back();
      }
    } else if (rank_of() == 0) {
      d.node_global.push_back(d.node_global[0]);
      d.node_id.push_back(0);
      for (int k = 0; k < 3; ++k) {
        d.coords.push_back(0); d.displacement.push_back(0); d.velocity.push_back(0);
      }
    }
    EXPECT_THROW(w.write(1, 0.0, d), std::runtime_error);
  }
}
