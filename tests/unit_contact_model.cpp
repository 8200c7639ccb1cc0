// The contact-model table (normal_law() in dem/contact_law.hpp, ContactModel in dem/material.hpp)
// against closed-form answers: Hertz-Mindlin's force-overlap law and tangential stiffness for
// two spheres and a sphere on a flat body; the linear model bit for bit as the contact law was
// written before the table (a copy of that code is kept below as the reference); the automatic
// time step with Hertz pairs.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "app/engine.hpp"
#include "dem/contact_law.hpp"
#include "dem/material.hpp"

using namespace fdem;

namespace {

Material mat(const std::string& name, double E, double nu) {
  Material m;
  m.name = name; m.young = E; m.poisson = nu; m.density = 2650; m.kt_kn = 0.3; m.friction = 0.5;
  m.rolling_stiffness = 0.2; m.rolling_limit = 0.5;
  return m;
}

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }
bool same_bits(const Vec3& a, const Vec3& b) { return same_bits(a.x, b.x) && same_bits(a.y, b.y) && same_bits(a.z, b.z); }

// The contact law as it was before the model table (commit 5f2cb67), the reference for the
// linear model: kn given, fn = kn delta, kt = alpha kn, the rest unchanged.
ContactForce legacy_contact_law(const Vec3& n, double delta, const Vec3& la, const Vec3& lb, const Vec3& vrel,
                                const Vec3& w_a_minus_b, double kn, double rbar, const PairParams& p, double dt,
                                Vec3& ft_state, Vec3& rot_state) {
  ContactForce out;
  const double fn = kn * delta;
  out.fn = fn;
  const double kt = p.kt_kn * kn;
  Vec3 ft = ft_state;
  const double ft_mag2 = norm2(ft);
  if (ft_mag2 > 0.0) {
    const double fn_part = dot(ft, n);
    ft -= fn_part * n;
    const double proj2 = ft_mag2 - fn_part * fn_part;
    if (proj2 > 0.0) ft *= std::sqrt(ft_mag2 / proj2);
  }
  const Vec3 vt = vrel - dot(vrel, n) * n;
  ft -= (kt * dt) * vt;
  const double ft_max = fn * p.friction;
  const double ft_now2 = norm2(ft);
  if (ft_now2 > ft_max * ft_max) ft *= ft_max / std::sqrt(ft_now2);
  ft_state = ft;
  out.force_b = fn * n + ft;
  out.torque_b = cross(lb, out.force_b);
  out.torque_a = cross(la, -out.force_b);
  if (p.beta_r > 0.0) {
    const double kr = p.beta_r * rbar * rbar * kt;
    Vec3 th = rot_state;
    const double th_mag2 = norm2(th);
    if (th_mag2 > 0.0) {
      const double n_part = dot(th, n);
      th -= n_part * n;
      const double proj2 = th_mag2 - n_part * n_part;
      if (proj2 > 0.0) th *= std::sqrt(th_mag2 / proj2);
    }
    th += dt * (w_a_minus_b - dot(w_a_minus_b, n) * n);
    const double m_lim = p.eta_r * rbar * fn;
    const double m2 = kr * kr * norm2(th);
    if (m2 > m_lim * m_lim) th *= m_lim / std::sqrt(m2);
    rot_state = th;
    const Vec3 mr = -kr * th;
    out.torque_a += mr;
    out.torque_b -= mr;
  }
  return out;
}

}  // namespace

TEST(ContactModel, NamesTable) {
  ContactModel m = ContactModel::kLinear;
  ASSERT_TRUE(contact_model_from_name("hertz_mindlin", m));
  EXPECT_EQ(m, ContactModel::kHertzMindlin);
  ASSERT_TRUE(contact_model_from_name("linear", m));
  EXPECT_EQ(m, ContactModel::kLinear);
  EXPECT_FALSE(contact_model_from_name("hertz", m));
  EXPECT_STREQ(contact_model_name(ContactModel::kHertzMindlin), "hertz_mindlin");
  EXPECT_EQ(contact_model_names(), "linear, hertz_mindlin");
}

TEST(ContactModel, PairTableModelsAndModuli) {
  const Material a = mat("a", 7e10, 0.22), b = mat("b", 2e11, 0.3);
  PairOverride o;
  o.a = 0; o.b = 1; o.has_model = true; o.model = ContactModel::kHertzMindlin;
  const MaterialTable lin({a, b});
  EXPECT_EQ(lin.pair(0, 1).model, ContactModel::kLinear);  // the default
  EXPECT_FALSE(lin.any_hertz());
  const MaterialTable one({a, b}, {o});
  EXPECT_EQ(one.pair(0, 1).model, ContactModel::kHertzMindlin);
  EXPECT_EQ(one.pair(1, 0).model, ContactModel::kHertzMindlin);
  EXPECT_EQ(one.pair(0, 0).model, ContactModel::kLinear);
  EXPECT_TRUE(one.any_hertz());
  const MaterialTable all({a, b}, {}, ContactModel::kHertzMindlin);  // the case-wide default
  EXPECT_EQ(all.pair(1, 1).model, ContactModel::kHertzMindlin);
  const double es = 1.0 / ((1 - 0.22 * 0.22) / 7e10 + (1 - 0.3 * 0.3) / 2e11);
  const double gs = 1.0 / (2 * (2 - 0.22) * (1 + 0.22) / 7e10 + 2 * (2 - 0.3) * (1 + 0.3) / 2e11);
  EXPECT_NEAR(one.pair(0, 1).e_star / es, 1.0, 1e-15);
  EXPECT_NEAR(one.pair(0, 1).g_star / gs, 1.0, 1e-15);
  // Two equal materials: E* = E / (2 (1 - nu^2)), G* = E / (4 (2 - nu)(1 + nu)) = G / (2 (2 - nu)).
  EXPECT_NEAR(one.pair(1, 1).e_star / (2e11 / (2 * (1 - 0.09))), 1.0, 1e-15);
  EXPECT_NEAR(one.pair(1, 1).g_star / (2e11 / (4 * 1.7 * 1.3)), 1.0, 1e-15);
}

TEST(ContactModel, HertzForceOverlapTwoSpheresAndWall) {
  const MaterialTable t({mat("glass", 6.3e10, 0.24), mat("steel", 2.1e11, 0.29)}, {},
                        ContactModel::kHertzMindlin);
  const double ra = 1.5e-3, rb = 0.9e-3;
  for (int ab : {0, 1}) {
    const PairParams& p = t.pair(0, ab);
    for (double delta : {1e-9, 3.7e-7, 2e-5, 1e-4}) {
      // Two spheres: R* = ra rb / (ra + rb).
      const double rs = ra * rb / (ra + rb);
      const NormalLaw s = normal_law(p, t[0].young, ra, t[ab].young, rb, effective_radius(ra, rb), delta);
      EXPECT_NEAR(s.fn / (4.0 / 3.0 * p.e_star * std::sqrt(rs) * std::pow(delta, 1.5)), 1.0, 1e-12) << delta;
      EXPECT_NEAR(s.kt / (8.0 * p.g_star * std::sqrt(rs * delta)), 1.0, 1e-12) << delta;
      EXPECT_NEAR(s.k / (2.0 * p.e_star * std::sqrt(rs * delta)), 1.0, 1e-12) << delta;
      // k is dfn/ddelta (central difference).
      const double h = 1e-4 * delta;
      const double fp = normal_law(p, 0, ra, 0, rb, rs, delta + h).fn, fm = normal_law(p, 0, ra, 0, rb, rs, delta - h).fn;
      EXPECT_NEAR((fp - fm) / (2 * h) / s.k, 1.0, 1e-6) << delta;
      // A sphere on a flat body (wall, FE triangle): R* = r.
      const NormalLaw w = normal_law(p, t[0].young, ra, t[ab].young, ra, ra, delta);
      EXPECT_NEAR(w.fn / (4.0 / 3.0 * p.e_star * std::sqrt(ra) * std::pow(delta, 1.5)), 1.0, 1e-12) << delta;
      EXPECT_NEAR(w.kt / (8.0 * p.g_star * std::sqrt(ra * delta)), 1.0, 1e-12) << delta;
    }
  }
}

// Hertz pair, one step: the tangential increment is -kt vt dt with Mindlin's kt, capped by
// Coulomb at friction * fn, and the rolling stiffness is beta_r rbar^2 kt.
TEST(ContactModel, HertzTangentialSpringAndCap) {
  const MaterialTable t({mat("glass", 6.3e10, 0.24)}, {}, ContactModel::kHertzMindlin);
  const PairParams& p = t.pair(0, 0);
  const double r = 1e-3, delta = 1e-6, dt = 1e-7;
  const NormalLaw nl = normal_law(p, t[0].young, r, t[0].young, r, 0.5 * r, delta);
  Vec3 ft{}, rot{};
  const Vec3 n{0, 0, 1}, vrel{0.01, 0, 0}, wrel{3.0, 0, 0};
  const ContactForce f = contact_force(n, nl.fn, nl.kt, {0, 0, r}, {0, 0, -r}, vrel, wrel, r, p, dt, ft, rot);
  EXPECT_NEAR(ft.x / (-nl.kt * 0.01 * dt), 1.0, 1e-14);
  EXPECT_EQ(f.fn, nl.fn);
  EXPECT_NEAR(f.torque_a.x / (-p.beta_r * r * r * nl.kt * 3.0 * dt), 1.0, 1e-12);
  Vec3 ft2{}, rot2{};
  contact_force(n, nl.fn, nl.kt, {0, 0, r}, {0, 0, -r}, {10.0, 0, 0}, {}, r, p, dt, ft2, rot2);
  EXPECT_NEAR(-ft2.x / (p.friction * nl.fn), 1.0, 1e-14);  // slipping
}

// The linear model through the table gives the same bits as the law before the table, over a
// sliding, rolling, turning contact (tangential history rotation, Coulomb cap, rolling cap).
TEST(ContactModel, LinearIsBitwiseTheOldLaw) {
  const MaterialTable t({mat("sand", 7e7, 0.2), mat("wall", 2e8, 0.3)});
  for (int ab : {0, 1}) {
    const PairParams& p = t.pair(0, ab);
    ASSERT_EQ(p.model, ContactModel::kLinear);
    const double ra = 1.3e-3, rb = ab == 0 ? 0.7e-3 : ra, dt = 2e-6;
    Vec3 ft_new{}, rot_new{}, ft_old{}, rot_old{};
    for (int k = 0; k < 300; ++k) {
      const double th = 0.01 * k;
      const Vec3 n{std::sin(th) * 0.6, std::cos(th) * 0.6, 0.8};
      const double delta = 1e-6 * (1.0 + 0.5 * std::sin(0.1 * k));
      const Vec3 la = (ra - 0.5 * delta) * n, lb = -(rb - 0.5 * delta) * n;
      const Vec3 vrel{0.02 * std::cos(0.05 * k), 0.01, -0.003}, wrel{5.0, -2.0 * std::sin(0.07 * k), 1.0};
      const double rbar = 0.5 * (ra + rb);
      const NormalLaw nl = normal_law(p, t[0].young, ra, t[ab].young, rb, effective_radius(ra, rb), delta);
      const double kn = normal_stiffness(t[0].young, ra, t[ab].young, rb);
      ASSERT_TRUE(same_bits(nl.fn, kn * delta));
      ASSERT_TRUE(same_bits(nl.kt, p.kt_kn * kn));
      ASSERT_TRUE(same_bits(nl.k, kn));
      const ContactForce a = contact_force(n, nl.fn, nl.kt, la, lb, vrel, wrel, rbar, p, dt, ft_new, rot_new);
      const ContactForce b = legacy_contact_law(n, delta, la, lb, vrel, wrel, kn, rbar, p, dt, ft_old, rot_old);
      ASSERT_TRUE(same_bits(a.force_b, b.force_b)) << "step " << k;
      ASSERT_TRUE(same_bits(a.torque_a, b.torque_a)) << "step " << k;
      ASSERT_TRUE(same_bits(a.torque_b, b.torque_b)) << "step " << k;
      ASSERT_TRUE(same_bits(a.fn, b.fn));
      ASSERT_TRUE(same_bits(ft_new, ft_old) && same_bits(rot_new, rot_old)) << "step " << k;
    }
  }
}

// The critical step: linear tables keep sqrt(m / (2 E r)) (the same bits); a table with a Hertz
// pair takes the smaller of it and the Rayleigh step pi r sqrt(rho/G) / (0.1631 nu + 0.8766).
TEST(ContactModel, CriticalStepWithHertzPairs) {
  Material m = mat("sand", 1e8, 0.3);
  ParticleStore p;
  const double r = 1e-3, mass = sphere_mass(m.density, r);
  p.push_back({0, 0, 0}, {}, {}, r, mass, 0, 0, 0, {0, 0, 0});
  const double lin = std::sqrt(mass / (2.0 * m.young * r));
  EXPECT_TRUE(same_bits(critical_dt(p, MaterialTable({m})), lin));
  const double g = m.young / (2 * 1.3);
  const double rayleigh = M_PI * r * std::sqrt(m.density / g) / (0.1631 * 0.3 + 0.8766);
  EXPECT_GT(rayleigh, lin);  // for a sphere the spring's estimate is the smaller
  EXPECT_DOUBLE_EQ(critical_dt(p, MaterialTable({m}, {}, ContactModel::kHertzMindlin)), std::min(lin, rayleigh));
  // For a sphere of its material's density and nu >= 0 the Rayleigh step is the larger (>= 3.5x); a
  // grain 100x heavier than its density says (mass scaling) shows the branch where it decides.
  Material soft = mat("soft", 1e8, 0.49);
  soft.density = 10;
  ParticleStore q;
  q.push_back({0, 0, 0}, {}, {}, r, 100 * sphere_mass(soft.density, r), 0, 0, 0, {0, 0, 0});
  const double lin_q = std::sqrt(q.m[0] / (2.0 * soft.young * r));
  const double ray_q = M_PI * r * std::sqrt(soft.density / (soft.young / 2.98)) / (0.1631 * 0.49 + 0.8766);
  ASSERT_LT(ray_q, lin_q);
  EXPECT_DOUBLE_EQ(critical_dt(q, MaterialTable({soft}, {}, ContactModel::kHertzMindlin)), ray_q);
}
