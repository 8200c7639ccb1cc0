#pragma once
// Local topology of the finite elements: the faces of each element type (edges for the 2-D
// quadrilateral), as lists of local node numbers. See docs/mesh-formats.md.
//
// Face numbering (all types): face = 2 * axis + side, axis 0/1/2 = xi/eta/zeta, side 0 = the
// face at -1, side 1 = the face at +1:
//   0: xi = -1   1: xi = +1   2: eta = -1   3: eta = +1   4: zeta = -1   5: zeta = +1
// (the Quad4 has faces 0..3 only). For an undistorted element aligned with the axes face 0 faces
// -x, 1 +x, 2 -y, 3 +y, 4 -z (bottom), 5 +z (top).
//
// Node order of a face: corners first, counter-clockwise seen from OUTSIDE the element (so
// (p1 - p0) x (p3 - p0) points outward for a quad face, and for a 2-D edge (a, b) the outward
// normal is (t_y, -t_x) with t = b - a); for Hex20 the corners are followed by the mid-edge
// nodes of the face's edges c0-c1, c1-c2, c2-c3, c3-c0. Element node orders as in element.hpp
// (Gmsh). Hex8R has the Hex8 topology.
#include <array>
#include <cstdint>
#include <vector>

#include "fem/element.hpp"

namespace fdem::fem {

struct Mesh;

/// Local face numbers by direction (see above).
enum LocalFace : int { kFaceXiMinus = 0, kFaceXiPlus = 1, kFaceEtaMinus = 2, kFaceEtaPlus = 3,
                       kFaceZetaMinus = 4, kFaceZetaPlus = 5 };

/// Node lists of the faces of an element type, indexed by local face number.
/// Hex8/Hex8R: 6 faces of 4 nodes; Hex20: 6 faces of 8 nodes; Quad4: 4 edges of 2 nodes.
const std::vector<std::vector<int>>& element_faces(ElemType t);
/// Number of corner nodes of a face of type t (4 for bricks, 2 for the quad).
int face_corner_count(ElemType t);
/// Number of nodes of an element type (same values as element_nodes(); kept here so the mesh
/// code does not depend on the element kernels).
int topology_node_count(ElemType t);
/// Spatial dimension of an element type (3 for bricks, 2 for the quad).
int topology_dim(ElemType t);

/// A face of an element: (element index, local face number).
using FaceRef = std::array<std::int32_t, 2>;

/// Corner node indices of a face, sorted, padded with -1 (2-D edges): equal for the two
/// elements that share the face.
std::array<std::int32_t, 4> face_key(const Mesh& mesh, std::size_t element, int face);

/// All faces of the mesh that belong to exactly one element (boundary faces), matched by their
/// corner nodes; in element order, then local face order.
std::vector<FaceRef> boundary_faces(const Mesh& mesh);

/// Outward normal of a face, scaled by the face's area (3-D: the area of the quadrilateral
/// through its corners, computed as half the cross product of the diagonals; 2-D: the edge
/// length, with a zero z component).
std::array<double, 3> face_area_normal(const Mesh& mesh, std::int32_t element, int face);

}  // namespace fdem::fem
