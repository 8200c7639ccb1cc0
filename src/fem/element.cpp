// Finite-element kernels (DESIGN.md 4.3). See element.hpp for conventions.
//
// Implementation notes
//  - Every element type is a compile-time `Shape` (node count, dimension, shape functions);
//    the per-call kernels are templates over it and work on fixed-size stack arrays only
//    (no heap allocation), since the explicit solver calls element_internal_force every step.
//  - Shape-function derivatives at the integration points are tabulated once (function-local
//    statics, thread-safe initialisation).
//  - Integration-point order: index g = i + 2 j + 4 k, natural coordinates
//    (xi, eta, zeta) = (s_i, s_j, s_k) with s_0 = -1/sqrt(3), s_1 = +1/sqrt(3) (2-D: g = i + 2 j).
//    Hex8R has a single point (the element centre).
//  - Quad4 is plane strain with unit thickness (forces per metre, mass per metre).
//  - Hex8R (Flanagan & Belytschko 1981, IJNME 17:679): the one-point B matrix uses the
//    *uniform* (volume-averaged) gradients bbar_a = (1/V) int dN_a/dx dV (exact with 2x2x2
//    Gauss for the trilinear brick), which — unlike the gradients at the centre — pass the
//    patch test on distorted bricks. Hourglass base vectors gamma_al = h_al - (h_al . x_j) bbar_j
//    with h_1 = eta zeta, h_2 = xi zeta, h_3 = xi eta, h_4 = xi eta zeta at the nodes; they are
//    orthogonal to every linear field, so hourglass forces vanish for u = A x + c.
//    Hourglass stiffness (stiffness form, always elastic):
//        f_ai = k sum_al gamma_al,a (sum_b gamma_al,b u_bi),
//        k = hourglass * G * (2/3) V (bbar : bbar),   bbar : bbar = sum_a sum_j bbar_aj^2,
//    i.e. FB's stiffness form with the shear modulus, normalised so that for a cube of side L
//    k = hourglass * G L: a fraction `hourglass` of the element's shear stiffness G A / L.
//    (V bbar:bbar follows the element's shape: for an L x h x h brick, L >> h, it tends to L.)
//    For reference, on a cube the fully integrated Hex8 resists the hourglass (bending) mode
//    with k = L (lambda + 3 G) / 48 (0.094 G L at nu = 0.3, including parasitic shear) and
//    pure bending would need k = E L / 48 (0.054 G L at nu = 0.3): the default 0.05 is close
//    to the latter.
#include <stdexcept>

#include "fem/element.hpp"
#include "fem/shell.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstring>
#include <limits>

#include "fem/mohr_coulomb_detail.hpp"

namespace fdem::fem {

std::string element_type_names() {
  std::string s;
  for (const ElementTraits& e : kElementTraits) s += (s.empty() ? "" : ", ") + std::string(e.name);
  return s;
}

bool parse_element_type(const std::string& name, ElemType& out) {
  std::string s(name);
  for (char& ch : s) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  for (const ElementTraits& e : kElementTraits)
    if (s == e.name) { out = e.type; return true; }
  return false;
}

void elastic_matrix(double young, double poisson, double* D) {
  const double lam = young * poisson / ((1 + poisson) * (1 - 2 * poisson));
  const double G = young / (2 * (1 + poisson));
  for (int i = 0; i < 36; ++i) D[i] = 0;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) D[6 * i + j] = lam;
    D[6 * i + i] = lam + 2 * G;
    D[6 * (i + 3) + (i + 3)] = G;
  }
}

namespace {

// ---------------------------------------------------------------------------------------------
// Shape functions in natural coordinates.

// The brick's corners (as doubles, for the shape functions) and Hex20's edges: kHexCorner,
// kHex20Edge (fem/element_types.hpp).
constexpr std::array<std::array<double, 3>, 8> kHexCornerD = [] {
  std::array<std::array<double, 3>, 8> c{};
  for (int a = 0; a < 8; ++a)
    for (int i = 0; i < 3; ++i) c[a][i] = kHexCorner[a][i];
  return c;
}();
constexpr double kQuadCorner[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};

struct Hex8Shape {
  static constexpr int N = 8, D = 3;
  static void natural(int a, double* xi) {
    for (int i = 0; i < 3; ++i) xi[i] = kHexCornerD[a][i];
  }
  static void eval(const double* x, double* Nv, double (*dN)[3]) {
    for (int a = 0; a < 8; ++a) {
      const double* c = kHexCornerD[a].data();
      const double p0 = 1 + c[0] * x[0], p1 = 1 + c[1] * x[1], p2 = 1 + c[2] * x[2];
      Nv[a] = 0.125 * p0 * p1 * p2;
      dN[a][0] = 0.125 * c[0] * p1 * p2;
      dN[a][1] = 0.125 * p0 * c[1] * p2;
      dN[a][2] = 0.125 * p0 * p1 * c[2];
    }
  }
};

struct Hex20Shape {
  static constexpr int N = 20, D = 3;
  static void natural(int a, double* xi) {
    if (a < 8) {
      for (int i = 0; i < 3; ++i) xi[i] = kHexCornerD[a][i];
    } else {
      const int p = kHex20Edge[a - 8][0], q = kHex20Edge[a - 8][1];
      for (int i = 0; i < 3; ++i) xi[i] = 0.5 * (kHexCornerD[p][i] + kHexCornerD[q][i]);
    }
  }
  static void eval(const double* x, double* Nv, double (*dN)[3]) {
    for (int a = 0; a < 8; ++a) {
      const double* c = kHexCornerD[a].data();
      const double p0 = 1 + c[0] * x[0], p1 = 1 + c[1] * x[1], p2 = 1 + c[2] * x[2];
      const double s = c[0] * x[0] + c[1] * x[1] + c[2] * x[2] - 2;
      Nv[a] = 0.125 * p0 * p1 * p2 * s;
      dN[a][0] = 0.125 * c[0] * p1 * p2 * (s + p0);
      dN[a][1] = 0.125 * c[1] * p0 * p2 * (s + p1);
      dN[a][2] = 0.125 * c[2] * p0 * p1 * (s + p2);
    }
    for (int e = 0; e < 12; ++e) {
      const int a = 8 + e;
      double c[3];
      natural(a, c);
      // The direction with c = 0 carries (1 - x^2); the other two (1 + c x).
      double f[3], df[3];
      for (int i = 0; i < 3; ++i) {
        if (c[i] == 0) { f[i] = 1 - x[i] * x[i]; df[i] = -2 * x[i]; }
        else { f[i] = 1 + c[i] * x[i]; df[i] = c[i]; }
      }
      Nv[a] = 0.25 * f[0] * f[1] * f[2];
      dN[a][0] = 0.25 * df[0] * f[1] * f[2];
      dN[a][1] = 0.25 * f[0] * df[1] * f[2];
      dN[a][2] = 0.25 * f[0] * f[1] * df[2];
    }
  }
};

struct Quad4Shape {
  static constexpr int N = 4, D = 2;
  static void natural(int a, double* xi) {
    xi[0] = kQuadCorner[a][0];
    xi[1] = kQuadCorner[a][1];
  }
  static void eval(const double* x, double* Nv, double (*dN)[2]) {
    for (int a = 0; a < 4; ++a) {
      const double* c = kQuadCorner[a];
      const double p0 = 1 + c[0] * x[0], p1 = 1 + c[1] * x[1];
      Nv[a] = 0.25 * p0 * p1;
      dN[a][0] = 0.25 * c[0] * p1;
      dN[a][1] = 0.25 * p0 * c[1];
    }
  }
};

// Tensor-product Gauss rule with P points per direction in D dimensions, with shape values
// and natural derivatives tabulated at the points.
template <class S, int P>
struct Rule {
  static constexpr int NG = (S::D == 3) ? P * P * P : P * P;
  double xi[NG][S::D];
  double w[NG];
  double Nv[NG][S::N];
  double dN[NG][S::N][S::D];
  Rule() {
    double s[3], ws[3];
    if (P == 1) { s[0] = 0; ws[0] = 2; }
    else if (P == 2) { s[0] = -1 / std::sqrt(3.0); s[1] = -s[0]; ws[0] = ws[1] = 1; }
    else { s[0] = -std::sqrt(0.6); s[1] = 0; s[2] = -s[0]; ws[0] = ws[2] = 5.0 / 9; ws[1] = 8.0 / 9; }
    for (int g = 0; g < NG; ++g) {
      int idx[3] = {g % P, (g / P) % P, g / (P * P)};
      w[g] = 1;
      for (int d = 0; d < S::D; ++d) { xi[g][d] = s[idx[d]]; w[g] *= ws[idx[d]]; }
      S::eval(xi[g], Nv[g], dN[g]);
    }
  }
  static const Rule& get() {
    static const Rule r;
    return r;
  }
};

// Jacobian J_ij = sum_a dN_a/dxi_i X_aj; returns det J and fills dNdx = J^-1 dN/dxi.
template <int N>
double gradients(const double (*dN)[3], const double* X, double (*dNdx)[3]) {
  double J[3][3] = {};
  for (int a = 0; a < N; ++a)
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) J[i][j] += dN[a][i] * X[3 * a + j];
  double C[3][3];  // cofactors: inverse = C^T / det
  C[0][0] = J[1][1] * J[2][2] - J[1][2] * J[2][1];
  C[0][1] = J[1][2] * J[2][0] - J[1][0] * J[2][2];
  C[0][2] = J[1][0] * J[2][1] - J[1][1] * J[2][0];
  C[1][0] = J[0][2] * J[2][1] - J[0][1] * J[2][2];
  C[1][1] = J[0][0] * J[2][2] - J[0][2] * J[2][0];
  C[1][2] = J[0][1] * J[2][0] - J[0][0] * J[2][1];
  C[2][0] = J[0][1] * J[1][2] - J[0][2] * J[1][1];
  C[2][1] = J[0][2] * J[1][0] - J[0][0] * J[1][2];
  C[2][2] = J[0][0] * J[1][1] - J[0][1] * J[1][0];
  const double det = J[0][0] * C[0][0] + J[0][1] * C[0][1] + J[0][2] * C[0][2];
  const double inv = 1 / det;
  for (int a = 0; a < N; ++a)
    for (int j = 0; j < 3; ++j)  // (J^-1)_ji = C_ij / det
      dNdx[a][j] = inv * (C[0][j] * dN[a][0] + C[1][j] * dN[a][1] + C[2][j] * dN[a][2]);
  return det;
}

template <int N>
double gradients(const double (*dN)[2], const double* X, double (*dNdx)[2]) {
  double J[2][2] = {};
  for (int a = 0; a < N; ++a)
    for (int i = 0; i < 2; ++i)
      for (int j = 0; j < 2; ++j) J[i][j] += dN[a][i] * X[2 * a + j];
  const double det = J[0][0] * J[1][1] - J[0][1] * J[1][0];
  const double inv = 1 / det;
  for (int a = 0; a < N; ++a) {
    dNdx[a][0] = inv * (J[1][1] * dN[a][0] - J[0][1] * dN[a][1]);
    dNdx[a][1] = inv * (-J[1][0] * dN[a][0] + J[0][0] * dN[a][1]);
  }
  return det;
}

template <int N>
double det_only(const double (*dN)[3], const double* X) {
  double J[3][3] = {};
  for (int a = 0; a < N; ++a)
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) J[i][j] += dN[a][i] * X[3 * a + j];
  return J[0][0] * (J[1][1] * J[2][2] - J[1][2] * J[2][1]) -
         J[0][1] * (J[1][0] * J[2][2] - J[1][2] * J[2][0]) +
         J[0][2] * (J[1][0] * J[2][1] - J[1][1] * J[2][0]);
}
template <int N>
double det_only(const double (*dN)[2], const double* X) {
  double J[2][2] = {};
  for (int a = 0; a < N; ++a)
    for (int i = 0; i < 2; ++i)
      for (int j = 0; j < 2; ++j) J[i][j] += dN[a][i] * X[2 * a + j];
  return J[0][0] * J[1][1] - J[0][1] * J[1][0];
}

// Strain (Voigt, 6 components, engineering shear) from gradients and nodal displacements.
template <int N>
inline void strain_of(const double (*g)[3], const double* u, double* e) {
  for (int i = 0; i < 6; ++i) e[i] = 0;
  for (int a = 0; a < N; ++a) {
    const double* ua = u + 3 * a;
    e[0] += g[a][0] * ua[0];
    e[1] += g[a][1] * ua[1];
    e[2] += g[a][2] * ua[2];
    e[3] += g[a][1] * ua[0] + g[a][0] * ua[1];
    e[4] += g[a][2] * ua[1] + g[a][1] * ua[2];
    e[5] += g[a][2] * ua[0] + g[a][0] * ua[2];
  }
}
template <int N>
inline void strain_of(const double (*g)[2], const double* u, double* e) {
  for (int i = 0; i < 6; ++i) e[i] = 0;
  for (int a = 0; a < N; ++a) {
    const double* ua = u + 2 * a;
    e[0] += g[a][0] * ua[0];
    e[1] += g[a][1] * ua[1];
    e[3] += g[a][1] * ua[0] + g[a][0] * ua[1];
  }
}

// f += dV * B^T sigma.
template <int N>
inline void add_force(const double (*g)[3], const double* s, double dV, double* f) {
  for (int a = 0; a < N; ++a) {
    f[3 * a + 0] += dV * (g[a][0] * s[0] + g[a][1] * s[3] + g[a][2] * s[5]);
    f[3 * a + 1] += dV * (g[a][0] * s[3] + g[a][1] * s[1] + g[a][2] * s[4]);
    f[3 * a + 2] += dV * (g[a][0] * s[5] + g[a][1] * s[4] + g[a][2] * s[2]);
  }
}
template <int N>
inline void add_force(const double (*g)[2], const double* s, double dV, double* f) {
  for (int a = 0; a < N; ++a) {
    f[2 * a + 0] += dV * (g[a][0] * s[0] + g[a][1] * s[3]);
    f[2 * a + 1] += dV * (g[a][0] * s[3] + g[a][1] * s[1]);
  }
}

// K += dV * B^T D B for isotropic D (lam, G); K row-major (N*Dm)^2.
template <int N>
inline void add_stiffness(const double (*g)[3], double lam, double G, double dV, double* K) {
  constexpr int n = 3 * N;
  for (int a = 0; a < N; ++a) {
    for (int b = 0; b < N; ++b) {
      const double* ga = g[a];
      const double* gb = g[b];
      const double dot = ga[0] * gb[0] + ga[1] * gb[1] + ga[2] * gb[2];
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
          // K_ab,ij = lam ga_i gb_j + G ga_j gb_i + G delta_ij (ga . gb)
          double k = lam * ga[i] * gb[j] + G * ga[j] * gb[i];
          if (i == j) k += G * dot;
          K[(3 * a + i) * n + 3 * b + j] += dV * k;
        }
    }
  }
}
template <int N>
inline void add_stiffness(const double (*g)[2], double lam, double G, double dV, double* K) {
  constexpr int n = 2 * N;
  for (int a = 0; a < N; ++a)
    for (int b = 0; b < N; ++b) {
      const double* ga = g[a];
      const double* gb = g[b];
      const double dot = ga[0] * gb[0] + ga[1] * gb[1];
      for (int i = 0; i < 2; ++i)
        for (int j = 0; j < 2; ++j) {
          double k = lam * ga[i] * gb[j] + G * ga[j] * gb[i];
          if (i == j) k += G * dot;
          K[(2 * a + i) * n + 2 * b + j] += dV * k;
        }
    }
}

inline void lame(const FeMaterial& m, double& lam, double& G) {
  lam = m.young * m.poisson / ((1 + m.poisson) * (1 - 2 * m.poisson));
  G = m.young / (2 * (1 + m.poisson));
}

// Isotropic elastic stress from strain (6 components, engineering shear).
inline void elastic_stress(double lam, double G, const double* e, double* s) {
  const double tr = lam * (e[0] + e[1] + e[2]);
  s[0] = tr + 2 * G * e[0];
  s[1] = tr + 2 * G * e[1];
  s[2] = tr + 2 * G * e[2];
  s[3] = G * e[3];
  s[4] = G * e[4];
  s[5] = G * e[5];
}

// Stress at one integration point from the total strain e: elastic, or Mohr-Coulomb from the
// stored state; commits the state if asked.
inline void point_stress(const FeMaterial& m, double lam, double G, const double* e,
                         GaussState* st, bool commit, double* s) {
  if (m.kind == FeMaterial::kMohrCoulomb && st) {
    double trial[6], de[6];
    for (int i = 0; i < 6; ++i) de[i] = e[i] - st->strain[i];
    elastic_stress(lam, G, de, trial);
    for (int i = 0; i < 6; ++i) trial[i] += st->stress[i];
    bool y = false;
    mohr_coulomb_return(trial, m, s, y);
    if (commit) {
      if (y) {
        double dep[6], ds[6];
        for (int i = 0; i < 6; ++i) ds[i] = trial[i] - s[i];
        detail::elastic_compliance(m.young, m.poisson, ds, dep);
        for (int i = 0; i < 6; ++i) st->plastic_strain[i] += dep[i];
      }
      for (int i = 0; i < 6; ++i) { st->stress[i] = s[i]; st->strain[i] = e[i]; }
      st->yielded = y;
    }
  } else {
    elastic_stress(lam, G, e, s);
    if (commit && st) {
      for (int i = 0; i < 6; ++i) { st->stress[i] = s[i]; st->strain[i] = e[i]; }
      st->yielded = false;
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Full integration elements (Hex8, Hex20, Quad4).

// Total Lagrangian (m.nlgeom, elastic only): at each point F = I + grad_0 u, the Green-Lagrange
// strain E = (F^T F - I) / 2, the second Piola-Kirchhoff stress S = D : E (St Venant-Kirchhoff),
// and f_a = int_V0 F S grad_0 N_a dV0, so a rigid rotation of any size gives no force. The state
// keeps E (engineering shear) and the Cauchy stress F S F^T / det F (what the output shows).
// Plane strain (D = 2): F_zz = 1, E_zz = 0, S_zz = lam (E_xx + E_yy).
template <int N, int D>
void tl_point(const double (*g)[D], const double* u, double lam, double G, double dV, GaussState* st,
              bool commit, double* f) {
  double F[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  for (int a = 0; a < N; ++a)
    for (int i = 0; i < D; ++i)
      for (int j = 0; j < D; ++j) F[i][j] += u[D * a + i] * g[a][j];
  double C[3][3];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) C[i][j] = F[0][i] * F[0][j] + F[1][i] * F[1][j] + F[2][i] * F[2][j];
  const double e[6] = {0.5 * (C[0][0] - 1), 0.5 * (C[1][1] - 1), 0.5 * (C[2][2] - 1), C[0][1], C[1][2], C[0][2]};
  double sv[6];
  elastic_stress(lam, G, e, sv);
  const double S[3][3] = {{sv[0], sv[3], sv[5]}, {sv[3], sv[1], sv[4]}, {sv[5], sv[4], sv[2]}};
  double Pk[3][3] = {};  // first Piola-Kirchhoff, F S
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 3; ++k) Pk[i][j] += F[i][k] * S[k][j];
  for (int a = 0; a < N; ++a)
    for (int i = 0; i < D; ++i) {
      double v = 0;
      for (int j = 0; j < D; ++j) v += Pk[i][j] * g[a][j];
      f[D * a + i] += dV * v;
    }
  if (!(commit && st)) return;
  const double J = F[0][0] * (F[1][1] * F[2][2] - F[1][2] * F[2][1]) - F[0][1] * (F[1][0] * F[2][2] - F[1][2] * F[2][0]) +
                   F[0][2] * (F[1][0] * F[2][1] - F[1][1] * F[2][0]);
  double sig[3][3] = {};  // P F^T / J
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 3; ++k) sig[i][j] += Pk[i][k] * F[j][k] / J;
  const double out[6] = {sig[0][0], sig[1][1], sig[2][2], sig[0][1], sig[1][2], sig[0][2]};
  for (int i = 0; i < 6; ++i) { st->stress[i] = out[i]; st->strain[i] = e[i]; }
  st->yielded = false;
}

template <class S, int P>
void full_internal_force(const double* X, const double* u, const FeMaterial& m,
                         GaussState* states, bool commit, double* f) {
  constexpr int N = S::N, D = S::D;
  const auto& R = Rule<S, P>::get();
  double lam, G;
  lame(m, lam, G);
  for (int i = 0; i < N * D; ++i) f[i] = 0;
  double g[N][D], e[6], s[6];
  if (m.nlgeom) {
    if (m.kind != FeMaterial::kElastic) throw std::logic_error("nlgeom is for elastic materials");
    for (int q = 0; q < R.NG; ++q) {
      const double det = gradients<N>(R.dN[q], X, g);
      tl_point<N, D>(g, u, lam, G, det * R.w[q], states ? states + q : nullptr, commit, f);
    }
    return;
  }
  for (int q = 0; q < R.NG; ++q) {
    const double det = gradients<N>(R.dN[q], X, g);
    strain_of<N>(g, u, e);
    point_stress(m, lam, G, e, states ? states + q : nullptr, commit, s);
    add_force<N>(g, s, det * R.w[q], f);
  }
}

template <class S, int P>
void full_stiffness(const double* X, const FeMaterial& m, double* K) {
  constexpr int N = S::N, D = S::D;
  const auto& R = Rule<S, P>::get();
  double lam, G;
  lame(m, lam, G);
  for (int i = 0; i < N * D * N * D; ++i) K[i] = 0;
  double g[N][D];
  for (int q = 0; q < R.NG; ++q) {
    const double det = gradients<N>(R.dN[q], X, g);
    add_stiffness<N>(g, lam, G, det * R.w[q], K);
  }
}

// Row-sum lumped mass (linear elements): m_a = rho int N_a dV.
template <class S, int P>
void rowsum_mass(const double* X, double rho, double* mass) {
  constexpr int N = S::N;
  const auto& R = Rule<S, P>::get();
  for (int a = 0; a < N; ++a) mass[a] = 0;
  for (int q = 0; q < R.NG; ++q) {
    const double dV = det_only<N>(R.dN[q], X) * R.w[q];
    for (int a = 0; a < N; ++a) mass[a] += rho * R.Nv[q][a] * dV;
  }
}

// HRZ lumping: diagonal of the consistent mass scaled so the total is rho V.
template <class S, int P>
void hrz_mass(const double* X, double rho, double* mass) {
  constexpr int N = S::N;
  const auto& R = Rule<S, P>::get();
  double V = 0, diag_sum = 0;
  for (int a = 0; a < N; ++a) mass[a] = 0;
  for (int q = 0; q < R.NG; ++q) {
    const double dV = det_only<N>(R.dN[q], X) * R.w[q];
    V += dV;
    for (int a = 0; a < N; ++a) mass[a] += R.Nv[q][a] * R.Nv[q][a] * dV;
  }
  for (int a = 0; a < N; ++a) diag_sum += mass[a];
  const double scale = rho * V / diag_sum;
  for (int a = 0; a < N; ++a) mass[a] *= scale;
}

template <class S, int P>
void body_force(const double* X, const double* b, double* f) {
  constexpr int N = S::N, D = S::D;
  const auto& R = Rule<S, P>::get();
  for (int i = 0; i < N * D; ++i) f[i] = 0;
  for (int q = 0; q < R.NG; ++q) {
    const double dV = det_only<N>(R.dN[q], X) * R.w[q];
    for (int a = 0; a < N; ++a)
      for (int d = 0; d < D; ++d) f[D * a + d] += R.Nv[q][a] * dV * b[d];
  }
}

// Smallest det J over the element's integration points (the given rule and 2x2x2), the centre
// and the nodes.
template <class S>
double min_detj(const double* X) {
  constexpr int N = S::N, D = S::D;
  double dmin = std::numeric_limits<double>::infinity();
  const auto& R2 = Rule<S, 2>::get();
  for (int q = 0; q < R2.NG; ++q) dmin = std::min(dmin, det_only<N>(R2.dN[q], X));
  const auto& R1 = Rule<S, 1>::get();
  dmin = std::min(dmin, det_only<N>(R1.dN[0], X));
  double xi[3], Nv[N], dN[N][D];
  for (int a = 0; a < N; ++a) {
    S::natural(a, xi);
    S::eval(xi, Nv, dN);
    dmin = std::min(dmin, det_only<N>(dN, X));
  }
  return dmin;
}

// det J at the nodes, then the centre; the first smallest and where (local node, -1: centre).
template <class S>
double min_nodal_detj(const double* X, int& where) {
  constexpr int N = S::N, D = S::D;
  double best = std::numeric_limits<double>::infinity();
  where = -1;
  double xi[3], Nv[N], dN[N][D];
  for (int s = 0; s <= N; ++s) {
    const int at = s < N ? s : -1;
    if (at >= 0) S::natural(at, xi);
    else xi[0] = xi[1] = xi[2] = 0;
    S::eval(xi, Nv, dN);
    const double d = det_only<N>(dN, X);
    if (d < best) { best = d; where = at; }
  }
  return best;
}

template <class S>
double detj_at(const double* X, const double* xi) {
  constexpr int N = S::N, D = S::D;
  double Nv[N], dN[N][D];
  S::eval(xi, Nv, dN);
  return det_only<N>(dN, X);
}

// Shell4, a flat-ish quad in space: at each corner, the corner's edge cross product projected on
// the element normal (X2 - X0) x (X3 - X1) must be positive (convex, consistently ordered).
double shell4_min_corner_cross(const double* X, int& where) {
  double best = std::numeric_limits<double>::infinity();
  where = -1;
  auto P = [&](int i, int c) { return X[3 * i + c]; };
  double nrm[3], d1[3], d2[3];
  for (int c = 0; c < 3; ++c) { d1[c] = P(2, c) - P(0, c); d2[c] = P(3, c) - P(1, c); }
  nrm[0] = d1[1] * d2[2] - d1[2] * d2[1];
  nrm[1] = d1[2] * d2[0] - d1[0] * d2[2];
  nrm[2] = d1[0] * d2[1] - d1[1] * d2[0];
  const double ln = std::sqrt(nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2]);
  if (!(ln > 0)) return 0.0;
  for (int a = 0; a < 4; ++a) {
    double e1[3], e2[3];
    for (int c = 0; c < 3; ++c) { e1[c] = P((a + 1) % 4, c) - P(a, c); e2[c] = P((a + 3) % 4, c) - P(a, c); }
    const double cr[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
    const double v = (cr[0] * nrm[0] + cr[1] * nrm[1] + cr[2] * nrm[2]) / ln;
    if (v < best) { best = v; where = a; }
  }
  return best;
}

// ---------------------------------------------------------------------------------------------
// Hex8R: uniform-gradient one-point brick with Flanagan-Belytschko hourglass control.

struct Hex8RKin {
  double bbar[8][3];   // uniform gradients (1/V) int dN/dx dV
  double gamma[4][8];  // hourglass shape vectors
  double V;
};

void hex8r_kinematics(const double* X, Hex8RKin& k) {
  const auto& R = Rule<Hex8Shape, 2>::get();
  double g[8][3];
  for (int a = 0; a < 8; ++a) k.bbar[a][0] = k.bbar[a][1] = k.bbar[a][2] = 0;
  k.V = 0;
  for (int q = 0; q < R.NG; ++q) {
    const double dV = gradients<8>(R.dN[q], X, g) * R.w[q];
    k.V += dV;
    for (int a = 0; a < 8; ++a)
      for (int j = 0; j < 3; ++j) k.bbar[a][j] += g[a][j] * dV;
  }
  const double iv = 1 / k.V;
  for (int a = 0; a < 8; ++a)
    for (int j = 0; j < 3; ++j) k.bbar[a][j] *= iv;
  for (int al = 0; al < 4; ++al) {
    double h[8];
    for (int a = 0; a < 8; ++a) {
      const double* c = kHexCornerD[a].data();
      h[a] = al == 0 ? c[1] * c[2] : al == 1 ? c[0] * c[2] : al == 2 ? c[0] * c[1]
                                                                     : c[0] * c[1] * c[2];
    }
    double hx[3] = {0, 0, 0};
    for (int a = 0; a < 8; ++a)
      for (int j = 0; j < 3; ++j) hx[j] += h[a] * X[3 * a + j];
    for (int a = 0; a < 8; ++a)
      k.gamma[al][a] = h[a] - (hx[0] * k.bbar[a][0] + hx[1] * k.bbar[a][1] + hx[2] * k.bbar[a][2]);
  }
}

double hex8r_hourglass_k(const Hex8RKin& k, const FeMaterial& m) {
  double bb = 0;
  for (int a = 0; a < 8; ++a)
    for (int j = 0; j < 3; ++j) bb += k.bbar[a][j] * k.bbar[a][j];
  const double G = m.young / (2 * (1 + m.poisson));
  return m.hourglass * G * (2.0 / 3.0) * k.V * bb;
}

void hex8r_internal_force(const double* X, const double* u, const FeMaterial& m,
                          GaussState* states, bool commit, double* f) {
  Hex8RKin k;
  hex8r_kinematics(X, k);
  double lam, G;
  lame(m, lam, G);
  for (int i = 0; i < 24; ++i) f[i] = 0;
  double e[6], s[6];
  strain_of<8>(k.bbar, u, e);
  point_stress(m, lam, G, e, states, commit, s);
  add_force<8>(k.bbar, s, k.V, f);
  const double kh = hex8r_hourglass_k(k, m);
  for (int al = 0; al < 4; ++al) {
    double q[3] = {0, 0, 0};
    for (int a = 0; a < 8; ++a)
      for (int i = 0; i < 3; ++i) q[i] += k.gamma[al][a] * u[3 * a + i];
    for (int a = 0; a < 8; ++a)
      for (int i = 0; i < 3; ++i) f[3 * a + i] += kh * k.gamma[al][a] * q[i];
  }
}

void hex8r_stiffness(const double* X, const FeMaterial& m, double* K) {
  Hex8RKin k;
  hex8r_kinematics(X, k);
  double lam, G;
  lame(m, lam, G);
  for (int i = 0; i < 24 * 24; ++i) K[i] = 0;
  add_stiffness<8>(k.bbar, lam, G, k.V, K);
  const double kh = hex8r_hourglass_k(k, m);
  for (int a = 0; a < 8; ++a)
    for (int b = 0; b < 8; ++b) {
      double s = 0;
      for (int al = 0; al < 4; ++al) s += k.gamma[al][a] * k.gamma[al][b];
      for (int i = 0; i < 3; ++i) K[(3 * a + i) * 24 + 3 * b + i] += kh * s;
    }
}


// ---------------------------------------------------------------------------------------------
// Hex8I: the trilinear brick enriched with Wilson's incompatible modes (Wilson, Taylor, Doherty &
// Ghaboussi 1973), in Taylor, Beresford & Wilson's form (1976, IJNME 10:1211) that passes the patch
// test on distorted bricks; the element Abaqus calls C3D8I. Three bubble modes 1 - xi_k^2 per
// displacement component (9 internal parameters alpha) let a brick bend: a beam of one brick
// through its depth is exact in pure bending (rectangular bricks), where the plain Hex8 locks
// (parasitic shear). The modes' gradients use the Jacobian at the centre, scaled by
// det J0 / det J at each point, so int B~ dV = 0 and a constant strain is reproduced exactly.
// The alphas are condensed out per element and per call (static condensation of a linear
// element: alpha = -K_aa^-1 int B~^T sigma(B u) dV; then sigma = D (B u + B~ alpha)), so the
// element keeps no extra state. Elastic only.
//
// Large rotations (m.nlgeom): corotational. The rotation R of the element is the polar factor of
// the deformation gradient at its centre; the small-strain element works on the displacements
// seen in the rotated frame, u_loc,a = R^T (X_a + u_a) - X_a, and its forces and stresses are
// turned back with R. A rigid rotation of any size makes no force; a sagging rib stretches (a
// string's membrane force), as long as each brick's own strain stays small.

struct Hex8IKin {
  double g[8][8][3];  // compatible gradients dN_a/dx at the 8 points
  double h[8][3][3];  // incompatible-mode gradients at the 8 points (3 modes)
  double dV[8];
  double L[81];       // Cholesky factor of K_aa (9 x 9, lower, row-major)
};

// Cholesky of a symmetric positive definite n x n matrix (row-major), in place (lower part).
void cholesky(int n, double* A) {
  for (int j = 0; j < n; ++j) {
    double d = A[j * n + j];
    for (int k = 0; k < j; ++k) d -= A[j * n + k] * A[j * n + k];
    A[j * n + j] = std::sqrt(d);
    for (int i = j + 1; i < n; ++i) {
      double s = A[i * n + j];
      for (int k = 0; k < j; ++k) s -= A[i * n + k] * A[j * n + k];
      A[i * n + j] = s / A[j * n + j];
    }
  }
}

void cholesky_solve(int n, const double* L, double* x) {
  for (int i = 0; i < n; ++i) {
    double s = x[i];
    for (int k = 0; k < i; ++k) s -= L[i * n + k] * x[k];
    x[i] = s / L[i * n + i];
  }
  for (int i = n - 1; i >= 0; --i) {
    double s = x[i];
    for (int k = i + 1; k < n; ++k) s -= L[k * n + i] * x[k];
    x[i] = s / L[i * n + i];
  }
}

void hex8i_kinematics(const double* X, double lam, double G, Hex8IKin& k) {
  const auto& R = Rule<Hex8Shape, 2>::get();
  const auto& R1 = Rule<Hex8Shape, 1>::get();
  // J0^-1 at the centre: the gradients of the coordinates' own shape functions there give it
  // column by column (dN/dx = J^-1 dN/dxi), taken from unit natural derivatives.
  double J0[3][3] = {};
  for (int a = 0; a < 8; ++a)
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) J0[i][j] += R1.dN[0][a][i] * X[3 * a + j];
  const double det0 = J0[0][0] * (J0[1][1] * J0[2][2] - J0[1][2] * J0[2][1]) -
                      J0[0][1] * (J0[1][0] * J0[2][2] - J0[1][2] * J0[2][0]) +
                      J0[0][2] * (J0[1][0] * J0[2][1] - J0[1][1] * J0[2][0]);
  double Ji[3][3];  // (J0^-1)_ji = cofactor_ij / det0
  Ji[0][0] = (J0[1][1] * J0[2][2] - J0[1][2] * J0[2][1]) / det0;
  Ji[1][0] = (J0[1][2] * J0[2][0] - J0[1][0] * J0[2][2]) / det0;
  Ji[2][0] = (J0[1][0] * J0[2][1] - J0[1][1] * J0[2][0]) / det0;
  Ji[0][1] = (J0[0][2] * J0[2][1] - J0[0][1] * J0[2][2]) / det0;
  Ji[1][1] = (J0[0][0] * J0[2][2] - J0[0][2] * J0[2][0]) / det0;
  Ji[2][1] = (J0[0][1] * J0[2][0] - J0[0][0] * J0[2][1]) / det0;
  Ji[0][2] = (J0[0][1] * J0[1][2] - J0[0][2] * J0[1][1]) / det0;
  Ji[1][2] = (J0[0][2] * J0[1][0] - J0[0][0] * J0[1][2]) / det0;
  Ji[2][2] = (J0[0][0] * J0[1][1] - J0[0][1] * J0[1][0]) / det0;
  for (int i = 0; i < 81; ++i) k.L[i] = 0;
  for (int q = 0; q < 8; ++q) {
    const double det = gradients<8>(R.dN[q], X, k.g[q]);
    k.dV[q] = det * R.w[q];
    // mode m = 1 - xi_m^2: d/dxi_i = -2 xi_m delta_im, so dN~_m/dx_j = -2 xi_m (J0^-1)_jm.
    for (int mo = 0; mo < 3; ++mo)
      for (int j = 0; j < 3; ++j) k.h[q][mo][j] = (det0 / det) * (-2 * R.xi[q][mo]) * Ji[j][mo];
    add_stiffness<3>(k.h[q], lam, G, k.dV[q], k.L);
  }
  cholesky(9, k.L);
}

// Small-strain force for the displacements u (element frame); stresses and strains at the points
// into sig/eps when given.
void hex8i_force(const Hex8IKin& k, const double* u, double lam, double G, double* f, double (*sig)[6],
                 double (*eps)[6]) {
  double alpha[9] = {};
  double e[6], s[6];
  for (int q = 0; q < 8; ++q) {  // r = int B~^T D B u dV
    strain_of<8>(k.g[q], u, e);
    elastic_stress(lam, G, e, s);
    add_force<3>(k.h[q], s, k.dV[q], alpha);
  }
  cholesky_solve(9, k.L, alpha);
  for (double& a : alpha) a = -a;
  for (int i = 0; i < 24; ++i) f[i] = 0;
  for (int q = 0; q < 8; ++q) {
    double ea[6];
    strain_of<8>(k.g[q], u, e);
    strain_of<3>(k.h[q], alpha, ea);
    for (int i = 0; i < 6; ++i) e[i] += ea[i];
    elastic_stress(lam, G, e, s);
    add_force<8>(k.g[q], s, k.dV[q], f);
    if (sig)
      for (int i = 0; i < 6; ++i) { sig[q][i] = s[i]; eps[q][i] = e[i]; }
  }
}

// The rotation of the polar decomposition F = R U (Higham's iteration R <- (R + R^-T) / 2).
void polar_rotation(const double (*F)[3], double (*R)[3]) {
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) R[i][j] = F[i][j];
  for (int it = 0; it < 50; ++it) {
    const double c00 = R[1][1] * R[2][2] - R[1][2] * R[2][1], c01 = R[1][2] * R[2][0] - R[1][0] * R[2][2],
                 c02 = R[1][0] * R[2][1] - R[1][1] * R[2][0], c10 = R[0][2] * R[2][1] - R[0][1] * R[2][2],
                 c11 = R[0][0] * R[2][2] - R[0][2] * R[2][0], c12 = R[0][1] * R[2][0] - R[0][0] * R[2][1],
                 c20 = R[0][1] * R[1][2] - R[0][2] * R[1][1], c21 = R[0][2] * R[1][0] - R[0][0] * R[1][2],
                 c22 = R[0][0] * R[1][1] - R[0][1] * R[1][0];
    const double det = R[0][0] * c00 + R[0][1] * c01 + R[0][2] * c02;
    const double C[3][3] = {{c00, c01, c02}, {c10, c11, c12}, {c20, c21, c22}};  // R^-T = C / det
    double change = 0;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        const double v = 0.5 * (R[i][j] + C[i][j] / det);
        change = std::max(change, std::abs(v - R[i][j]));
        R[i][j] = v;
      }
    if (change < 1e-15) break;
  }
}

constexpr int kHex8IPrepared = static_cast<int>(sizeof(Hex8IKin) / sizeof(double));
static_assert(sizeof(Hex8IKin) == kHex8IPrepared * sizeof(double), "Hex8IKin: doubles only");

void hex8i_internal_force(const double* X, const double* u, const FeMaterial& m, GaussState* states,
                          bool commit, double* f, const double* prep) {
  if (m.kind != FeMaterial::kElastic) throw std::logic_error("hex8i is for elastic materials");
  double lam, G;
  lame(m, lam, G);
  Hex8IKin k;
  if (prep) std::memcpy(&k, prep, sizeof k);  // element_prepare's copy: the same bits
  else hex8i_kinematics(X, lam, G, k);
  const bool store = commit && states;
  double sig[8][6], eps[8][6];
  if (!m.nlgeom) {
    hex8i_force(k, u, lam, G, f, store ? sig : nullptr, eps);
    if (store)
      for (int q = 0; q < 8; ++q) {
        for (int i = 0; i < 6; ++i) { states[q].stress[i] = sig[q][i]; states[q].strain[i] = eps[q][i]; }
        states[q].yielded = false;
      }
    return;
  }
  // Corotational: F at the centre, its rotation, the element's displacements in the rotated frame.
  const auto& R1 = Rule<Hex8Shape, 1>::get();
  double g0[8][3];
  gradients<8>(R1.dN[0], X, g0);
  double F[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  for (int a = 0; a < 8; ++a)
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) F[i][j] += u[3 * a + i] * g0[a][j];
  double Rot[3][3];
  polar_rotation(F, Rot);
  double ul[24], fl[24];
  for (int a = 0; a < 8; ++a)
    for (int i = 0; i < 3; ++i) {
      double v = 0;
      for (int j = 0; j < 3; ++j) v += Rot[j][i] * (X[3 * a + j] + u[3 * a + j]);
      ul[3 * a + i] = v - X[3 * a + i];
    }
  hex8i_force(k, ul, lam, G, fl, store ? sig : nullptr, eps);
  for (int a = 0; a < 8; ++a)
    for (int i = 0; i < 3; ++i)
      f[3 * a + i] = Rot[i][0] * fl[3 * a] + Rot[i][1] * fl[3 * a + 1] + Rot[i][2] * fl[3 * a + 2];
  if (!store) return;
  for (int q = 0; q < 8; ++q) {  // sigma = R sigma_loc R^T; the strain likewise (tensor shears)
    const double* s = sig[q];
    const double* e = eps[q];
    const double S[3][3] = {{s[0], s[3], s[5]}, {s[3], s[1], s[4]}, {s[5], s[4], s[2]}};
    const double E[3][3] = {{e[0], 0.5 * e[3], 0.5 * e[5]}, {0.5 * e[3], e[1], 0.5 * e[4]}, {0.5 * e[5], 0.5 * e[4], e[2]}};
    double Sg[3][3] = {}, Eg[3][3] = {};
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        for (int p = 0; p < 3; ++p)
          for (int r = 0; r < 3; ++r) {
            Sg[i][j] += Rot[i][p] * S[p][r] * Rot[j][r];
            Eg[i][j] += Rot[i][p] * E[p][r] * Rot[j][r];
          }
    const double so[6] = {Sg[0][0], Sg[1][1], Sg[2][2], Sg[0][1], Sg[1][2], Sg[0][2]};
    const double eo[6] = {Eg[0][0], Eg[1][1], Eg[2][2], 2 * Eg[0][1], 2 * Eg[1][2], 2 * Eg[0][2]};
    for (int i = 0; i < 6; ++i) { states[q].stress[i] = so[i]; states[q].strain[i] = eo[i]; }
    states[q].yielded = false;
  }
}

// K = K_uu - K_ua K_aa^-1 K_au, column by column from the (linear) condensed force.
void hex8i_stiffness(const double* X, const FeMaterial& m, double* K) {
  double lam, G;
  lame(m, lam, G);
  Hex8IKin k;
  hex8i_kinematics(X, lam, G, k);
  double u[24] = {}, f[24];
  for (int j = 0; j < 24; ++j) {
    u[j] = 1;
    hex8i_force(k, u, lam, G, f, nullptr, nullptr);
    u[j] = 0;
    for (int i = 0; i < 24; ++i) K[i * 24 + j] = f[i];
  }
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Public entry points: dispatch on the type.

double element_min_detj(ElemType t, const double* X) {
  switch (t) {
    case ElemType::kHex8:
    case ElemType::kHex8R:
    case ElemType::kHex8I: return min_detj<Hex8Shape>(X);
    case ElemType::kHex20: return min_detj<Hex20Shape>(X);
    case ElemType::kQuad4: return min_detj<Quad4Shape>(X);
    case ElemType::kShell4: return shell4_frame(X, nullptr, nullptr, nullptr, nullptr);  // projected area
  }
  return 0;
}

double element_min_nodal_detj(ElemType t, const double* X, int& where) {
  switch (t) {
    case ElemType::kHex8:
    case ElemType::kHex8R:
    case ElemType::kHex8I: return min_nodal_detj<Hex8Shape>(X, where);
    case ElemType::kHex20: return min_nodal_detj<Hex20Shape>(X, where);
    case ElemType::kQuad4: return min_nodal_detj<Quad4Shape>(X, where);
    case ElemType::kShell4: return shell4_min_corner_cross(X, where);
  }
  where = -1;
  return 0;
}

double element_detj_at(ElemType t, const double* X, const double* xi) {
  switch (t) {
    case ElemType::kHex8:
    case ElemType::kHex8R:
    case ElemType::kHex8I: return detj_at<Hex8Shape>(X, xi);
    case ElemType::kHex20: return detj_at<Hex20Shape>(X, xi);
    case ElemType::kQuad4: return detj_at<Quad4Shape>(X, xi);
    case ElemType::kShell4: throw std::logic_error("element_detj_at: shell4 has no solid Jacobian");
  }
  return 0;
}

void element_stiffness(ElemType t, const double* X, const FeMaterial& m, double* K) {
  switch (t) {
    case ElemType::kHex8: full_stiffness<Hex8Shape, 2>(X, m, K); return;
    case ElemType::kHex8R: hex8r_stiffness(X, m, K); return;
    case ElemType::kHex8I: hex8i_stiffness(X, m, K); return;
    case ElemType::kHex20: full_stiffness<Hex20Shape, 2>(X, m, K); return;
    case ElemType::kQuad4: full_stiffness<Quad4Shape, 2>(X, m, K); return;
    case ElemType::kShell4: shell4_stiffness(X, m.young, m.poisson, m.thickness, K); return;
  }
}

int element_prepared_size(ElemType t, const FeMaterial& m) {
  return t == ElemType::kHex8I && m.kind == FeMaterial::kElastic ? kHex8IPrepared : 0;
}

void element_prepare(ElemType t, const double* X, const FeMaterial& m, double* prep) {
  if (element_prepared_size(t, m) == 0) return;
  double lam, G;
  lame(m, lam, G);
  Hex8IKin k;
  hex8i_kinematics(X, lam, G, k);
  std::memcpy(prep, &k, sizeof k);
}

void element_internal_force(ElemType t, const double* X, const double* u, const FeMaterial& m,
                            GaussState* states, bool commit, double* f, const double* prep) {
  switch (t) {
    case ElemType::kHex8: full_internal_force<Hex8Shape, 2>(X, u, m, states, commit, f); return;
    case ElemType::kHex8R:
      if (m.nlgeom) throw std::logic_error("nlgeom: hex8r's hourglass control is small-strain");
      hex8r_internal_force(X, u, m, states, commit, f);
      return;
    case ElemType::kHex8I: hex8i_internal_force(X, u, m, states, commit, f, prep); return;
    case ElemType::kHex20: full_internal_force<Hex20Shape, 2>(X, u, m, states, commit, f); return;
    case ElemType::kQuad4: full_internal_force<Quad4Shape, 2>(X, u, m, states, commit, f); return;
    case ElemType::kShell4:
      if (m.nlgeom) throw std::logic_error("nlgeom: shell4 is small-strain");
      shell4_internal_force(X, u, m.young, m.poisson, m.thickness, f);
      if (commit && states) {
        double N[3], M[3], Q[2], R[9];
        shell4_membrane_bending_stress(X, u, m.young, m.poisson, m.thickness, N, M, Q, R);
        for (int k = 0; k < 3; ++k) { states[0].stress[k] = N[k]; states[0].stress[3 + k] = M[k]; }
      }
      return;
  }
}

void element_lumped_mass(ElemType t, const double* X, double density, double* mass) {
  switch (t) {
    case ElemType::kHex8:
    case ElemType::kHex8R:
    case ElemType::kHex8I: rowsum_mass<Hex8Shape, 2>(X, density, mass); return;
    case ElemType::kHex20: hrz_mass<Hex20Shape, 3>(X, density, mass); return;
    case ElemType::kQuad4: rowsum_mass<Quad4Shape, 2>(X, density, mass); return;
    case ElemType::kShell4: throw std::logic_error("shell4 mass needs the thickness: use element_lumped_mass(t, X, material, ...)");
  }
}

void element_rotary_inertia(ElemType t, const double* X, double density, double thickness, double* j) {
  if (t != ElemType::kShell4) {
    for (int a = 0; a < element_nodes(t); ++a) j[a] = 0;
    return;
  }
  double m[4];
  shell4_lumped_mass(X, density, thickness, m, j);
}

void element_body_force(ElemType t, const double* X, const double* b, double* f) {
  switch (t) {
    case ElemType::kHex8:
    case ElemType::kHex8R:
    case ElemType::kHex8I: body_force<Hex8Shape, 2>(X, b, f); return;
    case ElemType::kHex20: body_force<Hex20Shape, 3>(X, b, f); return;
    case ElemType::kQuad4: body_force<Quad4Shape, 2>(X, b, f); return;
    case ElemType::kShell4: throw std::logic_error("shell4 body force needs the thickness");
  }
}

}  // namespace fdem::fem
