// fdem-test-ranks: 1 2
// Walls (box, facets, free, moving), blocked dofs and particles leaving the domain.
#include <gtest/gtest.h>

#include <cmath>

#include "support/dem_fixtures.hpp"

using namespace fdem;
using namespace fdem::testing;

namespace {

// A flat square [0,L]^2 at height z made of n x n cells, each split into two triangles.
Wall triangulated_floor(double L, int n, double z, int mat) {
  Wall w;
  w.kind = Wall::kFacets; w.name = "mesh"; w.mat = mat;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) w.verts.push_back({L * i / n, L * j / n, z});
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const int a = j * (n + 1) + i, b = a + 1, c = a + n + 2, d = a + n + 1;
      w.tris.push_back({a, b, c});
      w.tris.push_back({a, c, d});
    }
  return w;
}

}  // namespace

// A sphere resting on top of a solid box: overlap = m g / K_N, as on a plane.
TEST(Walls, SphereRestingOnBox) {
  const double r = 2e-3, rho = 2650, E = 5e7, g = 9.81;
  MaterialTable mats({make_material("sand", E, rho, 0.5)});
  ParticleStore p;
  add_sphere(p, 3, {0.011, 0.012, 0.005 + 1.1 * r}, r, rho);
  Wall box;
  box.kind = Wall::kBox; box.name = "block"; box.bmin = {0.0, 0.0, 0.0}; box.bmax = {0.02, 0.02, 0.005};
  DemEngine e(MPI_COMM_WORLD, params({0, 0, 0}, {0.02, 0.02, 0.04}, {0, 0, -g}, 0.3), mats, {box}, p);
  e.run(40000);
  const Gathered s = gather(e);
  const double m = sphere_mass(rho, r), kn = normal_stiffness(E, r, E, r);
  EXPECT_NEAR((0.005 + r - s.x[0].z) / (m * g / kn), 1.0, 1e-6);
  EXPECT_NEAR(s.x[0].x, 0.011, 1e-12);
}

// A sphere sliding at a fixed height over a triangulated floor, straight across edges and
// through vertices: the floor pushes back once, with the same force everywhere.
TEST(Walls, FacetSurfacePushesOnceAcrossEdgesAndVertices) {
  const double r = 2e-3, rho = 2650, E = 5e7, delta = 1e-5;
  MaterialTable mats({make_material("sand", E, rho, 0.0)});  // frictionless: pure normal force
  const double kn = normal_stiffness(E, r, E, r);
  for (const Vec3& vel : {Vec3{0.05, 0, 0}, Vec3{0.05, 0.05, 0}, Vec3{0.03, 0.05, 0}}) {
    ParticleStore p;
    // Starting exactly over a vertex; the diagonal path runs along triangle edges and through
    // every vertex on the diagonal.
    add_sphere(p, 0, {0.01, 0.01, r - delta}, r, rho, 0, vel, kDofAll);
    DemEngine e(MPI_COMM_WORLD, params({0, 0, -0.01}, {0.06, 0.06, 0.01}, {0, 0, 0}, 0.0, 1e-5), mats,
                {triangulated_floor(0.06, 12, 0.0, 0)}, p);
    double fmin = 1e300, fmax = -1e300;
    for (int k = 0; k < 500; ++k) {
      e.step();
      e.reduce_wall_forces();
      const Vec3 f = e.walls().walls[0].force;
      fmin = std::min(fmin, f.z);
      fmax = std::max(fmax, f.z);
      ASSERT_NEAR(f.x, 0.0, 1e-12 * kn * delta);
      ASSERT_NEAR(f.y, 0.0, 1e-12 * kn * delta);
    }
    EXPECT_NEAR(fmin / (-kn * delta), 1.0, 1e-9) << "velocity " << vel.x << "," << vel.y;
    EXPECT_NEAR(fmax / (-kn * delta), 1.0, 1e-9) << "velocity " << vel.x << "," << vel.y;
  }
}

// The same with friction: once the tangential spring has built up, the floor's friction force
// stays at the Coulomb limit mu k_n delta against the motion -- a contact moving on to the next
// triangle keeps its history instead of starting from zero (the friction would drop at every edge).
TEST(Walls, FacetFrictionCarriesAcrossEdges) {
  const double r = 2e-3, rho = 2650, E = 5e7, delta = 1e-5, mu = 0.5;
  MaterialTable mats({make_material("sand", E, rho, mu)});
  const double kn = normal_stiffness(E, r, E, r);
  for (const Vec3& dir : {Vec3{1, 0, 0}, Vec3{0.6, 0.8, 0}, Vec3{std::sqrt(0.5), std::sqrt(0.5), 0}}) {
    ParticleStore p;
    add_sphere(p, 0, {0.0101, 0.0102, r - delta}, r, rho, 0, 0.5 * dir, kDofAll);  // 5e-6 m per step
    DemEngine e(MPI_COMM_WORLD, params({0, 0, -0.01}, {0.06, 0.06, 0.01}, {0, 0, 0}, 0.0, 1e-5), mats,
                {triangulated_floor(0.06, 12, 0.0, 0)}, p);
    double tmin = 1e300, tmax = -1e300, along = 1e300;
    for (int k = 0; k < 7000; ++k) {  // 35 mm: 7 cells of 5 mm, 14 or more edges crossed
      e.step();
      e.reduce_wall_forces();
      const Vec3 f = e.walls().walls[0].force;  // on the wall: along the motion
      if (k < 20) continue;
      const double ft = std::hypot(f.x, f.y);
      tmin = std::min(tmin, ft);
      tmax = std::max(tmax, ft);
      along = std::min(along, dot(f, dir) / ft);
    }
    EXPECT_NEAR(tmin / (mu * kn * delta), 1.0, 1e-9) << "direction " << dir.x << "," << dir.y;
    EXPECT_NEAR(tmax / (mu * kn * delta), 1.0, 1e-9) << "direction " << dir.x << "," << dir.y;
    EXPECT_GT(along, 1 - 1e-9) << "direction " << dir.x << "," << dir.y;
  }
}

// A concave corner of one mesh (a floor and a vertical face sharing an edge) pushes back from
// both faces; a convex ridge (the same mesh seen from outside) pushes once, along the bisector.
TEST(Walls, FacetCornersConcaveAndConvex) {
  const double r = 2e-3, rho = 2650, E = 5e7, delta = 1e-5;
  MaterialTable mats({make_material("sand", E, rho, 0.0)});
  const double kn = normal_stiffness(E, r, E, r);
  Wall corner;
  corner.kind = Wall::kFacets; corner.name = "corner";
  // Floor z = 0 for x in [0, 0.02], wall x = 0.02 for z in [0, 0.02]; shared edge along y.
  corner.verts = {{0, 0, 0}, {0.02, 0, 0}, {0.02, 0.02, 0}, {0, 0.02, 0}, {0.02, 0, 0.02}, {0.02, 0.02, 0.02}};
  corner.tris = {{0, 1, 2}, {0, 2, 3}, {1, 4, 5}, {1, 5, 2}};
  {
    ParticleStore p;  // inside the corner, touching both faces
    add_sphere(p, 0, {0.02 - (r - delta), 0.01, r - delta}, r, rho, 0, {}, kDofAll);
    DemEngine e(MPI_COMM_WORLD, params({-0.01, -0.01, -0.01}, {0.03, 0.03, 0.03}, {0, 0, 0}, 0.0, 1e-5), mats, {corner}, p);
    e.step();
    e.reduce_wall_forces();
    const Vec3 f = e.walls().walls[0].force;
    EXPECT_NEAR(f.x / (kn * delta), 1.0, 1e-9);
    EXPECT_NEAR(f.z / (-kn * delta), 1.0, 1e-9);
  }
  {
    ParticleStore p;  // outside, over the ridge (the edge x = 0.02, z = 0), along the bisector
    const double d = (r - delta) / std::sqrt(2.0);
    add_sphere(p, 0, {0.02 + d, 0.01, -d}, r, rho, 0, {}, kDofAll);
    DemEngine e(MPI_COMM_WORLD, params({-0.01, -0.01, -0.01}, {0.03, 0.03, 0.03}, {0, 0, 0}, 0.0, 1e-5), mats, {corner}, p);
    e.step();
    e.reduce_wall_forces();
    const Vec3 f = e.walls().walls[0].force;
    EXPECT_NEAR(norm(f) / (kn * delta), 1.0, 1e-9);
    EXPECT_NEAR(f.x, -f.z, 1e-12);  // along the bisector: the wall is pushed towards (-1, 0, 1)
    EXPECT_GT(f.z, 0.0);
  }
}

// A free plate (gravity on, z free) resting on a fixed particle: overlap = M g / K_N; the fixed
// particle does not move.
TEST(Walls, FreePlateRestsOnFixedParticle) {
  const double r = 2e-3, rho = 2650, E = 5e7, g = 9.81, M = 0.05;
  MaterialTable mats({make_material("sand", E, rho, 0.5)});
  ParticleStore p;
  const Vec3 x0{0.01, 0.01, 0.01};
  add_sphere(p, 0, x0, r, rho, 0, {}, kDofAll);
  Wall lid = make_plane("lid", {0, 0, 0.01 + 1.05 * r}, {0, 0, -1}, 0);
  lid.motion = Wall::kFree; lid.mass = M; lid.gravity = true; lid.free_dofs = 4;
  DemEngine e(MPI_COMM_WORLD, params({0, 0, 0}, {0.02, 0.02, 0.02}, {0, 0, -g}, 0.3, 2e-5), mats, {lid}, p);
  e.run(60000);
  const Gathered s = gather(e);
  const double kn = normal_stiffness(E, r, E, r);
  const double overlap = r - (0.01 + 1.05 * r + e.walls().walls[0].disp.z - s.x[0].z);
  EXPECT_NEAR(overlap / (M * g / kn), 1.0, 1e-5);
  EXPECT_EQ(s.x[0].x, x0.x);
  EXPECT_EQ(s.x[0].y, x0.y);
  EXPECT_EQ(s.x[0].z, x0.z);
}

// A wall moved with a prescribed velocity sweeps particles out of the domain: they are
// removed, counted and reported by id, never silently lost.
TEST(Walls, ParticlesLeavingTheDomainAreReported) {
  const double r = 1e-3, rho = 2650, E = 1e7;
  MaterialTable mats({make_material("sand", E, rho, 0.3)});
  ParticleStore p;
  for (int i = 0; i < 20; ++i) add_sphere(p, 100 + i, {0.002 + 0.0025 * i, 0.01, 0.01}, r, rho);
  Wall pusher = make_plane("pusher", {0.0005, 0, 0}, {1, 0, 0}, 0);
  pusher.motion = Wall::kVelocity; pusher.vel = {1.0, 0, 0};
  DemEngine e(MPI_COMM_WORLD, params({0, 0, 0}, {0.06, 0.02, 0.02}, {0, 0, 0}, 0.0, 1e-6), mats, {pusher}, p);
  std::vector<std::int64_t> gone;
  for (int k = 0; k < 100 && gone.size() < 20; ++k) {
    e.run(1000);
    std::vector<std::int64_t> g = e.take_removed();
    gone.insert(gone.end(), g.begin(), g.end());
  }
  EXPECT_NEAR(e.walls().walls[0].disp.x, 1.0 * e.time(), 1e-12);
  std::sort(gone.begin(), gone.end());
  ASSERT_EQ(gone.size(), 20u);
  for (int i = 0; i < 20; ++i) EXPECT_EQ(gone[i], 100 + i);
  EXPECT_EQ(e.stats().particles, 0);
  EXPECT_EQ(e.removed_total(), 20);
}
