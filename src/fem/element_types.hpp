#pragma once
// The element types and what is fixed about each, in one table indexed by ElemType: the name a
// case file uses, node count, dimension, Gauss points, dofs per node, how its boundary is made
// (faces of a solid, edges of a quad or shell), and its XDMF topology for output. The kernels
// (element.cpp, shell.cpp), the mesh readers and generators (mesh*.cpp), the topology
// (topology.cpp), the case reader and the FE output all read it here. A new element type is
// one row here and its kernel in element.cpp.
//
// Node numbering of the bricks (Gmsh/VTK corner order; Hex20's mid-edge nodes in Gmsh order)
// is also kept here, for the same reason.
#include <cstdint>
#include <string>

namespace fdem::fem {

enum class ElemType : std::int8_t {
  kHex8,    // 8-node brick, 2x2x2 Gauss points (the thesis's geogrid element)
  kHex8R,   // 8-node brick, 1 point, stiffness-type hourglass control
  kHex20,   // 20-node serendipity brick, 2x2x2 points
  kQuad4,   // 4-node plane-strain quadrilateral, 2x2 points
  kShell4,  // 4-node flat shell (MITC4), 6 dofs per node (fem/shell.hpp); 3-D meshes only
  kHex8I,   // 8-node brick with incompatible (bubble) modes, 2x2x2 points: bends without locking
};
constexpr int kElemTypeCount = 6;

struct ElementTraits {
  ElemType type;
  const char* name;       // as in case files and messages
  int nodes;              // nodes per element
  int dim;                // of the element's parametric space (3 bricks, 2 quads and shells)
  int space_dim;          // of the mesh it lives in (quad4: plane strain in 2-D; shell4: 3-D)
  int gauss_points;       // integration points with stored state (shell4: the centre's resultants)
  int node_dofs;          // degrees of freedom per node
  int face_corners;       // corners of a boundary face (bricks: 4-node quads; quads, shells: 2-node edges)
  int xdmf_code;          // XDMF topology code in a Mixed topology
  const char* xdmf_name;  // XDMF TopologyType of a mesh of this type alone
  const char* help;       // one line, for docs and `fdem schema`
};

inline constexpr ElementTraits kElementTraits[kElemTypeCount] = {
    {ElemType::kHex8, "hex8", 8, 3, 3, 8, 3, 4, 9, "Hexahedron", "8-node brick, 2x2x2 Gauss points"},
    {ElemType::kHex8R, "hex8r", 8, 3, 3, 1, 3, 4, 9, "Hexahedron", "8-node brick, one point, hourglass control"},
    {ElemType::kHex20, "hex20", 20, 3, 3, 8, 3, 4, 48, "Hexahedron_20", "20-node serendipity brick, 2x2x2 points"},
    {ElemType::kQuad4, "quad4", 4, 2, 2, 4, 2, 2, 5, "Quadrilateral", "4-node plane-strain quadrilateral, 2x2 points"},
    {ElemType::kShell4, "shell4", 4, 2, 3, 1, 6, 2, 5, "Quadrilateral", "4-node flat shell (MITC4), 6 dofs per node"},
    {ElemType::kHex8I, "hex8i", 8, 3, 3, 8, 3, 4, 9, "Hexahedron", "8-node brick with incompatible modes (as Abaqus's C3D8I), 2x2x2 points: bends without locking, one brick through a rib's thickness suffices"},
};

inline const ElementTraits& element_traits(ElemType t) { return kElementTraits[static_cast<int>(t)]; }

/// "hex8, hex8r, hex20, quad4, shell4, hex8i": the valid names, for messages.
std::string element_type_names();

// ---- brick node numbering (Gmsh/VTK) ----

/// Natural coordinates of the 8 corners.
inline constexpr int kHexCorner[8][3] = {{-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1},
                                         {-1, -1, 1},  {1, -1, 1},  {1, 1, 1},  {-1, 1, 1}};
/// Hex20: mid-edge node 8 + k lies on the edge between corners kHex20Edge[k].
inline constexpr int kHex20Edge[12][2] = {{0, 1}, {0, 3}, {0, 4}, {1, 2}, {1, 5}, {2, 3},
                                          {2, 6}, {3, 7}, {4, 5}, {4, 7}, {5, 6}, {6, 7}};

}  // namespace fdem::fem
