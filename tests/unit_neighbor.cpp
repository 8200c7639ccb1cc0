// Linked cells against brute force: same pairs in the same canonical order; the order key.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "dem/neighbor.hpp"
#include "dem/particles.hpp"
#include "partition/decomposition.hpp"

using namespace fdem;

TEST(Neighbor, LinkedCellsMatchBruteForce) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<Vec3> x;
  std::vector<double> r;
  std::vector<std::int64_t> id, key;
  for (int i = 0; i < 1500; ++i) {
    x.push_back({0.05 * u(rng), 0.03 * u(rng), 0.04 * u(rng)});
    r.push_back(0.001 + 0.001 * u(rng));
    id.push_back((i * 7919) % 1500);  // ids in a scrambled order
    // Keys from the positions, every seventh one shared with its predecessor (ties: by id).
    key.push_back(i % 7 == 6 ? key.back() : order_key(x.back(), {0, 0, 0}, {0.05, 0.03, 0.04}));
  }
  auto before = [&](std::uint32_t i, std::uint32_t j) {
    return key[i] < key[j] || (key[i] == key[j] && id[i] < id[j]);
  };
  for (std::size_t n_owned : {std::size_t(1500), std::size_t(900)}) {
    PairList a, b;
    build_pairs(x, r, id, key, n_owned, 4e-4, a);
    build_pairs_brute(x, r, id, key, n_owned, 4e-4, b);
    ASSERT_GT(a.size(), 1000u);
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t k = 0; k < a.size(); ++k) {
      ASSERT_EQ(a.a[k], b.a[k]);
      ASSERT_EQ(a.b[k], b.b[k]);
      ASSERT_LT(id[a.a[k]], id[a.b[k]]);
      if (k) ASSERT_TRUE(before(a.a[k - 1], a.a[k]) || (a.a[k - 1] == a.a[k] && before(a.b[k - 1], a.b[k])));
      ASSERT_TRUE(a.a[k] < n_owned || a.b[k] < n_owned);
    }
  }
}

TEST(Neighbor, OrderKeyIsTheMortonIndexOfTheCell) {
  // Against a bit-by-bit interleave of the cell indices on the 2^17 grid.
  const Vec3 lo{-1, 0, 2}, hi{1, 0.5, 6};
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(0, 1);
  for (int t = 0; t < 2000; ++t) {
    const Vec3 x{lo.x + (hi.x - lo.x) * u(rng), lo.y + (hi.y - lo.y) * u(rng), lo.z + (hi.z - lo.z) * u(rng)};
    std::uint64_t c[3], want = 0;
    for (int d = 0; d < 3; ++d) c[d] = static_cast<std::uint64_t>((x[d] - lo[d]) / (hi[d] - lo[d]) * 131072.0);
    for (int bit = 0; bit < 17; ++bit)
      for (int d = 0; d < 3; ++d) want |= ((c[d] >> bit) & 1u) << (3 * bit + d);
    ASSERT_EQ(order_key(x, lo, hi), static_cast<std::int64_t>(want));
  }
  // The corners and beyond: clamped, the largest key below 2^51 (exact as a double).
  EXPECT_EQ(order_key(lo, lo, hi), 0);
  EXPECT_EQ(order_key({-5, -5, -5}, lo, hi), 0);
  EXPECT_EQ(order_key(hi, lo, hi), (std::int64_t{1} << 51) - 1);
  EXPECT_EQ(order_key({9, 9, 9}, lo, hi), (std::int64_t{1} << 51) - 1);
  EXPECT_EQ(order_key({std::nan(""), 1, 3}, lo, hi), order_key({-1, 1, 3}, lo, hi));
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

TEST(Decomposition, NotCutAcrossGravity) {
  // The same tall box under gravity along z: cut along x or y instead (equal areas).
  auto g = choose_grid(2, {0.1, 0.1, 0.4}, 0.01, 2);
  EXPECT_EQ(g[2], 1);
  EXPECT_EQ(g[0] * g[1], 2);
  g = choose_grid(8, {0.2, 0.1, 0.4}, 0.01, 2);
  EXPECT_EQ(g, (std::array<int, 3>{4, 2, 1}));
  // No grid leaves z whole (x and y thinner than two ghost layers): z is cut after all.
  g = choose_grid(2, {0.03, 0.03, 0.4}, 0.02, 2);
  EXPECT_EQ(g, (std::array<int, 3>{1, 1, 2}));
  // Gravity's axis: its largest component's.
  EXPECT_EQ(gravity_axis({0, 0, -9.81}), 2);
  EXPECT_EQ(gravity_axis({-9.81, 0.5, 0}), 0);
  EXPECT_EQ(gravity_axis({0, 0, 0}), -1);
}
