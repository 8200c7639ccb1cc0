// Mohr-Coulomb return map (fem/element.hpp) against closed-form answers: triaxial strength,
// consistency of the returned stress, closest-point property, apex (no MPI).
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "fem/element.hpp"

using namespace fdem::fem;

namespace {

constexpr double kPi = 3.14159265358979323846;

FeMaterial mc(double phi_deg, double psi_deg, double c = 20e3) {
  FeMaterial m;
  m.kind = FeMaterial::kMohrCoulomb;
  m.young = 50e6;
  m.poisson = 0.25;
  m.cohesion = c;
  m.friction = phi_deg * kPi / 180;
  m.dilation = psi_deg * kPi / 180;
  return m;
}

Eigen::Vector3d principal(const double* s) {  // sorted descending: s1 >= s2 >= s3
  Eigen::Matrix3d S;
  S << s[0], s[3], s[5], s[3], s[1], s[4], s[5], s[4], s[2];
  Eigen::Vector3d ev = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(S).eigenvalues();
  return {ev(2), ev(1), ev(0)};
}

double yield(const Eigen::Vector3d& p, const FeMaterial& m) {
  return (p(0) - p(2)) + (p(0) + p(2)) * std::sin(m.friction) -
         2 * m.cohesion * std::cos(m.friction);
}

// Complementary energy of a stress difference (Voigt): ds^T D^-1 ds.
double energy(const double* ds, const FeMaterial& m) {
  const double E = m.young, nu = m.poisson, G = E / (2 * (1 + nu));
  double w = 0;
  for (int i = 0; i < 3; ++i) {
    double e = ds[i];
    for (int j = 0; j < 3; ++j)
      if (j != i) e -= nu * ds[j];
    w += ds[i] * e / E;
  }
  for (int i = 3; i < 6; ++i) w += ds[i] * ds[i] / G;
  return w;
}

void rotate(const double* p, const Eigen::Matrix3d& R, double* s) {  // R diag(p) R^T -> Voigt
  Eigen::Matrix3d S = R * Eigen::Vector3d(p[0], p[1], p[2]).asDiagonal() * R.transpose();
  s[0] = S(0, 0); s[1] = S(1, 1); s[2] = S(2, 2); s[3] = S(0, 1); s[4] = S(1, 2); s[5] = S(0, 2);
}

Eigen::Matrix3d random_rotation(std::mt19937& rng) {
  std::normal_distribution<double> N;
  Eigen::Quaterniond q(N(rng), N(rng), N(rng), N(rng));
  return q.normalized().toRotationMatrix();
}

// Strain-driven triaxial compression at the material level: axial strain eps_zz decreases in
// increments while the lateral strain (eps_xx = eps_yy) is solved each increment so that the
// lateral stresses stay at -p. Returns the final axial stress.
double triaxial_axial_stress(const FeMaterial& m, double p, int steps, double deps) {
  const double E = m.young, nu = m.poisson;
  // Initial isotropic state -p (elastic).
  const double e0 = -p * (1 - 2 * nu) / E;
  double strain[6] = {e0, e0, e0, 0, 0, 0}, stress[6] = {-p, -p, -p, 0, 0, 0};
  double lat = e0, ax = e0;
  for (int k = 0; k < steps; ++k) {
    ax -= deps;
    auto lateral_residual = [&](double el, double* s_out) {
      const double lam = E * nu / ((1 + nu) * (1 - 2 * nu)), G = E / (2 * (1 + nu));
      double de[3] = {el - strain[0], el - strain[1], ax - strain[2]};
      double trial[6];
      for (int i = 0; i < 3; ++i) trial[i] = stress[i] + lam * (de[0] + de[1] + de[2]) + 2 * G * de[i];
      trial[3] = trial[4] = trial[5] = 0;
      bool y;
      mohr_coulomb_return(trial, m, s_out, y);
      return s_out[0] + p;
    };
    // Secant iterations on the piecewise-linear residual.
    double s[6];
    double x0 = lat, x1 = lat + 1e-6;
    double r0 = lateral_residual(x0, s), r1 = lateral_residual(x1, s);
    for (int it = 0; it < 100 && std::abs(r1) > 1e-13 * p; ++it) {
      const double x2 = x1 - r1 * (x1 - x0) / (r1 - r0);
      x0 = x1; r0 = r1;
      x1 = x2; r1 = lateral_residual(x1, s);
    }
    lat = x1;
    lateral_residual(lat, s);
    strain[0] = strain[1] = lat;
    strain[2] = ax;
    for (int i = 0; i < 6; ++i) stress[i] = s[i];
    EXPECT_NEAR(stress[1], -p, 1e-9 * p);
  }
  return stress[2];
}

}  // namespace

TEST(MohrCoulomb, TriaxialCompressionStrength) {
  for (double coh : {20e3, 0.0})  // cohesive and cohesionless (the thesis's sands)
  for (double phi : {20.0, 30.0, 40.0}) {
    for (double psi : {0.0, 10.0, phi}) {
      const FeMaterial m = mc(phi, psi, coh);
      const double p = 100e3;
      const double s = std::sin(m.friction), c = m.cohesion, cphi = std::cos(m.friction);
      const double qf = 2 * (c * cphi + p * s) / (1 - s);
      // 200 increments of 1e-4 axial strain: well past yield (elastic limit ~ qf / E ~ 1e-2).
      const double sax = triaxial_axial_stress(m, p, 200, 1e-4);
      EXPECT_NEAR(sax, -p - qf, 1e-8 * (p + qf)) << "phi " << phi << " psi " << psi;
    }
  }
}

// Element-level triaxial test: one unit-cube Hex8 with homogeneous nodal displacements
// u = diag(e_lat, e_lat, e_ax) x. The lateral strain is solved so that the nodal forces on the
// face x = 1 equal the confining load p A (a quarter per node); after yield, the axial face
// force equals (p + q_f) A.
TEST(MohrCoulomb, ElementTriaxialHex8) {
  const FeMaterial m = mc(30, 10);
  const double p = 100e3;
  const double s = std::sin(m.friction), cphi = std::cos(m.friction);
  const double qf = 2 * (m.cohesion * cphi + p * s) / (1 - s);
  double X[24];
  const int corner[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                            {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
  for (int a = 0; a < 8; ++a)
    for (int d = 0; d < 3; ++d) X[3 * a + d] = corner[a][d];
  GaussState st[8];
  for (auto& g : st)
    for (int i = 0; i < 3; ++i) {
      g.stress[i] = -p;
      g.strain[i] = -p * (1 - 2 * m.poisson) / m.young;
    }
  double lat = st[0].strain[0], ax = lat;
  double f[24];
  auto face_force = [&](double el, bool commit) {  // x-force on the x = 1 face, compression > 0
    double u[24];
    for (int a = 0; a < 8; ++a) {
      u[3 * a + 0] = el * X[3 * a + 0];
      u[3 * a + 1] = el * X[3 * a + 1];
      u[3 * a + 2] = ax * X[3 * a + 2];
    }
    element_internal_force(ElemType::kHex8, X, u, m, st, commit, f);
    double fx = 0;
    for (int a : {1, 2, 5, 6}) fx += f[3 * a];
    return -fx;
  };
  for (int k = 0; k < 150; ++k) {
    ax -= 1e-4;
    double x0 = lat, x1 = lat + 1e-6;
    double r0 = face_force(x0, false) - p, r1 = face_force(x1, false) - p;
    for (int it = 0; it < 100 && std::abs(r1) > 1e-13 * p; ++it) {
      const double x2 = x1 - r1 * (x1 - x0) / (r1 - r0);
      x0 = x1; r0 = r1;
      x1 = x2; r1 = face_force(x1, false) - p;
    }
    lat = x1;
    face_force(lat, true);
  }
  double fz = 0;
  for (int a : {4, 5, 6, 7}) fz += f[3 * a + 2];
  EXPECT_NEAR(-fz, p + qf, 1e-8 * (p + qf));
  for (const auto& g : st) {
    EXPECT_TRUE(g.yielded);
    EXPECT_NEAR(g.stress[2], -p - qf, 1e-8 * (p + qf));
    // Plastic strain volumetric part for psi = 10 deg: dilatant (positive) under compression.
    EXPECT_GT(g.plastic_strain[0] + g.plastic_strain[1] + g.plastic_strain[2], 0);
  }
}

// Random trial stresses (all return regions): the result is on or inside the surface; for
// associated flow it is the closest admissible stress in the complementary-energy norm.
TEST(MohrCoulomb, ReturnIsConsistentAndClosestPoint) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> U(-1, 1);
  int yielded_count = 0, edges = 0, apexes = 0;
  for (double psi_frac : {1.0, 0.5, 0.0}) {
    const FeMaterial m = mc(35, 35 * psi_frac);
    const double c = m.cohesion, scale = 400e3;
    const double apex = c / std::tan(m.friction);
    for (int trial_no = 0; trial_no < 400; ++trial_no) {
      const Eigen::Matrix3d R = random_rotation(rng);
      double pt[3] = {scale * U(rng), scale * U(rng), scale * U(rng)};
      if (trial_no % 4 == 0) pt[1] = pt[2] + 1e3 * U(rng);  // near the edges
      if (trial_no % 4 == 1) pt[1] = pt[0] + 1e3 * U(rng);
      double trial[6], s[6];
      rotate(pt, R, trial);
      bool y = false;
      mohr_coulomb_return(trial, m, s, y);
      const Eigen::Vector3d ps = principal(s), pt_sorted = principal(trial);
      const double f_trial = yield(pt_sorted, m);
      EXPECT_EQ(y, f_trial > 0);
      EXPECT_LE(yield(ps, m), 1e-9 * scale);
      if (!y) {
        for (int i = 0; i < 6; ++i) EXPECT_EQ(s[i], trial[i]);
        continue;
      }
      ++yielded_count;
      EXPECT_NEAR(yield(ps, m), 0, 1e-9 * scale);
      if (std::abs(ps(0) - ps(2)) < 1e-6 * scale) ++apexes;
      else if (std::abs(ps(0) - ps(1)) < 1e-6 * scale || std::abs(ps(1) - ps(2)) < 1e-6 * scale)
        ++edges;
      // Coaxial with the trial: s and trial commute.
      Eigen::Matrix3d S, T;
      S << s[0], s[3], s[5], s[3], s[1], s[4], s[5], s[4], s[2];
      T << trial[0], trial[3], trial[5], trial[3], trial[1], trial[4], trial[5], trial[4], trial[2];
      EXPECT_LT((S * T - T * S).norm(), 1e-9 * scale * scale);
      // Return of the returned stress is itself.
      double s2[6];
      bool y2 = true;
      mohr_coulomb_return(s, m, s2, y2);
      for (int i = 0; i < 6; ++i) EXPECT_NEAR(s2[i], s[i], 1e-9 * scale);
      // Plastic strain increment n = D^-1 (trial - sigma), in the trial's principal axes.
      double dsv[6], nv[6];
      for (int i = 0; i < 6; ++i) dsv[i] = trial[i] - s[i];
      const double E = m.young, nu = m.poisson, G = E / (2 * (1 + nu));
      for (int i = 0; i < 3; ++i) nv[i] = (dsv[i] - nu * (dsv[(i + 1) % 3] + dsv[(i + 2) % 3])) / E;
      for (int i = 3; i < 6; ++i) nv[i] = dsv[i] / G / 2;  // tensor shear strain
      Eigen::Matrix3d Nt;
      Nt << nv[0], nv[3], nv[5], nv[3], nv[1], nv[4], nv[5], nv[4], nv[2];
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eT(T);
      const Eigen::Matrix3d V = eT.eigenvectors();  // ascending trial eigenvalues
      const Eigen::Matrix3d Sp = V.transpose() * S * V, Np = V.transpose() * Nt * V;
      EXPECT_LT((Sp - Sp.diagonal().asDiagonal().toDenseMatrix()).norm(), 1e-9 * scale);
      EXPECT_LT((Np - Np.diagonal().asDiagonal().toDenseMatrix()).norm(), 1e-9 * Np.norm());
      // Sorted descending (the ordering of the trial is kept by the return).
      const Eigen::Vector3d sp(Sp(2, 2), Sp(1, 1), Sp(0, 0)), np(Np(2, 2), Np(1, 1), Np(0, 0));
      const double nn = np.norm();
      const bool at_apex = std::abs(sp(0) - sp(2)) < 1e-9 * scale;
      if (!at_apex) {
        // Flow rule: n is a non-negative combination of the flow directions of the planes
        // active at sigma: (1,3) always, (2,3) if s1 = s2, (1,2) if s2 = s3.
        const double sps = std::sin(m.dilation);
        std::vector<Eigen::Vector3d> dirs{{1 + sps, 0, -1 + sps}};
        if (std::abs(sp(0) - sp(1)) < 1e-9 * scale) dirs.push_back({0, 1 + sps, -1 + sps});
        if (std::abs(sp(1) - sp(2)) < 1e-9 * scale) dirs.push_back({1 + sps, -1 + sps, 0});
        Eigen::MatrixXd Bm(3, dirs.size());
        for (std::size_t k = 0; k < dirs.size(); ++k) Bm.col(k) = dirs[k];
        const Eigen::VectorXd coef = Bm.colPivHouseholderQr().solve(np);
        EXPECT_LT((Bm * coef - np).norm(), 1e-8 * nn);
        EXPECT_GE(coef.minCoeff(), -1e-8 * nn);
      }
      if (psi_frac != 1.0) continue;
      // Closest point (associated), exactly: sigma minimises the complementary energy of
      // trial - sigma over the admissible set iff n = D^-1 (trial - sigma) satisfies
      // (q - sigma) . n <= 0 for every admissible q. With sigma coaxial with the trial this is
      // a statement in principal space, where the admissible set is the Mohr-Coulomb pyramid:
      // the apex plus the cone of its 6 edge rays, permutations of -(1-s, 1-s, 1+s)
      // (triaxial compression) and -(1-s, 1+s, 1+s) (triaxial extension), s = sin(phi).
      {
        const double sn = std::sin(m.friction);
        EXPECT_LE((Eigen::Vector3d::Constant(apex) - sp).dot(np), 1e-9 * scale * nn);
        for (int k = 0; k < 3; ++k) {
          Eigen::Vector3d rc = -Eigen::Vector3d::Constant(1 - sn), re = -Eigen::Vector3d::Constant(1 + sn);
          rc(k) = -(1 + sn);
          re(k) = -(1 - sn);
          EXPECT_LE(rc.dot(np), 1e-9 * nn * rc.norm());
          EXPECT_LE(re.dot(np), 1e-9 * nn * re.norm());
        }
      }
      // And by sampling: no admissible stress nearby or far is closer in energy.
      double ds[6];
      for (int i = 0; i < 6; ++i) ds[i] = trial[i] - s[i];
      const double best = energy(ds, m);
      for (int k = 0; k < 300; ++k) {
        const double amp = k < 150 ? 1e-3 * scale : 0.3 * scale;
        double q[6];
        for (int i = 0; i < 6; ++i) q[i] = s[i] + amp * U(rng);
        if (yield(principal(q), m) > 0) continue;
        for (int i = 0; i < 6; ++i) ds[i] = trial[i] - q[i];
        EXPECT_GE(energy(ds, m), best * (1 - 1e-12));
      }
    }
  }
  // The sampling reached the plane, edge and apex regions.
  EXPECT_GT(yielded_count, 300);
  EXPECT_GT(edges, 20);
  EXPECT_GT(apexes, 5);
  std::printf("[mc] yielded %d, edge returns %d, apex returns %d\n", yielded_count, edges, apexes);
}

TEST(MohrCoulomb, ElasticTrialUntouched) {
  const FeMaterial m = mc(30, 0);
  const double trial[6] = {-50e3, -80e3, -120e3, 5e3, -3e3, 2e3};
  double s[6];
  bool y = true;
  mohr_coulomb_return(trial, m, s, y);
  EXPECT_FALSE(y);
  for (int i = 0; i < 6; ++i) EXPECT_EQ(s[i], trial[i]);
}

TEST(MohrCoulomb, HydrostaticTensionReturnsToApex) {
  for (double psi : {0.0, 15.0, 30.0}) {
    const FeMaterial m = mc(30, psi);
    const double apex = m.cohesion / std::tan(m.friction);
    const double trial[6] = {3 * apex, 3 * apex, 3 * apex, 0, 0, 0};
    double s[6];
    bool y = false;
    mohr_coulomb_return(trial, m, s, y);
    EXPECT_TRUE(y);
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(s[i], apex, 1e-12 * apex);
    for (int i = 3; i < 6; ++i) EXPECT_NEAR(s[i], 0, 1e-12 * apex);
    // Tension with a little shear is still in the apex region.
    const double t2[6] = {2 * apex, 2.1 * apex, 1.9 * apex, 0.05 * apex, 0, 0.02 * apex};
    mohr_coulomb_return(t2, m, s, y);
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(s[i], apex, 1e-12 * apex);
  }
  // Cohesionless: any tension returns to zero stress.
  {
    const FeMaterial m0 = mc(35, 5, 0.0);
    const double t[6] = {1e3, 2e3, -0.5e3, 0.3e3, 0, 0};
    double s[6];
    bool y = false;
    mohr_coulomb_return(t, m0, s, y);
    EXPECT_TRUE(y);
    for (int i = 0; i < 6; ++i) EXPECT_NEAR(s[i], 0, 1e-12 * 2e3);
  }
  // Just below the apex in hydrostatic tension: elastic.
  const FeMaterial m = mc(30, 0);
  const double apex = m.cohesion / std::tan(m.friction);
  const double t3[6] = {0.99 * apex, 0.99 * apex, 0.99 * apex, 0, 0, 0};
  double s[6];
  bool y = true;
  mohr_coulomb_return(t3, m, s, y);
  EXPECT_FALSE(y);
}
