#pragma once
// The thesis's DEM contact law (Tran 2013, eqs 4-1 ... 4-11 and 3-1 ... 3-10; DESIGN.md 4.1)
// and the contact-model table: normal_law() gives the normal force and the tangential stiffness
// of the pair's model (linear or Hertz-Mindlin), contact_force() applies the rest of the law
// (tangential spring, Coulomb cap, rolling resistance), the same for every model. Every contact
// (particle-particle, particle-wall, particle-FE interface) calls the two in this order.
//
// Stateless kernels over plain values: no MPI, no I/O. Conventions:
//  - body A and body B; the unit normal n points from A to B;
//  - overlap delta > 0 means contact (delta = r_A + r_B - |x_B - x_A| for two spheres);
//  - la, lb are the vectors from the centres of A and B to the contact point;
//  - the returned force is the force ON B; A receives its negative;
//  - ContactState is the history of one contact: the tangential spring force on B (kept in the
//    current tangent plane) and the accumulated relative rotation of A against B (the
//    incremental law: rolling only, capped; the total law: the whole rotation, never capped).
#include <algorithm>
#include <cmath>

#include "dem/material.hpp"
#include "base/vec3.hpp"

namespace fdem {

struct ContactState {
  Vec3 ft;   // tangential spring force on B, N
  Vec3 rot;  // accumulated relative rolling rotation theta_r (A relative to B), rad
};

struct ContactForce {
  Vec3 force_b;   // total contact force on B (A gets -force_b), N
  Vec3 torque_a;  // torque on A about its centre, N m
  Vec3 torque_b;  // torque on B about its centre, N m
  double fn = 0;  // magnitude of the normal force, N
};

/// Normal stiffness of two particles (eq 4-2): springs k = 2 E r in series.
inline double normal_stiffness(double ea, double ra, double eb, double rb) {
  const double ka = 2.0 * ea * ra, kb = 2.0 * eb * rb;
  return ka * kb / (ka + kb);
}

/// Effective radius R* of two spheres, r_a r_b / (r_a + r_b). A sphere against a wall or an
/// FE interface triangle (flat) has R* = r of the sphere.
inline double effective_radius(double ra, double rb) { return ra * rb / (ra + rb); }

/// What a contact model gives for one overlap: the normal force, the tangential stiffness of
/// the incremental tangential spring, and the normal tangent stiffness d fn / d delta (for the
/// servo's stiffness sum and stable-step estimates).
struct NormalLaw {
  double fn = 0;  // normal force magnitude, N
  double kt = 0;  // tangential stiffness, N/m
  double k = 0;   // normal tangent stiffness, N/m
};

/// The contact-model table: the one place that dispatches on PairParams::model.
/// ea, ra, eb, rb: Young's moduli and the radii that set the linear K_N (a wall or an FE
/// triangle passes the particle's radius for both, as the thesis does); rstar: Hertz's effective
/// radius (effective_radius() for two spheres, r for a sphere on a flat body); delta > 0.
///  - linear (eq 4-2 ... 4-4): fn = K_N delta, K_T = alpha K_N;
///  - Hertz-Mindlin, no slip (as LIGGGHTS `hertz` / YADE `HertzMindlin` without viscous
///    damping; Johnson 1985, eqs 4.22 and 7.34): fn = 4/3 E* sqrt(R*) delta^1.5,
///    K_T = 8 G* sqrt(R* delta), dfn/ddelta = 2 E* sqrt(R* delta); E*, G* from PairParams.
inline NormalLaw normal_law(const PairParams& p, double ea, double ra, double eb, double rb, double rstar,
                            double delta) {
  NormalLaw out;
  if (p.model == ContactModel::kHertzMindlin) {
    const double a = std::sqrt(rstar * delta);  // contact radius a = sqrt(R* delta)
    out.fn = (4.0 / 3.0) * p.e_star * a * delta;
    out.kt = 8.0 * p.g_star * a;
    out.k = 2.0 * p.e_star * a;
    return out;
  }
  const double kn = normal_stiffness(ea, ra, eb, rb);
  out.fn = kn * delta;
  out.kt = p.kt_kn * kn;
  out.k = kn;
  return out;
}

/// The geometry-independent part of the contact law, for one step of length dt, given the
/// normal force fn and the tangential stiffness kt of the pair's model (normal_law()).
/// rbar: mean radius (r_A + r_B)/2 used by rolling resistance; vrel: velocity of B's contact
/// point relative to A's; w_a_minus_b = w_A - w_B. The history is passed as its two parts (kept
/// in separate arrays by the engine, so a run without rolling resistance never touches `rot`).
inline ContactForce contact_force(const Vec3& n, double fn, double kt, const Vec3& la, const Vec3& lb,
                                  const Vec3& vrel, const Vec3& w_a_minus_b, double rbar,
                                  const PairParams& p, double dt, Vec3& ft_state, Vec3& rot_state) {
  ContactForce out;
  out.fn = fn;
  // Tangential spring: rotate the stored force into the current tangent plane keeping its
  // magnitude, then add the increment of elastic tangential displacement (eq 4-5/4-6).
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
  // Coulomb cap (eq 4-7): slip scales the spring back onto the friction cone.
  const double ft_max = fn * p.friction;
  const double ft_now2 = norm2(ft);
  if (ft_now2 > ft_max * ft_max) ft *= ft_max / std::sqrt(ft_now2);
  ft_state = ft;

  out.force_b = fn * n + ft;
  out.torque_b = cross(lb, out.force_b);
  out.torque_a = cross(la, -out.force_b);

  // Rolling resistance (eqs 3-7 ... 3-10), K_r = beta_r rbar^2 K_T, M_lim = eta_r rbar |F_N|.
  if (p.beta_r > 0.0) {
    const double kr = p.beta_r * rbar * rbar * kt;
    const double m_lim = p.eta_r * rbar * fn;
    if (p.rolling == RollingLaw::kTotal) {
      // The thesis's law as printed (eq 3-7: theta_r the sum of the increments; eq 3-8: the
      // moment capped, never the rotation) and as its engine computed it (YADE's
      // NormalInelasticity law: the relative rotation of A against B since the contact formed,
      // twist included with the same K_r, nothing reset). The rotation is that of a rotation:
      // the engine reads its angle from a quaternion, in (-pi, pi], so a sum past pi wraps.
      const Vec3 th = rot_state + dt * w_a_minus_b;
      rot_state = th;
      Vec3 mr = -kr * th;  // moment on A
      const double th2 = norm2(th);
      constexpr double kPi = 3.14159265358979323846;
      if (th2 > kPi * kPi) {
        const double t = std::sqrt(th2);
        const double wrapped = t - 2.0 * kPi * std::floor((t + kPi) / (2.0 * kPi));  // in [-pi, pi)
        mr = (-kr * wrapped / t) * th;
      }
      const double m2 = norm2(mr);
      if (m2 > m_lim * m_lim) mr *= m_lim / std::sqrt(m2);
      out.torque_a += mr;
      out.torque_b -= mr;
      return out;
    }
    // The incremental law (YADE 2023's CohFrictMat moment law): the stored rotation is kept in
    // the current tangent plane (twist excluded) and capped with the moment (elastic-perfectly
    // plastic), so a reversal past the cap unloads from the cap.
    Vec3 th = rot_state;
    const double th_mag2 = norm2(th);
    if (th_mag2 > 0.0) {
      const double n_part = dot(th, n);
      th -= n_part * n;
      const double proj2 = th_mag2 - n_part * n_part;
      if (proj2 > 0.0) th *= std::sqrt(th_mag2 / proj2);
    }
    th += dt * (w_a_minus_b - dot(w_a_minus_b, n) * n);
    const double m2 = kr * kr * norm2(th);
    if (m2 > m_lim * m_lim) th *= m_lim / std::sqrt(m2);
    rot_state = th;
    const Vec3 mr = -kr * th;  // moment on A resisting A's rolling relative to B
    out.torque_a += mr;
    out.torque_b -= mr;
  }
  return out;
}

inline ContactForce contact_force(const Vec3& n, const NormalLaw& nl, const Vec3& la, const Vec3& lb,
                                  const Vec3& vrel, const Vec3& w_a_minus_b, double rbar, const PairParams& p,
                                  double dt, ContactState& s) {
  return contact_force(n, nl.fn, nl.kt, la, lb, vrel, w_a_minus_b, rbar, p, dt, s.ft, s.rot);
}

/// The contact law with a given linear normal stiffness kn (N/m): fn = kn delta, K_T = alpha kn.
inline ContactForce contact_law(const Vec3& n, double delta, const Vec3& la, const Vec3& lb,
                                const Vec3& vrel, const Vec3& w_a_minus_b, double kn, double rbar,
                                const PairParams& p, double dt, Vec3& ft_state, Vec3& rot_state) {
  return contact_force(n, kn * delta, p.kt_kn * kn, la, lb, vrel, w_a_minus_b, rbar, p, dt, ft_state, rot_state);
}

inline ContactForce contact_law(const Vec3& n, double delta, const Vec3& la, const Vec3& lb,
                                const Vec3& vrel, const Vec3& w_a_minus_b, double kn, double rbar,
                                const PairParams& p, double dt, ContactState& s) {
  return contact_law(n, delta, la, lb, vrel, w_a_minus_b, kn, rbar, p, dt, s.ft, s.rot);
}

/// Cundall's local non-viscous damping as in YADE's NewtonIntegrator: each component of the
/// force is reduced by lambda*|f| in the direction opposing the mid-step velocity.
/// f (1 - lambda sign(f v_mid)) = f - lambda |f| sign(v_mid), written branch-free with
/// copysign. (Where v_mid is exactly zero this damps by lambda |f| instead of not at all.)
inline double local_damping(double f, double v, double dt_over_m, double lambda) {
  const double vmid = v + 0.5 * dt_over_m * f;
  return f - lambda * std::copysign(f, vmid);
}

}  // namespace fdem
