// fdem-test-ranks: 1 2 3
// Ghost exchange and migration keep every particle exactly once, and every rank sees all the
// particles within the ghost width of its subdomain (checked against a brute-force gather).
#include <gtest/gtest.h>

#include <random>
#include <set>

#include "partition/halo.hpp"
#include "partition/scatter.hpp"
#include "support/dem_fixtures.hpp"
#include "base/allgather.hpp"

using namespace fdem;
using namespace fdem::testing;

TEST(Halo, MigrationAndGhostsKeepEveryParticleOnce) {
  const Vec3 lo{0, 0, 0}, hi{0.09, 0.05, 0.04};
  const double cutoff = 0.006;
  Decomposition dd = Decomposition::create(MPI_COMM_WORLD, lo, hi, cutoff);
  // Every rank starts with a different, arbitrary subset (not the one it owns).
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(0, 1);
  ParticleStore p;
  const int N = 3000;
  for (int i = 0; i < N; ++i) {
    Vec3 x{hi.x * u(rng), hi.y * u(rng), hi.z * u(rng)};
    if (i % dd.size == dd.rank) add_sphere(p, i, x, 0.001 + 0.001 * u(rng), 1000.0);
  }
  HistoryMap history;
  // A contact record for each local particle with its id+1, to check that records travel.
  for (std::size_t i = 0; i < p.n_owned; ++i) {
    ContactState s;
    s.ft = {static_cast<double>(p.id[i]), 0, 0};
    history[ContactKey{p.id[i], p.id[i] + 1, 0, -1}] = s;
  }
  Distributor dist;
  for (int round = 0; round < 3; ++round) {
    dist.migrate(dd, p, history);
    // Owned particles lie in the subdomain; the global set of ids is exactly 0..N-1.
    std::vector<double> ids;
    for (std::size_t i = 0; i < p.n_owned; ++i) {
      ASSERT_EQ(dd.owner_of(p.x[i]), dd.rank);
      ids.push_back(static_cast<double>(p.id[i]));
      auto h = history.find(ContactKey{p.id[i], p.id[i] + 1, 0, -1});
      ASSERT_NE(h, history.end()) << "history of particle " << p.id[i] << " did not follow it";
      ASSERT_EQ(h->second.ft.x, static_cast<double>(p.id[i]));
    }
    std::vector<double> all = allgather(ids, MPI_COMM_WORLD);
    ASSERT_EQ(all.size(), static_cast<std::size_t>(N));
    std::set<double> uniq(all.begin(), all.end());
    ASSERT_EQ(uniq.size(), static_cast<std::size_t>(N));
    // Ghosts: every particle within `cutoff` of the subdomain box is present locally.
    Halo halo;
    halo.exchange(dd, p, cutoff);
    std::vector<double> loc;
    for (std::size_t i = 0; i < p.n_owned; ++i) {
      loc.push_back(static_cast<double>(p.id[i]));
      loc.push_back(p.x[i].x); loc.push_back(p.x[i].y); loc.push_back(p.x[i].z);
    }
    std::vector<double> every = allgather(loc, MPI_COMM_WORLD);
    std::set<std::int64_t> local_ids(p.id.begin(), p.id.end());
    ASSERT_EQ(local_ids.size(), p.size()) << "a particle appears twice on one rank";
    std::size_t expected_ghosts = 0;
    for (std::size_t k = 0; k < every.size(); k += 4) {
      const Vec3 x{every[k + 1], every[k + 2], every[k + 3]};
      if (dd.owner_of(x) == dd.rank) continue;
      bool near = true;
      for (int d = 0; d < 3; ++d) near = near && x[d] >= dd.lo[d] - cutoff && x[d] < dd.hi[d] + cutoff;
      if (!near) continue;
      ++expected_ghosts;
      ASSERT_TRUE(local_ids.count(static_cast<std::int64_t>(every[k]))) << "missing ghost " << every[k];
    }
    EXPECT_GE(p.n_ghost(), expected_ghosts);
    // Ghost update carries the owners' new positions.
    for (std::size_t i = 0; i < p.n_owned; ++i) p.x[i].x += 1e-9 * static_cast<double>(p.id[i] % 7);
    halo.update(dd, p);
    std::map<std::int64_t, double> owner_x;
    loc.clear();
    for (std::size_t i = 0; i < p.n_owned; ++i) { loc.push_back(static_cast<double>(p.id[i])); loc.push_back(p.x[i].x); }
    every = allgather(loc, MPI_COMM_WORLD);
    for (std::size_t k = 0; k < every.size(); k += 2) owner_x[static_cast<std::int64_t>(every[k])] = every[k + 1];
    for (std::size_t i = p.n_owned; i < p.size(); ++i) ASSERT_EQ(p.x[i].x, owner_x[p.id[i]]);
    // Move everything by a random step up to 1.5 subdomain widths and migrate again.
    p.clear_ghosts();
    for (std::size_t i = 0; i < p.n_owned; ++i)
      for (int d = 0; d < 3; ++d) {
        const double w = (hi[d] - lo[d]) / dd.dims[d];
        p.x[i][d] = std::clamp(p.x[i][d] + 1.5 * w * (u(rng) - 0.5), lo[d], hi[d]);
      }
  }
}

// Memory: the shared start's scatter allocates the store with room for the ghosts the ghost layer's
// volume predicts (Decomposition::ghost_share), so the halo exchange appends them without
// allocating the store's arrays again (a regrown array stays with the process: docs/performance.md
// #memory-per-rank); the prediction is within 25 % of the ghosts of a uniform cloud.
TEST(Halo, StartStoreHasRoomForTheGhosts) {
  const Vec3 lo{0, 0, 0}, hi{0.09, 0.05, 0.04};
  const double cutoff = 0.004;
  Decomposition dd = Decomposition::create(MPI_COMM_WORLD, lo, hi, cutoff);
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(0, 1);
  ParticleStore p;
  const int N = 20000;
  for (int i = 0; i < N; ++i) {
    const Vec3 x{hi.x * u(rng), hi.y * u(rng), hi.z * u(rng)};
    if (i % dd.size == dd.rank) add_sphere(p, i, x, 0.0005, 1000.0);
  }
  std::vector<ContactRecord> none;
  const double share = dd.ghost_share(cutoff);
  scatter_to_owners(dd, p, none, share + 1.0 / 16);
  const Vec3* before = p.x.data();
  const std::size_t owned = p.n_owned;
  Halo halo;
  halo.exchange(dd, p, cutoff);
  EXPECT_EQ(p.x.data(), before) << "the store was allocated again for " << p.n_ghost() << " ghosts";
  const double predicted = share * static_cast<double>(owned);
  EXPECT_NEAR(static_cast<double>(p.n_ghost()), predicted, 0.25 * predicted + 1);
  if (dd.size == 1) EXPECT_EQ(p.n_ghost(), 0u);
  // The next exchange (the same particles) reuses the same arrays.
  halo.exchange(dd, p, cutoff);
  EXPECT_EQ(p.x.data(), before);
}

// Load balance: the cut planes move to the weighted quantiles of the particles' coordinates
// (weight = cost). Particles uniform in z on [0, 1], weight 3 below z = 0.5 and 1 above: the
// cumulative weight is W(z) = 3z (z < 0.5), 1.5 + (z - 0.5) above, total 2.
TEST(Halo, RebalanceMovesCutsToWeightedQuantiles) {
  Decomposition dd = Decomposition::create(MPI_COMM_WORLD, {0, 0, 0}, {0.1, 0.1, 1.0}, 0.01);
  if (dd.size == 1) return;
  ASSERT_EQ(dd.dims[2], dd.size);
  std::vector<Vec3> x;
  std::vector<double> w;
  const int N = 60000;
  for (int i = dd.rank; i < N; i += dd.size) {  // every rank a share, wherever it is
    const double z = (i + 0.5) / N;
    x.push_back({0.05, 0.05, z});
    w.push_back(z < 0.5 ? 3.0 : 1.0);
  }
  dd.rebalance(x, x.size(), w.data());
  auto z_of = [](double W) { return W < 1.5 ? W / 3.0 : 0.5 + (W - 1.5); };
  for (int k = 1; k < dd.size; ++k) {
    const double expect = z_of(2.0 * k / dd.size);
    EXPECT_NEAR(dd.cut(2, k), expect, 2.0 / 2048) << "cut " << k;
  }
  // Unweighted: the plain median(s).
  dd.rebalance(x, x.size());
  for (int k = 1; k < dd.size; ++k) EXPECT_NEAR(dd.cut(2, k), static_cast<double>(k) / dd.size, 2.0 / 2048);
}
