// fdem-test-ranks: 1 2 3
// The FE mesh in parts (issue 20, src/partition/mesh_distribute.hpp): rank 0 partitions the whole
// mesh and sends each rank its part; the part received equals the one extracted from a replicated
// mesh under the same partition; the parts cover every element once, every node's owner holds it,
// the named sets are split without loss; explicit FE steps on the parts give the replicated
// model's displacements bit for bit, and the static solve (KSP) its answer within the solver's
// error bound.
#include <gtest/gtest.h>

#include "support/mpi_util.hpp"
#include <mpi.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>

#include "fem/fe_model.hpp"
#include "fem/mesh.hpp"
#include "partition/mesh_distribute.hpp"
#include "partition/mesh_partition.hpp"

using namespace fdem;
using namespace fdem::fem;

namespace {

// A block with named sets of every kind: node sets (faces), an element set (the half x < L/2)
// and a face set (the top faces of the elements there).
Mesh test_mesh() {
  Mesh m = make_block({0, 0, 0}, {1.0, 0.1, 0.1}, 24, 3, 3);
  std::vector<std::int32_t> half;
  std::vector<std::array<std::int32_t, 2>> top;
  for (std::size_t e = 0; e < m.n_elements(); ++e) {
    const std::int32_t* nodes;
    const int n = m.nodes_of(e, nodes);
    double x = 0, zmin = 1e9;
    for (int k = 0; k < n; ++k) {
      x += m.coords[3 * static_cast<std::size_t>(nodes[k])] / n;
      zmin = std::min(zmin, m.coords[3 * static_cast<std::size_t>(nodes[k]) + 2]);
    }
    if (x < 0.5) half.push_back(static_cast<std::int32_t>(e));
    if (x < 0.5 && zmin > 0.06) top.push_back({static_cast<std::int32_t>(e), 5});
  }
  m.element_sets["half"] = half;
  m.face_sets["top_half"] = top;
  return m;
}

FeMaterial material() {
  FeMaterial m;
  m.young = 2e11; m.poisson = 0.3; m.density = 7800; m.unit_weight = 7800 * 9.81;
  return m;
}

/// The cantilever's boundary conditions on a model of `mesh` (whole or part): the face x = 0
/// clamped, `total` N down on the face x = L, load factor 1.
void clamp_and_load(FeModel& m, const Mesh& mesh, double total, std::size_t n_tip_nodes) {
  for (std::int32_t n : mesh.node_sets.at("xmin")) m.restrain(n, {true, true, true});
  for (std::int32_t n : mesh.node_sets.at("xmax")) m.add_load(n, {0, 0, -total / static_cast<double>(n_tip_nodes)});
  m.set_load_factor(1.0);
}

std::int64_t sum_all(std::int64_t v) {
  MPI_Allreduce(MPI_IN_PLACE, &v, 1, MPI_INT64_T, MPI_SUM, MPI_COMM_WORLD);
  return v;
}

}  // namespace

TEST(MeshDistribute, PartsEqualTheExtractionAndCoverTheMesh) {
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  const Mesh whole = test_mesh();
  const MeshPart got = distribute_mesh(rank == 0 ? whole : Mesh{}, MPI_COMM_WORLD);
  const MeshPart want = mesh_part(whole, partition_mesh(whole, MPI_COMM_WORLD), rank);
  EXPECT_EQ(got.mesh.dim, want.mesh.dim);
  EXPECT_EQ(got.mesh.node_id, want.mesh.node_id);
  EXPECT_EQ(got.mesh.coords, want.mesh.coords);
  EXPECT_EQ(got.mesh.elem_id, want.mesh.elem_id);
  EXPECT_EQ(got.mesh.elem_type, want.mesh.elem_type);
  EXPECT_EQ(got.mesh.elem_offset, want.mesh.elem_offset);
  EXPECT_EQ(got.mesh.elem_nodes, want.mesh.elem_nodes);
  EXPECT_EQ(got.mesh.elem_material, want.mesh.elem_material);
  EXPECT_EQ(got.mesh.node_sets, want.mesh.node_sets);
  EXPECT_EQ(got.mesh.element_sets, want.mesh.element_sets);
  EXPECT_EQ(got.mesh.face_sets, want.mesh.face_sets);
  EXPECT_EQ(got.part.nparts, size);
  EXPECT_EQ(got.part.elem_part, want.part.elem_part);
  EXPECT_EQ(got.part.node_owner, want.part.node_owner);
  EXPECT_EQ(got.part.node_global, want.part.node_global);
  EXPECT_EQ(got.part.owned_count, want.part.owned_count);
  EXPECT_EQ(got.part.elem_index, want.part.elem_index);
  EXPECT_EQ(got.part.node_index, want.part.node_index);
  EXPECT_EQ(got.n_elements_global, static_cast<std::int64_t>(whole.n_elements()));
  EXPECT_EQ(got.n_nodes_global, static_cast<std::int64_t>(whole.n_nodes()));

  // Every element in exactly one part, with its own nodes' coordinates and ids.
  std::vector<std::int32_t> count(whole.n_elements(), 0);
  for (std::size_t le = 0; le < got.part.elem_index.size(); ++le) {
    const std::int64_t e = got.part.elem_index[le];
    ++count[e];
    const std::int32_t *a, *b;
    const int n = got.mesh.nodes_of(le, a);
    ASSERT_EQ(n, whole.nodes_of(static_cast<std::size_t>(e), b));
    for (int k = 0; k < n; ++k) {
      EXPECT_EQ(got.part.node_index[a[k]], b[k]);
      EXPECT_EQ(got.mesh.node_id[a[k]], whole.node_id[b[k]]);
      for (int d = 0; d < 3; ++d) EXPECT_EQ(got.mesh.coords[3 * a[k] + d], whole.coords[3 * b[k] + d]);
    }
  }
  MPI_Allreduce(MPI_IN_PLACE, count.data(), static_cast<int>(count.size()), MPI_INT32_T, MPI_SUM, MPI_COMM_WORLD);
  EXPECT_TRUE(std::all_of(count.begin(), count.end(), [](std::int32_t c) { return c == 1; }));
  // Every node owned by exactly one part, which holds it; the global numbers 0 .. N-1 once each.
  std::vector<std::int32_t> owned(whole.n_nodes(), 0), number(whole.n_nodes(), 0);
  for (std::size_t i = 0; i < got.part.node_index.size(); ++i)
    if (got.part.node_owner[i] == rank) {
      ++owned[got.part.node_index[i]];
      ++number[got.part.node_global[i]];
    }
  MPI_Allreduce(MPI_IN_PLACE, owned.data(), static_cast<int>(owned.size()), MPI_INT32_T, MPI_SUM, MPI_COMM_WORLD);
  MPI_Allreduce(MPI_IN_PLACE, number.data(), static_cast<int>(number.size()), MPI_INT32_T, MPI_SUM, MPI_COMM_WORLD);
  EXPECT_TRUE(std::all_of(owned.begin(), owned.end(), [](std::int32_t c) { return c == 1; }));
  EXPECT_TRUE(std::all_of(number.begin(), number.end(), [](std::int32_t c) { return c == 1; }));
  // The sets split without loss: owned members of the node sets, every element and face once.
  for (const auto& [name, s] : whole.node_sets) {
    std::int64_t mine = 0;
    for (std::int32_t l : got.mesh.node_sets.at(name)) mine += got.part.node_owner[l] == rank;
    EXPECT_EQ(sum_all(mine), static_cast<std::int64_t>(s.size())) << name;
  }
  EXPECT_EQ(sum_all(static_cast<std::int64_t>(got.mesh.element_sets.at("half").size())),
            static_cast<std::int64_t>(whole.element_sets.at("half").size()));
  EXPECT_EQ(sum_all(static_cast<std::int64_t>(got.mesh.face_sets.at("top_half").size())),
            static_cast<std::int64_t>(whole.face_sets.at("top_half").size()));
  ASSERT_GT(whole.face_sets.at("top_half").size(), 0u);
  for (const auto& f : got.mesh.face_sets.at("top_half")) {
    const std::array<std::int32_t, 2> g{static_cast<std::int32_t>(got.part.elem_index[f[0]]), f[1]};
    const auto& w = whole.face_sets.at("top_half");
    EXPECT_NE(std::find(w.begin(), w.end(), g), w.end());
  }
}

// A cantilever under its weight and a tip load, 2 000 explicit steps: the FeModel built on this
// rank's part and the one built on the replicated mesh own the same nodes in the same order and
// reach the same displacements bit for bit; then with elements removed, the restart state, the
// health check, and a part model restored from the replicated model's state.
TEST(MeshDistribute, ExplicitStepsOnPartsEqualTheReplicatedModel) {
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  const Mesh whole = test_mesh();
  const MeshPart got = distribute_mesh(rank == 0 ? whole : Mesh{}, MPI_COMM_WORLD);
  const FePartition part = partition_mesh(whole, MPI_COMM_WORLD);
  FeParams prm;
  prm.damping = 300.0;  // fixed: the adaptive estimate is a reduction (round-off order)
  FeModel a(MPI_COMM_WORLD, whole, part, {material()}, prm);
  FeModel b(MPI_COMM_WORLD, got.mesh, got.part, {material()}, prm);
  EXPECT_EQ(a.n_elements_global(), b.n_elements_global());
  const std::size_t n_tip = whole.node_sets.at("xmax").size();
  clamp_and_load(a, whole, 2000.0, n_tip);
  clamp_and_load(b, got.mesh, 2000.0, n_tip);
  const double dt = 0.5 * a.critical_dt();
  EXPECT_EQ(dt, 0.5 * b.critical_dt());
  for (int k = 0; k < 2000; ++k) {
    a.step(dt);
    b.step(dt);
  }
  ASSERT_EQ(a.n_owned(), b.n_owned());
  EXPECT_EQ(a.local_global_numbers(), b.local_global_numbers());
  for (std::size_t i = 0; i < a.local_nodes().size(); ++i)
    EXPECT_EQ(got.part.node_index[b.local_nodes()[i]], a.local_nodes()[i]);
  const std::vector<double> ua = a.owned_displacements(), ub = b.owned_displacements();
  double umax = 0;
  for (double x : ua) umax = std::max(umax, std::abs(x));
  MPI_Allreduce(MPI_IN_PLACE, &umax, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
  EXPECT_GT(umax, 1e-7);
  EXPECT_EQ(ua, ub) << "explicit steps on the parts differ from the replicated model's";
  if (rank == 0) std::printf("parts vs replicated mesh on %d rank(s): max displacement %.4e m, equal bit for bit\n", size, umax);

  // Remove the elements of the set 'half' (by the whole mesh's indices, as the drivers give them)
  // and go on: the same again; the restart state (keyed by the whole mesh's indices), the health
  // check and the gathered displacements equal the replicated model's.
  std::vector<std::int32_t> half(whole.element_sets.at("half").begin(), whole.element_sets.at("half").begin() + 20);
  a.remove_elements(half);
  b.remove_elements(half);
  for (int k = 0; k < 500; ++k) {
    a.step(dt);
    b.step(dt);
  }
  const FeState sa = a.state(), sb = b.state();
  EXPECT_EQ(sa.node, sb.node);
  EXPECT_EQ(sa.u, sb.u);
  EXPECT_EQ(sa.v, sb.v);
  EXPECT_EQ(sa.gp_elem, sb.gp_elem);
  EXPECT_EQ(sa.gp_k, sb.gp_k);
  EXPECT_EQ(sa.gp_data, sb.gp_data);
  EXPECT_EQ(sa.removed, sb.removed);
  EXPECT_EQ(sa.removed.size(), half.size());
  EXPECT_EQ(a.gather_displacements(), b.gather_displacements());
  const FeModel::Health ha = a.health(), hb = b.health();
  EXPECT_EQ(ha.max_node, hb.max_node);
  EXPECT_EQ(ha.max_u, hb.max_u);
  EXPECT_EQ(hb.nonfinite_node, -1);

  // A model on the parts restarted from the replicated model's state (every rank's rows: as a
  // checkpoint read by every rank) continues as the replicated one does.
  FeState all;
  {
    std::vector<double> rows;  // node, u, v per owned node of every rank
    for (std::size_t k = 0; k < sa.node.size(); ++k) {
      rows.push_back(static_cast<double>(sa.node[k]));
      for (int d = 0; d < 3; ++d) rows.push_back(sa.u[3 * k + d]);
      for (int d = 0; d < 3; ++d) rows.push_back(sa.v[3 * k + d]);
    }
    int n = static_cast<int>(rows.size());
    std::vector<int> counts(size), displs(size, 0);
    MPI_Allgather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, MPI_COMM_WORLD);
    for (int r = 1; r < size; ++r) displs[r] = displs[r - 1] + counts[r - 1];
    std::vector<double> every(static_cast<std::size_t>(displs[size - 1] + counts[size - 1]));
    MPI_Allgatherv(rows.data(), n, MPI_DOUBLE, every.data(), counts.data(), displs.data(), MPI_DOUBLE, MPI_COMM_WORLD);
    for (std::size_t k = 0; k < every.size(); k += 7) {
      all.node.push_back(static_cast<std::int64_t>(every[k]));
      all.u.insert(all.u.end(), every.begin() + k + 1, every.begin() + k + 4);
      all.v.insert(all.v.end(), every.begin() + k + 4, every.begin() + k + 7);
    }
  }
  all.removed = sa.removed;
  all.c_last = sa.c_last;
  FeModel c(MPI_COMM_WORLD, got.mesh, got.part, {material()}, prm);
  clamp_and_load(c, got.mesh, 2000.0, n_tip);
  c.restore(all);
  for (int k = 0; k < 300; ++k) {
    a.step(dt);
    c.step(dt);
  }
  EXPECT_EQ(a.owned_displacements(), c.owned_displacements()) << "a part restored from a whole state";
}

// The static solve (KSP) on the parts: the stiffness matrix is preallocated from each rank's own
// elements (MATPREALLOCATOR), so a part model assembles the same system as the replicated one; the
// two answers agree within the solves' error bounds (condition x residual), and both satisfy the
// equilibrium the method guarantees: the restrained face's reaction balances the load.
TEST(MeshDistribute, StaticSolveOnPartsEqualsTheReplicatedModel) {
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  const Mesh whole = test_mesh();
  const MeshPart got = distribute_mesh(rank == 0 ? whole : Mesh{}, MPI_COMM_WORLD);
  const FePartition part = partition_mesh(whole, MPI_COMM_WORLD);
  FeModel a(MPI_COMM_WORLD, whole, part, {material()}, FeParams{});
  FeModel b(MPI_COMM_WORLD, got.mesh, got.part, {material()}, FeParams{});
  const std::size_t n_tip = whole.node_sets.at("xmax").size();
  clamp_and_load(a, whole, 2000.0, n_tip);
  clamp_and_load(b, got.mesh, 2000.0, n_tip);
  const FeModel::StaticSolveInfo ia = a.solve_static(), ib = b.solve_static();
  // (the true residual of the answer, which sits within round-off of CG's stopping test)
  EXPECT_LE(ia.residual, 10 * ia.rtol);
  EXPECT_LE(ib.residual, 10 * ib.rtol);
  const std::vector<double> ua = a.gather_displacements(), ub = b.gather_displacements();
  ASSERT_EQ(ua.size(), ub.size());
  double umax = 0, dmax = 0;
  for (std::size_t k = 0; k < ua.size(); ++k) {
    umax = std::max(umax, std::abs(ua[k]));
    dmax = std::max(dmax, std::abs(ua[k] - ub[k]));
  }
  EXPECT_GT(umax, 1e-7);
  const double bound = ia.error_bound() + ib.error_bound();
  EXPECT_LE(dmax, bound * umax) << "static solve on the parts differs from the replicated model's";
  // Equilibrium: the restrained face's reaction balances the tip load and the weight.
  const std::array<double, 3> ra = a.reaction(whole.node_sets.at("xmin"));
  const std::array<double, 3> rb = b.reaction(got.mesh.node_sets.at("xmin"));
  const double load = 2000.0 + material().unit_weight * 1.0 * 0.1 * 0.1;  // tip load + weight
  EXPECT_NEAR(ra[2], load, 1e-6 * load);
  EXPECT_NEAR(rb[2], load, 1e-6 * load);
  if (rank == 0)
    std::printf("static solve, parts vs replicated on %d rank(s): %d / %d iterations, max |du| %.2e of %.4e m "
                "(bound %.1e); reaction %.6f / %.6f N\n", size, ia.iterations, ib.iterations, dmax, umax, bound * umax, ra[2], rb[2]);
}
