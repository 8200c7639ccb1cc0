// fdem-test-ranks: 1 2 3
// Micro-mechanics measurements across ranks (src/app/measurements.cpp, DESIGN.md 4.2):
//  (a) a simple cubic lattice under a uniform overlap: Love-Weber stress k_n delta / a^2 on
//      every axis, fabric I/3, Z = 6 inside, 6 (n-1)/n over the whole lattice;
//  (b) porosity of touching simple cubic lattices: 1 - pi/6 for boxes aligned with the cells
//      and for boxes whose faces cut the spheres through their centres;
//  (c) a settled random bed: every measurement the same on 1, 2 and 3 ranks, contacts across
//      subdomains counted once (force network compared segment by segment).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "app/measurements.hpp"
#include "support/dem_fixtures.hpp"
#include "support/mpi_util.hpp"
#include "base/allgather.hpp"

using namespace fdem;
using namespace fdem::testing;

namespace {

const double kE = 1e7, kRho = 2650;

/// An n x n x n simple cubic lattice of spacing a, centres at (i + 1/2) a, radius r, every
/// particle held fixed (no gravity): positions never change, so a step sets the forces.
DemEngine lattice_engine(MPI_Comm comm, int n, double a, double r) {
  ParticleStore p;
  std::int64_t id = 0;
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i)
        add_sphere(p, id++, {a * (i + 0.5), a * (j + 0.5), a * (k + 0.5)}, r, kRho, 0, {}, kDofAll);
  EngineParams prm;
  prm.domain_min = {0, 0, 0};
  prm.domain_max = {n * a, n * a, n * a};
  prm.gravity = {0, 0, 0};
  prm.dt = 1e-6;
  MaterialTable mats({make_material("m", kE, kRho, 0.5)});
  return DemEngine(comm, prm, mats, {}, p);
}

std::vector<ForceSegment> gather_network(const std::vector<ForceSegment>& mine, MPI_Comm comm) {
  std::vector<double> loc;
  for (const ForceSegment& s : mine)
    loc.insert(loc.end(), {static_cast<double>(s.id_a), static_cast<double>(s.id_b), s.xa.x, s.xa.y, s.xa.z, s.xb.x,
                           s.xb.y, s.xb.z, s.fn, s.force.x, s.force.y, s.force.z});
  const std::vector<double> all = allgather(loc, comm);
  const int total = static_cast<int>(all.size());
  std::vector<ForceSegment> out;
  for (int k = 0; k < total; k += 12) {
    const double* v = &all[k];
    out.push_back({static_cast<std::int64_t>(v[0]), static_cast<std::int64_t>(v[1]), {v[2], v[3], v[4]},
                   {v[5], v[6], v[7]}, v[8], {v[9], v[10], v[11]}});
  }
  std::sort(out.begin(), out.end(), [](const ForceSegment& x, const ForceSegment& y) {
    return x.id_a != y.id_a ? x.id_a < y.id_a : x.id_b < y.id_b;
  });
  return out;
}

}  // namespace

TEST(Measure, LatticeUnderUniformOverlap) {
  const int n = 6;
  const double r = 1e-3, delta = 2e-6, a = 2 * r - delta;
  DemEngine e = lattice_engine(MPI_COMM_WORLD, n, a, r);
  e.step();
  MeasureSpec spec;
  spec.boxes = {MeasureBox{{a, a, a}, {5 * a, 5 * a, 5 * a}},     // interior: 4^3 whole cells
                MeasureBox{{0, 0, 0}, {n * a, n * a, n * a}}};   // the whole lattice
  spec.roses.push_back({0, 2, 4, "xz"});
  spec.force_network = true;
  const MeasureResult m = measure(e, spec);
  const double kn = kE * r;  // two springs 2 E r in series
  const double sigma = kn * delta / (a * a);  // f a / a^3 per axis (compression positive)
  const BoxMeasure& in = m.boxes[0];
  for (int d = 0; d < 3; ++d) EXPECT_NEAR(in.stress[d], sigma, 1e-12 * sigma) << d;
  for (int d = 3; d < 6; ++d) EXPECT_NEAR(in.stress[d], 0.0, 1e-12 * sigma) << d;
  EXPECT_NEAR(in.p, sigma, 1e-12 * sigma);
  EXPECT_NEAR(in.q, 0.0, 1e-9 * sigma);
  for (int d = 0; d < 3; ++d) EXPECT_NEAR(in.fabric[d], 1.0 / 3.0, 1e-15);
  for (int d = 3; d < 6; ++d) EXPECT_NEAR(in.fabric[d], 0.0, 1e-15);
  EXPECT_DOUBLE_EQ(in.z, 6.0);
  EXPECT_DOUBLE_EQ(in.z_mech, 6.0);
  EXPECT_EQ(in.particles, 64.0);
  // Whole lattice: N_c = 3 n^2 (n - 1), Z = 6 (n - 1) / n; the boundary particles still have
  // >= 3 contacts, so Z_mech = Z.
  const BoxMeasure& all = m.boxes[1];
  EXPECT_DOUBLE_EQ(all.contacts, 3.0 * n * n * (n - 1));
  EXPECT_NEAR(all.z, 6.0 * (n - 1) / n, 1e-14);
  EXPECT_NEAR(all.z_mech, all.z, 1e-14);
  // the whole lattice carries the same stress over (n - 1) / n of its length per axis
  EXPECT_NEAR(all.stress[0], sigma * (n - 1) / n, 1e-12 * sigma);
  // rose (xz, 4 bins of 45 degrees): the x contacts at 0, the z contacts at 90 degrees; the y
  // contacts have no component in the plane
  EXPECT_EQ(m.rose_count[0][0], n * n * (n - 1.0));
  EXPECT_EQ(m.rose_count[0][2], n * n * (n - 1.0));
  EXPECT_EQ(m.rose_count[0][1] + m.rose_count[0][3], 0.0);
  EXPECT_NEAR(m.rose_fn[0][0] / m.rose_count[0][0], kn * delta, 1e-12 * kn * delta);
  // force network: every contact exactly once over the ranks
  const std::vector<ForceSegment> net = gather_network(m.network, MPI_COMM_WORLD);
  ASSERT_EQ(net.size(), static_cast<std::size_t>(3 * n * n * (n - 1)));
  for (std::size_t k = 1; k < net.size(); ++k)
    EXPECT_FALSE(net[k].id_a == net[k - 1].id_a && net[k].id_b == net[k - 1].id_b);
  for (const ForceSegment& s : net) EXPECT_NEAR(s.fn, kn * delta, 1e-12 * kn * delta);
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  if (rank == 0)
    std::printf("lattice: sigma %.12e Pa (analytic %.12e), Z %.6f, whole-lattice Z %.6f, %zu segments\n", in.stress[0],
                sigma, in.z, all.z, net.size());
}

TEST(Measure, PorosityOfSimpleCubicLattices) {
  const int n = 6;
  const double a = 2e-3, r = a / 2;  // touching spheres
  DemEngine e = lattice_engine(MPI_COMM_WORLD, n, a, r);
  MeasureSpec spec;
  spec.boxes = {MeasureBox{{a, a, a}, {5 * a, 5 * a, 4 * a}},                  // cell boundaries
                MeasureBox{{1.5 * a, 0.5 * a, 2.5 * a}, {4.5 * a, 5.5 * a, 5.5 * a}}};  // through centres
  spec.has_grid = true;
  spec.grid = MeasureGrid{{0, 0, 0}, {n * a, n * a, n * a}, {3, 2, 3}};  // cells of whole lattice cells
  const MeasureResult m = measure(e, spec);
  const double phi = 1 - M_PI / 6;
  EXPECT_NEAR(m.boxes[0].porosity, phi, 1e-13);
  EXPECT_NEAR(m.boxes[1].porosity, phi, 1e-13);
  for (const BoxMeasure& c : m.cells) EXPECT_NEAR(c.porosity, phi, 1e-13);
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  if (rank == 0)
    std::printf("porosity: aligned %.15f, through centres %.15f, exact 1 - pi/6 = %.15f\n", m.boxes[0].porosity,
                m.boxes[1].porosity, phi);
}

namespace {

struct BedResult {
  MeasureResult m;
  std::vector<ForceSegment> net;
  std::int64_t contacts = 0;
};

BedResult settled_bed(MPI_Comm comm) {
  const double rmax = 1.5e-3;
  MaterialTable mats({make_material("sand", 5e6, kRho, 0.5, 0.25, 0.05, 1.0), make_material("wall", 5e6, 7800, 0.2)});
  const Vec3 lo{0, 0, 0}, hi{0.031, 0.025, 0.05};
  ParticleStore p = lattice_block({0.0005, 0.0005, 0.0005}, 9, 7, 10, rmax, kRho, 7, 0.8, 2.1);
  for (std::size_t i = 0; i < p.size(); ++i) p.v[i] = {0.05 * std::sin(1.0 * i), 0.05 * std::cos(2.0 * i), -0.1};
  std::vector<Wall> walls{make_plane("floor", {0, 0, 0}, {0, 0, 1}, 1), make_plane("x0", {0, 0, 0}, {1, 0, 0}, 1),
                          make_plane("x1", {0.031, 0, 0}, {-1, 0, 0}, 1), make_plane("y0", {0, 0, 0}, {0, 1, 0}, 1),
                          make_plane("y1", {0, 0.025, 0}, {0, -1, 0}, 1)};
  EngineParams prm;
  prm.domain_min = lo; prm.domain_max = hi; prm.gravity = {0, 0, -9.81 * 20}; prm.damping = 0.3;
  prm.dt_safety = 0.3;
  DemEngine e(comm, prm, mats, walls, p);
  e.run(3500);
  reset_displacement_reference(e);
  e.run(300);
  MeasureSpec spec;
  spec.boxes = {MeasureBox{{0.004, 0.004, 0.002}, {0.027, 0.021, 0.012}}, MeasureBox{lo, hi},
                MeasureBox{{0.0, 0.0, 0.0}, {0.0155, 0.025, 0.02}}};
  spec.has_grid = true;
  spec.grid = MeasureGrid{{0, 0, 0}, {0.031, 0.025, 0.03}, {3, 2, 4}};
  spec.roses = {{0, 2, 12, "xz"}, {0, 1, 8, "xy"}};
  spec.force_network = true;
  spec.particle_displacements = true;
  BedResult out;
  out.m = measure(e, spec);
  out.net = gather_network(out.m.network, comm);
  out.contacts = e.stats().contacts;
  return out;
}

/// |a - b| <= tol * scale, NaN == NaN.
bool close(double a, double b, double scale, double tol = 1e-12) {
  if (std::isnan(a) || std::isnan(b)) return std::isnan(a) && std::isnan(b);
  return std::fabs(a - b) <= tol * scale;
}

double worst_box_diff(const BoxMeasure& a, const BoxMeasure& b) {
  double s = 0;
  for (int k = 0; k < 6; ++k) s = std::max(s, std::fabs(a.stress[k]));
  double w = 0;
  auto upd = [&](double x, double y, double scale) {
    if (std::isnan(x) && std::isnan(y)) return;
    w = std::max(w, std::fabs(x - y) / std::max(scale, 1e-300));
  };
  for (int k = 0; k < 6; ++k) upd(a.stress[k], b.stress[k], s);
  upd(a.p, b.p, s);
  upd(a.q, b.q, s);
  upd(a.z, b.z, 6);
  upd(a.z_mech, b.z_mech, 6);
  upd(a.porosity, b.porosity, 1);
  for (int k = 0; k < 6; ++k) upd(a.fabric[k], b.fabric[k], 1);
  double u = 0;
  for (int k = 0; k < 3; ++k) u = std::max(u, std::fabs(a.displacement[k]));
  for (int k = 0; k < 3; ++k) upd(a.displacement[k], b.displacement[k], u);
  upd(a.particles, b.particles, 1);
  upd(a.contacts, b.contacts, 1);
  return w;
}

}  // namespace

TEST(Measure, SettledBedIsTheSameOn1To3Ranks) {
  int world = 0, rank = 0;
  MPI_Comm_size(MPI_COMM_WORLD, &world);
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  std::vector<BedResult> res;
  for (int n = 1; n <= world; ++n) {
    MPI_Comm sub = first_ranks(n);
    BedResult r;
    if (sub != MPI_COMM_NULL) {
      r = settled_bed(sub);
      MPI_Comm_free(&sub);
    }
    res.push_back(r);
    MPI_Barrier(MPI_COMM_WORLD);
  }
  if (rank != 0) return;
  const BedResult& a = res[0];
  ASSERT_EQ(a.m.boxes.size(), 3u);
  const BoxMeasure& b0 = a.m.boxes[0];
  std::printf("bed (1 rank): %lld contacts; box 0: szz %.6e Pa, sxx/szz %.4f, Z %.4f, Z_mech %.4f, porosity %.4f, "
              "fabric zz %.4f\n",
              static_cast<long long>(a.contacts), b0.stress[2], b0.stress[0] / b0.stress[2], b0.z, b0.z_mech,
              b0.porosity, b0.fabric[2]);
  EXPECT_GT(b0.stress[2], 0.0);              // compression positive
  EXPECT_GT(b0.z, 2.5);
  EXPECT_GT(b0.porosity, 0.3);
  EXPECT_LT(b0.porosity, 0.6);
  EXPECT_EQ(static_cast<std::int64_t>(a.net.size()), a.contacts);  // each contact once
  EXPECT_EQ(a.m.boxes[1].contacts, static_cast<double>(a.contacts));  // whole domain: all contacts
  for (int n = 2; n <= world; ++n) {
    const BedResult& b = res[n - 1];
    double worst = 0;
    for (std::size_t k = 0; k < a.m.boxes.size(); ++k) worst = std::max(worst, worst_box_diff(a.m.boxes[k], b.m.boxes[k]));
    ASSERT_EQ(a.m.cells.size(), b.m.cells.size());
    for (std::size_t k = 0; k < a.m.cells.size(); ++k) worst = std::max(worst, worst_box_diff(a.m.cells[k], b.m.cells[k]));
    for (std::size_t k = 0; k < a.m.rose_count.size(); ++k)
      for (std::size_t j = 0; j < a.m.rose_count[k].size(); ++j) {
        EXPECT_EQ(a.m.rose_count[k][j], b.m.rose_count[k][j]);
        EXPECT_TRUE(close(a.m.rose_fn[k][j], b.m.rose_fn[k][j], std::fabs(a.m.rose_fn[k][j])));
      }
    ASSERT_EQ(a.net.size(), b.net.size()) << n << " ranks";
    std::size_t differ = 0;
    for (std::size_t k = 0; k < a.net.size(); ++k) {
      const ForceSegment &x = a.net[k], &y = b.net[k];
      if (x.id_a != y.id_a || x.id_b != y.id_b || !close(x.fn, y.fn, x.fn) || !close(norm(x.force - y.force), 0, x.fn) ||
          !close(norm(x.xa - y.xa), 0, 1) || !close(norm(x.xb - y.xb), 0, 1))
        ++differ;
    }
    std::printf("1 vs %d ranks: worst relative difference of box/cell values %.3e, %zu of %zu segments differ\n", n,
                worst, differ, a.net.size());
    EXPECT_LE(worst, 1e-12) << n << " ranks";
    EXPECT_EQ(differ, 0u) << n << " ranks";
  }
}
