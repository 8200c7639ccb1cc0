#pragma once
// Contact selection on a triangulated surface (rigid facet walls and the FE interface): a
// smooth surface must push back once, with no jump when a particle crosses an edge or a vertex.
//
// A face contact (the centre projects inside the triangle) always counts. An edge contact
// counts only if the centre lies beyond the edge for every triangle sharing it (in that
// triangle's plane): otherwise a neighbouring face or edge is closer to the truth and this
// contact is a shadow of it. A vertex contact counts only if the centre lies behind the vertex
// along every edge meeting there. Of several contacts at the same point (a shared edge or
// vertex seen from each of its triangles), the first counts. The tolerance treats "exactly on
// the boundary" as beyond it, so one of the triangles always counts. Flat and convex meshes
// give one contact; concave corners one per face.
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "dem/facet_geometry.hpp"
#include "dem/walls.hpp"

namespace fdem {

/// A vertex contact counts only if the centre x lies behind vertex v along every edge meeting
/// there.
template <class VertFn>
bool facet_vertex_contact_counts(const FacetTopology& topo, VertFn&& vert, const Vec3& x, int v, double tol) {
  const Vec3 pv = vert(v);
  for (std::int32_t it = topo.vert_off[v]; it < topo.vert_off[v + 1]; ++it) {
    const Vec3 ed = vert(topo.vert_nbrs[it]) - pv;
    if (dot(x - pv, ed) / norm(ed) > tol) return false;
  }
  return true;
}

/// A valid contact counts unless one at the same contact point was taken already (a shared edge
/// or vertex seen from each of its triangles); records it when it counts.
inline bool facet_contact_is_new(bool valid, const Vec3& x, double r, const WallGeom& g, double tol,
                                 std::vector<Vec3>& taken) {
  if (!valid) return false;
  const Vec3 cp = x + (r - g.delta) * g.n;
  for (const Vec3& o : taken)
    if (norm(o - cp) <= tol) return false;
  taken.push_back(cp);
  return true;
}

/// Contacts whose normals are closer than 15 degrees lie on one smooth surface (the coupler
/// merges them; a contact moving on to such a neighbour keeps its history).
inline const double kSmoothSurfaceCos = std::cos(15.0 * M_PI / 180.0);

/// Contact history on a triangulated surface: a particle that slides or rolls from one triangle
/// onto the next has its contact with the first end and a new one with the second start in the
/// same step. The new contact continues the history (tangential spring, rolling rotation) of the
/// ended contact whose normal now is closest to its own, when within 15 degrees of it (the same
/// smooth surface) -- as LIGGGHTS hands a mesh contact's history to the coplanar neighbour
/// triangle -- instead of starting from zero, which would make the friction drop at every edge.
/// n: the new contact's normal; ended_n[0..count): the normals the ended contacts would have now.
/// Returns the index of the ended contact to continue, or -1 (a genuinely new contact). Ties go
/// to the first, so the choice depends only on the order of the candidates.
inline int continued_contact(const Vec3& n, const Vec3* ended_n, std::size_t count) {
  int best = -1;
  double best_c = kSmoothSurfaceCos;
  for (std::size_t j = 0; j < count; ++j) {
    const double c = dot(n, ended_n[j]);
    if (c >= best_c && (best < 0 || c > best_c)) { best = static_cast<int>(j); best_c = c; }
  }
  return best;
}

/// The unit normal n from x towards the closest point of triangle (a, b, c), touching or not
/// (the normal an ended contact would have now); false when x lies on the triangle.
inline bool facet_normal_now(const Vec3& x, const Vec3& a, const Vec3& b, const Vec3& c, Vec3& n) {
  int region = 0;
  const Vec3 dv = closest_on_triangle(x, a, b, c, region) - x;
  const double dist = norm(dv);
  if (dist == 0.0) return false;
  n = (1.0 / dist) * dv;
  return true;
}

/// Candidates of ONE particle (x, r) against triangles tri[0..count) of a surface (vertex
/// triples `tris`, adjacency `topo`, current vertex positions vert(v)) with geometries geo[]
/// (from closest_on_triangle); clears accept[q] of the candidates that must not count.
/// corners(q) is tris[tri[q]] (a caller may read it from a record nearer at hand);
/// opposite(q, k) the vertex opposite edge k of that triangle in the one other triangle sharing
/// the edge (-1: no other triangle), or -2: look the edge's triangles up in `topo` -- the same
/// test either way, so the same choice.
template <class VertFn, class CornerFn, class OppositeFn>
void select_facet_contacts(const std::vector<std::array<int, 3>>& tris, const FacetTopology& topo, VertFn&& vert,
                           CornerFn&& corners, OppositeFn&& opposite, const Vec3& x, double r,
                           const std::int32_t* tri, const WallGeom* geo, std::uint8_t* accept, std::size_t count,
                           std::vector<Vec3>& taken) {
  const double tol = 1e-9 * r;
  taken.clear();
  for (std::size_t q = 0; q < count; ++q) {
    if (!accept[q]) continue;
    const WallGeom& g = geo[q];
    const std::array<int, 3>& t = corners(q);
    bool valid = true;
    if (g.region >= 1 && g.region <= 3) {
      const int k = g.region - 1;
      const int a = t[k], b = t[g.region % 3];
      const Vec3 pa = vert(a), ed = vert(b) - pa;
      const double ed2 = norm2(ed);
      // Beyond the edge in the plane of the triangle with third corner o: along the direction in
      // that plane, perpendicular to the edge, inwards.
      auto beyond = [&](int o) {
        Vec3 in = vert(o) - pa;
        in -= (dot(in, ed) / ed2) * ed;
        const double len = norm(in);
        return !(len > 0 && dot(x - pa, in) / len > tol);
      };
      const std::int32_t o2 = opposite(q, k);
      if (o2 != -2) {
        valid = beyond(t[(k + 2) % 3]) && (o2 < 0 || beyond(o2));
      } else {
        const std::int32_t grp = topo.edge_group[3 * static_cast<std::size_t>(tri[q]) + k];
        for (std::int32_t it = topo.group_off[grp]; it < topo.group_off[grp + 1] && valid; ++it) {
          const auto& tf = tris[topo.group_tris[it]];
          const int o = tf[0] != a && tf[0] != b ? tf[0] : (tf[1] != a && tf[1] != b ? tf[1] : tf[2]);
          valid = beyond(o);
        }
      }
    } else if (g.region >= 4) {
      valid = facet_vertex_contact_counts(topo, vert, x, t[g.region - 4], tol);
    }
    if (!facet_contact_is_new(valid, x, r, g, tol, taken)) accept[q] = 0;
  }
}

/// select_facet_contacts with the edges' triangles always looked up in `topo` (rigid facet walls).
template <class VertFn>
void select_facet_contacts(const std::vector<std::array<int, 3>>& tris, const FacetTopology& topo, VertFn&& vert,
                           const Vec3& x, double r, const std::int32_t* tri, const WallGeom* geo,
                           std::uint8_t* accept, std::size_t count, std::vector<Vec3>& taken) {
  select_facet_contacts(
      tris, topo, vert, [&](std::size_t q) -> const std::array<int, 3>& { return tris[tri[q]]; },
      [](std::size_t, int) { return std::int32_t{-2}; }, x, r, tri, geo, accept, count, taken);
}

}  // namespace fdem
