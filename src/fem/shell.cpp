// 4-node flat shell (MITC4 bending/shear, Q4 membrane, drilling penalty). See shell.hpp.
//
// Implementation notes
//  - One routine (build_local) computes, for the flat projected element, the strain-
//    displacement matrices in the local dofs (u, v, w, t1, t2, t3 per node) at the 2 x 2 Gauss
//    points: membrane Bm (3 x 24), bending Bb (3 x 24), MITC4 shear Bs (2 x 24), and the
//    drilling rows Bd (4 x 24, one per node: theta_3a - omega_c). Stiffness and internal force
//    both use them (K = sum B^T D B w, f = sum B^T D (B u) w), so f = K u to round-off.
//  - Global <-> local: per node, T_a = [[R, z_a R [n]x], [0, R]] (6 x 6) maps the global dofs
//    (u_a, theta_a) of the real node to the local dofs of the projected node p_a = X_a - z_a n:
//    u(p_a) = u_a + theta_a x (p_a - X_a) = u_a + z_a n x theta_a. K = T^T K_loc T.
//  - Fixed-size stack arrays only (no heap), as the explicit solver calls the force each step.
#include "fem/shell.hpp"

#include <cmath>

namespace fdem::fem {

namespace {

constexpr double kNat[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};

inline void cross(const double* a, const double* b, double* c) {
  c[0] = a[1] * b[2] - a[2] * b[1];
  c[1] = a[2] * b[0] - a[0] * b[2];
  c[2] = a[0] * b[1] - a[1] * b[0];
}

inline void shape(double xi, double eta, double* N, double (*dN)[2]) {
  for (int a = 0; a < 4; ++a) {
    const double p = 1 + kNat[a][0] * xi, q = 1 + kNat[a][1] * eta;
    N[a] = 0.25 * p * q;
    dN[a][0] = 0.25 * kNat[a][0] * q;
    dN[a][1] = 0.25 * p * kNat[a][1];
  }
}

struct Frame {
  double R[3][3];   // rows e1, e2, n
  double c[3];
  double xl[4][2];  // projected local coordinates
  double z[4];      // warp offsets
  double area;
};

void make_frame(const double* X, Frame& F) {
  for (int i = 0; i < 3; ++i)
    F.c[i] = 0.25 * (X[i] + X[3 + i] + X[6 + i] + X[9 + i]);
  double d1[3], d2[3], n[3], g[3];
  for (int i = 0; i < 3; ++i) {
    d1[i] = X[6 + i] - X[i];
    d2[i] = X[9 + i] - X[3 + i];
    g[i] = 0.5 * (X[3 + i] + X[6 + i] - X[i] - X[9 + i]);
  }
  cross(d1, d2, n);
  const double nn = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  for (double& v : n) v /= nn;
  const double gn = g[0] * n[0] + g[1] * n[1] + g[2] * n[2];
  double e1[3], e2[3];
  for (int i = 0; i < 3; ++i) e1[i] = g[i] - gn * n[i];
  const double ne = std::sqrt(e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2]);
  for (double& v : e1) v /= ne;
  cross(n, e1, e2);
  for (int i = 0; i < 3; ++i) {
    F.R[0][i] = e1[i];
    F.R[1][i] = e2[i];
    F.R[2][i] = n[i];
  }
  for (int a = 0; a < 4; ++a) {
    double r[3];
    for (int i = 0; i < 3; ++i) r[i] = X[3 * a + i] - F.c[i];
    F.xl[a][0] = r[0] * e1[0] + r[1] * e1[1] + r[2] * e1[2];
    F.xl[a][1] = r[0] * e2[0] + r[1] * e2[1] + r[2] * e2[2];
    F.z[a] = r[0] * n[0] + r[1] * n[1] + r[2] * n[2];
  }
  // Projected area = |d1 x d2| / 2 (exact for the flat bilinear quad).
  F.area = 0.5 * nn;
}

// Global dofs of node a -> local dofs of its projected node.
inline void to_local(const Frame& F, int a, const double* ug, double* ul) {
  const double* n = F.R[2];
  double nxt[3], up[3];
  cross(n, ug + 3, nxt);
  for (int i = 0; i < 3; ++i) up[i] = ug[i] + F.z[a] * nxt[i];
  for (int r = 0; r < 3; ++r) {
    ul[r] = F.R[r][0] * up[0] + F.R[r][1] * up[1] + F.R[r][2] * up[2];
    ul[3 + r] = F.R[r][0] * ug[3] + F.R[r][1] * ug[4] + F.R[r][2] * ug[5];
  }
}

// Local generalised forces of node a -> global (transpose of to_local).
inline void to_global(const Frame& F, int a, const double* fl, double* fg) {
  double Fp[3], Mp[3];
  for (int i = 0; i < 3; ++i) {
    Fp[i] = F.R[0][i] * fl[0] + F.R[1][i] * fl[1] + F.R[2][i] * fl[2];
    Mp[i] = F.R[0][i] * fl[3] + F.R[1][i] * fl[4] + F.R[2][i] * fl[5];
  }
  // moment of the force at p_a about X_a: (p_a - X_a) x F = -z n x F
  double nxF[3];
  cross(F.R[2], Fp, nxF);
  for (int i = 0; i < 3; ++i) {
    fg[i] = Fp[i];
    fg[3 + i] = Mp[i] - F.z[a] * nxF[i];
  }
}

struct LocalB {
  double Bm[4][3][24];
  double Bb[4][3][24];
  double Bs[4][2][24];
  double Bd[4][24];
  double w[4];  // Gauss weight * det J
  double Nint[4];  // int N_a dA
};

// Local dof index: 6 a + (0 u, 1 v, 2 w, 3 t1, 4 t2, 5 t3).
void build_local(const Frame& F, LocalB& L) {
  for (int g = 0; g < 4; ++g) {
    for (int r = 0; r < 3; ++r)
      for (int k = 0; k < 24; ++k) L.Bm[g][r][k] = L.Bb[g][r][k] = 0;
    for (int r = 0; r < 2; ++r)
      for (int k = 0; k < 24; ++k) L.Bs[g][r][k] = 0;
    for (int k = 0; k < 24; ++k) L.Bd[g][k] = 0;
  }
  for (int a = 0; a < 4; ++a) L.Nint[a] = 0;

  // MITC4 tying points: gamma_xi at A (0,-1), C (0,+1); gamma_eta at D (-1,0), B (+1,0).
  // Covariant shear gamma_r = w_,r + beta . x_,r with beta = (t2, -t1).
  double tie[4][24];  // A, C (xi-direction), D, B (eta-direction)
  const double tp[4][2] = {{0, -1}, {0, 1}, {-1, 0}, {1, 0}};
  const int tdir[4] = {0, 0, 1, 1};
  for (int p = 0; p < 4; ++p) {
    double N[4], dN[4][2];
    shape(tp[p][0], tp[p][1], N, dN);
    const int d = tdir[p];
    double xr = 0, yr = 0;
    for (int a = 0; a < 4; ++a) {
      xr += dN[a][d] * F.xl[a][0];
      yr += dN[a][d] * F.xl[a][1];
    }
    for (int k = 0; k < 24; ++k) tie[p][k] = 0;
    for (int a = 0; a < 4; ++a) {
      tie[p][6 * a + 2] = dN[a][d];
      tie[p][6 * a + 4] = N[a] * xr;   // beta_1 = t2
      tie[p][6 * a + 3] = -N[a] * yr;  // beta_2 = -t1
    }
  }

  const double s = 1.0 / std::sqrt(3.0);
  for (int g = 0; g < 4; ++g) {
    const double xi = (g & 1) ? s : -s, eta = (g & 2) ? s : -s;
    double N[4], dN[4][2];
    shape(xi, eta, N, dN);
    double J[2][2] = {{0, 0}, {0, 0}};  // J[r][i] = d x_i / d r
    for (int a = 0; a < 4; ++a)
      for (int r = 0; r < 2; ++r)
        for (int i = 0; i < 2; ++i) J[r][i] += dN[a][r] * F.xl[a][i];
    const double det = J[0][0] * J[1][1] - J[0][1] * J[1][0];
    const double Ji[2][2] = {{J[1][1] / det, -J[0][1] / det}, {-J[1][0] / det, J[0][0] / det}};
    L.w[g] = det;  // Gauss weights are 1
    double dx[4][2];
    for (int a = 0; a < 4; ++a) {
      dx[a][0] = Ji[0][0] * dN[a][0] + Ji[0][1] * dN[a][1];
      dx[a][1] = Ji[1][0] * dN[a][0] + Ji[1][1] * dN[a][1];
      L.Nint[a] += N[a] * det;
    }
    for (int a = 0; a < 4; ++a) {
      const int o = 6 * a;
      // membrane
      L.Bm[g][0][o + 0] = dx[a][0];
      L.Bm[g][1][o + 1] = dx[a][1];
      L.Bm[g][2][o + 0] = dx[a][1];
      L.Bm[g][2][o + 1] = dx[a][0];
      // bending: kappa = (beta1_1, beta2_2, beta1_2 + beta2_1), beta1 = t2, beta2 = -t1
      L.Bb[g][0][o + 4] = dx[a][0];
      L.Bb[g][1][o + 3] = -dx[a][1];
      L.Bb[g][2][o + 4] = dx[a][1];
      L.Bb[g][2][o + 3] = -dx[a][0];
    }
    // MITC4 shear: covariant strains interpolated, then (gxz, gyz) = J^-1 (g_xi, g_eta).
    double gxi[24], geta[24];
    for (int k = 0; k < 24; ++k) {
      gxi[k] = 0.5 * (1 - eta) * tie[0][k] + 0.5 * (1 + eta) * tie[1][k];
      geta[k] = 0.5 * (1 - xi) * tie[2][k] + 0.5 * (1 + xi) * tie[3][k];
    }
    for (int k = 0; k < 24; ++k) {
      L.Bs[g][0][k] = Ji[0][0] * gxi[k] + Ji[0][1] * geta[k];
      L.Bs[g][1][k] = Ji[1][0] * gxi[k] + Ji[1][1] * geta[k];
    }
  }

  // Drilling: theta_3a - omega_c, omega_c = (v_,1 - u_,2)/2 at the centre.
  {
    double N[4], dN[4][2];
    shape(0, 0, N, dN);
    double J[2][2] = {{0, 0}, {0, 0}};
    for (int a = 0; a < 4; ++a)
      for (int r = 0; r < 2; ++r)
        for (int i = 0; i < 2; ++i) J[r][i] += dN[a][r] * F.xl[a][i];
    const double det = J[0][0] * J[1][1] - J[0][1] * J[1][0];
    const double Ji[2][2] = {{J[1][1] / det, -J[0][1] / det}, {-J[1][0] / det, J[0][0] / det}};
    for (int b = 0; b < 4; ++b) {
      const double dxb = Ji[0][0] * dN[b][0] + Ji[0][1] * dN[b][1];
      const double dyb = Ji[1][0] * dN[b][0] + Ji[1][1] * dN[b][1];
      for (int a = 0; a < 4; ++a) {
        L.Bd[a][6 * b + 0] += 0.5 * dyb;
        L.Bd[a][6 * b + 1] += -0.5 * dxb;
      }
    }
    for (int a = 0; a < 4; ++a) L.Bd[a][6 * a + 5] += 1.0;
  }
}

struct Moduli {
  double Dm[3][3];  // membrane, includes t
  double Db[3][3];  // bending, includes t^3/12
  double Ds;        // kappa G t
  double kd;        // drilling penalty per node
};

Moduli moduli(double E, double nu, double t, double area) {
  Moduli M;
  const double c = E / (1 - nu * nu);
  const double P[3][3] = {{1, nu, 0}, {nu, 1, 0}, {0, 0, 0.5 * (1 - nu)}};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      M.Dm[i][j] = c * t * P[i][j];
      M.Db[i][j] = c * t * t * t / 12.0 * P[i][j];
    }
  const double G = E / (2 * (1 + nu));
  M.Ds = kShell4ShearFactor * G * t;
  M.kd = kShell4DrillFactor * G * t * area;
  return M;
}

// Local internal force fl = K_loc ul.
void local_force(const LocalB& L, const Moduli& M, const double* ul, double* fl) {
  for (int k = 0; k < 24; ++k) fl[k] = 0;
  for (int g = 0; g < 4; ++g) {
    double em[3] = {0, 0, 0}, kb[3] = {0, 0, 0}, gs[2] = {0, 0};
    for (int k = 0; k < 24; ++k) {
      for (int r = 0; r < 3; ++r) {
        em[r] += L.Bm[g][r][k] * ul[k];
        kb[r] += L.Bb[g][r][k] * ul[k];
      }
      gs[0] += L.Bs[g][0][k] * ul[k];
      gs[1] += L.Bs[g][1][k] * ul[k];
    }
    double Nr[3], Mr[3];
    for (int r = 0; r < 3; ++r) {
      Nr[r] = (M.Dm[r][0] * em[0] + M.Dm[r][1] * em[1] + M.Dm[r][2] * em[2]) * L.w[g];
      Mr[r] = (M.Db[r][0] * kb[0] + M.Db[r][1] * kb[1] + M.Db[r][2] * kb[2]) * L.w[g];
    }
    const double Q0 = M.Ds * gs[0] * L.w[g], Q1 = M.Ds * gs[1] * L.w[g];
    for (int k = 0; k < 24; ++k)
      fl[k] += L.Bm[g][0][k] * Nr[0] + L.Bm[g][1][k] * Nr[1] + L.Bm[g][2][k] * Nr[2] +
               L.Bb[g][0][k] * Mr[0] + L.Bb[g][1][k] * Mr[1] + L.Bb[g][2][k] * Mr[2] +
               L.Bs[g][0][k] * Q0 + L.Bs[g][1][k] * Q1;
  }
  for (int a = 0; a < 4; ++a) {
    double e = 0;
    for (int k = 0; k < 24; ++k) e += L.Bd[a][k] * ul[k];
    e *= M.kd;
    for (int k = 0; k < 24; ++k) fl[k] += L.Bd[a][k] * e;
  }
}

void local_stiffness(const LocalB& L, const Moduli& M, double (*K)[24]) {
  for (int i = 0; i < 24; ++i)
    for (int j = 0; j < 24; ++j) K[i][j] = 0;
  for (int g = 0; g < 4; ++g) {
    double DBm[3][24], DBb[3][24];
    for (int r = 0; r < 3; ++r)
      for (int k = 0; k < 24; ++k) {
        DBm[r][k] = (M.Dm[r][0] * L.Bm[g][0][k] + M.Dm[r][1] * L.Bm[g][1][k] +
                     M.Dm[r][2] * L.Bm[g][2][k]) * L.w[g];
        DBb[r][k] = (M.Db[r][0] * L.Bb[g][0][k] + M.Db[r][1] * L.Bb[g][1][k] +
                     M.Db[r][2] * L.Bb[g][2][k]) * L.w[g];
      }
    const double ds = M.Ds * L.w[g];
    for (int i = 0; i < 24; ++i)
      for (int j = 0; j < 24; ++j) {
        double s = ds * (L.Bs[g][0][i] * L.Bs[g][0][j] + L.Bs[g][1][i] * L.Bs[g][1][j]);
        for (int r = 0; r < 3; ++r) s += L.Bm[g][r][i] * DBm[r][j] + L.Bb[g][r][i] * DBb[r][j];
        K[i][j] += s;
      }
  }
  for (int a = 0; a < 4; ++a)
    for (int i = 0; i < 24; ++i) {
      if (L.Bd[a][i] == 0) continue;
      for (int j = 0; j < 24; ++j) K[i][j] += M.kd * L.Bd[a][i] * L.Bd[a][j];
    }
}

// 6 x 6 node transformation T_a (local = T_a global).
void node_transform(const Frame& F, int a, double (*T)[6]) {
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j) T[i][j] = 0;
  const double* n = F.R[2];
  const double nx[3][3] = {{0, -n[2], n[1]}, {n[2], 0, -n[0]}, {-n[1], n[0], 0}};
  for (int r = 0; r < 3; ++r)
    for (int j = 0; j < 3; ++j) {
      T[r][j] = F.R[r][j];
      T[3 + r][3 + j] = F.R[r][j];
      double s = 0;
      for (int k = 0; k < 3; ++k) s += F.R[r][k] * nx[k][j];
      T[r][3 + j] = F.z[a] * s;
    }
}

}  // namespace

double shell4_frame(const double* X, double* R, double* c, double* xl, double* z) {
  Frame F;
  make_frame(X, F);
  if (R)
    for (int i = 0; i < 9; ++i) R[i] = F.R[i / 3][i % 3];
  if (c)
    for (int i = 0; i < 3; ++i) c[i] = F.c[i];
  if (xl)
    for (int a = 0; a < 4; ++a) {
      xl[2 * a] = F.xl[a][0];
      xl[2 * a + 1] = F.xl[a][1];
    }
  if (z)
    for (int a = 0; a < 4; ++a) z[a] = F.z[a];
  return F.area;
}

void shell4_stiffness(const double* X, double E, double nu, double t, double* K) {
  Frame F;
  make_frame(X, F);
  LocalB L;
  build_local(F, L);
  const Moduli M = moduli(E, nu, t, F.area);
  double Kl[24][24];
  local_stiffness(L, M, Kl);
  double T[4][6][6];
  for (int a = 0; a < 4; ++a) node_transform(F, a, T[a]);
  // K_ab = T_a^T Kl_ab T_b
  for (int a = 0; a < 4; ++a)
    for (int b = 0; b < 4; ++b) {
      double KT[6][6];  // Kl_ab T_b
      for (int i = 0; i < 6; ++i)
        for (int j = 0; j < 6; ++j) {
          double s = 0;
          for (int k = 0; k < 6; ++k) s += Kl[6 * a + i][6 * b + k] * T[b][k][j];
          KT[i][j] = s;
        }
      for (int i = 0; i < 6; ++i)
        for (int j = 0; j < 6; ++j) {
          double s = 0;
          for (int k = 0; k < 6; ++k) s += T[a][k][i] * KT[k][j];
          K[(6 * a + i) * 24 + 6 * b + j] = s;
        }
    }
}

void shell4_internal_force(const double* X, const double* u, double E, double nu, double t,
                           double* f) {
  Frame F;
  make_frame(X, F);
  LocalB L;
  build_local(F, L);
  const Moduli M = moduli(E, nu, t, F.area);
  double ul[24], fl[24];
  for (int a = 0; a < 4; ++a) to_local(F, a, u + 6 * a, ul + 6 * a);
  local_force(L, M, ul, fl);
  for (int a = 0; a < 4; ++a) to_global(F, a, fl + 6 * a, f + 6 * a);
}

void shell4_lumped_mass(const double* X, double density, double t, double* m, double* j) {
  Frame F;
  make_frame(X, F);
  LocalB L;
  build_local(F, L);
  for (int a = 0; a < 4; ++a) {
    const double ma = density * t * L.Nint[a];
    if (m) m[a] = ma;
    if (j) j[a] = ma * (t * t + 0.25 * F.area) / 12.0;
  }
}

void shell4_membrane_bending_stress(const double* X, const double* u, double E, double nu,
                                    double t, double* N, double* M, double* Q, double* R) {
  Frame F;
  make_frame(X, F);
  LocalB L;
  build_local(F, L);
  const Moduli D = moduli(E, nu, t, F.area);
  double ul[24];
  for (int a = 0; a < 4; ++a) to_local(F, a, u + 6 * a, ul + 6 * a);
  // "Centre" values: the average of the strains at the four Gauss points (exactly the centre
  // value for a parallelogram, and exact for any shape when the strain field is constant).
  double em[3] = {0, 0, 0}, kb[3] = {0, 0, 0}, gs[2] = {0, 0};
  for (int g = 0; g < 4; ++g)
    for (int k = 0; k < 24; ++k) {
      for (int r = 0; r < 3; ++r) {
        em[r] += 0.25 * L.Bm[g][r][k] * ul[k];
        kb[r] += 0.25 * L.Bb[g][r][k] * ul[k];
      }
      gs[0] += 0.25 * L.Bs[g][0][k] * ul[k];
      gs[1] += 0.25 * L.Bs[g][1][k] * ul[k];
    }
  for (int r = 0; r < 3; ++r) {
    if (N) N[r] = D.Dm[r][0] * em[0] + D.Dm[r][1] * em[1] + D.Dm[r][2] * em[2];
    if (M) M[r] = D.Db[r][0] * kb[0] + D.Db[r][1] * kb[1] + D.Db[r][2] * kb[2];
  }
  if (Q) {
    Q[0] = D.Ds * gs[0];
    Q[1] = D.Ds * gs[1];
  }
  if (R)
    for (int i = 0; i < 9; ++i) R[i] = F.R[i / 3][i % 3];
}

}  // namespace fdem::fem
