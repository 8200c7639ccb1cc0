#pragma once
// InterfaceSurface: the FE-DE interface as a triangulated surface (DESIGN.md 4.4) -- its
// vertices, topology, and the current positions, velocities and planes of its triangles.
//
// * Vertices: the distinct corners of the interface triangles (coupling/interface.hpp), each a
//   real FE node (weight 1) or a quad centre (4 nodes, weight 1/4 each), keyed by the sorted node
//   list. All nodes of one vertex have the same weight.
// * Positions are known only where the caller placed them (a DEM rank: the vertices of the
//   triangles it sees); they start at the reference positions (the mesh coordinates).
// * Between FE updates the surface is extrapolated, x = x_FE + s v_FE (DESIGN.md 4.4), from the
//   positions at the last FE update (fe positions) and the last FE step's velocities.
// * A triangle's plane (TrianglePlane) is that of its FE positions; compute() of the coupler
//   tests the extrapolated triangle against it with a slack.
// Pure: no MPI, no PETSc.
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "base/vec3.hpp"
#include "coupling/interface.hpp"
#include "dem/walls.hpp"
#include "fem/mesh.hpp"

namespace fdem::coupling {

/// A triangle's plane and bounding sphere: unit normal (the triangle's orientation, out of the
/// solid), offset d (normal . x = d on the plane), centroid and the largest corner distance from
/// it (m). A degenerate triangle has a NaN normal and offset.
struct TrianglePlane {
  Vec3 normal;
  double offset = 0;
  Vec3 centroid;
  double radius = 0;
};

/// True when the triangle of plane `pl` cannot touch the sphere (x, r): its plane is at least r
/// away, or the circle the sphere cuts from the plane lies outside the triangle's bounding
/// circle. Never true for a degenerate (NaN) plane.
inline bool cannot_touch(const TrianglePlane& pl, const Vec3& x, double r) {
  const double h = pl.normal.x * x.x + pl.normal.y * x.y + pl.normal.z * x.z - pl.offset;
  if (std::abs(h) >= r) return true;
  const double px = x.x - h * pl.normal.x - pl.centroid.x, py = x.y - h * pl.normal.y - pl.centroid.y,
               pz = x.z - h * pl.normal.z - pl.centroid.z;
  const double rho = std::sqrt(r * r - h * h) + pl.radius;
  return px * px + py * py + pz * pz >= rho * rho;
}

class InterfaceSurface {
 public:
  /// One vertex: its FE nodes (mesh indices, -1 unused) and their weights.
  struct Vertex {
    std::array<std::int32_t, 4> nodes;
    std::array<double, 4> weights;
  };

  /// `mesh` must outlive the surface (its coordinates are the reference positions). Throws
  /// std::invalid_argument when the nodes of a corner have different weights or a triangle has a
  /// negative surface group.
  InterfaceSurface(const fem::Mesh& mesh, std::vector<InterfaceTriangle> triangles);

  // ---- topology ----
  std::size_t n_triangles() const { return triangles_.size(); }
  std::size_t n_vertices() const { return vertices_.size(); }
  const std::vector<InterfaceTriangle>& triangles() const { return triangles_; }
  const Vertex& vertex(std::int32_t v) const { return vertices_[v]; }
  /// Vertex indices of triangle t (edge k runs from corner k to corner k + 1).
  const std::array<int, 3>& corners(std::size_t t) const { return corners_[t]; }
  const std::vector<std::array<int, 3>>& all_corners() const { return corners_; }
  const FacetTopology& topology() const { return topology_; }
  /// Per edge k of triangle t: the vertex opposite it in the one other triangle sharing the edge
  /// (-1: no other triangle; -2: not such a simple edge, see the topology).
  const std::array<std::int32_t, 3>& opposite(std::size_t t) const { return opposite_[t]; }
  /// The weight of each of vertex v's nodes (1, or 1/4 at a quad centre) and their number.
  double node_weight(std::int32_t v) const { return node_weight_[v]; }
  int node_count(std::int32_t v) const { return node_count_[v]; }
  std::int32_t group(std::size_t t) const { return group_[t]; }
  int n_groups() const { return n_groups_; }

  /// Which triangles take part in contacts: all of them at the start. `active[t]` 0 takes
  /// triangle t out (the face of a removed element, or one that a removal has not yet exposed);
  /// the topology and the opposite vertices are then those of the active triangles alone (an
  /// edge a removal turned from flat into a corner is one). Same on every rank.
  void set_active(const std::vector<std::uint8_t>& active);
  bool active(std::size_t t) const { return active_[t] != 0; }
  std::size_t n_active_triangles() const;

  /// Active triangles (ascending) whose reference bounding box grown by `grow` overlaps [lo, hi].
  std::vector<std::int32_t> triangles_near(const Vec3& lo, const Vec3& hi, double grow) const;
  /// The FE nodes of triangles `tris` (mesh indices, ascending, unique).
  std::vector<std::int32_t> nodes_of(const std::vector<std::int32_t>& tris) const;
  /// The vertices of triangles `tris` (ascending, unique).
  std::vector<std::int32_t> vertices_of(const std::vector<std::int32_t>& tris) const;

  // ---- state ----
  const Vec3& position(std::int32_t v) const { return vertex_pos_[v]; }
  const Vec3& velocity(std::int32_t v) const { return vertex_vel_[v]; }
  const TrianglePlane& plane(std::size_t t) const { return planes_[t]; }
  /// The vertices of triangles `tris` at x = X + u and as the positions of an FE update, and the
  /// triangles' planes; u of mesh node n is disp[slot[n]].
  void place_at_fe(const std::vector<std::int32_t>& tris, const std::vector<std::int32_t>& verts,
                   const std::vector<Vec3>& disp, const std::vector<std::int32_t>& slot);
  /// The velocities of the vertices of triangles `tris` from nodal velocities vel[slot[n]].
  void set_velocities(const std::vector<std::int32_t>& tris, const std::vector<Vec3>& vel,
                      const std::vector<std::int32_t>& slot);
  /// Every vertex at rest.
  void clear_velocities();
  /// Vertices `verts` at x = x_FE + s v (s: time since the FE update, s).
  void extrapolate(const std::vector<std::int32_t>& verts, double s);
  /// Vertices `verts` back at their FE positions, and the planes of `tris` from them.
  void return_to_fe(const std::vector<std::int32_t>& verts, const std::vector<std::int32_t>& tris);

 private:
  void index_vertices();
  void find_opposite_vertices();
  void place_reference();
  void update_planes(const std::vector<std::int32_t>& tris);

  const fem::Mesh& mesh_;
  std::vector<InterfaceTriangle> triangles_;
  std::vector<Vertex> vertices_;
  std::vector<std::array<int, 3>> corners_;           // triangle -> vertices
  FacetTopology topology_;
  std::vector<std::array<std::int32_t, 3>> opposite_; // triangle edge -> opposite vertex across it
  std::vector<std::array<Vec3, 2>> reference_box_;    // triangle -> reference bounding box
  std::vector<std::int32_t> group_;                   // triangle -> surface group
  int n_groups_ = 1;
  std::vector<double> node_weight_;                   // vertex -> weight of each of its nodes
  std::vector<std::uint8_t> node_count_;              // vertex -> number of its nodes
  std::vector<Vec3> vertex_pos_, vertex_vel_;         // current (valid where placed)
  std::vector<Vec3> vertex_pos_fe_;                   // at the last FE update
  std::vector<TrianglePlane> planes_;                 // triangle -> plane at the FE positions
  std::vector<std::uint8_t> active_;                  // triangle -> takes part in contacts
};

}  // namespace fdem::coupling
