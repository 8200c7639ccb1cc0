// Exact, order-independent sums (src/base/exact_sum.hpp): the same bits whatever the order
// of the terms and however they are split over ranks -- what makes coupled runs rank-independent.
// fdem-test-ranks: 1 2 3
#include <gtest/gtest.h>
#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "base/exact_sum.hpp"

using namespace fdem;

namespace {

int rank_of(MPI_Comm c) { int r = 0; MPI_Comm_rank(c, &r); return r; }
int size_of(MPI_Comm c) { int s = 1; MPI_Comm_size(c, &s); return s; }

/// Terms spanning 30 orders of magnitude and both signs, the same on every rank.
std::vector<double> terms(std::size_t n) {
  std::mt19937_64 g(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0), e(-15.0, 15.0);
  std::vector<double> t(n);
  for (double& x : t) x = u(g) * std::pow(10.0, e(g));
  return t;
}

}  // namespace

TEST(ExactSum, SplitAndMergeAreInverse) {
  std::mt19937_64 g(3);
  for (int k = 0; k < 10000; ++k) {
    // (shifted as unsigned: << of a negative signed value is undefined before C++20)
    using U = unsigned __int128;
    const exact::Int v = static_cast<exact::Int>((static_cast<U>(static_cast<exact::Int>(static_cast<std::int64_t>(g()))) << 62) ^
                                                 static_cast<U>(g()));
    double l[exact::kLimbs];
    exact::split(v, l);
    ASSERT_TRUE(exact::merge(l) == v);
    for (int i = 0; i < 3; ++i) ASSERT_TRUE(l[i] >= 0 && l[i] < 4294967296.0);
  }
  // sums of limbs (as PETSc's ADD scatters form them) merge to the sum
  double a[exact::kLimbs], b[exact::kLimbs], s[exact::kLimbs];
  const exact::Int x = -exact::to_fixed(12345.678), y = exact::to_fixed(-0.5e-12);
  exact::split(x, a);
  exact::split(y, b);
  for (int i = 0; i < exact::kLimbs; ++i) s[i] = a[i] + b[i];
  EXPECT_TRUE(exact::merge(s) == x + y);
}

TEST(ExactSum, ToFixedIsTruncatedScaling) {
  // to_fixed reads the bits of x; it must equal the truncation toward zero of x 2^shift
  // (std::ldexp, exact for a power of two, then the compiler's double -> __int128 conversion)
  // for every magnitude, sign and shift in use -- including exact integers, values whose
  // scaled fraction is cut, zero, subnormals and values below the resolution.
  std::mt19937_64 g(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0), e(-40.0, 17.0);
  std::vector<double> xs = {0.0, -0.0, 1.0, -1.0, 0.5, 3.0, -2.75, 1e-300, -4.9e-324, 0x1p-64, -0x1p-65,
                            0x1p-70, 12345.678, -0x1.fffffffffffffp+40};
  for (int k = 0; k < 200000; ++k) xs.push_back(u(g) * std::pow(10.0, e(g)));
  for (int shift : {0, 20, 64, 100}) {
    for (double x : xs) {
      if (std::abs(std::ldexp(x, shift)) >= 0x1p126) continue;
      const exact::Int ref = static_cast<exact::Int>(std::ldexp(x, shift));
      ASSERT_TRUE(exact::to_fixed(x, shift) == ref) << "x = " << x << ", shift = " << shift;
    }
  }
}

TEST(ExactSum, OrderOfTermsDoesNotMatter) {
  std::vector<double> t = terms(5000);
  exact::ExactSums a(1), b(1);
  for (double x : t) a.add(0, x);
  std::reverse(t.begin(), t.end());
  std::shuffle(t.begin(), t.end(), std::mt19937_64(11));
  for (double x : t) b.add(0, x);
  const double sa = a.sums(MPI_COMM_SELF)[0], sb = b.sums(MPI_COMM_SELF)[0];
  EXPECT_EQ(sa, sb);
  // and it is the sum (to the double rounding of the result)
  long double ref = 0;
  for (double x : t) ref += x;
  EXPECT_NEAR(sa, static_cast<double>(ref), 1e-12 * std::fabs(static_cast<double>(ref)) + 1e-15);
  // a plain double sum does depend on the order here
  double p = 0, q = 0;
  for (double x : t) p += x;
  for (auto it = t.rbegin(); it != t.rend(); ++it) q += *it;
  std::printf("plain double sums in two orders differ by %.3e; exact sums by %.3e\n", p - q, sa - sb);
}

TEST(ExactSum, SameOnAnyNumberOfRanks) {
  // The terms dealt round-robin to the ranks (and, separately, in blocks): the global sums are
  // bitwise those of one rank holding them all.
  const std::vector<double> t = terms(3001);
  const int r = rank_of(MPI_COMM_WORLD), n = size_of(MPI_COMM_WORLD);
  exact::ExactSums all(2), rr(2), blk(2);
  for (std::size_t i = 0; i < t.size(); ++i) {
    all.add(0, t[i]);
    all.add(1, t[i] * t[i]);
    if (static_cast<int>(i % n) == r) { rr.add(0, t[i]); rr.add(1, t[i] * t[i]); }
    if (static_cast<int>(i * n / t.size()) == r) { blk.add(0, t[i]); blk.add(1, t[i] * t[i]); }
  }
  const std::vector<double> s1 = all.sums(MPI_COMM_SELF), s2 = rr.sums(MPI_COMM_WORLD), s3 = blk.sums(MPI_COMM_WORLD);
  for (int k = 0; k < 2; ++k) {
    EXPECT_EQ(s1[k], s2[k]);
    EXPECT_EQ(s1[k], s3[k]);
  }
  // fixed-point forces through the int128 allreduce
  exact::Int loc = 0, whole = 0;
  for (std::size_t i = 0; i < t.size(); ++i) {
    const exact::Int v = exact::to_fixed(t[i] * 1e-3);
    whole += v;
    if (static_cast<int>(i % n) == r) loc += v;
  }
  exact::allreduce_sum(&loc, 1, MPI_COMM_WORLD);
  EXPECT_TRUE(loc == whole);
}

// The step's one reduction (exact::StepSums + exact::allreduce): fixed-point sums and maxima of
// doubles in one buffer give, on any number of ranks, the sums of the terms' fixed-point values
// (as exact::allreduce_sum) and the largest value (NaN wins), slot by slot, in any interleaving.
TEST(ExactSum, StepSumsReduceSumsAndMaximaInOneCall) {
  const MPI_Comm c = MPI_COMM_WORLD;
  const int rank = rank_of(c), size = size_of(c);
  const std::vector<double> t = terms(3000);
  // Three sums and two maxima, interleaved; rank r takes every size-th term from r.
  exact::Int part[3] = {0, 0, 0}, whole[3] = {0, 0, 0};
  double mx = -1e300, whole_mx = -1e300;
  for (std::size_t k = 0; k < t.size(); ++k) {
    const exact::Int v = exact::to_fixed(t[k]);
    whole[k % 3] += v;
    whole_mx = std::max(whole_mx, t[k]);
    if (static_cast<int>(k % static_cast<std::size_t>(size)) == rank) { part[k % 3] += v; mx = std::max(mx, t[k]); }
  }
  exact::StepSums s;
  const std::size_t a = s.add_sums(part, 2);
  const std::size_t m = s.add_max(mx);
  const std::size_t b = s.add_sums(part + 2, 1);
  const std::size_t n = s.add_max(rank == size - 1 ? std::nan("") : -1.0);  // NaN on one rank
  exact::allreduce(s, c);
  EXPECT_TRUE(s.sum(a) == whole[0]);
  EXPECT_TRUE(s.sum(a + 1) == whole[1]);
  EXPECT_TRUE(s.sum(b) == whole[2]);
  EXPECT_EQ(s.max(m), whole_mx);
  EXPECT_TRUE(std::isnan(s.max(n)));
  // the same values as the separate reductions
  exact::Int sep[3] = {part[0], part[1], part[2]};
  exact::allreduce_sum(sep, 3, c);
  double sep_mx = 0;
  MPI_Allreduce(&mx, &sep_mx, 1, MPI_DOUBLE, MPI_MAX, c);
  EXPECT_TRUE(sep[0] == s.sum(a) && sep[1] == s.sum(a + 1) && sep[2] == s.sum(b));
  EXPECT_EQ(sep_mx, s.max(m));
}
