// Perfectly plastic Mohr-Coulomb return map in principal stresses (DESIGN.md 4.3).
//
// Tension positive; principal stresses sorted s1 >= s2 >= s3 (s1 the most tensile). Yield
// function and plastic potential of the plane through (s1, s3):
//     f = (s1 - s3) + (s1 + s3) sin(phi) - 2 c cos(phi),
//     g = (s1 - s3) + (s1 + s3) sin(psi).
// All surfaces are planes in principal space and the material is perfectly plastic, so each
// return is one linear solve (no Newton iterations). Order of attempts, as in de Souza Neto,
// Peric & Owen, "Computational Methods for Plasticity" (2008), boxes 8.4/8.5:
//   1. main plane (one multiplier); accepted if the ordering s1 >= s2 >= s3 survives;
//   2. otherwise the edge the return crossed first — s1 = s2 (triaxial compression in
//      tension-positive terms; planes (1,3) and (2,3)) or s2 = s3 (triaxial extension; planes
//      (1,3) and (1,2)) — with two multipliers; accepted if the ordering holds and both
//      multipliers are non-negative;
//   3. otherwise the apex s1 = s2 = s3 = c cot(phi).
// The stress is rotated back with the trial's principal directions (isotropy).
#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "fem/element.hpp"

namespace fdem::fem {

namespace {

// Plane through principal stresses (i, j), i the more tensile one.
struct Plane {
  int i, j;
};

inline double plane_f(const Plane& p, const double* s, double sphi, double two_c_cos) {
  return (s[p.i] - s[p.j]) + (s[p.i] + s[p.j]) * sphi - two_c_cos;
}

// Principal elastic stress increment per unit multiplier along the flow direction of plane p:
// Dp * n, n = (1 + sin psi) e_i + (-1 + sin psi) e_j.
inline void d_flow(const Plane& p, double lam, double G, double spsi, double* out) {
  double n[3] = {0, 0, 0};
  n[p.i] = 1 + spsi;
  n[p.j] = -1 + spsi;
  const double tr = lam * (n[0] + n[1] + n[2]);
  for (int k = 0; k < 3; ++k) out[k] = tr + 2 * G * n[k];
}

// Gradient of plane p's yield function dotted with a principal-stress vector.
inline double grad_dot(const Plane& p, double sphi, const double* v) {
  return (1 + sphi) * v[p.i] + (-1 + sphi) * v[p.j];
}

inline bool ordered(const double* s, double tol) {
  return s[0] >= s[1] - tol && s[1] >= s[2] - tol;
}

}  // namespace

void mohr_coulomb_return(const double* trial, const FeMaterial& m, double* stress,
                         bool& yielded) {
  Eigen::Matrix3d S;
  S << trial[0], trial[3], trial[5],
       trial[3], trial[1], trial[4],
       trial[5], trial[4], trial[2];
  // Eigenvalues only for the yield check (most calls are elastic); vectors when yielded.
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(S, Eigen::EigenvaluesOnly);
  const Eigen::Vector3d ev = eig.eigenvalues();  // ascending
  // st[0] = s1 (most tensile) ... st[2] = s3.
  const double st[3] = {ev(2), ev(1), ev(0)};
  const double sphi = std::sin(m.friction), cphi = std::cos(m.friction);
  const double spsi = std::sin(m.dilation);
  const double two_c_cos = 2 * m.cohesion * cphi;
  const double scale = std::max({std::abs(st[0]), std::abs(st[2]), m.cohesion * cphi});
  const double tol = 1e-12 * scale;

  const Plane main{0, 2};
  const double f_trial = plane_f(main, st, sphi, two_c_cos);
  if (!(f_trial > tol)) {
    for (int i = 0; i < 6; ++i) stress[i] = trial[i];
    yielded = false;
    return;
  }
  yielded = true;
  const double G = m.young / (2 * (1 + m.poisson));
  const double lam = m.young * m.poisson / ((1 + m.poisson) * (1 - 2 * m.poisson));

  double s[3];
  bool done = false;
  // 1. Main plane.
  {
    double dn[3];
    d_flow(main, lam, G, spsi, dn);
    const double dg = f_trial / grad_dot(main, sphi, dn);
    for (int k = 0; k < 3; ++k) s[k] = st[k] - dg * dn[k];
    done = ordered(s, tol);
  }
  // 2. Edge: the one whose ordering constraint the main-plane return violates first.
  if (!done) {
    const bool right = (1 - spsi) * st[0] - 2 * st[1] + (1 + spsi) * st[2] > 0;
    const Plane second = right ? Plane{0, 1} : Plane{1, 2};  // s2 = s3 : s1 = s2
    const Plane pl[2] = {main, second};
    double dn[2][3];
    d_flow(pl[0], lam, G, spsi, dn[0]);
    d_flow(pl[1], lam, G, spsi, dn[1]);
    double A[2][2], r[2];
    for (int a = 0; a < 2; ++a) {
      r[a] = plane_f(pl[a], st, sphi, two_c_cos);
      for (int b = 0; b < 2; ++b) A[a][b] = grad_dot(pl[a], sphi, dn[b]);
    }
    const double det = A[0][0] * A[1][1] - A[0][1] * A[1][0];
    const double g0 = (r[0] * A[1][1] - r[1] * A[0][1]) / det;
    const double g1 = (A[0][0] * r[1] - A[1][0] * r[0]) / det;
    for (int k = 0; k < 3; ++k) s[k] = st[k] - g0 * dn[0][k] - g1 * dn[1][k];
    // Both planes active: the two equal principal stresses come out equal up to round-off;
    // make them exactly equal.
    if (right) s[1] = s[2] = 0.5 * (s[1] + s[2]);
    else s[0] = s[1] = 0.5 * (s[0] + s[1]);
    const bool apex_available = sphi > 1e-12;
    done = !apex_available || (ordered(s, tol) && g0 >= -1e-12 && g1 >= -1e-12);
  }
  // 3. Apex.
  if (!done) {
    const double p = m.cohesion * cphi / sphi;
    s[0] = s[1] = s[2] = p;
  }
  // Rotate back: sigma = V diag(s) V^T with V's columns in ascending order (s3, s2, s1).
  eig.compute(S, Eigen::ComputeEigenvectors);
  const Eigen::Matrix3d& V = eig.eigenvectors();
  const Eigen::Vector3d d(s[2], s[1], s[0]);
  const Eigen::Matrix3d R = V * d.asDiagonal() * V.transpose();
  stress[0] = R(0, 0);
  stress[1] = R(1, 1);
  stress[2] = R(2, 2);
  stress[3] = R(0, 1);
  stress[4] = R(1, 2);
  stress[5] = R(0, 2);
}

}  // namespace fdem::fem
