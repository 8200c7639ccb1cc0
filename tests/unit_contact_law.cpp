// The contact-law kernels against closed-form answers (no MPI).
#include <gtest/gtest.h>

#include <cmath>

#include "dem/contact_law.hpp"

using namespace fdem;

TEST(ContactLaw, NormalStiffnessIsSpringsInSeries) {
  EXPECT_DOUBLE_EQ(normal_stiffness(1e7, 1e-3, 1e7, 1e-3), 1e7 * 1e-3);
  const double ka = 2 * 3e7 * 2e-3, kb = 2 * 1e7 * 1e-3;
  EXPECT_DOUBLE_EQ(normal_stiffness(3e7, 2e-3, 1e7, 1e-3), ka * kb / (ka + kb));
}

TEST(ContactLaw, TangentialSpringThenCoulombCap) {
  PairParams p;
  p.kt_kn = 0.25; p.friction = 0.5;
  ContactState s;
  const Vec3 n{0, 0, 1};
  const double kn = 1e4, delta = 1e-4, dt = 1e-5;  // fn = 1 N, cap 0.5 N, kt = 2500 N/m
  const Vec3 vrel{0.1, 0, 0};                       // B slides along +x: 1e-6 m per step
  for (int k = 1; k <= 100; ++k) {
    ContactForce f = contact_law(n, delta, {0, 0, 1e-3}, {0, 0, -1e-3}, vrel, {}, kn, 1e-3, p, dt, s);
    const double elastic = -2500.0 * 1e-6 * k;
    const double expected = std::max(elastic, -0.5);
    ASSERT_NEAR(f.force_b.x, expected, 1e-12) << "step " << k;
    ASSERT_DOUBLE_EQ(f.force_b.z, 1.0);
    // Torques from the tangential force about each centre.
    ASSERT_NEAR(f.torque_b.y, -1e-3 * f.force_b.x, 1e-15);
  }
}

TEST(ContactLaw, RollingMomentCappedAtLimit) {
  PairParams p;
  p.kt_kn = 0.2; p.friction = 0.5; p.beta_r = 1.0; p.eta_r = 1.0;
  const double kn = 1e4, delta = 1e-4, rbar = 1e-3, dt = 1e-2;
  const double kr = p.beta_r * rbar * rbar * p.kt_kn * kn, mlim = p.eta_r * rbar * kn * delta;
  ContactState s;
  const Vec3 n{0, 0, 1}, wrel{0.5, 0, 0};  // w_A - w_B, rolling about x
  for (int k = 1; k <= 400; ++k) {
    ContactForce f = contact_law(n, delta, {0, 0, 1e-3}, {0, 0, -1e-3}, {}, wrel, kn, rbar, p, dt, s);
    const double theta = 0.5 * dt * k;
    const double expected = std::min(kr * theta, mlim);
    ASSERT_NEAR(-f.torque_a.x / expected, 1.0, 1e-12) << "step " << k;
    ASSERT_NEAR(f.torque_a.x + f.torque_b.x, 0.0, 1e-18);
  }
  EXPECT_NEAR(norm(kr * s.rot), mlim, 1e-15);
  // Twisting about the normal is not rolling: no moment from it.
  ContactState s2;
  ContactForce f2 = contact_law(n, delta, {0, 0, 1e-3}, {0, 0, -1e-3}, {}, {0, 0, 3.0}, kn, rbar, p, dt, s2);
  EXPECT_EQ(norm(f2.torque_a), 0.0);
}

TEST(ContactLaw, LocalDampingOpposesMotion) {
  // Force along the velocity is reduced, against it increased (YADE's form).
  EXPECT_DOUBLE_EQ(local_damping(10.0, 1.0, 1e-3, 0.2), 8.0);
  EXPECT_DOUBLE_EQ(local_damping(10.0, -1.0, 1e-3, 0.2), 12.0);
  EXPECT_DOUBLE_EQ(local_damping(10.0, 0.0, 1e-3, 0.2), 8.0);  // mid-step velocity from f
  EXPECT_DOUBLE_EQ(local_damping(-10.0, 1.0, 1e-3, 0.2), -12.0);
  EXPECT_DOUBLE_EQ(local_damping(-10.0, -1.0, 1e-3, 0.2), -8.0);
}
