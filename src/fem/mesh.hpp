#pragma once
// A finite-element mesh: nodes, elements of mixed types, named node, element and face sets;
// readers for the thesis's text formats and Gmsh .msh 4.1 ASCII; generators for geogrids and
// blocks. No MPI: every rank reads the same mesh; partitioning is done elsewhere (src/partition).
#include <array>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "fem/element.hpp"

namespace fdem::fem {

struct Mesh {
  int dim = 3;
  // Nodes: user ids (from the file) and coordinates (dim per node, row-major).
  std::vector<std::int64_t> node_id;
  std::vector<double> coords;
  // Elements: user ids, type, connectivity as node INDICES (0-based into node arrays),
  // flattened with offsets (elem_offset.size() == n_elements + 1).
  std::vector<std::int64_t> elem_id;
  std::vector<ElemType> elem_type;
  std::vector<std::int32_t> elem_offset{0};
  std::vector<std::int32_t> elem_nodes;
  std::vector<std::int32_t> elem_material;  // index into the case's FE materials (default 0)
  // Named sets (indices).
  std::map<std::string, std::vector<std::int32_t>> node_sets;
  std::map<std::string, std::vector<std::int32_t>> element_sets;
  /// Face sets: (element index, local face number) pairs; faces numbered as in fem/topology.
  std::map<std::string, std::vector<std::array<std::int32_t, 2>>> face_sets;
  /// Tied nodes (fem.ties): tied_to[i] is the node that node i became (no element uses node i
  /// then), -1 where none; empty when nothing is tied.
  std::vector<std::int32_t> tied_to;

  std::size_t n_nodes() const { return node_id.size(); }
  std::size_t n_elements() const { return elem_id.size(); }
  int nodes_of(std::size_t e, const std::int32_t*& first) const {
    first = elem_nodes.data() + elem_offset[e];
    return elem_offset[e + 1] - elem_offset[e];
  }
  /// Append an element (connectivity as node indices).
  void add_element(std::int64_t id, ElemType t, const std::vector<std::int32_t>& nodes, int material = 0);
  /// Index of a node id, -1 if none (built lazily).
  std::int32_t node_index(std::int64_t id) const;

 private:
  mutable std::map<std::int64_t, std::int32_t> node_lookup_;
};

/// Nodal boundary data of the thesis's formats, by node INDEX.
struct NodalRestraint { std::int32_t node; std::array<bool, 3> fixed; };
struct NodalVector { std::int32_t node; std::array<double, 3> value; };

// ---- readers (throw fdem::InputError with file, line and what is wrong) ----
/// Thesis nodes file: "id x y (z)" per line.
void read_thesis_nodes(const std::string& path, int dim, Mesh& mesh);
/// Thesis elements file: "id n1 n2 ..." per line (node ids), all of type `t`; checks ids exist,
/// duplicates, and inverted/degenerate elements (negative Jacobian) naming the element.
void read_thesis_elements(const std::string& path, ElemType t, Mesh& mesh, int material = 0);
/// Thesis restraints "id rx ry (rz)" (1 = fixed), loads "id fx fy (fz)", displacements "id ux uy (uz)".
std::vector<NodalRestraint> read_thesis_restraints(const std::string& path, const Mesh& mesh);
std::vector<NodalVector> read_thesis_nodal_vectors(const std::string& path, const Mesh& mesh);
/// Gmsh .msh 4.1 ASCII: nodes, elements (hex8 = type 5, hex20 = 17, quad4 = 3), physical groups
/// as element sets (volume/surface groups of the mesh's dimension) and node sets (all groups);
/// (dim-1) quadrangle/line groups also become face sets. Replaces the contents of `mesh`.
void read_gmsh(const std::string& path, Mesh& mesh, ElemType hex8_as = ElemType::kHex8);

// ---- generators ----
/// Biaxial geogrid: a rectangular grid of longitudinal ribs (along x) and transverse ribs
/// (along y), meshed with 8-node bricks.
struct GeogridSpec {
  double length = 0;          // along x (pull direction), m
  double width = 0;           // along y, m
  int longitudinal_ribs = 0;  // ribs along x (count across the width)
  int transverse_ribs = 0;    // ribs along y (count along the length)
  double rib_width = 0;       // m (both rib families)
  double thickness = 0;       // m
  double junction_thickness = 0;  // m, 0: same as thickness
  double clamp_length = 0;    // m, a solid clamp zone at x = origin.x (0: none)
  std::array<double, 3> origin{0, 0, 0};  // minimum corner (x, y, z of the grid's bottom face)
  int elements_per_rib_width = 1;   // mesh density across a rib
  int elements_through_thickness = 1;
  double max_element_length = 0;    // along ribs; 0: rib width
  /// Added: clear distance along x from the clamp's back end (x = origin.x + clamp_length) to
  /// the front face of the first transverse rib, m. < 0 (default): one aperture a_x, i.e. the
  /// clamp stands in the rib pattern like a transverse rib; 0 with no clamp puts the first
  /// transverse rib at the front end. SS-1 in the thesis: 0.03 (first rib 30 mm behind the wall).
  double clamp_gap = -1;
  /// Added: the transverse ribs (and the clamp) run on this far beyond the outermost
  /// longitudinal ribs, on both sides, m (0: the outermost ribs are the grid's edges). A slice
  /// of a wide grid between symmetry planes through the middle of its apertures: half the
  /// aperture a_y. `width` is the whole width, overhangs included.
  double side_overhang = 0;
};

/// Added: the layout make_geogrid() builds (all lengths in m; see docs/mesh-formats.md).
struct GeogridInfo {
  double aperture_x = 0;  // clear aperture along x: between adjacent transverse ribs
  double aperture_y = 0;  // clear aperture along y: between adjacent longitudinal ribs
  double pitch_x = 0;     // aperture_x + rib_width (centre-to-centre of transverse ribs)
  double pitch_y = 0;     // aperture_y + rib_width
  double clamp_gap = 0;   // clamp end (or front end) to the first transverse rib's front face
  double junction_thickness = 0;  // effective (= thickness when the spec says 0)
  std::vector<double> transverse_x;    // x of the front (-x) face of each transverse rib
  std::vector<double> longitudinal_y;  // y of the -y side of each longitudinal rib
  double plan_area = 0;   // area of the grid seen from above (clamp included), m^2
  double volume = 0;      // analytic solid volume (junctions counted once), m^3
};
/// Added: the layout of a spec without meshing it; throws fdem::InputError (file "geogrid",
/// line 0) if the spec is impossible (non-positive apertures, sizes, counts < 2, ...).
GeogridInfo geogrid_layout(const GeogridSpec& s);
/// Build the grid mesh; element sets "longitudinal", "transverse", "junction", "clamp", node set
/// "clamp" (the nodes of the clamp's front face, x = origin.x), face sets "top", "bottom",
/// "transverse_front" (the transverse ribs' faces facing -x). Clear apertures follow from the
/// rib counts: a_y = (width - n_l w)/(n_l - 1); a_x = (length - clamp - gap - n_t w)/(n_t - 1)
/// (without a clamp and gap: (length - n_t w)/(n_t - 1)); see docs/mesh-formats.md.
Mesh make_geogrid(const GeogridSpec& s);
/// Added: same, also returning the layout.
Mesh make_geogrid(const GeogridSpec& s, GeogridInfo& info);

/// A cylindrical shell (a pipe) of shell4 elements along +axis (0 x, 1 y, 2 z) from `base` (the
/// axis point of the start section): n_around elements around, n_along along. Node i of a ring
/// lies at angle a = 2 pi i / n_around from the in-plane axis p = axis + 1 towards q = axis + 2
/// (cyclic): base + r (cos a e_p + sin a e_q); along z: from x towards y, along y: from z towards
/// x. The element normals point outwards. Node sets "start" and "end" (the two end rings);
/// element set "all".
Mesh make_cylinder_shell(const std::array<double, 3>& base, double radius, double length, int n_around, int n_along,
                         int axis = 2);

/// A flat plate of shell4 elements in the plane x[flat_axis] = lo[flat_axis], filling [lo, hi]
/// in the two other directions a = flat_axis + 1, b = flat_axis + 2 (cyclic) with n_a x n_b
/// elements; the element normals point along +flat_axis. Node sets "xmin".."zmax" for the
/// four edges (those of the in-plane directions); element set "all".
Mesh make_shell_plate(const std::array<double, 3>& lo, const std::array<double, 3>& hi, int flat_axis, int n_a, int n_b);

/// A block of nx x ny x nz Hex8 elements filling [lo, hi], optionally without the elements
/// whose centres lie inside a void box (element set "void" holds them instead, so they can be
/// removed during a run). Node sets "xmin".."zmax" for the six faces.
Mesh make_block(const std::array<double, 3>& lo, const std::array<double, 3>& hi, int nx, int ny, int nz,
                const std::array<double, 3>* void_lo = nullptr, const std::array<double, 3>* void_hi = nullptr);

}  // namespace fdem::fem
