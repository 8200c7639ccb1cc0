#pragma once
// The thesis's DEM contact law (Tran 2013, eqs 4-1 ... 4-11 and 3-1 ... 3-10; DESIGN.md 4.1).
//
// Stateless kernels over plain values: no MPI, no I/O. Conventions:
//  - body A and body B; the unit normal n points from A to B;
//  - overlap delta > 0 means contact (delta = r_A + r_B - |x_B - x_A| for two spheres);
//  - la, lb are the vectors from the centres of A and B to the contact point;
//  - the returned force is the force ON B; A receives its negative;
//  - ContactState is the history of one contact: the tangential spring force on B (kept in the
//    current tangent plane) and the accumulated relative rolling rotation of A against B.
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

/// Apply the contact law for one step of length dt.
/// kn: normal stiffness (N/m); rbar: mean radius (r_A + r_B)/2 used by rolling resistance;
/// vrel: velocity of B's contact point relative to A's; wrel_a_minus_b = w_A - w_B.
/// The history is passed as its two parts (kept in separate arrays by the engine, so a run
/// without rolling resistance never touches `rot`).
inline ContactForce contact_law(const Vec3& n, double delta, const Vec3& la, const Vec3& lb,
                                const Vec3& vrel, const Vec3& w_a_minus_b, double kn, double rbar,
                                const PairParams& p, double dt, Vec3& ft_state, Vec3& rot_state) {
  ContactForce out;
  const double fn = kn * delta;
  out.fn = fn;
  const double kt = p.kt_kn * kn;

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

  // Rolling resistance (eqs 3-8 ... 3-10): elastic-perfectly plastic moment on the relative
  // rolling rotation (the twist component about n is excluded).
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
    const Vec3 mr = -kr * th;  // moment on A resisting A's rolling relative to B
    out.torque_a += mr;
    out.torque_b -= mr;
  }
  return out;
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
