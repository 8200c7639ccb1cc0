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

namespace {

// Two spheres rolled about x by prescribed w_A - w_B, the normal force and K_T held: the
// moment on A after each step. rbar 5 mm, F_N 10 N, eta_r 1: M_lim = 0.05 N m; beta_r 0.12 and
// K_T 40 000 N/m: K_r = 0.12 N m/rad, the cap reached at 0.417 rad (the two spheres).
struct RollRig {
  PairParams p;
  double fn = 10.0, rbar = 5e-3, kt = 0, dt = 1e-3;
  Vec3 ft, rot;
  explicit RollRig(RollingLaw law) {
    p.kt_kn = 0.25; p.friction = 0.5; p.beta_r = 0.12; p.eta_r = 1.0; p.rolling = law;
    kt = 40000.0;
  }
  double kr() const { return p.beta_r * rbar * rbar * kt; }
  double mlim() const { return p.eta_r * rbar * fn; }
  // Roll by `dtheta` (rad) in steps of `step` (rad); returns the last moment on A.
  Vec3 roll(const Vec3& axis, double dtheta, double step = 1e-3) {
    const int n = static_cast<int>(std::lround(std::fabs(dtheta) / step));
    const Vec3 w = (dtheta / (n * dt)) * axis;
    ContactForce f;
    for (int k = 0; k < n; ++k)
      f = contact_force({0, 0, 1}, fn, kt, {0, 0, -rbar}, {0, 0, rbar}, {}, w, rbar, p, dt, ft, rot);
    return f.torque_a;
  }
};

}  // namespace

// The reversal past the cap (0.8 rad forward, then back to 0.7, 0.3, 0): the incremental law
// unloads from the cap (its stored rotation was capped), eq 3-8 as printed caps only the moment
// of the total rotation. Closed forms: incremental M = K_r (theta_cap - back), capped at -M_lim;
// total M = min(K_r theta, M_lim).
TEST(ContactLaw, RollingReversalIncrementalAgainstTotal) {
  const Vec3 x{1, 0, 0};
  RollRig inc(RollingLaw::kIncremental), tot(RollingLaw::kTotal);
  const double kr = inc.kr(), mlim = inc.mlim(), cap = mlim / kr;
  ASSERT_NEAR(kr, 0.12, 1e-15);
  ASSERT_NEAR(cap, 0.05 / 0.12, 1e-12);
  ASSERT_NEAR(mlim, 0.05, 1e-15);
  // Moments on A resist A's rotation: M_A = -K_r theta.
  EXPECT_NEAR(-inc.roll(x, 0.8).x, mlim, 1e-12);
  EXPECT_NEAR(-tot.roll(x, 0.8).x, mlim, 1e-12);
  const double back[] = {0.1, 0.5, 0.8};  // to 0.7, 0.3, 0.0
  double done = 0;
  for (double b : back) {
    const double mi = -inc.roll(x, -(b - done)).x, mt = -tot.roll(x, -(b - done)).x;
    done = b;
    const double theta = 0.8 - b;
    EXPECT_NEAR(mi, std::max(kr * (cap - b), -mlim), 1e-9) << "incremental at " << theta;
    EXPECT_NEAR(mt, std::min(kr * theta, mlim), 1e-9) << "total at " << theta;
  }
  // The table (moments in N m to 4 decimals): incremental 0.0380 / -0.0100 / -0.0460,
  // total 0.0500 / 0.0360 / 0.0000 at 0.7 / 0.3 / 0.0 rad.
  RollRig i2(RollingLaw::kIncremental), t2(RollingLaw::kTotal);
  i2.roll(x, 0.8); t2.roll(x, 0.8);
  EXPECT_NEAR(-i2.roll(x, -0.1).x, 0.0380, 5e-5);
  EXPECT_NEAR(-t2.roll(x, -0.1).x, 0.0500, 5e-5);
  EXPECT_NEAR(-i2.roll(x, -0.4).x, -0.0100, 5e-5);
  EXPECT_NEAR(-t2.roll(x, -0.4).x, 0.0360, 5e-5);
  EXPECT_NEAR(-i2.roll(x, -0.3).x, -0.0460, 5e-5);
  EXPECT_NEAR(t2.roll(x, -0.3).x, 0.0, 1e-12);
  EXPECT_NEAR(norm(t2.rot), 0.0, 1e-12);  // the total rotation is back to zero
}

// The total law keeps twist (the thesis's engine: one K_r for twist and bending, one cap on the
// whole moment), sums rotations about different axes as a vector, and reads a sum past pi as
// the rotation it is (its engine takes the angle of a quaternion, in (-pi, pi]).
TEST(ContactLaw, TotalRollingLawTwistAxesAndWrap) {
  const Vec3 x{1, 0, 0}, y{0, 1, 0}, z{0, 0, 1};
  RollRig t(RollingLaw::kTotal);
  const double kr = t.kr();
  Vec3 m = t.roll(z, 0.2);  // twist about the normal: resisted by the same K_r
  EXPECT_NEAR(m.z, -kr * 0.2, 1e-12);
  EXPECT_NEAR(norm(m), kr * 0.2, 1e-12);
  RollRig i(RollingLaw::kIncremental);
  EXPECT_EQ(norm(i.roll(z, 0.2)), 0.0);  // the incremental law has no twist resistance
  // 0.1 about x then 0.15 about y then 0.05 twist: theta = (0.1, 0.15, 0.05), one cap on |M|.
  RollRig t2(RollingLaw::kTotal);
  t2.roll(x, 0.1); t2.roll(y, 0.15);
  m = t2.roll(z, 0.05);
  const Vec3 th{0.1, 0.15, 0.05};
  EXPECT_NEAR(norm(m + kr * th), 0.0, 1e-12);
  RollRig t3(RollingLaw::kTotal);
  t3.roll(x, 0.4); t3.roll(y, 0.4);  // |theta| 0.566 > 0.42: |M| = M_lim along -theta
  m = t3.roll(z, 1e-9, 1e-9);  // one step of (almost) nothing, to read the moment
  EXPECT_NEAR(norm(m), t3.mlim(), 1e-12);
  EXPECT_NEAR(m.x, m.y, 1e-15);
  EXPECT_LT(m.x, 0.0);
  // Past pi: 4 rad about x is the rotation of 4 - 2 pi = -2.28 rad; with the cap lifted the
  // moment is -K_r (4 - 2 pi), against the sense of the roll.
  RollRig t4(RollingLaw::kTotal);
  t4.p.eta_r = 1e6;
  m = t4.roll(x, 4.0);
  EXPECT_NEAR(m.x, -kr * (4.0 - 2.0 * 3.14159265358979323846), 1e-9);
  EXPECT_NEAR(norm(t4.rot), 4.0, 1e-9);  // the stored sum is not wrapped
}

TEST(ContactLaw, LocalDampingOpposesMotion) {
  // Force along the velocity is reduced, against it increased (YADE's form).
  EXPECT_DOUBLE_EQ(local_damping(10.0, 1.0, 1e-3, 0.2), 8.0);
  EXPECT_DOUBLE_EQ(local_damping(10.0, -1.0, 1e-3, 0.2), 12.0);
  EXPECT_DOUBLE_EQ(local_damping(10.0, 0.0, 1e-3, 0.2), 8.0);  // mid-step velocity from f
  EXPECT_DOUBLE_EQ(local_damping(-10.0, 1.0, 1e-3, 0.2), -12.0);
  EXPECT_DOUBLE_EQ(local_damping(-10.0, -1.0, 1e-3, 0.2), -8.0);
}
