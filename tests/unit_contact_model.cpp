// The contact-model table (normal_law() in dem/contact_law.hpp, ContactModel in dem/material.hpp)
// against closed-form answers: Hertz-Mindlin's force-overlap law and tangential stiffness for
// two spheres and a sphere on a flat body; the automatic time step with Hertz pairs; and the
// whole law (normal_law() then contact_force(), as the engine calls them) driven through
// two-body protocols whose answers are derived by hand from the law's definition: normal loading
// at fixed overlap, tangential loading to Coulomb slip, reversal, a normal turning under a stored
// shear force, rolling to the moment cap and back (both rolling laws), and the torques of the
// lever arms. No copy of the law is kept here as a reference: every expected value is a closed
// form of the inputs.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <iomanip>
#include <sstream>
#include <string>
#include <vector>

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

// The tolerance of the protocols below, relative to the scale of the quantity compared. The
// expected values are closed forms evaluated in floating point, while the law sums its spring
// increment by increment (up to ~100 steps here) and re-projects its history each step: each
// operation rounds by ~1e-16 relative, so the two agree to ~1e-14. 1e-12 leaves room for that
// and nothing else: an error of the law's slope, cap or direction by 1e-9 relative fails.
constexpr double kTol = 1e-12;

std::string str(const Vec3& v) {
  std::ostringstream s;
  s << std::setprecision(17) << "(" << v.x << ", " << v.y << ", " << v.z << ")";
  return s.str();
}

// |got - want| <= kTol * scale (scale: the magnitude the comparison is relative to).
::testing::AssertionResult near(const Vec3& got, const Vec3& want, double scale) {
  const double err = norm(got - want);
  if (err <= kTol * scale) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "got " << str(got) << ", want " << str(want) << ": |diff| " << err
                                       << " > " << kTol << " * " << scale;
}

// The frame of the protocols: a normal n in no axis' direction and two tangents t, b with
// (n, t, b) orthonormal and b = n x t.
const Vec3 kN{1.0 / 3, 2.0 / 3, 2.0 / 3}, kT{2.0 / 3, 1.0 / 3, -2.0 / 3}, kB{-2.0 / 3, 2.0 / 3, -1.0 / 3};

// Two bodies for the protocols: sphere A (radius ra) at the origin, sphere B (radius rb) at
// (ra + rb - delta) n, held at one overlap; the pair's model and rolling law from the table.
// fn(), kt() are the closed forms of the pair's model written here from its definition, not read
// from normal_law(): linear fn = kn delta with kn the springs 2 E_a r_a and 2 E_b r_b in series
// and kt = alpha kn; Hertz-Mindlin fn = 4/3 E* sqrt(R*) delta^1.5, kt = 8 G* sqrt(R* delta) with
// E*, G* from the two materials' E and nu. The rolling stiffness is kr = beta_r rbar^2 kt and the
// moment cap eta_r rbar fn, rbar = (ra + rb) / 2; the Coulomb cap is friction * fn.
struct Rig {
  std::string name;
  MaterialTable table;
  int a = 0, b = 1;
  bool hertz = false;
  double ra = 1.3e-3, rb = 0.7e-3, delta = 1e-5, dt = 2e-6;
  Vec3 n = kN, ft, rot;

  const PairParams& p() const { return table.pair(a, b); }
  double kn() const {
    const double ka = 2.0 * table[a].young * ra, kb = 2.0 * table[b].young * rb;
    return ka * kb / (ka + kb);
  }
  double rstar() const { return ra * rb / (ra + rb); }
  double e_star() const {
    const Material &ma = table[a], &mb = table[b];
    return 1.0 / ((1 - ma.poisson * ma.poisson) / ma.young + (1 - mb.poisson * mb.poisson) / mb.young);
  }
  double g_star() const {
    const Material &ma = table[a], &mb = table[b];
    return 1.0 / (2 * (2 - ma.poisson) * (1 + ma.poisson) / ma.young +
                  2 * (2 - mb.poisson) * (1 + mb.poisson) / mb.young);
  }
  double fn() const { return hertz ? 4.0 / 3.0 * e_star() * std::sqrt(rstar()) * std::pow(delta, 1.5) : kn() * delta; }
  double kt() const { return hertz ? 8.0 * g_star() * std::sqrt(rstar() * delta) : p().kt_kn * kn(); }
  double rbar() const { return 0.5 * (ra + rb); }
  double kr() const { return p().beta_r * rbar() * rbar() * kt(); }
  double coulomb() const { return p().friction * fn(); }
  double mlim() const { return p().eta_r * rbar() * fn(); }
  Vec3 la() const { return (ra - 0.5 * delta) * n; }
  Vec3 lb() const { return -(rb - 0.5 * delta) * n; }
  Vec3 xb() const { return (ra + rb - delta) * n; }

  // One step of the law as the engine takes it: the pair's model, then the rest of the law.
  ContactForce step(const Vec3& vrel, const Vec3& w_a_minus_b) {
    const NormalLaw nl = normal_law(p(), table[a].young, ra, table[b].young, rb, effective_radius(ra, rb), delta);
    return contact_force(n, nl.fn, nl.kt, la(), lb(), vrel, w_a_minus_b, rbar(), p(), dt, ft, rot);
  }
};

// The rigs of every protocol: two linear pairs (different materials and radii; one material,
// equal radii) and a Hertz-Mindlin pair, all of the rolling law `law`.
std::vector<Rig> rigs(RollingLaw law) {
  Material sand = mat("sand", 7e7, 0.2), wall = mat("wall", 2e8, 0.3);
  sand.rolling_law = law; wall.rolling_law = law;
  std::vector<Rig> out(3);
  out[0].name = "linear sand-wall";
  out[0].table = MaterialTable({sand, wall});
  out[1].name = "linear sand-sand";
  out[1].table = MaterialTable({sand, wall});
  out[1].b = 0; out[1].rb = out[1].ra;
  out[2].name = "hertz_mindlin sand-wall";
  out[2].table = MaterialTable({sand, wall}, {}, ContactModel::kHertzMindlin);
  out[2].hertz = true;
  return out;
}

// The torques of the lever arms (the law's force on B is F, A receives -F; the contact point is
// la from A's centre and lb from B's): torque_b = lb x F - M, torque_a = la x (-F) + M with M the
// rolling moment on A; and the pair's torques balance the couple of the two forces, whatever M:
// torque_a + torque_b + xb x F = 0 (A at the origin). F and M are the protocols' closed forms.
void expect_torques(const Rig& r, const ContactForce& f, const Vec3& force, const Vec3& m_a, const std::string& at) {
  const double scale = norm(r.la()) * norm(force) + norm(m_a);
  EXPECT_TRUE(near(f.torque_a, cross(r.la(), -force) + m_a, scale)) << r.name << " torque on A, " << at;
  EXPECT_TRUE(near(f.torque_b, cross(r.lb(), force) - m_a, scale)) << r.name << " torque on B, " << at;
  EXPECT_TRUE(near(f.torque_a + f.torque_b + cross(r.xb(), f.force_b), {}, norm(r.xb()) * norm(force)))
      << r.name << " moment balance, " << at;
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

// Protocol 1, normal loading at fixed overlap, no relative motion: the linear model's normal
// force is kn delta (kn the springs 2 E r in series), its tangential stiffness alpha kn and its
// tangent stiffness kn, for overlaps over five decades (Hertz-Mindlin's closed forms are
// asserted by HertzForceOverlapTwoSpheresAndWall above). The whole law then gives B the force
// fn n and no tangential force or rolling rotation, and the force along the line of centres has
// no torque about either centre.
TEST(ContactModel, ProtocolNormalLoadingAtFixedOverlap) {
  for (Rig r : rigs(RollingLaw::kIncremental)) {
    for (double delta : {1e-9, 3.7e-7, 1e-5, 2e-4}) {
      r.delta = delta;
      r.ft = {}; r.rot = {};
      const std::string at = "delta " + std::to_string(delta);
      if (!r.hertz) {
        const NormalLaw nl = normal_law(r.p(), r.table[r.a].young, r.ra, r.table[r.b].young, r.rb,
                                        effective_radius(r.ra, r.rb), delta);
        EXPECT_NEAR(nl.fn / (r.kn() * delta), 1.0, kTol) << r.name << ", " << at;
        EXPECT_NEAR(nl.kt / (r.p().kt_kn * r.kn()), 1.0, kTol) << r.name << ", " << at;
        EXPECT_NEAR(nl.k / r.kn(), 1.0, kTol) << r.name << ", " << at;
      }
      const ContactForce f = r.step({}, {});
      EXPECT_NEAR(f.fn / r.fn(), 1.0, kTol) << r.name << ", " << at;
      EXPECT_TRUE(near(f.force_b, r.fn() * r.n, r.fn())) << r.name << ", " << at;
      EXPECT_EQ(norm(r.ft), 0.0) << r.name << ", " << at;
      EXPECT_EQ(norm(r.rot), 0.0) << r.name << ", " << at;
      expect_torques(r, f, r.fn() * r.n, {}, at);
    }
  }
}

// Protocol 2, tangential loading: B slides along t at a constant v relative to A (plus a normal
// component, which the spring ignores), at fixed overlap. The spring's elastic displacement
// after k steps is v dt k, so |ft| = kt v dt k while that is below the Coulomb cap friction fn,
// and exactly the cap from the first step past it, k_slip = floor(friction fn / (kt v dt)) + 1;
// the force on B points against B's sliding, along -t. v is chosen to put the cap between steps
// 40 and 41 (k_slip = 41), away from a step where rounding could decide. Protocol 6 at every
// step: the torques are those of the lever arms of the force fn n - |ft| t.
TEST(ContactModel, ProtocolTangentialLoadingToSlip) {
  for (Rig r : rigs(RollingLaw::kIncremental)) {
    const double fn = r.fn(), kt = r.kt(), cap = r.coulomb();
    const double v = cap / (40.5 * kt * r.dt);
    const int k_slip = static_cast<int>(std::floor(cap / (kt * v * r.dt))) + 1;
    ASSERT_EQ(k_slip, 41) << r.name;
    for (int k = 1; k <= 80; ++k) {
      const ContactForce f = r.step(v * kT + 0.37 * v * kN, {});
      const double mag = k < k_slip ? kt * v * r.dt * k : cap;
      const Vec3 force = fn * kN - mag * kT;
      const std::string at = "step " + std::to_string(k);
      EXPECT_NEAR(f.fn / fn, 1.0, kTol) << r.name << ", " << at;
      EXPECT_TRUE(near(r.ft, -mag * kT, mag)) << r.name << ", " << at;
      EXPECT_TRUE(near(f.force_b, force, norm(force))) << r.name << ", " << at;
      expect_torques(r, f, force, {}, at);
    }
  }
}

// Protocol 3, reversal: after sliding at the cap (protocol 2, 60 steps), B's velocity reverses.
// The spring unloads from the cap with the same stiffness: along t, ft = -cap + kt v dt j after
// j reversed steps, so |ft| = |cap - kt v dt j| falls linearly with slope kt v dt to zero
// (between steps 40 and 41) and rises the other way to the cap, reached from step 82 on
// (-cap + kt v dt j > cap for j > 81). The tolerance is relative to the cap, the scale of the
// force, since ft passes through zero.
TEST(ContactModel, ProtocolReversalUnloadsLinearly) {
  for (Rig r : rigs(RollingLaw::kIncremental)) {
    const double fn = r.fn(), kt = r.kt(), cap = r.coulomb(), v = cap / (40.5 * kt * r.dt);
    for (int k = 0; k < 60; ++k) r.step(v * kT, {});
    ASSERT_TRUE(near(r.ft, -cap * kT, cap)) << r.name;
    for (int j = 1; j <= 100; ++j) {
      const ContactForce f = r.step(-v * kT, {});
      const double along = std::min(-cap + kt * v * r.dt * j, cap);
      const std::string at = "reversed step " + std::to_string(j);
      EXPECT_TRUE(near(r.ft, along * kT, cap)) << r.name << ", " << at;
      if (j <= 40) {
        EXPECT_NEAR(norm(r.ft), cap - kt * v * r.dt * j, kTol * cap) << r.name << ", " << at;
      }
      expect_torques(r, f, fn * kN + along * kT, {}, at);
    }
  }
}

// Protocol 4, the normal turns with no tangential motion (vrel = 0, w = 0): the law rotates the
// stored shear force into the new tangent plane keeping its magnitude. The spring is first
// loaded to F = 20 kt v dt (below the cap; v as in protocol 2) along -(cos a t + sin a b), then
// the normal turns about b by phi: n(phi) = cos phi n + sin phi t, whose tangent in the plane of
// the turn is t(phi) = cos phi t - sin phi n. A force along t projects onto t(phi)
// (t - (t.n(phi)) n(phi) = cos phi t(phi)), so it follows the turn, ft = -F t(phi), turned in
// one step or in many; a force along b, the axis of the turn, stays as it is. A force with both
// parts turned in one step keeps its magnitude in the direction of its projection,
// -F (cos a cos phi t(phi) + sin a b) / sqrt(cos^2 a cos^2 phi + sin^2 a) (not a rigid rotation
// of the force, which would keep the angle a). In every case |ft| = F and ft is perpendicular
// to the new normal; the torques are those of the turned lever arms.
TEST(ContactModel, ProtocolNormalTurnsShearForceFollows) {
  struct Turn { double a, phi; int steps; };
  const double kHalfPi = 0.5 * 3.14159265358979323846;
  for (const Turn& c : {Turn{0.0, 0.6, 60}, Turn{0.0, 0.3, 1}, Turn{kHalfPi, 0.5, 60}, Turn{0.7, 0.5, 1}}) {
    for (Rig r : rigs(RollingLaw::kIncremental)) {
      const double fn = r.fn(), kt = r.kt(), v = r.coulomb() / (40.5 * kt * r.dt);
      const Vec3 slide = std::cos(c.a) * kT + std::sin(c.a) * kB;
      for (int k = 0; k < 20; ++k) r.step(v * slide, {});
      const double big_f = 20 * kt * v * r.dt;
      ASSERT_TRUE(near(r.ft, -big_f * slide, big_f)) << r.name;
      ContactForce f;
      for (int s = 1; s <= c.steps; ++s) {
        const double phi = c.phi * s / c.steps;
        r.n = std::cos(phi) * kN + std::sin(phi) * kT;
        f = r.step({}, {});
      }
      const Vec3 n_phi = std::cos(c.phi) * kN + std::sin(c.phi) * kT;
      const Vec3 t_phi = std::cos(c.phi) * kT - std::sin(c.phi) * kN;
      const Vec3 u = std::cos(c.a) * std::cos(c.phi) * t_phi + std::sin(c.a) * kB;
      const Vec3 ft = (-big_f / norm(u)) * u;
      const std::string at = "a " + std::to_string(c.a) + ", phi " + std::to_string(c.phi) + " in " +
                             std::to_string(c.steps) + " steps";
      EXPECT_NEAR(norm(r.ft) / big_f, 1.0, kTol) << r.name << ", " << at;
      EXPECT_NEAR(dot(r.ft, n_phi), 0.0, kTol * big_f) << r.name << ", " << at;
      EXPECT_TRUE(near(r.ft, ft, big_f)) << r.name << ", " << at;
      expect_torques(r, f, fn * n_phi + ft, {}, at);
    }
  }
}

// Protocol 4 for the rolling history: A first rolls about t relative to B for 20 steps (below
// the moment cap), the stored rotation theta = 20 w dt t and the moment on A -kr theta; then the
// normal turns about b by 0.6 rad in 60 steps, with neither body rotating. The incremental law
// keeps its rolling rotation in the tangent plane as it keeps the shear force (the same
// projection at the same magnitude): the moment follows the turn, -kr theta t(phi). The total
// law's rotation is the relative rotation of A against B since the contact formed, a vector the
// turn of the normal does not change: the moment stays -kr theta t. B receives the opposite.
TEST(ContactModel, ProtocolNormalTurnsRollingHistory) {
  for (RollingLaw law : {RollingLaw::kIncremental, RollingLaw::kTotal}) {
    for (Rig r : rigs(law)) {
      ASSERT_EQ(r.p().rolling, law) << r.name;
      const double fn = r.fn(), kr = r.kr(), w = r.mlim() / (40.5 * kr * r.dt);
      for (int k = 0; k < 20; ++k) r.step({}, w * kT);
      const double theta = 20 * w * r.dt;
      ContactForce f;
      const int steps = 60;
      const double phi = 0.6;
      for (int s = 1; s <= steps; ++s) {
        const double turned = phi * s / steps;
        r.n = std::cos(turned) * kN + std::sin(turned) * kT;
        f = r.step({}, {});
      }
      const Vec3 n_phi = std::cos(phi) * kN + std::sin(phi) * kT;
      const Vec3 t_phi = std::cos(phi) * kT - std::sin(phi) * kN;
      const Vec3 m_a = -kr * theta * (law == RollingLaw::kTotal ? kT : t_phi);
      const std::string at = std::string(rolling_law_name(law)) + " law after the turn";
      EXPECT_EQ(norm(r.ft), 0.0) << r.name << ", " << at;
      expect_torques(r, f, fn * n_phi, m_a, at);
    }
  }
}

// Protocol 5, rolling: A rolls relative to B at a constant w_A - w_B = w, about the tangent t
// with a twist part 0.4 |w| about n, at fixed overlap and no sliding. The rotation the law
// resists after k steps is theta_k = k dt w_eff, w_eff the tangential part of w for the
// incremental law (twist is not rolling) and the whole of w for the total law (twist resisted
// with the same kr); the moment on A is -kr theta_k until its magnitude passes the cap
// eta_r rbar fn, then the cap, along -e (e the direction of w_eff); B receives the opposite
// moment. |w_eff| is chosen to put the cap between steps 30 and 31. Then w reverses for as many
// steps (60), back to zero net rotation:
//  - the total law (eqs 3-7/3-8: the moment of the total rotation, only the moment capped):
//    theta = (60 - j) dt w_eff after j reversed steps, the moment -min(kr |theta|, cap) e, held
//    at the cap to step 29, zero at zero net rotation;
//  - the incremental law (the stored rotation capped with the moment): it unloads from the cap,
//    M = -(cap - kr |w_eff| dt j) e, through zero between steps 30 and 31, and at zero net
//    rotation holds cap (60 / 30.5 - 1) e, the other way.
TEST(ContactModel, ProtocolRollingToCapAndBack) {
  for (RollingLaw law : {RollingLaw::kIncremental, RollingLaw::kTotal}) {
    const bool total = law == RollingLaw::kTotal;
    for (Rig r : rigs(law)) {
      ASSERT_EQ(r.p().rolling, law) << r.name;
      const double fn = r.fn(), kr = r.kr(), mlim = r.mlim();
      const double w_eff = mlim / (30.5 * kr * r.dt);
      const Vec3 e = total ? (1.0 / std::sqrt(1.16)) * (kT + 0.4 * kN) : kT;
      const Vec3 w = total ? w_eff * e : w_eff * (kT + 0.4 * kN);
      const int k_cap = static_cast<int>(std::floor(mlim / (kr * w_eff * r.dt))) + 1;
      ASSERT_EQ(k_cap, 31) << r.name;
      const Vec3 force = fn * kN;
      for (int k = 1; k <= 60; ++k) {
        const ContactForce f = r.step({}, w);
        const double m = k < k_cap ? kr * w_eff * r.dt * k : mlim;
        const std::string at = std::string(rolling_law_name(law)) + " law, step " + std::to_string(k);
        expect_torques(r, f, force, -m * e, at);
        EXPECT_TRUE(near(f.torque_a - cross(r.la(), -f.force_b), -(f.torque_b - cross(r.lb(), f.force_b)), mlim))
            << r.name << ", " << at;  // the moments on A and B equal and opposite
      }
      ContactForce f;
      for (int j = 1; j <= 60; ++j) {
        f = r.step({}, -1.0 * w);
        const double m = total ? std::min(kr * w_eff * r.dt * (60 - j), mlim)
                               : std::max(mlim - kr * w_eff * r.dt * j, -mlim);
        const std::string at = std::string(rolling_law_name(law)) + " law, reversed step " + std::to_string(j);
        expect_torques(r, f, force, -m * e, at);
      }
      // Zero net rotation: the total law's moment is gone, the incremental law's is not.
      const Vec3 m_a = f.torque_a - cross(r.la(), -force);
      if (total) {
        EXPECT_LE(norm(m_a), kTol * mlim) << r.name;
        EXPECT_LE(norm(r.rot), kTol * mlim / kr) << r.name;
      } else {
        EXPECT_TRUE(near(m_a, mlim * (60 / 30.5 - 1) * e, mlim)) << r.name;
      }
      EXPECT_EQ(norm(r.ft), 0.0) << r.name;
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
