// 4-node flat shell kernel (fem/shell.hpp) against closed-form answers: symmetry and the
// rigid-body spectrum (flat and warped), K u vs the internal force, membrane and
// constant-curvature patch tests on a distorted 2 x 2 mesh placed obliquely in space, a thin
// cantilever strip (shear-locking check), the pressurised ring (membrane) and the pinched ring
// (bending), lumped mass. Dense global assembly with Eigen (no MPI).
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <array>
#include <cmath>
#include <cstdio>
#include <vector>

#include "fem/shell.hpp"

using namespace fdem::fem;

namespace {

struct ShellMesh {
  std::vector<double> X;  // n x 3
  std::vector<std::array<int, 4>> conn;
  int nodes() const { return static_cast<int>(X.size() / 3); }
};

Eigen::MatrixXd assemble(const ShellMesh& m, double E, double nu, double t) {
  const int n = 6 * m.nodes();
  Eigen::MatrixXd K = Eigen::MatrixXd::Zero(n, n);
  for (const auto& c : m.conn) {
    double Xe[12], Ke[576];
    for (int a = 0; a < 4; ++a)
      for (int i = 0; i < 3; ++i) Xe[3 * a + i] = m.X[3 * c[a] + i];
    shell4_stiffness(Xe, E, nu, t, Ke);
    for (int a = 0; a < 4; ++a)
      for (int i = 0; i < 6; ++i)
        for (int b = 0; b < 4; ++b)
          for (int j = 0; j < 6; ++j)
            K(6 * c[a] + i, 6 * c[b] + j) += Ke[(6 * a + i) * 24 + 6 * b + j];
  }
  return K;
}

// Global internal force from the element kernel (no K).
Eigen::VectorXd internal_force(const ShellMesh& m, const Eigen::VectorXd& u, double E,
                               double nu, double t) {
  Eigen::VectorXd f = Eigen::VectorXd::Zero(6 * m.nodes());
  for (const auto& c : m.conn) {
    double Xe[12], ue[24], fe[24];
    for (int a = 0; a < 4; ++a) {
      for (int i = 0; i < 3; ++i) Xe[3 * a + i] = m.X[3 * c[a] + i];
      for (int i = 0; i < 6; ++i) ue[6 * a + i] = u[6 * c[a] + i];
    }
    shell4_internal_force(Xe, ue, E, nu, t, fe);
    for (int a = 0; a < 4; ++a)
      for (int i = 0; i < 6; ++i) f[6 * c[a] + i] += fe[6 * a + i];
  }
  return f;
}

// Solve K u = F with the dofs in `fixed` held at zero.
Eigen::VectorXd solve(const Eigen::MatrixXd& K, const Eigen::VectorXd& F,
                      const std::vector<bool>& fixed) {
  const int n = static_cast<int>(K.rows());
  std::vector<int> map;
  for (int i = 0; i < n; ++i)
    if (!fixed[i]) map.push_back(i);
  const int m = static_cast<int>(map.size());
  Eigen::MatrixXd Kff(m, m);
  Eigen::VectorXd Ff(m);
  for (int i = 0; i < m; ++i) {
    Ff[i] = F[map[i]];
    for (int j = 0; j < m; ++j) Kff(i, j) = K(map[i], map[j]);
  }
  Eigen::LLT<Eigen::MatrixXd> llt(Kff);
  EXPECT_EQ(llt.info(), Eigen::Success) << "reduced stiffness not positive definite";
  const Eigen::VectorXd uf = llt.solve(Ff);
  Eigen::VectorXd u = Eigen::VectorXd::Zero(n);
  for (int i = 0; i < m; ++i) u[map[i]] = uf[i];
  return u;
}

// A proper rotation (rows/columns orthonormal) from three angles.
Eigen::Matrix3d rotation(double a, double b, double c) {
  return (Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(b, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(c, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

// Element in space: local (x, y, z) points mapped by Q and shifted.
void place(const double (*p)[3], const Eigen::Matrix3d& Q, const Eigen::Vector3d& o, int n,
           double* X) {
  for (int a = 0; a < n; ++a) {
    const Eigen::Vector3d x = o + Q * Eigen::Vector3d(p[a][0], p[a][1], p[a][2]);
    for (int i = 0; i < 3; ++i) X[3 * a + i] = x[i];
  }
}

struct Spectrum {
  int zeros;
  double smallest_nonzero;  // relative to lambda_max
  double largest_zero;      // relative to lambda_max
};

// Spectrum of the element stiffness. The ratios depend on units because translations and
// rotations are mixed; ell != 1 uses the dofs (u, ell theta) instead (ell ~ element size).
Spectrum spectrum(const double* X, double E, double nu, double t, double ell = 1.0) {
  double Ke[576];
  shell4_stiffness(X, E, nu, t, Ke);
  Eigen::Map<Eigen::Matrix<double, 24, 24, Eigen::RowMajor>> K(Ke);
  EXPECT_LT((K - K.transpose()).cwiseAbs().maxCoeff(), 1e-12 * K.cwiseAbs().maxCoeff());
  Eigen::Matrix<double, 24, 24> S = Eigen::Matrix<double, 24, 24>::Identity();
  for (int k = 0; k < 24; ++k)
    if (k % 6 >= 3) S(k, k) = 1.0 / ell;
  const Eigen::Matrix<double, 24, 24> Ks = S * (0.5 * (K + K.transpose())) * S;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 24, 24>> es(Ks);
  const auto& ev = es.eigenvalues();
  const double lmax = ev.cwiseAbs().maxCoeff();
  Spectrum s{0, 1e300, 0};
  for (int i = 0; i < 24; ++i) {
    const double r = ev[i] / lmax;
    if (std::abs(r) < 1e-9) {
      ++s.zeros;
      s.largest_zero = std::max(s.largest_zero, std::abs(r));
    } else {
      s.smallest_nonzero = std::min(s.smallest_nonzero, r);
    }
  }
  // The six rigid-body motions give zero force.
  double c[3] = {0, 0, 0};
  for (int a = 0; a < 4; ++a)
    for (int i = 0; i < 3; ++i) c[i] += 0.25 * X[3 * a + i];
  for (int mode = 0; mode < 6; ++mode) {
    Eigen::Matrix<double, 24, 1> r = Eigen::Matrix<double, 24, 1>::Zero();
    for (int a = 0; a < 4; ++a) {
      if (mode < 3) {
        r[6 * a + mode] = 1;
      } else {
        Eigen::Vector3d w = Eigen::Vector3d::Unit(mode - 3);
        Eigen::Vector3d d(X[3 * a] - c[0], X[3 * a + 1] - c[1], X[3 * a + 2] - c[2]);
        r.segment<3>(6 * a) = w.cross(d);
        r.segment<3>(6 * a + 3) = w;
      }
    }
    EXPECT_LT((K * r).norm(), 1e-9 * lmax * r.norm()) << "rigid mode " << mode;
  }
  return s;
}

constexpr double kE = 450e6, kNu = 0.46;  // the thesis's pipe material

}  // namespace

TEST(Shell4, FrameAndMass) {
  // Distorted quad in an oblique plane.
  const double p[4][3] = {{0, 0, 0}, {1.2, 0.1, 0}, {1.0, 0.9, 0}, {-0.1, 1.1, 0}};
  const Eigen::Matrix3d Q = rotation(0.3, -0.7, 1.1);
  double X[12];
  place(p, Q, Eigen::Vector3d(1, -2, 0.5), 4, X);
  double R[9], c[3], xl[8], z[4];
  const double A = shell4_frame(X, R, c, xl, z);
  // planar area of the quad (shoelace)
  double A0 = 0;
  for (int a = 0; a < 4; ++a) {
    const int b = (a + 1) % 4;
    A0 += 0.5 * (p[a][0] * p[b][1] - p[b][0] * p[a][1]);
  }
  EXPECT_NEAR(A, A0, 1e-14);
  for (int a = 0; a < 4; ++a) EXPECT_NEAR(z[a], 0, 1e-14);
  // normal = Q e_z for a counter-clockwise quad
  const Eigen::Vector3d n(R[6], R[7], R[8]);
  EXPECT_NEAR((n - Q.col(2)).norm(), 0, 1e-14);

  const double rho = 1500, t = 0.004;
  double m[4], j[4];
  shell4_lumped_mass(X, rho, t, m, j);
  double msum = 0;
  for (int a = 0; a < 4; ++a) {
    EXPECT_GT(m[a], 0);
    EXPECT_NEAR(j[a], m[a] * (t * t + A / 4) / 12, 1e-15 * m[a]);
    msum += m[a];
  }
  EXPECT_NEAR(msum, rho * t * A, 1e-12 * rho * t * A);
}

TEST(Shell4, SymmetricWithSixRigidBodyModes) {
  const Eigen::Matrix3d Q = rotation(0.4, 0.9, -0.3);
  const Eigen::Vector3d o(0.2, 0.1, -0.4);
  const double t = 0.05;
  {
    const double p[4][3] = {{0, 0, 0}, {1.1, -0.1, 0}, {0.9, 0.8, 0}, {0.1, 1.0, 0}};
    double X[12];
    place(p, Q, o, 4, X);
    const Spectrum s = spectrum(X, kE, kNu, t);
    std::printf("flat element:   zero eigenvalues %d (largest %.2e lmax), smallest nonzero %.3e lmax\n",
                s.zeros, s.largest_zero, s.smallest_nonzero);
    EXPECT_EQ(s.zeros, 6);
    EXPECT_GT(s.smallest_nonzero, 1e-8);
  }
  {
    const double h = 0.05;  // warp: z = +h, -h, +h, -h
    const double p[4][3] = {{0, 0, h}, {1.1, -0.1, -h}, {0.9, 0.8, h}, {0.1, 1.0, -h}};
    double X[12];
    place(p, Q, o, 4, X);
    double z[4];
    shell4_frame(X, nullptr, nullptr, nullptr, z);
    EXPECT_NEAR(std::abs(z[0]), h, 1e-12);
    const Spectrum s = spectrum(X, kE, kNu, t);
    std::printf("warped element: zero eigenvalues %d (largest %.2e lmax), smallest nonzero %.3e lmax\n",
                s.zeros, s.largest_zero, s.smallest_nonzero);
    EXPECT_EQ(s.zeros, 6);
    EXPECT_GT(s.smallest_nonzero, 1e-8);
  }
}

TEST(Shell4, PipeElementSpectrumAndFrequencies) {
  // An element of the thesis's pipe: 64 around D = 0.15 m (7.4 mm), 20 mm wide, t = 4 mm.
  const double t = 0.004, rho = 1500, w = 2 * 0.075 * std::sin(M_PI / 64), b = 0.02;
  const double p[4][3] = {{0, 0, 0}, {w, 0, 0}, {w, b, 0}, {0, b, 0}};
  double X[12];
  place(p, Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero(), 4, X);
  // The smallest nonzero modes are the three drilling ones (kShell4DrillFactor = 1e-3); in
  // raw SI dofs they sit near 1.4e-8 lmax for this 7 mm element, with (u, sqrt(A) theta)
  // near 1e-4 lmax.
  const Spectrum s = spectrum(X, kE, kNu, t);
  const Spectrum ss = spectrum(X, kE, kNu, t, std::sqrt(w * b));
  std::printf("pipe element:   zero eigenvalues %d, smallest nonzero %.3e lmax (SI dofs), "
              "%.3e lmax (dofs u, sqrt(A) theta)\n", s.zeros, s.smallest_nonzero,
              ss.smallest_nonzero);
  EXPECT_EQ(s.zeros, 6);
  EXPECT_EQ(ss.zeros, 6);
  EXPECT_GT(ss.smallest_nonzero, 1e-5);
  // Highest free-element frequency with the lumped (m, j) vs the membrane alone (ux, uy with
  // m): the rotational mass scaling keeps the rotations from governing the explicit step.
  double Ke[576], m[4], j[4];
  shell4_stiffness(X, kE, kNu, t, Ke);
  shell4_lumped_mass(X, rho, t, m, j);
  Eigen::Map<Eigen::Matrix<double, 24, 24, Eigen::RowMajor>> K(Ke);
  auto omega_max = [&](const std::vector<int>& dofs, bool physical_rotary) {
    const int n = static_cast<int>(dofs.size());
    Eigen::MatrixXd A(n, n);
    for (int r = 0; r < n; ++r) {
      const int a = dofs[r] / 6, i = dofs[r] % 6;
      const double mr = i < 3 ? m[a] : (physical_rotary ? m[a] * t * t / 12 : j[a]);
      for (int c = 0; c < n; ++c) {
        const int b2 = dofs[c] / 6, k = dofs[c] % 6;
        const double mc = k < 3 ? m[b2] : (physical_rotary ? m[b2] * t * t / 12 : j[b2]);
        A(r, c) = K(dofs[r], dofs[c]) / std::sqrt(mr * mc);
      }
    }
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(0.5 * (A + A.transpose()));
    return std::sqrt(es.eigenvalues().maxCoeff());
  };
  std::vector<int> all, membrane;
  for (int k = 0; k < 24; ++k) {
    all.push_back(k);
    if (k % 6 < 2) membrane.push_back(k);
  }
  const double wm = omega_max(membrane, false), wa = omega_max(all, false),
               wp = omega_max(all, true);
  std::printf("pipe element omega_max / membrane omega_max: scaled rotary inertia %.3f, "
              "physical rho t^3/12 only %.3f\n", wa / wm, wp / wm);
  EXPECT_LT(wa / wm, 1.05);
}

TEST(Shell4, InternalForceEqualsKu) {
  const double h = 0.03;
  const double p[4][3] = {{0, 0, h}, {1.1, -0.1, -h}, {0.9, 0.8, h}, {0.1, 1.0, -h}};
  double X[12];
  place(p, rotation(-0.2, 0.5, 0.8), Eigen::Vector3d(1, 2, 3), 4, X);
  double K[576], u[24], f[24];
  for (int k = 0; k < 24; ++k) u[k] = 1e-3 * std::sin(1.7 * k + 0.3);
  shell4_stiffness(X, kE, kNu, 0.01, K);
  shell4_internal_force(X, u, kE, kNu, 0.01, f);
  double scale = 0;
  for (int i = 0; i < 24; ++i) scale = std::max(scale, std::abs(f[i]));
  for (int i = 0; i < 24; ++i) {
    double s = 0;
    for (int j = 0; j < 24; ++j) s += K[24 * i + j] * u[j];
    EXPECT_NEAR(f[i], s, 1e-12 * scale);
  }
}

namespace {

// Distorted 2 x 2 patch on [0,2]^2 (node 4 interior), mapped obliquely into space.
struct Patch {
  ShellMesh mesh;
  std::vector<Eigen::Vector2d> p;  // in-plane coordinates
  Eigen::Matrix3d Q;
};

Patch make_patch() {
  Patch P;
  const double xy[9][2] = {{0, 0},     {1.1, 0},  {2, 0},   {0, 0.9}, {1.2, 1.15},
                           {2, 1.1},   {0, 2},    {0.85, 2}, {2, 2}};
  P.Q = rotation(0.7, -0.4, 0.25);
  const Eigen::Vector3d o(0.3, -0.1, 0.2);
  for (auto& q : xy) {
    P.p.emplace_back(q[0], q[1]);
    const Eigen::Vector3d x = o + P.Q * Eigen::Vector3d(q[0], q[1], 0);
    for (int i = 0; i < 3; ++i) P.mesh.X.push_back(x[i]);
  }
  P.mesh.conn = {{0, 1, 4, 3}, {1, 2, 5, 4}, {3, 4, 7, 6}, {4, 5, 8, 7}};
  return P;
}

}  // namespace

TEST(Shell4, MembranePatchTest) {
  Patch P = make_patch();
  const double t = 0.01;
  // u = A x + b in the plane, theta = omega about the normal.
  Eigen::Matrix2d A;
  A << 1e-3, 4e-4, -2e-4, -5e-4;
  const Eigen::Vector2d b(1e-4, -3e-4);
  const double omega = 0.5 * (A(1, 0) - A(0, 1));
  Eigen::VectorXd u = Eigen::VectorXd::Zero(6 * 9);
  for (int k = 0; k < 9; ++k) {
    const Eigen::Vector2d d = A * P.p[k] + b;
    u.segment<3>(6 * k) = P.Q.col(0) * d[0] + P.Q.col(1) * d[1];
    u.segment<3>(6 * k + 3) = P.Q.col(2) * omega;
  }
  const Eigen::VectorXd f = internal_force(P.mesh, u, kE, kNu, t);
  const double scale = f.cwiseAbs().maxCoeff();
  std::printf("membrane patch: interior node |f| = %.2e of max |f| (%.3e)\n",
              f.segment<6>(24).cwiseAbs().maxCoeff() / scale, scale);
  EXPECT_LT(f.segment<6>(24).cwiseAbs().maxCoeff(), 1e-10 * scale);
  // Resultants: N invariant trace, no bending, no shear.
  const double ex = A(0, 0), ey = A(1, 1);
  const double c = kE * t / (1 - kNu * kNu);
  for (const auto& e : P.mesh.conn) {
    double Xe[12], ue[24], N[3], M[3], Q[2];
    for (int a = 0; a < 4; ++a) {
      for (int i = 0; i < 3; ++i) Xe[3 * a + i] = P.mesh.X[3 * e[a] + i];
      for (int i = 0; i < 6; ++i) ue[6 * a + i] = u[6 * e[a] + i];
    }
    shell4_membrane_bending_stress(Xe, ue, kE, kNu, t, N, M, Q, nullptr);
    EXPECT_NEAR(N[0] + N[1], c * (1 + kNu) * (ex + ey), 1e-9 * c * 1e-3);
    for (int r = 0; r < 3; ++r) EXPECT_NEAR(M[r], 0, 1e-9 * c * 1e-3 * t);
    for (int r = 0; r < 2; ++r) EXPECT_NEAR(Q[r], 0, 1e-9 * c * 1e-3);
  }
}

TEST(Shell4, ConstantCurvaturePatchTest) {
  Patch P = make_patch();
  const double t = 0.01;
  // w = a x^2 + b y^2 + c x y, beta = -grad w (no transverse shear), theta1 = -beta2,
  // theta2 = beta1. Curvatures (beta1_1, beta2_2, beta1_2 + beta2_1) = -(2a, 2b, 2c).
  const double a = 1e-3, bq = -4e-4, cq = 6e-4;
  Eigen::VectorXd u = Eigen::VectorXd::Zero(6 * 9);
  for (int k = 0; k < 9; ++k) {
    const double x = P.p[k][0], y = P.p[k][1];
    const double w = a * x * x + bq * y * y + cq * x * y;
    const double beta1 = -(2 * a * x + cq * y), beta2 = -(2 * bq * y + cq * x);
    u.segment<3>(6 * k) = P.Q.col(2) * w;
    u.segment<3>(6 * k + 3) = P.Q.col(0) * (-beta2) + P.Q.col(1) * beta1;
  }
  const Eigen::VectorXd f = internal_force(P.mesh, u, kE, kNu, t);
  const double scale = f.cwiseAbs().maxCoeff();
  std::printf("bending patch: interior node |f| = %.2e of max |f| (%.3e)\n",
              f.segment<6>(24).cwiseAbs().maxCoeff() / scale, scale);
  // round-off: the shear stiffness is (L/t)^2 larger than the bending one
  EXPECT_LT(f.segment<6>(24).cwiseAbs().maxCoeff(), 1e-9 * scale);
  const double D = kE * t * t * t / (12 * (1 - kNu * kNu));
  for (const auto& e : P.mesh.conn) {
    double Xe[12], ue[24], N[3], M[3], Q[2];
    for (int n = 0; n < 4; ++n) {
      for (int i = 0; i < 3; ++i) Xe[3 * n + i] = P.mesh.X[3 * e[n] + i];
      for (int i = 0; i < 6; ++i) ue[6 * n + i] = u[6 * e[n] + i];
    }
    shell4_membrane_bending_stress(Xe, ue, kE, kNu, t, N, M, Q, nullptr);
    const double scaleM = D * 1e-3;
    EXPECT_NEAR(M[0] + M[1], D * (1 + kNu) * -2 * (a + bq), 1e-9 * scaleM);
    for (int r = 0; r < 2; ++r) EXPECT_NEAR(Q[r], 0, 1e-9 * scaleM);
    for (int r = 0; r < 3; ++r) EXPECT_NEAR(N[r], 0, 1e-9 * scaleM);
  }
}

namespace {

// Cantilever strip: nx x ny elements on [0,L] x [0,b], clamped at x = 0, tip line load P
// (total, -z). Returns the mean tip deflection / (P L^3 / (3 E I)).
// skew > 0 distorts the mesh: the middle line's nodes shift along x by +/- skew * L / nx.
double cantilever_ratio(int nx, int ny, double L, double b, double t, double E, double nu,
                        double skew = 0) {
  ShellMesh m;
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) {
      const bool shift = j > 0 && j < ny && i > 0 && i < nx;
      m.X.push_back(L * (i + (shift ? skew * (i % 2 ? 1 : -1) : 0.0)) / nx);
      m.X.push_back(b * j / ny);
      m.X.push_back(0);
    }
  auto id = [&](int i, int j) { return j * (nx + 1) + i; };
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i)
      m.conn.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)});
  const Eigen::MatrixXd K = assemble(m, E, nu, t);
  std::vector<bool> fixed(6 * m.nodes(), false);
  Eigen::VectorXd F = Eigen::VectorXd::Zero(6 * m.nodes());
  const double P = 1.0;
  for (int j = 0; j <= ny; ++j) {
    for (int k = 0; k < 6; ++k) fixed[6 * id(0, j) + k] = true;
    const double wgt = (j == 0 || j == ny) ? 0.5 : 1.0;
    F[6 * id(nx, j) + 2] = -P * wgt / ny;
  }
  const Eigen::VectorXd u = solve(K, F, fixed);
  double tip = 0;
  for (int j = 0; j <= ny; ++j) tip += -u[6 * id(nx, j) + 2] / (ny + 1);
  const double I = b * t * t * t / 12;
  return tip / (P * L * L * L / (3 * E * I));
}

}  // namespace

TEST(Shell4, CantileverStripNoShearLocking) {
  // nu = 0: the strip is a beam; MITC4 on 20 x 2 elements is within 0.1 % of PL^3/3EI for
  // L/t = 100, 1000 and 10000 (no shear locking).
  const double r0 = cantilever_ratio(20, 2, 1.0, 0.1, 0.01, 2e11, 0.0);
  const double r0t = cantilever_ratio(20, 2, 1.0, 0.1, 0.001, 2e11, 0.0);
  const double r0tt = cantilever_ratio(20, 2, 1.0, 0.1, 0.0001, 2e11, 0.0);
  // nu > 0: the clamp restrains the anticlastic curvature over a length ~ b, a real plate
  // effect that stiffens the strip (converged: about 0.991 at nu = 0.3 and 0.979 at
  // nu = 0.46 for b/L = 0.1; 20x2 -> 40x4 -> 80x8 gives 0.9885, 0.9898, 0.9905 at nu = 0.3).
  const double r1 = cantilever_ratio(20, 2, 1.0, 0.1, 0.01, 2e11, 0.3);
  const double r2 = cantilever_ratio(20, 2, 1.0, 0.1, 0.001, 2e11, 0.3);
  const double r3 = cantilever_ratio(20, 2, 1.0, 0.1, 0.01, kE, kNu);
  std::printf("cantilever 20x2, tip / (PL^3/3EI): nu=0: t=0.01 %.5f, t=0.001 %.5f, "
              "t=0.0001 %.5f; nu=0.3: t=0.01 %.5f, t=0.001 %.5f; nu=0.46: t=0.01 %.5f\n",
              r0, r0t, r0tt, r1, r2, r3);
  EXPECT_NEAR(r0, 1.0, 0.001);
  EXPECT_NEAR(r0t, 1.0, 0.001);
  EXPECT_NEAR(r0tt, 1.0, 0.001);
  EXPECT_NEAR(r1, 1.0, 0.02);
  EXPECT_NEAR(r2, 1.0, 0.02);
  EXPECT_NEAR(r3, 0.979, 0.01);
  // Distorted elements (middle-line nodes shifted by +/- 0.3 element lengths: trapezoids).
  const double rd = cantilever_ratio(20, 2, 1.0, 0.1, 0.01, 2e11, 0.0, 0.3);
  const double rdt = cantilever_ratio(20, 2, 1.0, 0.1, 0.0001, 2e11, 0.0, 0.3);
  std::printf("cantilever 20x2 distorted, nu=0: t=0.01 %.5f, t=0.0001 %.5f\n", rd, rdt);
  EXPECT_NEAR(rd, 1.0, 0.02);
  EXPECT_NEAR(rdt, 1.0, 0.02);
}

namespace {

// Ring of radius R (axis z), width b, n elements around, one across the width.
// Node 2i at angle 2 pi i / n, z = 0; node 2i + 1 at z = b.
ShellMesh ring_mesh(int n, double R, double b) {
  ShellMesh m;
  for (int i = 0; i < n; ++i) {
    const double phi = 2 * M_PI * i / n;
    for (int k = 0; k < 2; ++k) {
      m.X.push_back(R * std::cos(phi));
      m.X.push_back(R * std::sin(phi));
      m.X.push_back(b * k);
    }
  }
  for (int i = 0; i < n; ++i) {
    const int j = (i + 1) % n;
    m.conn.push_back({2 * i, 2 * j, 2 * j + 1, 2 * i + 1});
  }
  return m;
}

// Statically determinate supports removing the 6 rigid-body modes (reactions vanish for a
// self-equilibrated load): node at phi = 0: ux, uy, uz; node at phi = pi: uy, uz; node at
// phi = pi/2: uz (all on the edge z = 0). plane_strain also holds uz, theta_x, theta_y everywhere.
std::vector<bool> ring_supports(int n, bool plane_strain) {
  std::vector<bool> fixed(6 * 2 * n, false);
  const int a = 0, b = 2 * (n / 2), c = 2 * (n / 4);
  fixed[6 * a + 0] = fixed[6 * a + 1] = true;
  fixed[6 * b + 1] = true;
  if (plane_strain) {
    for (int k = 0; k < 2 * n; ++k) fixed[6 * k + 2] = fixed[6 * k + 3] = fixed[6 * k + 4] = true;
  } else {
    fixed[6 * a + 2] = fixed[6 * b + 2] = fixed[6 * c + 2] = true;
  }
  return fixed;
}

}  // namespace

TEST(Shell4, PressurisedRing) {
  const double R = 0.075, b = 0.02, t = 0.004, p = 1e4;  // the thesis's pipe: D 0.15 m, 4 mm
  const int n = 64;
  for (bool plane_strain : {false, true}) {
    const ShellMesh m = ring_mesh(n, R, b);
    const Eigen::MatrixXd K = assemble(m, kE, kNu, t);
    Eigen::VectorXd F = Eigen::VectorXd::Zero(6 * m.nodes());
    // Uniform internal pressure: p A along the outward normal, a quarter to each node
    // (consistent for a flat rectangle).
    for (const auto& e : m.conn) {
      double Xe[12], Rf[9], c[3];
      for (int a = 0; a < 4; ++a)
        for (int i = 0; i < 3; ++i) Xe[3 * a + i] = m.X[3 * e[a] + i];
      const double A = shell4_frame(Xe, Rf, c, nullptr, nullptr);
      Eigen::Vector3d nrm(Rf[6], Rf[7], Rf[8]);
      if (nrm.dot(Eigen::Vector3d(c[0], c[1], 0)) < 0) nrm = -nrm;
      for (int a = 0; a < 4; ++a) F.segment<3>(6 * e[a]) += 0.25 * p * A * nrm;
    }
    const Eigen::VectorXd u = solve(K, F, ring_supports(n, plane_strain));
    // Radial displacement from the change of each diameter (free of the rigid motion that the
    // isostatic supports leave in u): u_r = (u_k - u_opposite) . rhat_k / 2.
    double ur = 0, umin = 1e300, umax = -1e300;
    for (int k = 0; k < m.nodes(); ++k) {
      const int o = (k + n) % (2 * n);  // node at phi + pi, same z
      const Eigen::Vector2d rh = Eigen::Vector2d(m.X[3 * k], m.X[3 * k + 1]).normalized();
      const double v = 0.5 * rh.dot(Eigen::Vector2d(u[6 * k] - u[6 * o], u[6 * k + 1] - u[6 * o + 1]));
      ur += v / m.nodes();
      umin = std::min(umin, v);
      umax = std::max(umax, v);
    }
    const double Eeff = plane_strain ? kE / (1 - kNu * kNu) : kE;
    const double exact = p * R * R / (Eeff * t);
    // The inscribed polygon with lumped nodal loads: hoop force p b R cos(pi/n) exactly.
    const double polygon = exact * std::cos(M_PI / n);
    std::printf("pressurised ring n=%d %s: u_r / (pR^2/Et) = %.5f (polygon %.5f), spread %.1e\n",
                n, plane_strain ? "plane strain" : "free edges", ur / exact, polygon / exact,
                (umax - umin) / ur);
    EXPECT_NEAR(ur / exact, 1.0, 0.01);
    EXPECT_NEAR(ur / polygon, 1.0, 1e-3);
    EXPECT_LT((umax - umin) / ur, 1e-6);
    // Self-equilibrated load on isostatic supports: no reactions.
    if (!plane_strain) {
      const Eigen::VectorXd r = K * u - F;
      EXPECT_LT(r.cwiseAbs().maxCoeff(), 1e-8 * F.cwiseAbs().maxCoeff());
    }
  }
}

TEST(Shell4, PinchedRing) {
  const double R = 0.075, b = 0.02, t = 0.004, P = 10.0;
  for (int n : {64, 128}) {
    for (bool plane_strain : {false, true}) {
      const ShellMesh m = ring_mesh(n, R, b);
      const Eigen::MatrixXd K = assemble(m, kE, kNu, t);
      Eigen::VectorXd F = Eigen::VectorXd::Zero(6 * m.nodes());
      const int top = n / 4, bot = 3 * n / 4;  // phi = pi/2, 3 pi/2
      for (int k = 0; k < 2; ++k) {
        F[6 * (2 * top + k) + 1] = -P / 2;
        F[6 * (2 * bot + k) + 1] = +P / 2;
      }
      const Eigen::VectorXd u = solve(K, F, ring_supports(n, plane_strain));
      double delta = 0;
      for (int k = 0; k < 2; ++k)
        delta += 0.5 * (u[6 * (2 * bot + k) + 1] - u[6 * (2 * top + k) + 1]);
      const double Eeff = plane_strain ? kE / (1 - kNu * kNu) : kE;
      const double I = b * t * t * t / 12;
      const double exact = (M_PI / 4 - 2 / M_PI) * P * R * R * R / (Eeff * I);
      // With the hoop-extension and transverse-shear flexibility of the ring (Roark, thin/thick
      // circular ring under diametral loads): delta = PR^3/EI (pi/4 k1 - 2 k2^2 / pi),
      // k1 = 1 - alpha + beta, k2 = 1 - alpha, alpha = I/(A R^2), beta = (6/5) E I/(G A R^2)
      // (+0.5 % for this R/t = 18.75 ring).
      const double alpha = t * t / (12 * R * R);
      const double beta = 1.2 * Eeff / (kE / (2 * (1 + kNu))) * alpha;
      const double k1 = 1 - alpha + beta, k2 = 1 - alpha;
      const double roark = P * R * R * R / (Eeff * I) * (M_PI / 4 * k1 - 2 * k2 * k2 / M_PI);
      std::printf("pinched ring n=%d %s: delta / (0.1488 PR^3/EI) = %.5f, / Roark (shear, "
                  "extension) = %.5f\n", n, plane_strain ? "plane strain" : "free edges",
                  delta / exact, delta / roark);
      EXPECT_NEAR(delta / exact, 1.0, 0.03);
      if (n == 128) EXPECT_NEAR(delta / roark, 1.0, 0.01);
      if (!plane_strain) {  // isostatic supports: no reactions
        const Eigen::VectorXd r = K * u - F;
        EXPECT_LT(r.cwiseAbs().maxCoeff(), 1e-8 * P);
      }
    }
  }
}
