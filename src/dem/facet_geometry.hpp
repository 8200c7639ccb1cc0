#pragma once
// Closest point of a triangle (rigid facet walls, the FE-DE interface, the packer's facet test):
// one implementation, with or without the barycentric coordinates of the point.
//
// Regions (Ericson, Real-Time Collision Detection, 5.1.5), as WallGeom::region: 0 face,
// 1..3 edge (v0v1, v1v2, v2v0), 4..6 vertex v0, v1, v2.
// Barycentric coordinates N (N0 + N1 + N2 = 1) come from the same sub-results as the point: on an
// edge the opposite N is exactly 0, at a vertex that vertex's N is exactly 1. A degenerate
// triangle (zero area, in region 0) gets those of triangle_barycentric.
#include <algorithm>
#include <array>

#include "base/vec3.hpp"

namespace fdem {

namespace facet_detail {

// N is written only when kWeights; the point's arithmetic does not depend on it.
template <bool kWeights>
inline Vec3 closest(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c, int& region,
                    std::array<double, 3>& N);

}  // namespace facet_detail

/// Closest point on triangle (a, b, c) to p, and its region.
inline Vec3 closest_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c, int& region) {
  std::array<double, 3> unused;
  return facet_detail::closest<false>(p, a, b, c, region, unused);
}

/// Closest point on triangle (a, b, c) to p, its region and its barycentric coordinates N.
inline Vec3 closest_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c, int& region,
                                std::array<double, 3>& N) {
  return facet_detail::closest<true>(p, a, b, c, region, N);
}

/// Barycentric coordinates (N0, N1, N2) of the point of triangle (a, b, c) closest to p, from the
/// closest point q alone (on an edge the opposite N is exactly 0, at a vertex that vertex's N is
/// exactly 1). N0 + N1 + N2 == 1. A degenerate triangle gives the nearest vertex.
inline std::array<double, 3> triangle_barycentric(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& p) {
  int region = 0;
  const Vec3 q = closest_on_triangle(p, a, b, c, region);
  switch (region) {
    case 4: return {1.0, 0.0, 0.0};
    case 5: return {0.0, 1.0, 0.0};
    case 6: return {0.0, 0.0, 1.0};
    case 1:
    case 2:
    case 3: {
      // edge (v_i, v_j): q = v_i + s (v_j - v_i)
      const int i = region - 1, j = region % 3;
      const Vec3 v[3] = {a, b, c};
      const Vec3 e = v[j] - v[i];
      const double l2 = norm2(e);
      double s = l2 > 0 ? dot(q - v[i], e) / l2 : 0.0;
      s = std::clamp(s, 0.0, 1.0);
      std::array<double, 3> N{0.0, 0.0, 0.0};
      N[i] = 1.0 - s;
      N[j] = s;
      return N;
    }
    default: break;
  }
  const Vec3 v0 = b - a, v1 = c - a, v2 = q - a;
  const double d00 = dot(v0, v0), d01 = dot(v0, v1), d11 = dot(v1, v1), d20 = dot(v2, v0), d21 = dot(v2, v1);
  const double den = d00 * d11 - d01 * d01;
  if (!(den > 0)) return {1.0, 0.0, 0.0};
  const double n1 = (d11 * d20 - d01 * d21) / den;
  const double n2 = (d00 * d21 - d01 * d20) / den;
  return {1.0 - n1 - n2, n1, n2};
}

namespace facet_detail {

template <bool kWeights>
inline Vec3 closest(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c, int& region,
                    std::array<double, 3>& N) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) {
    region = 4;
    if constexpr (kWeights) N = {1.0, 0.0, 0.0};
    return a;
  }
  const Vec3 bp = p - b;
  const double d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) {
    region = 5;
    if constexpr (kWeights) N = {0.0, 1.0, 0.0};
    return b;
  }
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    region = 1;
    const double s = d1 / (d1 - d3);
    if constexpr (kWeights) N = {1.0 - s, s, 0.0};
    return a + s * ab;
  }
  const Vec3 cp = p - c;
  const double d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) {
    region = 6;
    if constexpr (kWeights) N = {0.0, 0.0, 1.0};
    return c;
  }
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    region = 3;
    const double s = d2 / (d2 - d6);
    if constexpr (kWeights) N = {1.0 - s, 0.0, s};
    return a + s * ac;
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    region = 2;
    const double s = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    if constexpr (kWeights) N = {0.0, 1.0 - s, s};
    return b + s * (c - b);
  }
  region = 0;
  const double denom = 1.0 / (va + vb + vc);
  const Vec3 q = a + (vb * denom) * ab + (vc * denom) * ac;
  if constexpr (kWeights) {
    N = {1.0 - vb * denom - vc * denom, vb * denom, vc * denom};
    if (!(va + vb + vc > 0)) N = triangle_barycentric(a, b, c, q);  // degenerate
  }
  return q;
}

}  // namespace facet_detail

}  // namespace fdem
