#pragma once
// 4-node flat shell element kernel (the thesis's pipe, problem 8: "ShellBT4"): plain arrays in,
// plain arrays out; no MPI, no PETSc, no mesh. Small strain, linear elastic, isotropic (E, nu),
// uniform thickness t. Same conventions as element.hpp (row-major, SI units).
//
// Degrees of freedom: 6 per node, in GLOBAL axes: (ux, uy, uz, theta_x, theta_y, theta_z),
// node-major: dof 6 a + i. theta is the small rotation VECTOR of the node (right-hand rule);
// the conjugate generalised forces are forces (N) and moments (N m).
//   X: 4 x 3 reference coordinates; u: 4 x 6; f: 24; K: 24 x 24 row-major.
//   Node order: counter-clockwise seen from the element's positive normal side (any cyclic
//   order works for the stiffness; the normal n = (X2 - X0) x (X3 - X1) / |..| follows it).
//
// Local frame (see shell4_frame): origin at the node centroid c, normal n as above, which is
// the "mean plane" of a warped quad: the plane through c parallel to both diagonals, so the
// nodes' offsets from it are z_a = (X_a - c).n = (+h, -h, +h, -h) (bilinear warp).
// e1 = the mid-side direction (X1 + X2 - X0 - X3) projected on that plane, e2 = n x e1.
// The element is formulated as a FLAT quad on the nodes projected onto the mean plane,
// p_a = X_a - z_a n, and connected to the real nodes through rigid links (the classical
// warping correction): u(p_a) = u_a + theta_a x (p_a - X_a). Thus rigid-body motions of the
// real nodes are rigid-body motions of the flat element, and a warped element keeps exactly 6
// zero-energy modes. (For strongly warped elements the flat projection is an approximation;
// keep the warp h small relative to the element size.)
//
// Local (flat) formulation, in the (e1, e2, n) frame, per node (u, v, w, theta_1, theta_2,
// theta_3); Mindlin kinematics u_1 = z beta_1, u_2 = z beta_2 with beta_1 = theta_2,
// beta_2 = -theta_1:
//  - membrane: bilinear Q4, plane stress, 2 x 2 Gauss, N = E t / (1 - nu^2) [...] eps;
//  - bending: curvatures kappa = (beta_1,1, beta_2,2, beta_1,2 + beta_2,1) from the bilinear
//    rotations, M = E t^3 / (12 (1 - nu^2)) [...] kappa, 2 x 2 Gauss;
//  - transverse shear: MITC4 (Bathe & Dvorkin 1985, IJNME 21:367): covariant shear strains
//    gamma_xi (tied at the mid-points of the edges eta = -/+1) and gamma_eta (at xi = -/+1),
//    interpolated linearly across the element, Q = (5/6) G t gamma, 2 x 2 Gauss. No shear
//    locking, no spurious modes, passes the constant-curvature patch test;
//  - drilling (theta_3): the flat element has no natural stiffness for it; a penalty
//    (Hughes-Brezzi type) ties each node's theta_3 to the membrane's infinitesimal rotation at
//    the centre, omega_c = (v_,1 - u_,2) / 2:
//        U_drill = 1/2 k_d sum_a (theta_3a - omega_c)^2,   k_d = kShell4DrillFactor * G t A.
//    It vanishes for rigid motions and for every linear membrane field with theta_3 = omega, so
//    it keeps the 6 rigid-body modes and the membrane patch test, and leaves no spurious mode.
//
// Limitations: small strain/small rotation only (no co-rotational update yet); elastic only
// (no through-thickness integration, so no plasticity); the flat projection means a WARPED
// element does not pass the membrane patch test exactly (flat and mildly warped meshes do
// keep exactly 6 rigid-body modes); no consistent pressure/edge-load helpers (a uniform
// pressure p on a flat element is p A n / 4 per node for a parallelogram).
#include <cstddef>

namespace fdem::fem {

/// Drilling penalty as a fraction of G t A (per node); small, fictitious.
constexpr double kShell4DrillFactor = 1e-3;
/// Transverse-shear correction factor.
constexpr double kShell4ShearFactor = 5.0 / 6.0;

/// Local frame of the element: R (3 x 3, row-major) has rows e1, e2, n (global components);
/// centre c (3); local coordinates xl (4 x 2) of the projected nodes; warp offsets z (4).
/// Any output may be null. Returns the projected (flat) area A.
double shell4_frame(const double* X, double* R, double* c, double* xl, double* z);

/// Linear-elastic stiffness, 24 x 24 row-major, global dofs (see above).
void shell4_stiffness(const double* X, double E, double nu, double t, double* K);

/// Internal force f = K u (24), computed from the strains at the Gauss points without forming K.
void shell4_internal_force(const double* X, const double* u, double E, double nu, double t,
                           double* f);

/// Lumped mass. m (4): translational masses, row-sum m_a = rho t int N_a dA (sum = rho t A,
/// A the projected area). j (4): rotational inertia of each node about ANY axis (isotropic, so
/// that a diagonal mass is frame-invariant for the global rotation dofs):
///     j_a = m_a (t^2 + A / 4) / 12.
/// The first term is the physical rotary inertia of the section (rho t^3/12 per unit area);
/// the second is the inertia of the node's tributary patch (a square of side sqrt(A)/2)
/// about its centre line, i.e. a rotational mass scaling that keeps the rotational
/// frequencies of thin shells below the translational ones, so that the explicit critical
/// time step is governed by the membrane/translational waves. It changes only the rotary
/// inertia (second order for thin shells); translational mass is exact.
void shell4_lumped_mass(const double* X, double density, double t, double* m, double* j);

/// Stress resultants at the element centre, in the LOCAL frame (e1, e2, n) of shell4_frame:
/// N = (N11, N22, N12) (N/m), M = (M11, M22, M12) (N m / m; M11 = int sigma_11 z dz, positive
/// when the face z > 0 is in tension), Q = (Q1, Q2) (N/m, MITC4 shear). Any output may be
/// null. R (9, optional) returns the frame. Surface stresses: sigma = N/t -/+ 6 M/t^2.
void shell4_membrane_bending_stress(const double* X, const double* u, double E, double nu,
                                    double t, double* N, double* M, double* Q, double* R);

}  // namespace fdem::fem
