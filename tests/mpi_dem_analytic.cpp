// fdem-test-ranks: 1 2
// Analytical checks of the DEM engine (DESIGN.md 4.1), run through the full parallel engine.
// On 2 ranks the contacts happen across the subdomain boundary (ghosts, migration).
#include <gtest/gtest.h>

#include <cmath>

#include "support/dem_fixtures.hpp"

using namespace fdem;
using namespace fdem::testing;

namespace {

}  // namespace

// Two equal spheres meet head-on: linear spring, no damping. The contact lasts half a period
// of the spring-mass system, pi*sqrt(m_eff/K_N), and the restitution coefficient is 1.
TEST(DemAnalytic, HeadOnCollisionDurationAndRestitution) {
  const double r = 1e-3, rho = 2600, E = 1e7, v0 = 0.1;
  MaterialTable mats({make_material("m", E, rho, 0.5)});
  ParticleStore p;
  // Along x, the long direction of the box, so 2 ranks split between the two spheres.
  add_sphere(p, 0, {0.04 - 1.01 * r, 0.005, 0.005}, r, rho, 0, {v0, 0, 0});
  add_sphere(p, 1, {0.04 + 1.01 * r, 0.005, 0.005}, r, rho, 0, {-v0, 0, 0});
  const double m = sphere_mass(rho, r), kn = normal_stiffness(E, r, E, r);
  const double t_contact = M_PI * std::sqrt(0.5 * m / kn);
  const double dt = t_contact / 400;
  DemEngine e(MPI_COMM_WORLD, params({0, 0, 0}, {0.08, 0.01, 0.01}, {0, 0, 0}, 0.0, dt), mats, {}, p);
  // Contact begins when the gap 0.02 r closes.
  double t_first = -1, t_last = -1;
  for (int k = 0; k < 20000; ++k) {
    e.step();
    const Gathered g = gather(e);
    const double gap = norm(g.x[1] - g.x[0]) - 2 * r;
    if (gap < 0 && t_first < 0) t_first = e.time();
    if (gap < 0) t_last = e.time();
    if (t_first > 0 && gap > r) break;
  }
  ASSERT_GT(t_first, 0);
  const Gathered g = gather(e);
  EXPECT_NEAR((t_last - t_first + dt) / t_contact, 1.0, 0.01);
  EXPECT_NEAR(g.v[0].x / -v0, 1.0, 1e-3);   // restitution 1: velocities reversed
  EXPECT_NEAR(g.v[1].x / v0, 1.0, 1e-3);
  EXPECT_NEAR(g.v[0].x + g.v[1].x, 0.0, 1e-12);  // momentum
}

// A sphere resting on a plane under gravity: overlap = m g / K_N (K_N with the wall's E and
// the particle's radius).
TEST(DemAnalytic, SphereRestingOnPlane) {
  const double r = 2e-3, rho = 2650, E = 5e7, Ew = 2e8, g = 9.81;
  MaterialTable mats({make_material("sand", E, rho, 0.5), make_material("steel", Ew, 7800, 0.3)});
  ParticleStore p;
  add_sphere(p, 7, {0.01, 0.01, r * 1.2}, r, rho);
  std::vector<Wall> walls{make_plane("floor", {0, 0, 0}, {0, 0, 1}, 1)};
  DemEngine e(MPI_COMM_WORLD, params({0, 0, 0}, {0.02, 0.02, 0.02}, {0, 0, -g}, 0.3, 0), mats, walls, p);
  e.run(40000);
  const Gathered s = gather(e);
  const double m = sphere_mass(rho, r), kn = normal_stiffness(E, r, Ew, r);
  const double overlap = r - s.x[0].z;
  EXPECT_NEAR(overlap / (m * g / kn), 1.0, 1e-6);
  e.reduce_wall_forces();
  EXPECT_NEAR(e.walls().walls[0].force.z / (-m * g), 1.0, 1e-6);
}

// A sphere with blocked rotations (a sliding block) on a plane under inclined gravity:
// it sticks when tan(theta) < mu and slides with a = g (sin(theta) - mu cos(theta)) above.
TEST(DemAnalytic, InclinedPlaneStickAndSlide) {
  const double r = 2e-3, rho = 2650, E = 5e7, g = 9.81, mu = 0.4;
  for (double ratio : {0.8, 1.5}) {
    const double theta = std::atan(ratio * mu);
    const Vec3 grav{g * std::sin(theta), 0, -g * std::cos(theta)};
    MaterialTable mats({make_material("sand", E, rho, mu)});
    const double m = sphere_mass(rho, r), kn = normal_stiffness(E, r, E, r);
    ParticleStore p;
    // Start at the static overlap so the normal force is balanced from the first step.
    add_sphere(p, 0, {0.01, 0.01, r - m * g * std::cos(theta) / kn}, r, rho, 0, {}, kDofRX | kDofRY | kDofRZ);
    std::vector<Wall> walls{make_plane("slope", {0, 0, 0}, {0, 0, 1}, 0)};
    DemEngine e(MPI_COMM_WORLD, params({0, 0, -0.01}, {0.2, 0.02, 0.02}, grav, 0.0, 0), mats, walls, p);
    e.run(2000);
    const Gathered a = gather(e);
    const double t0 = e.time();
    e.run(2000);
    const Gathered b = gather(e);
    const double acc = (b.v[0].x - a.v[0].x) / (e.time() - t0);
    if (ratio < 1) {
      EXPECT_LT(std::abs(b.v[0].x), 1e-3 * g * e.time());  // stuck (only elastic creep)
      EXPECT_LT(std::abs(acc), 1e-3 * g);
    } else {
      EXPECT_NEAR(acc / (g * (std::sin(theta) - mu * std::cos(theta))), 1.0, 1e-6);
    }
  }
}
