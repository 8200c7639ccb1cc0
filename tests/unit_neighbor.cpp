// Linked cells against brute force: same pairs in the same canonical order.
#include <gtest/gtest.h>

#include <random>

#include "dem/neighbor.hpp"
#include "partition/decomposition.hpp"

using namespace fdem;

TEST(Neighbor, LinkedCellsMatchBruteForce) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<Vec3> x;
  std::vector<double> r;
  std::vector<std::int64_t> id;
  for (int i = 0; i < 1500; ++i) {
    x.push_back({0.05 * u(rng), 0.03 * u(rng), 0.04 * u(rng)});
    r.push_back(0.001 + 0.001 * u(rng));
    id.push_back((i * 7919) % 1500);  // ids in a scrambled order
  }
  for (std::size_t n_owned : {std::size_t(1500), std::size_t(900)}) {
    PairList a, b;
    build_pairs(x, r, id, n_owned, 4e-4, a);
    build_pairs_brute(x, r, id, n_owned, 4e-4, b);
    ASSERT_GT(a.size(), 1000u);
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t k = 0; k < a.size(); ++k) {
      ASSERT_EQ(a.a[k], b.a[k]);
      ASSERT_EQ(a.b[k], b.b[k]);
      ASSERT_LT(id[a.a[k]], id[a.b[k]]);
      if (k) ASSERT_TRUE(id[a.a[k - 1]] < id[a.a[k]] ||
                         (id[a.a[k - 1]] == id[a.a[k]] && id[a.b[k - 1]] < id[a.b[k]]));
      ASSERT_TRUE(a.a[k] < n_owned || a.b[k] < n_owned);
    }
  }
}

TEST(Decomposition, GridShapedToTheBox) {
  // Tall box: 2 ranks cut across the height.
  auto g = choose_grid(2, {0.1, 0.1, 0.4}, 0.01);
  EXPECT_EQ(g, (std::array<int, 3>{1, 1, 2}));
  g = choose_grid(4, {1, 1, 0.2}, 0.01);
  EXPECT_EQ(g, (std::array<int, 3>{2, 2, 1}));
  g = choose_grid(3, {0.68, 0.30, 0.62}, 0.01);
  EXPECT_EQ(g[0] * g[1] * g[2], 3);
  EXPECT_EQ(g[1], 1);  // never cut the thin direction
  // Too narrow for the ghost layer: no grid.
  g = choose_grid(8, {0.01, 0.01, 0.01}, 0.02);
  EXPECT_EQ(g[0], 0);
}
