// fdem-test-ranks: 2 3
// Results must not depend on the number of ranks: the same dense settling run on 1, 2 and 3
// ranks (sub-communicators of MPI_COMM_WORLD, run one after another) gives the same particle
// positions after 2000 steps. The aim, and what is asserted, is bitwise equality; the issue's
// bound (1e-10 of the domain size) is reported too.
#include <gtest/gtest.h>

#include <cmath>

#include "support/dem_fixtures.hpp"
#include "support/mpi_util.hpp"

using namespace fdem;
using namespace fdem::testing;

namespace {

Gathered settle(MPI_Comm comm, int steps, RollingLaw law, std::int64_t* rebuilds, std::int64_t* contacts,
               double* unbalanced) {
  const double rmax = 1.5e-3, rho = 2650;
  // Friction, rolling resistance (either law), different wall friction, all code paths of the law.
  std::vector<Material> m{make_material("sand", 5e6, rho, 0.5, 0.25, 0.05, 1.0), make_material("wall", 5e6, 7800, 0.2)};
  for (Material& q : m) q.rolling_law = law;
  MaterialTable mats(m);
  const Vec3 lo{0, 0, 0}, hi{0.04, 0.031, 0.06};
  ParticleStore p = lattice_block({0.0005, 0.0005, 0.0005}, 12, 9, 14, rmax, rho, 42, 0.9, 2.02);
  for (std::size_t i = 0; i < p.size(); ++i) p.v[i] = {0.05 * std::sin(1.0 * i), 0.05 * std::cos(2.0 * i), -0.1};
  std::vector<Wall> walls{make_plane("floor", {0, 0, 0}, {0, 0, 1}, 1),
                          make_plane("x0", {0, 0, 0}, {1, 0, 0}, 1),
                          make_plane("x1", {0.04, 0, 0}, {-1, 0, 0}, 1),
                          make_plane("y0", {0, 0, 0}, {0, 1, 0}, 1),
                          make_plane("y1", {0, 0.031, 0}, {0, -1, 0}, 1)};
  EngineParams prm;
  prm.domain_min = lo; prm.domain_max = hi; prm.gravity = {0, 0, -9.81 * 20}; prm.damping = 0.2;
  prm.dt_safety = 0.3;
  DemEngine e(comm, prm, mats, walls, p);
  e.run(steps);
  *rebuilds = e.rebuilds();
  const EngineStats st = e.stats();
  *contacts = st.contacts;
  *unbalanced = st.unbalanced;
  return gather(e);
}

}  // namespace

namespace {

void same_trajectories(RollingLaw law) {
  int world = 0, rank = 0;
  MPI_Comm_size(MPI_COMM_WORLD, &world);
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  std::vector<Gathered> results;
  std::int64_t rebuilds = 0, contacts = 0;
  std::vector<double> unb(world, 0.0);
  for (int n = 1; n <= world; ++n) {
    MPI_Comm sub = fdem::testing::first_ranks(n);
    Gathered g;
    if (sub != MPI_COMM_NULL) {
      g = settle(sub, 2000, law, &rebuilds, &contacts, &unb[n - 1]);
      MPI_Comm_free(&sub);
    }
    results.push_back(g);
    MPI_Barrier(MPI_COMM_WORLD);
  }
  if (rank != 0) return;  // rank 0 took part in every run
  ASSERT_EQ(results[0].id.size(), 12u * 9u * 14u);
  EXPECT_GT(contacts, static_cast<std::int64_t>(results[0].id.size()));  // dense: coordination > 2
  EXPECT_GT(rebuilds, 5);     // migrations happened
  const double L = 0.06;
  for (int n = 2; n <= world; ++n) {
    const Gathered& a = results[0];
    const Gathered& b = results[n - 1];
    ASSERT_EQ(a.id, b.id) << n << " ranks";
    double maxdiff = 0;
    std::size_t differ = 0;
    for (std::size_t i = 0; i < a.id.size(); ++i) {
      const double d = norm(a.x[i] - b.x[i]);
      maxdiff = std::max(maxdiff, d);
      if (a.x[i].x != b.x[i].x || a.x[i].y != b.x[i].y || a.x[i].z != b.x[i].z || a.v[i].x != b.v[i].x ||
          a.w[i].z != b.w[i].z)
        ++differ;
    }
    std::printf("%s rolling law, 1 vs %d ranks: max position difference %.3e m (%.3e of the domain), %zu particles not bitwise equal\n",
                rolling_law_name(law), n, maxdiff, maxdiff / L, differ);
    EXPECT_LE(maxdiff, 1e-10 * L);
    EXPECT_EQ(differ, 0u) << "not bitwise equal on " << n << " ranks";
    // The unbalanced-force ratio (history.csv, stop criteria) too, to round-off of the sums.
    std::printf("  unbalanced-force ratio %.15e (1 rank) vs %.15e (%d ranks)\n", unb[0], unb[n - 1], n);
    EXPECT_NEAR(unb[n - 1] / unb[0], 1.0, 1e-12);
  }
}

}  // namespace

TEST(Determinism, SameTrajectoriesOn1To3Ranks) { same_trajectories(RollingLaw::kIncremental); }

// The thesis's law (total rotation, twist included): its history migrates and sums the same way.
TEST(Determinism, SameTrajectoriesOn1To3RanksTotalRollingLaw) { same_trajectories(RollingLaw::kTotal); }
