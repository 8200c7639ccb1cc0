// Particle generation: size distributions (statistics over many draws), the sieve curve
// reproduced by mass, non-overlapping clouds (brute force check), determinism, porosity mode,
// the sphere text format and id assignment.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>

#include "dem/generate.hpp"
#include "io/case.hpp"  // CaseConfig and build_particles(const CaseConfig&)
#include "base/errors.hpp"

namespace fs = std::filesystem;
using namespace fdem;

namespace {

constexpr double kPi = 3.14159265358979323846;

std::vector<double> draws(const SizeDistribution& s, int n, std::uint64_t seed = 1) {
  std::mt19937_64 rng(seed);
  std::vector<double> d(n);
  for (auto& x : d) x = sample_diameter(s, rng);
  return d;
}

double mean(const std::vector<double>& v) {
  double s = 0;
  for (double x : v) s += x;
  return s / v.size();
}

double stdev(const std::vector<double>& v) {
  const double m = mean(v);
  double s = 0;
  for (double x : v) s += (x - m) * (x - m);
  return std::sqrt(s / (v.size() - 1));
}

ParticleSource cloud(std::int64_t count, std::uint64_t seed) {
  ParticleSource s;
  s.kind = ParticleSource::kGenerate;
  s.material = 0;
  s.source_file = "test.yaml";
  s.line = 12;
  s.box_min = {0, 0, 0};
  s.box_max = {0.1, 0.1, 0.1};
  s.count = count;
  s.seed = seed;
  s.size.kind = SizeDistribution::kUniform;
  s.size.dmin = 0.004;
  s.size.dmax = 0.006;
  return s;
}

CaseConfig case_with(std::vector<ParticleSource> src) {
  CaseConfig c;
  c.file = "test.yaml";
  c.domain_min = {-1, -1, -1};
  c.domain_max = {1, 1, 1};
  c.particles = std::move(src);
  return c;
}

std::string temp_file(const std::string& name, const std::string& text) {
  const fs::path p = fs::temp_directory_path() / ("fdem_gen_" + std::to_string(::getpid()) + "_" + name);
  std::ofstream(p) << text;
  return p.string();
}

}  // namespace

TEST(SampleDiameter, Constant) {
  SizeDistribution s;
  s.kind = SizeDistribution::kConstant;
  s.d = 0.003;
  s.scale = 2;
  const auto d = draws(s, 100);
  for (double x : d) EXPECT_DOUBLE_EQ(x, 0.006);
}

TEST(SampleDiameter, Uniform) {
  SizeDistribution s;
  s.kind = SizeDistribution::kUniform;
  s.dmin = 0.004;
  s.dmax = 0.006;
  const auto d = draws(s, 20000);
  EXPECT_NEAR(mean(d), 0.005, 0.00003);  // sd of the mean: 0.00058 / sqrt(20000) = 4e-6
  EXPECT_NEAR(stdev(d), 0.002 / std::sqrt(12.0), 0.00002);
  const auto [lo, hi] = std::minmax_element(d.begin(), d.end());
  EXPECT_GE(*lo, 0.004);
  EXPECT_LE(*hi, 0.006);
  EXPECT_LT(*lo, 0.00401);  // the whole range is used
  EXPECT_GT(*hi, 0.00599);
  // the scale multiplies every diameter
  s.scale = 10;
  const auto e = draws(s, 20000);
  EXPECT_NEAR(mean(e), 0.05, 0.0003);
  EXPECT_DOUBLE_EQ(e[17], 10 * d[17]);
}

TEST(SampleDiameter, Normal) {
  SizeDistribution s;
  s.kind = SizeDistribution::kNormal;
  s.mean = 0.0051;
  s.sd = 0.001;
  const auto d = draws(s, 20000);
  EXPECT_NEAR(mean(d), 0.0051, 0.00003);
  EXPECT_NEAR(stdev(d), 0.001, 0.00003);
  // truncated: all in range, and resampled (not clamped: no pile-up at the bounds)
  s.dmin = 0.004;
  s.dmax = 0.006;
  const auto t = draws(s, 20000);
  int at_bound = 0;
  for (double x : t) {
    EXPECT_GE(x, 0.004);
    EXPECT_LE(x, 0.006);
    at_bound += (x == 0.004 || x == 0.006);
  }
  EXPECT_EQ(at_bound, 0);
  // mean of a normal truncated to [mu - 1.1 sd, mu + 0.9 sd]: mu + sd (phi(a) - phi(b)) / (Phi(b) - Phi(a))
  const double a = -1.1, b = 0.9;
  auto phi = [](double x) { return std::exp(-0.5 * x * x) / std::sqrt(2 * kPi); };
  auto Phi = [](double x) { return 0.5 * std::erfc(-x / std::sqrt(2.0)); };
  const double expect = 0.0051 + 0.001 * (phi(a) - phi(b)) / (Phi(b) - Phi(a));
  EXPECT_NEAR(mean(t), expect, 0.00002);
}

/// Mass-weighted cumulative passing (%) of the samples at size x.
double mass_passing(const std::vector<double>& d, double x) {
  double below = 0, tot = 0;
  for (double v : d) {
    const double m = v * v * v;
    tot += m;
    if (v <= x) below += m;
  }
  return 100 * below / tot;
}

TEST(SampleDiameter, SieveCurveReproducedByMass) {
  SizeDistribution s;
  s.kind = SizeDistribution::kSieve;
  s.sieve_d = {0.001, 0.0015, 0.002, 0.003, 0.004};  // the thesis's direct-shear sand, 1-4 mm
  s.passing = {0, 20, 45, 85, 100};
  const auto d = draws(s, 20000);
  double worst = 0;
  for (std::size_t k = 0; k < s.sieve_d.size(); ++k) {
    const double p = mass_passing(d, s.sieve_d[k]);
    worst = std::max(worst, std::fabs(p - s.passing[k]));
    EXPECT_NEAR(p, s.passing[k], 3.0) << "at sieve " << s.sieve_d[k];
  }
  EXPECT_LT(worst, 3.0);
  for (double x : d) {
    EXPECT_GE(x, 0.001);
    EXPECT_LE(x, 0.004);
  }
  // by NUMBER the fines dominate: far more than the 45 % (by mass) of the particles pass 2 mm
  const double nfine = std::count_if(d.begin(), d.end(), [](double x) { return x <= 0.002; });
  EXPECT_GT(nfine / d.size(), 0.7);
}

// Kolmogorov-Smirnov distance between the samples' mass-passing curve and the requested one,
// over all sizes (not only at the sieves). Within a class [a, b] the sampler draws diameters
// uniformly by number, so the curve it targets there passes P_{k-1} + f_k (x^4 - a^4)/(b^4 - a^4)
// (mass of uniform diameters grows as d^4); at the sieves it is the requested curve. Mass
// weighting leaves an effective sample size n_eff = (sum m)^2 / sum m^2; the 99.9 % critical
// value of the KS statistic is 1.95 / sqrt(n_eff).
TEST(SampleDiameter, SieveCurveKolmogorovSmirnov) {
  SizeDistribution s;
  s.kind = SizeDistribution::kSieve;
  s.sieve_d = {0.001, 0.0015, 0.002, 0.003, 0.004};
  s.passing = {0, 20, 45, 85, 100};
  std::vector<double> d = draws(s, 20000);
  std::sort(d.begin(), d.end());
  auto model = [&](double x) {
    if (x <= s.sieve_d.front()) return 0.0;
    for (std::size_t k = 1; k < s.sieve_d.size(); ++k)
      if (x <= s.sieve_d[k]) {
        const double a = s.sieve_d[k - 1], b = s.sieve_d[k];
        const double f = (std::pow(x, 4) - std::pow(a, 4)) / (std::pow(b, 4) - std::pow(a, 4));
        return (s.passing[k - 1] + (s.passing[k] - s.passing[k - 1]) * f) / 100.0;
      }
    return 1.0;
  };
  double tot = 0, tot2 = 0;
  for (double x : d) { tot += x * x * x; tot2 += std::pow(x, 6); }
  double below = 0, ks = 0;
  for (double x : d) {
    const double before = below / tot;
    below += x * x * x;
    ks = std::max({ks, std::fabs(before - model(x)), std::fabs(below / tot - model(x))});
  }
  const double n_eff = tot * tot / tot2, crit = 1.95 / std::sqrt(n_eff);
  std::printf("sieve curve, 20000 draws: KS distance %.4f (n_eff %.0f, 99.9 %% critical value %.4f)\n", ks, n_eff, crit);
  EXPECT_LT(ks, crit);
}

TEST(SampleDiameter, WideSieveCurveReproducedByMass) {
  // size ratio 16: the coarse class holds few particles by number, so the mass-weighted
  // check needs more samples for the same statistical error
  SizeDistribution s;
  s.kind = SizeDistribution::kSieve;
  s.sieve_d = {0.001, 0.002, 0.004, 0.008, 0.016};
  s.passing = {0, 10, 35, 80, 100};
  const auto d = draws(s, 400000, 11);
  for (std::size_t k = 0; k < s.sieve_d.size(); ++k)
    EXPECT_NEAR(mass_passing(d, s.sieve_d[k]), s.passing[k], 2.0) << "at sieve " << s.sieve_d[k];
}

TEST(SampleDiameter, SieveWithFinesBelowSmallestSieveAndTruncation) {
  SizeDistribution s;
  s.kind = SizeDistribution::kSieve;
  s.sieve_d = {0.002, 0.004, 0.006};
  s.passing = {20, 60, 100};
  s.dmin = 0.001;  // the 20 % below 2 mm lie in [1, 2] mm
  const auto d = draws(s, 20000, 7);
  EXPECT_NEAR(mass_passing(d, 0.002), 20, 3.0);
  EXPECT_NEAR(mass_passing(d, 0.004), 60, 3.0);
  EXPECT_GE(*std::min_element(d.begin(), d.end()), 0.001);
  // truncation at 5 mm: the curve renormalised on [1, 5] mm (class 4-6 mm keeps half its mass)
  s.dmax = 0.005;
  const auto t = draws(s, 20000, 7);
  EXPECT_LE(*std::max_element(t.begin(), t.end()), 0.005);
  EXPECT_NEAR(mass_passing(t, 0.004), 100.0 * 60 / 80, 3.0);
  EXPECT_NEAR(mass_passing(t, 0.002), 100.0 * 20 / 80, 3.0);
}

TEST(Generate, CloudHasNoOverlapsAndIsInsideTheBox) {
  const CaseConfig c = case_with({cloud(2000, 3)});
  const auto p = build_particles(c);
  ASSERT_EQ(p.size(), 2000u);
  for (std::size_t i = 0; i < p.size(); ++i) {
    EXPECT_GE(p[i].r, 0.002);
    EXPECT_LE(p[i].r, 0.003);
    for (int k = 0; k < 3; ++k) {
      ASSERT_GE(p[i].x[k] - p[i].r, 0.0);
      ASSERT_LE(p[i].x[k] + p[i].r, 0.1);
    }
    EXPECT_EQ(p[i].id, static_cast<std::int64_t>(i));
    EXPECT_EQ(p[i].mat, 0);
  }
  int overlaps = 0;
  for (std::size_t i = 0; i < p.size(); ++i)
    for (std::size_t j = i + 1; j < p.size(); ++j) {
      const double rr = p[i].r + p[j].r;
      if (norm2(p[i].x - p[j].x) < rr * rr) ++overlaps;
    }
  EXPECT_EQ(overlaps, 0);
  // spatially ordered: cell (z, y, x) of size dmax is non-decreasing
  const double h = 2 * std::max_element(p.begin(), p.end(), [](auto& a, auto& b) { return a.r < b.r; })->r;
  auto key = [&](const SphereRecord& s) {
    return std::make_tuple(std::floor(s.x.z / h), std::floor(s.x.y / h), std::floor(s.x.x / h));
  };
  for (std::size_t i = 1; i < p.size(); ++i) ASSERT_LE(key(p[i - 1]), key(p[i])) << i;
}

TEST(Generate, DeterministicPerSeed) {
  const auto a = build_particles(case_with({cloud(2000, 3)}));
  const auto b = build_particles(case_with({cloud(2000, 3)}));
  const auto c = build_particles(case_with({cloud(2000, 4)}));
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(a[i].x.x, b[i].x.x);
    ASSERT_EQ(a[i].x.y, b[i].x.y);
    ASSERT_EQ(a[i].x.z, b[i].x.z);
    ASSERT_EQ(a[i].r, b[i].r);
  }
  int same = 0;
  for (std::size_t i = 0; i < a.size(); ++i) same += (a[i].x.x == c[i].x.x && a[i].r == c[i].r);
  EXPECT_EQ(same, 0);
}

TEST(Generate, PorosityModeReachesTarget) {
  for (const auto& [porosity, attempts] : std::vector<std::pair<double, int>>{{0.8, 100}, {0.7, 1000}}) {
    ParticleSource s = cloud(0, 9);
    s.porosity = porosity;
    s.max_attempts = attempts;
    const auto p = build_particles(case_with({s}));
    double solid = 0;
    for (const auto& q : p) solid += 4.0 / 3.0 * kPi * q.r * q.r * q.r;
    const double frac = solid / (0.1 * 0.1 * 0.1);
    EXPECT_NEAR(frac, 1 - porosity, 0.01 * (1 - porosity));  // within 1 % of the target
    EXPECT_GT(p.size(), 2500u);
  }
}

TEST(Generate, TooDenseThrowsWithSourceLine) {
  ParticleSource s = cloud(0, 1);
  s.porosity = 0.45;
  s.size.kind = SizeDistribution::kConstant;
  s.size.d = 0.01;
  try {
    build_particles(case_with({s}));
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), "test.yaml");
    EXPECT_EQ(e.line(), 12);
    EXPECT_NE(std::string(e.what()).find("too dense for the requested porosity 0.45"), std::string::npos) << e.what();
  }
}

// placement: cells -- a count split over the cells (one more in the first count mod C), any
// block of cells built alone equal to its part of the whole, two cells boxes that overlap refused.
TEST(GenerateCells, CountSplitBlocksAndOverlappingBoxes) {
  ParticleSource s = cloud(1001, 4);
  s.placement = ParticleSource::kCells;
  const GenerationCells g = generation_cells(s);  // 0.1 m box, d_max 6 mm: floor(0.1 / 0.12) -> 1
  EXPECT_EQ(g.count(), 1);
  s.box_max = {0.49, 0.25, 0.1};  // 4 x 2 x 1 cells of 0.1225 x 0.125 x 0.1 m
  s.count = 1003;
  const GenerationCells h = generation_cells(s);
  ASSERT_EQ(h.count(), 8);
  const std::vector<ParticleSource> one{s};
  const auto all = build_particle_share(one, {0, 0, 0}, {1, 1, 1}, 0, 1).records;
  ASSERT_EQ(all.size(), 1003u);
  std::size_t at = 0;
  for (int k = 0; k < 3; ++k) {  // three blocks: cells [0, 2), [2, 5), [5, 8)
    const auto part = build_particle_share(one, {0, 0, 0}, {1, 1, 1}, k, 3).records;
    const std::size_t expect = k == 0 ? 2 * 126 : k == 1 ? 126 + 2 * 125 : 3 * 125;  // 1003 = 8 x 125 + 3
    ASSERT_EQ(part.size(), expect) << "block " << k;
    for (const auto& q : part) {
      EXPECT_EQ(q.id, all[at].id);
      EXPECT_EQ(q.x.x, all[at].x.x);
      EXPECT_EQ(q.r, all[at].r);
      ++at;
    }
  }
  ParticleSource t = s;
  t.line = 20;
  t.box_min = {0.4, 0.1, 0.05};
  t.box_max = {0.6, 0.2, 0.2};
  try {
    build_particles(case_with({s, t}));
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.line(), 20);
    EXPECT_NE(std::string(e.what()).find("boxes must not overlap"), std::string::npos) << e.what();
  }
  t.box_min.x = 0.49;  // touching faces: allowed
  EXPECT_EQ(build_particles(case_with({s, t})).size(), 2006u);
}

// A large cloud is generated whole: every sphere inside its box, at its size. (Its speed is a
// benchmark's matter, not a test's: the wall-clock limit this test had failed on a busy machine.)
TEST(Generate, HundredThousandInsideTheBox) {
  ParticleSource s = cloud(100000, 2);
  s.box_max = {0.3, 0.3, 0.3};
  s.size.dmin = 0.002;
  s.size.dmax = 0.006;
  const auto p = build_particles(case_with({s}));
  ASSERT_EQ(p.size(), 100000u);
  std::size_t outside = 0, off_size = 0;
  const double lo[3] = {s.box_min.x, s.box_min.y, s.box_min.z}, hi[3] = {s.box_max.x, s.box_max.y, s.box_max.z};
  for (std::size_t i = 0; i < p.size(); ++i) {
    const double r = p[i].r;
    bool in = true;
    for (int k = 0; k < 3; ++k) in = in && p[i].x[k] - r >= lo[k] - 1e-12 && p[i].x[k] + r <= hi[k] + 1e-12;
    if (!in) ++outside;
    if (2 * r < s.size.dmin - 1e-15 || 2 * r > s.size.dmax + 1e-15) ++off_size;
  }
  EXPECT_EQ(outside, 0u);
  EXPECT_EQ(off_size, 0u);
}

TEST(SphereFile, ReadsScalesAndOffsets) {
  const std::string f = temp_file("ok.txt",
                                  "# id x y z r\n"
                                  "\n"
                                  "3 1 2 3 0.5\n"
                                  "  8   -1 0 1e-1   0.25  # comment\n");
  const auto p = read_sphere_file(f, 2.0, {10, 0, 0}, 4);
  ASSERT_EQ(p.size(), 2u);
  EXPECT_EQ(p[0].id, 3);
  EXPECT_DOUBLE_EQ(p[0].x.x, 12.0);
  EXPECT_DOUBLE_EQ(p[0].x.y, 4.0);
  EXPECT_DOUBLE_EQ(p[0].x.z, 6.0);
  EXPECT_DOUBLE_EQ(p[0].r, 1.0);
  EXPECT_EQ(p[0].mat, 4);
  EXPECT_EQ(p[1].id, 8);
  EXPECT_DOUBLE_EQ(p[1].x.x, 8.0);
  EXPECT_DOUBLE_EQ(p[1].x.z, 0.2);
  EXPECT_DOUBLE_EQ(p[1].r, 0.5);
  fs::remove(f);
}

TEST(SphereFile, MalformedLinesNamed) {
  struct Bad { std::string text; int line; std::string phrase; };
  const std::vector<Bad> bad = {
      {"1 0 0 0 1\n# c\n2 0 0 0\n", 3, "expected 5 values 'id x y z r', got 4"},
      {"1 0 0 0 1 7\n", 1, "expected 5 values 'id x y z r', got 6"},
      {"\n\n1 0 zero 0 1\n", 3, "column 3 (y): expected a number, got 'zero'"},
      {"1.5 0 0 0 1\n", 1, "the id must be a non-negative integer, got '1.5'"},
      {"1 0 0 0 1\n2 0 0 0 -1\n", 2, "radius must be positive, got -1"},
  };
  for (const auto& b : bad) {
    const std::string f = temp_file("bad.txt", b.text);
    try {
      read_sphere_file(f, 1.0, {}, 0);
      ADD_FAILURE() << "no error for " << b.text;
    } catch (const InputError& e) {
      EXPECT_EQ(e.file(), f);
      EXPECT_EQ(e.line(), b.line) << e.what();
      EXPECT_NE(std::string(e.what()).find(f + ":" + std::to_string(b.line) + ": error: " + b.phrase),
                std::string::npos)
          << e.what();
    }
    fs::remove(f);
  }
  try {
    read_sphere_file("/nonexistent/spheres.txt", 1.0, {}, 0);
    ADD_FAILURE();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("cannot read sphere file '/nonexistent/spheres.txt'"), std::string::npos);
  }
}

TEST(BuildParticles, IdsExplicitKeptAutoAfterLargest) {
  const std::string f = temp_file("ids.txt", "5 0 0 0 0.1\n20 0.5 0 0 0.1\n");
  ParticleSource in;
  in.kind = ParticleSource::kInline;
  in.material = 1;
  in.source_file = "c.yaml";
  in.line = 3;
  in.spheres.push_back({-1, {0, 0.5, 0}, 0.1, {0, 0, 1}});
  in.spheres.push_back({7, {0, -0.5, 0}, 0.1, {}});
  ParticleSource fl;
  fl.kind = ParticleSource::kFile;
  fl.material = 0;
  fl.source_file = "c.yaml";
  fl.line = 9;
  fl.path = f;
  fl.velocity = {1, 0, 0};
  ParticleSource g = cloud(3, 1);
  g.box_min = {0.5, 0.5, 0.5};
  g.box_max = {0.9, 0.9, 0.9};
  const auto p = build_particles(case_with({in, fl, g}));
  ASSERT_EQ(p.size(), 7u);
  EXPECT_EQ(p[0].id, 21);  // auto: after the largest explicit id (20), in source order
  EXPECT_DOUBLE_EQ(p[0].v.z, 1.0);
  EXPECT_EQ(p[0].mat, 1);
  EXPECT_EQ(p[1].id, 7);
  EXPECT_EQ(p[2].id, 5);
  EXPECT_DOUBLE_EQ(p[2].v.x, 1.0);
  EXPECT_EQ(p[3].id, 20);
  EXPECT_EQ(p[4].id, 22);
  EXPECT_EQ(p[6].id, 24);

  // duplicate ids: both sources named
  in.spheres[1].id = 20;
  try {
    build_particles(case_with({in, fl}));
    ADD_FAILURE();
  } catch (const InputError& e) {
    const std::string w = e.what();
    EXPECT_NE(w.find("duplicate particle id 20"), std::string::npos) << w;
    EXPECT_NE(w.find("c.yaml:3 (particles[0].inline.spheres[1])"), std::string::npos) << w;
    EXPECT_NE(w.find(f + ":2 (sphere file of particles[1])"), std::string::npos) << w;
  }
  // outside the domain: the id and, for a file, the file's line
  CaseConfig c = case_with({fl});
  c.domain_max = {0.3, 1, 1};
  try {
    build_particles(c);
    ADD_FAILURE();
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), f);
    EXPECT_EQ(e.line(), 2);
    EXPECT_NE(std::string(e.what()).find("particle id 20 (particles[0]) at (0.5, 0, 0) lies outside the domain"),
              std::string::npos)
        << e.what();
  }
  fs::remove(f);
}
