#pragma once
// FE–DEM interface surface (DESIGN.md 4.4): triangles made from FE surface faces, their current
// positions, and the distribution of a contact force on a triangle to FE nodes.
//
// * A triangular face is used as is; a quadrilateral face (Hex8/Hex8R faces) is split into 4
//   triangles (c0,c1,O), (c1,c2,O), (c2,c3,O), (c3,c0,O) around its centre O = 1/4 sum c_i. O is
//   not a mesh node: it is stored as a "corner" made of the 4 quad corners with weight 1/4 each,
//   so a force share at O goes in equal quarters to the four corners.
// * A Hex20 face (8 nodes: corners c_i, mid-edge nodes m_i of the edges c_i-c_{i+1}) gives 8
//   triangles: (c_i, m_i, m_{i-1}) at each corner and the quadrilateral m0 m1 m2 m3 split as
//   above. Every face node takes interface force (a uniform pressure on a flat face: A/24 per
//   corner, 5A/24 per mid-edge node; loading the corners alone punched the corners of an
//   elasto-plastic soil's surface) and the surface follows the mid-edge nodes.
// * Orientation: every triangle's normal (b - a) x (c - a) points OUT of the solid element (face
//   corners are counter-clockwise seen from outside, fem/topology.hpp). For a shell4 element
//   the quad is the element itself, with nodes in element order: the normal is the shell
//   normal (x1 - x0) x (x3 - x0) (for make_cylinder_shell: outwards).
// * Force distribution (F_i = N_i F_contact): barycentric N of the contact point for the three
//   corners, then each corner's share spread over its nodes by weight. The sum of the nodal
//   forces is F and, since O is the weighted mean of its nodes, the moment about any point is
//   that of F at the contact point.
// Pure functions: no MPI, no PETSc.
#include <array>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "base/vec3.hpp"
#include "fem/mesh.hpp"

namespace fdem::coupling {

/// One interface triangle: three "corners", each a weighted combination of FE nodes
/// (a real node: one node with weight 1; a quad's centre node: its 4 corners with weight 1/4).
struct InterfaceTriangle {
  std::array<std::array<std::int32_t, 4>, 3> nodes;   // mesh node indices (-1 = unused)
  std::array<std::array<double, 4>, 3> weights;
  std::int32_t element = -1, face = -1;               // FE element and local face it comes from
                                                      // (face = -1 for a shell element's quad)
  std::int32_t group = 0;                             // surface group (forces are also summed per group)
};

/// Interface triangles of
///  * the face set `face_set` of the mesh (when not empty; an unknown name, a bad element index
///    or face number, or a face of a 2-D / shell element throws fdem::InputError), plus
///  * the elements listed in `shell_elements`: a Shell4 element gives its own quad (4
///    triangles, face = -1); a brick listed there (only when face_set is empty) gives its faces
///    that lie on the mesh boundary (fem::boundary_faces); a Quad4 throws.
///  * face_set empty and shell_elements empty: the whole surface of the mesh, i.e. every
///    boundary face of every brick and every Shell4 element.
/// Triangles come in face-set order (then element-list order); each quad's 4 triangles are
/// consecutive. Requires mesh.dim == 3.
std::vector<InterfaceTriangle> make_interface(const fem::Mesh& mesh, const std::string& face_set,
                                              const std::vector<std::int32_t>& shell_elements = {});

/// The holds during which an interface triangle is on the surface: from hold `from` (at its
/// start) up to, not including, hold `until` (kForever: to the end of the run).
struct HoldRange {
  static constexpr std::int32_t kForever = 2147483647;
  std::int32_t from = 0, until = kForever;
  bool at(std::int32_t hold) const { return hold >= from && hold < until; }
};

/// make_interface over element removals (fem.remove): element e is removed at the start of hold
/// removed_at[e] (-1: never; an empty list: no element ever is). The triangles are those of every
/// face that is on the surface at some hold -- a face of a removed element until its removal, a
/// face it shared with a remaining element from then on (the walls of a void) -- and
/// holds[t] says when triangle t is. Face sets and shells: their faces while their element is
/// there. With no removals the triangles are make_interface's, in its order, all of them always.
std::vector<InterfaceTriangle> make_interface(const fem::Mesh& mesh, const std::string& face_set,
                                              const std::vector<std::int32_t>& shell_elements,
                                              const std::vector<std::int32_t>& removed_at, std::vector<HoldRange>& holds);

/// Current corner positions x = sum_k w_k (X_k + u_k) from nodal displacements u (3 per node,
/// mesh node order; an empty u means zero displacement).
void corner_positions(const fem::Mesh& mesh, const std::vector<double>& u, const InterfaceTriangle& t,
                      Vec3 out[3]);

/// Barycentric coordinates (N0, N1, N2) of the point of triangle (a, b, c) closest to p:
/// fdem::triangle_barycentric (dem/facet_geometry.hpp; on an edge the opposite N is exactly 0, at a
/// vertex that vertex's N is exactly 1). N0 + N1 + N2 == 1. A degenerate triangle gives the nearest
/// vertex.
std::array<double, 3> barycentric(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& p);

/// Distribute a force F applied at point p of triangle t (p inside or on it; otherwise the
/// closest point of the triangle is used) to FE nodes: barycentric N_i of p for the 3 corners,
/// then each corner's share spread over its nodes by weight. Appends (node, force) pairs
/// (a node may appear several times; zero shares are skipped).
void distribute_force(const InterfaceTriangle& t, const Vec3 corners[3], const Vec3& p, const Vec3& F,
                      std::vector<std::pair<std::int32_t, Vec3>>& out);

/// The FE nodes the triangles' forces go to (mesh node indices, ascending, unique).
std::vector<std::int32_t> interface_nodes(const std::vector<InterfaceTriangle>& tris);

/// Each interface node's share of the interface area (m^2, reference positions), in the order
/// of interface_nodes(tris): the integral of its interface shape function, sum over triangles of
/// area/3 per corner spread over the corner's nodes by weight (a quad face's corner gets a
/// quarter of the quad). The shares add up to the interface's area. A node's share bounds how
/// many contacts can load it at once (the coupled run's FE stable step).
std::vector<double> interface_node_areas(const fem::Mesh& mesh, const std::vector<InterfaceTriangle>& tris);

}  // namespace fdem::coupling
