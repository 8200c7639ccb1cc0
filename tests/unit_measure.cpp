// The geometric and tensor helpers of the measurements (src/dem/measure.hpp) against closed
// forms: sphere-box intersection volumes (plane cuts, faces, edges, corners, two planes, a
// partition of space), disc-rectangle areas, rose bins, stress invariants, grid indexing.
#include <gtest/gtest.h>

#include <cmath>

#include "dem/measure.hpp"

using namespace fdem;

namespace {
const double kSphere = 4.0 / 3.0 * M_PI;  // unit sphere volume
const Vec3 kBig{1e3, 1e3, 1e3};

/// Reference for a sphere (r = 1, centre 0) cut by x >= a and y >= b: 1-D integral of the
/// circular-segment area with a composite Gauss rule on many pieces (independent route).
double two_plane_reference(double a, double b) {
  const int pieces = 2000;
  const double gx[3] = {-std::sqrt(0.6), 0.0, std::sqrt(0.6)}, gw[3] = {5.0 / 9, 8.0 / 9, 5.0 / 9};
  // break the integral where the segment changes shape (rho(x) = |b|)
  const double xb = std::sqrt(1 - b * b);
  double edges[4] = {a, std::max(a, std::min(1.0, xb)), 1.0, 1.0};
  double v = 0;
  for (int e = 0; e < 2; ++e) {
    // substitution x = lo + (hi - lo) (1 - (1 - t)^2)... keep simple: split into pieces, graded
    const double lo = edges[e], hi = edges[e + 1];
    if (!(hi > lo)) continue;
    for (int k = 0; k < pieces; ++k) {
      // graded towards both ends (cosine spacing) to resolve the square-root behaviour
      const double t0 = 0.5 - 0.5 * std::cos(M_PI * k / pieces), t1 = 0.5 - 0.5 * std::cos(M_PI * (k + 1) / pieces);
      const double p = lo + (hi - lo) * t0, q = lo + (hi - lo) * t1;
      for (int g = 0; g < 3; ++g) {
        const double x = 0.5 * (p + q) + 0.5 * (q - p) * gx[g];
        const double rho2 = std::max(1 - x * x, 0.0), rho = std::sqrt(rho2);
        double area = 0;
        if (b <= -rho) area = M_PI * rho2;
        else if (b < rho) area = rho2 * std::acos(b / rho) - b * std::sqrt(rho2 - b * b);
        v += 0.5 * (q - p) * gw[g] * area;
      }
    }
  }
  return v;
}
}  // namespace

TEST(MeasureGeometry, SphereCutByOnePlaneIsTheCapVolume) {
  for (double r : {1.0, 0.003}) {
    for (double h : {0.0, 0.05, 0.3, 0.5, 1.0, 1.3, 1.7, 1.999, 2.0}) {
      const Vec3 c{0.1, -0.2, 0.3};
      for (int axis = 0; axis < 3; ++axis) {
        Vec3 lo = c - kBig, hi = c + kBig;
        hi[axis] = c[axis] - r + h * r;  // keep the part below the plane: a cap of height h r
        const double v = sphere_box_volume(c, r, lo, hi);
        const double ref = sphere_cap_volume(r, h * r);
        EXPECT_NEAR(v, ref, 1e-14 * kSphere * r * r * r) << "r " << r << " h " << h << " axis " << axis;
      }
    }
  }
}

TEST(MeasureGeometry, FacesEdgesCornersAndWholeSphere) {
  const Vec3 c{0, 0, 0};
  EXPECT_DOUBLE_EQ(sphere_box_volume(c, 1, {-2, -2, -2}, {2, 2, 2}), kSphere);
  EXPECT_DOUBLE_EQ(sphere_box_volume(c, 1, {1, -2, -2}, {2, 2, 2}), 0.0);
  EXPECT_NEAR(sphere_box_volume(c, 1, {0, -2, -2}, {2, 2, 2}), kSphere / 2, 1e-15);
  EXPECT_NEAR(sphere_box_volume(c, 1, {0, 0, -2}, {2, 2, 2}), kSphere / 4, 1e-15);
  EXPECT_NEAR(sphere_box_volume(c, 1, {0, 0, 0}, {2, 2, 2}), kSphere / 8, 1e-15);
  // the cube inscribed in the sphere is wholly inside it
  const double s = 1 / std::sqrt(3.0);
  EXPECT_NEAR(sphere_box_volume(c, 1, {-s, -s, -s}, {s, s, s}), 8 * s * s * s, 1e-14);
}

TEST(MeasureGeometry, TwoPlanesMatchAnIndependentIntegral) {
  for (double a : {-0.5, 0.0, 0.3, 0.8})
    for (double b : {-0.7, -0.2, 0.0, 0.4}) {
      const double v = sphere_box_volume({0, 0, 0}, 1, {a, b, -2}, {2, 2, 2});
      EXPECT_NEAR(v, two_plane_reference(a, b), 1e-10) << a << " " << b;
    }
}

TEST(MeasureGeometry, PiecesOfAPartitionAddUpToTheSphere) {
  const Vec3 c{0.123, -0.31, 0.077};
  const double r = 0.9;
  double sum = 0;
  // a 4 x 4 x 4 partition of [-1.5, 1.5]^3 that cuts the sphere into many irregular pieces
  const double cuts[5] = {-1.5, -0.41, 0.05, 0.6, 1.5};
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j)
      for (int k = 0; k < 4; ++k)
        sum += sphere_box_volume(c, r, {cuts[i], cuts[j], cuts[k]}, {cuts[i + 1], cuts[j + 1], cuts[k + 1]});
  EXPECT_NEAR(sum, kSphere * r * r * r, 1e-14);
}

TEST(MeasureGeometry, DiscRectangleArea) {
  EXPECT_NEAR(disc_rect_area(1, -2, 2, -2, 2), M_PI, 1e-15);
  EXPECT_NEAR(disc_rect_area(1, 0, 2, -2, 2), M_PI / 2, 1e-15);
  EXPECT_NEAR(disc_rect_area(1, 0, 2, 0, 2), M_PI / 4, 1e-15);
  EXPECT_NEAR(disc_rect_area(1, -0.5, 0.5, -0.5, 0.5), 1.0, 1e-15);
  EXPECT_NEAR(disc_rect_area(2, -1, 0.5, 0.2, 0.7), 1.5 * 0.5, 1e-15);
  // a segment: y >= 0.5 of the unit disc
  const double h = 0.5;
  EXPECT_NEAR(disc_rect_area(1, h, 2, -2, 2), std::acos(h) - h * std::sqrt(1 - h * h), 1e-15);
  EXPECT_EQ(disc_rect_area(0, -1, 1, -1, 1), 0.0);
}

TEST(MeasureGeometry, RoseBins) {
  EXPECT_EQ(rose_bin({1, 0, 0}, 0, 2, 36), 0);
  EXPECT_EQ(rose_bin({-1, 0, 0}, 0, 2, 36), 0);  // the same line
  EXPECT_EQ(rose_bin({0, 0, 1}, 0, 2, 36), 18);
  EXPECT_EQ(rose_bin({0, 0, -1}, 0, 2, 36), 18);
  EXPECT_EQ(rose_bin({-1, 0, 1}, 0, 2, 4), 3);   // 135 degrees
  EXPECT_EQ(rose_bin({1, 0, -1}, 0, 2, 4), 3);
  EXPECT_EQ(rose_bin({0, 1, 0}, 0, 2, 36), -1);  // normal to the xz plane
  EXPECT_EQ(rose_bin({0.3, 1, 0}, 0, 1, 2), 0);   // 73 degrees
  EXPECT_EQ(rose_bin({-0.3, 1, 0}, 0, 1, 2), 1);  // 107 degrees
}

TEST(MeasureGeometry, InvariantsAndFinish) {
  double p, q;
  const double hydro[6] = {5, 5, 5, 0, 0, 0};
  invariants(hydro, p, q);
  EXPECT_DOUBLE_EQ(p, 5);
  EXPECT_NEAR(q, 0, 1e-14);
  const double uni[6] = {0, 0, 9, 0, 0, 0};
  invariants(uni, p, q);
  EXPECT_DOUBLE_EQ(p, 3);
  EXPECT_NEAR(q, 9, 1e-14);
  // one pair along z, both centres inside, compression positive
  MeasureSums s;
  const Vec3 n{0, 0, 1}, fb{0, 0, 2.0};  // force on B (above A), repulsive
  add_contact_side(s, 0.5 * n, -1.0 * fb, n, true);    // side of A: lever up, force down
  add_contact_side(s, -0.5 * n, fb, n, true);          // side of B
  add_particle(s, 1, {1, 0, 0});
  add_particle(s, 1, {0, 0, 0});
  const BoxMeasure m = finish(s, 4.0);
  EXPECT_DOUBLE_EQ(m.stress[2], 2.0 * 1.0 / 4.0);  // f l / V
  EXPECT_DOUBLE_EQ(m.stress[0], 0.0);
  EXPECT_DOUBLE_EQ(m.fabric[2], 1.0);
  EXPECT_DOUBLE_EQ(m.z, 1.0);
  EXPECT_TRUE(std::isnan(m.z_mech));  // both particles are rattlers (1 contact)
  EXPECT_DOUBLE_EQ(m.displacement[0], 0.5);
  EXPECT_DOUBLE_EQ(m.contacts, 1.0);
}

TEST(MeasureGeometry, GridCells) {
  MeasureGrid g{{0, 0, 0}, {1, 2, 3}, {2, 4, 3}};
  EXPECT_EQ(g.cells(), 24u);
  EXPECT_EQ(g.cell_of({0.1, 0.1, 0.1}), 0);
  EXPECT_EQ(g.cell_of({0.6, 0.1, 0.1}), 1);
  EXPECT_EQ(g.cell_of({0.6, 0.6, 2.5}), (2 * 4 + 1) * 2 + 1);
  EXPECT_EQ(g.cell_of({1.0, 0.1, 0.1}), -1);   // half-open
  EXPECT_EQ(g.cell_of({-0.1, 0.1, 0.1}), -1);
  const MeasureBox b = g.cell((2 * 4 + 1) * 2 + 1);
  EXPECT_DOUBLE_EQ(b.lo.x, 0.5);
  EXPECT_DOUBLE_EQ(b.hi.z, 3.0);
  const auto r = g.range(1, -1, 0.7);
  EXPECT_EQ(r[0], 0);
  EXPECT_EQ(r[1], 1);
  const auto e = g.range(0, 1.5, 2.0);
  EXPECT_GT(e[0], e[1]);  // empty
}
