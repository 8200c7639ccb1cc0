// Micro-mechanical measurements: the pure kernels (see measure.hpp for the definitions).
#include "dem/measure.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace fdem {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// Nodes on (0, 1) and weights (summing to 1) of the n-point Gauss-Legendre rule.
struct GaussLegendre {
  static constexpr int kN = 20;
  double x[kN], w[kN];
  GaussLegendre() {
    for (int i = 0; i < kN; ++i) {
      double t = std::cos(M_PI * (i + 0.75) / (kN + 0.5));  // Newton on P_n from Tricomi's guess
      double dp = 1;
      for (int it = 0; it < 100; ++it) {
        double p0 = 1, p1 = t;
        for (int k = 2; k <= kN; ++k) {
          const double p2 = ((2 * k - 1) * t * p1 - (k - 1) * p0) / k;
          p0 = p1;
          p1 = p2;
        }
        dp = kN * (t * p1 - p0) / (t * t - 1);
        const double dt = p1 / dp;
        t -= dt;
        if (std::fabs(dt) < 1e-16) break;
      }
      x[i] = 0.5 * (1 - t);
      w[i] = 1.0 / ((1 - t * t) * dp * dp);  // = 2/((1-t^2) P'^2) / 2
    }
  }
};
const GaussLegendre& gauss() {
  static const GaussLegendre g;
  return g;
}

/// Integral of sqrt(rho^2 - y^2) from 0 to y (y clamped to [-rho, rho]).
double prim(double y, double rho) {
  y = std::clamp(y, -rho, rho);
  const double s = std::sqrt(std::max(rho * rho - y * y, 0.0));
  return 0.5 * (y * s + rho * rho * std::asin(std::clamp(y / rho, -1.0, 1.0)));
}

/// Area of the disc (radius rho, centre 0) intersected with {y <= Y, z <= Z}.
double corner_area(double rho, double Y, double Z) {
  if (!(rho > 0)) return 0;
  const double yc = std::clamp(Y, -rho, rho);
  if (Z >= rho) return 2 * (prim(yc, rho) - prim(-rho, rho));
  if (Z <= -rho) return 0;
  const double w = std::sqrt(std::max(rho * rho - Z * Z, 0.0));
  const double ym = std::clamp(yc, -w, w);
  // Slices |y| < w run from -s(y) to Z; the others (Z >= 0 only) are whole chords 2 s(y).
  const double mid = Z * (ym + w) + prim(ym, rho) - prim(-w, rho);
  if (Z < 0) return mid;
  return 2 * (prim(std::min(yc, -w), rho) - prim(-rho, rho)) + mid +
         2 * (prim(std::max(yc, w), rho) - prim(w, rho));
}

}  // namespace

long MeasureGrid::cell_of(const Vec3& x) const {
  long idx[3];
  for (int d = 0; d < 3; ++d) {
    const double h = (hi[d] - lo[d]) / n[d];
    const double t = (x[d] - lo[d]) / h;
    if (!(t >= 0 && t < n[d]) || !(x[d] < hi[d])) return -1;
    idx[d] = std::min(static_cast<long>(t), static_cast<long>(n[d] - 1));
  }
  return (idx[2] * n[1] + idx[1]) * n[0] + idx[0];
}

MeasureBox MeasureGrid::cell(std::size_t c) const {
  const long i = static_cast<long>(c % n[0]), j = static_cast<long>((c / n[0]) % n[1]),
             k = static_cast<long>(c / (static_cast<std::size_t>(n[0]) * n[1]));
  const long ijk[3] = {i, j, k};
  MeasureBox b;
  for (int d = 0; d < 3; ++d) {
    const double h = (hi[d] - lo[d]) / n[d];
    b.lo[d] = lo[d] + h * ijk[d];
    b.hi[d] = ijk[d] + 1 == n[d] ? hi[d] : lo[d] + h * (ijk[d] + 1);
  }
  return b;
}

std::array<int, 2> MeasureGrid::range(int d, double a, double b) const {
  const double h = (hi[d] - lo[d]) / n[d];
  const double ta = std::floor((a - lo[d]) / h), tb = std::floor((b - lo[d]) / h);
  const int i0 = static_cast<int>(std::max(0.0, std::min(ta, static_cast<double>(n[d]))));
  const int i1 = static_cast<int>(std::min(static_cast<double>(n[d] - 1), std::max(tb, -1.0)));
  return {i0, i1};
}

void add_particle(MeasureSums& s, int contacts, const Vec3& displacement) {
  s.particles += 1;
  s.sides += contacts;
  if (contacts >= 2) {
    s.mech_particles += 1;
    s.mech_sides += contacts;
  }
  for (int d = 0; d < 3; ++d) s.disp[d] += displacement[d];
}

void add_contact_side(MeasureSums& s, const Vec3& lever, const Vec3& force, const Vec3& n, bool particle_pair) {
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) s.stress[3 * i + j] -= lever[i] * force[j];
  if (!particle_pair) return;
  s.fabric[0] += n.x * n.x;
  s.fabric[1] += n.y * n.y;
  s.fabric[2] += n.z * n.z;
  s.fabric[3] += n.x * n.y;
  s.fabric[4] += n.x * n.z;
  s.fabric[5] += n.y * n.z;
}

void invariants(const double t[6], double& p, double& q) {
  p = (t[0] + t[1] + t[2]) / 3.0;
  const double a = t[0] - p, b = t[1] - p, c = t[2] - p;
  const double j2 = 0.5 * (a * a + b * b + c * c) + t[3] * t[3] + t[4] * t[4] + t[5] * t[5];
  q = std::sqrt(3.0 * j2);
}

BoxMeasure finish(const MeasureSums& s, double volume) {
  BoxMeasure m;
  const double iv = 1.0 / volume;
  const double* S = s.stress;
  m.stress[0] = S[0] * iv;
  m.stress[1] = S[4] * iv;
  m.stress[2] = S[8] * iv;
  m.stress[3] = 0.5 * (S[1] + S[3]) * iv;
  m.stress[4] = 0.5 * (S[2] + S[6]) * iv;
  m.stress[5] = 0.5 * (S[5] + S[7]) * iv;
  invariants(m.stress, m.p, m.q);
  m.z = s.particles > 0 ? s.sides / s.particles : kNaN;
  m.z_mech = s.mech_particles > 0 ? s.mech_sides / s.mech_particles : kNaN;
  m.porosity = 1.0 - s.solid * iv;
  for (int k = 0; k < 6; ++k) m.fabric[k] = s.sides > 0 ? s.fabric[k] / s.sides : kNaN;
  for (int d = 0; d < 3; ++d) m.displacement[d] = s.particles > 0 ? s.disp[d] / s.particles : kNaN;
  m.particles = s.particles;
  m.contacts = 0.5 * s.sides;
  return m;
}

double disc_rect_area(double rho, double y0, double y1, double z0, double z1) {
  if (!(rho > 0) || y1 <= y0 || z1 <= z0) return 0;
  return corner_area(rho, y1, z1) - corner_area(rho, y0, z1) - corner_area(rho, y1, z0) + corner_area(rho, y0, z0);
}

double sphere_box_volume(const Vec3& c, double r, const Vec3& lo, const Vec3& hi) {
  const double x0 = lo.x - c.x, x1 = hi.x - c.x, y0 = lo.y - c.y, y1 = hi.y - c.y, z0 = lo.z - c.z,
               z1 = hi.z - c.z;
  if (!(r > 0) || x0 >= r || x1 <= -r || y0 >= r || y1 <= -r || z0 >= r || z1 <= -r) return 0;
  if (x0 <= -r && x1 >= r && y0 <= -r && y1 >= r && z0 <= -r && z1 >= r) return 4.0 / 3.0 * M_PI * r * r * r;
  const double a = std::max(x0, -r), b = std::min(x1, r);
  // Break points: where the slice's circle passes a rectangle edge or corner.
  double bp[2 + 8 + 8];
  int nb = 0;
  bp[nb++] = a;
  bp[nb++] = b;
  auto add = [&](double d2) {
    if (d2 < r * r) {
      const double t = std::sqrt(r * r - d2);
      if (t > a && t < b) bp[nb++] = t;
      if (-t > a && -t < b) bp[nb++] = -t;
    }
  };
  for (double d : {y0, y1, z0, z1}) add(d * d);
  for (double y : {y0, y1})
    for (double z : {z0, z1}) add(y * y + z * z);
  std::sort(bp, bp + nb);
  // Each piece in the smoothstep variable s in [0, 1]: x = p + L s^2 (3 - 2 s). The slice area
  // still has branch points (rho = 0 at x = +-r) close to some pieces, so the s range is
  // bisected until a 20-point rule and its two halves agree.
  const GaussLegendre& g = gauss();
  auto rule = [&](double p, double L, double s0, double s1) {
    double part = 0;
    for (int q = 0; q < GaussLegendre::kN; ++q) {
      const double s = s0 + (s1 - s0) * g.x[q];
      const double x = p + L * s * s * (3 - 2 * s);
      const double rho = std::sqrt(std::max(r * r - x * x, 0.0));
      part += g.w[q] * 6 * s * (1 - s) * disc_rect_area(rho, y0, y1, z0, z1);
    }
    return L * (s1 - s0) * part;
  };
  const double tol = 1e-16 * r * r * r;
  auto adapt = [&](auto&& self, double p, double L, double s0, double s1, double whole, int depth) -> double {
    const double m = 0.5 * (s0 + s1);
    const double left = rule(p, L, s0, m), right = rule(p, L, m, s1);
    if (depth >= 12 || std::fabs(left + right - whole) <= tol) return left + right;
    return self(self, p, L, s0, m, left, depth + 1) + self(self, p, L, m, s1, right, depth + 1);
  };
  double v = 0;
  for (int k = 0; k + 1 < nb; ++k) {
    const double p = bp[k], L = bp[k + 1] - bp[k];
    if (!(L > 0)) continue;
    v += adapt(adapt, p, L, 0.0, 1.0, rule(p, L, 0.0, 1.0), 0);
  }
  return v;
}

int rose_bin(const Vec3& n, int a0, int a1, int bins) {
  const double u = n[a0], w = n[a1];
  if (u == 0 && w == 0) return -1;
  double t = std::atan2(w, u);  // (-pi, pi]
  if (t < 0) t += M_PI;
  if (t >= M_PI) t -= M_PI;
  const int b = static_cast<int>(t / M_PI * bins);
  return std::clamp(b, 0, bins - 1);
}

}  // namespace fdem
