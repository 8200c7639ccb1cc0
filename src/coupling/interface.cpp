#include "coupling/interface.hpp"

#include <algorithm>
#include <map>
#include <stdexcept>

#include "dem/facet_geometry.hpp"
#include "fem/topology.hpp"
#include "base/errors.hpp"

namespace fdem::coupling {
namespace {

using Corner = std::pair<std::array<std::int32_t, 4>, std::array<double, 4>>;

Corner node_corner(std::int32_t n) { return {{n, -1, -1, -1}, {1.0, 0.0, 0.0, 0.0}}; }

void add_triangle(std::vector<InterfaceTriangle>& out, const Corner& a, const Corner& b, const Corner& c,
                  std::int32_t element, std::int32_t face) {
  InterfaceTriangle t;
  t.nodes = {a.first, b.first, c.first};
  t.weights = {a.second, b.second, c.second};
  t.element = element;
  t.face = face;
  out.push_back(t);
}

// A polygon of 3 or 4 corner nodes, counter-clockwise seen from the side the normal points to.
void add_polygon(std::vector<InterfaceTriangle>& out, const std::int32_t* c, int nc, std::int32_t element,
                 std::int32_t face) {
  if (nc == 3) {
    add_triangle(out, node_corner(c[0]), node_corner(c[1]), node_corner(c[2]), element, face);
    return;
  }
  const Corner centre{{c[0], c[1], c[2], c[3]}, {0.25, 0.25, 0.25, 0.25}};
  for (int i = 0; i < 4; ++i)
    add_triangle(out, node_corner(c[i]), node_corner(c[(i + 1) % 4]), centre, element, face);
}

// An 8-node (serendipity) quadrilateral face: corners c[0..3] counter-clockwise, then the
// mid-edge nodes c[4 + i] of the edges c[i]-c[i+1]. Four corner triangles (c_i, m_i, m_{i-1}) and
// the inner quadrilateral of the mid-edge nodes split around its centre: every node of the face
// carries interface force (a uniform pressure on a flat face: A/24 to each corner, 5A/24 to each
// mid-edge node), and the surface follows the mid-edge nodes (a curved face's arc).
void add_quadratic_quad(std::vector<InterfaceTriangle>& out, const std::int32_t* c, std::int32_t element,
                        std::int32_t face) {
  const std::int32_t* m = c + 4;
  for (int i = 0; i < 4; ++i)
    add_triangle(out, node_corner(c[i]), node_corner(m[i]), node_corner(m[(i + 3) % 4]), element, face);
  add_polygon(out, m, 4, element, face);
}

bool is_brick(fem::ElemType t) {
  return fem::element_traits(t).dim == 3;
}

void add_face(const fem::Mesh& mesh, std::int32_t e, std::int32_t f, std::vector<InterfaceTriangle>& out,
              const std::string& where) {
  if (e < 0 || static_cast<std::size_t>(e) >= mesh.n_elements())
    throw InputError("interface", 0, where + ": element index " + std::to_string(e) + " out of range");
  const fem::ElemType type = mesh.elem_type[e];
  if (!is_brick(type))
    throw InputError("interface", 0, where + ": element " + std::to_string(mesh.elem_id[e]) +
                                         " is not a brick (use shell_elements for shells; 2-D quads have no surface)");
  const auto& faces = fem::element_faces(type);
  if (f < 0 || static_cast<std::size_t>(f) >= faces.size())
    throw InputError("interface", 0, where + ": element " + std::to_string(mesh.elem_id[e]) + " has no face " +
                                         std::to_string(f));
  const std::int32_t* en;
  mesh.nodes_of(e, en);
  const int nc = fem::face_corner_count(type);
  if (type == fem::ElemType::kHex20) {
    std::int32_t c[8];
    for (int i = 0; i < 8; ++i) c[i] = en[faces[f][i]];
    add_quadratic_quad(out, c, e, f);
    return;
  }
  std::int32_t c[4];
  for (int i = 0; i < nc; ++i) c[i] = en[faces[f][i]];
  add_polygon(out, c, nc, e, f);
}

void add_shell(const fem::Mesh& mesh, std::int32_t e, std::vector<InterfaceTriangle>& out) {
  const std::int32_t* en;
  mesh.nodes_of(e, en);
  add_polygon(out, en, 4, e, -1);
}

// The triangles being made, and the holds during which each is there.
struct Surface {
  const fem::Mesh& mesh;
  const std::vector<std::int32_t>& removed_at;
  std::vector<InterfaceTriangle>& out;
  std::vector<HoldRange>& holds;
  // the hold at whose start element e goes (kForever: never)
  std::int32_t gone_at(std::int32_t e) const {
    return removed_at.empty() || removed_at[e] < 0 ? HoldRange::kForever : removed_at[e];
  }
  // the triangles added since `from` are there during [from_hold, until_hold)
  void mark(std::int32_t from_hold, std::int32_t until_hold) {
    holds.resize(out.size(), HoldRange{from_hold, until_hold});
  }
};

// The faces of a face set, and the listed shell elements.
void add_face_set(Surface& s, const std::string& face_set, const std::vector<std::int32_t>& shell_elements) {
  const fem::Mesh& mesh = s.mesh;
  const auto it = mesh.face_sets.find(face_set);
  if (it == mesh.face_sets.end()) throw InputError("interface", 0, "no face set '" + face_set + "' in the mesh");
  for (const auto& fr : it->second) {
    add_face(mesh, fr[0], fr[1], s.out, "face set '" + face_set + "'");
    s.mark(0, s.gone_at(fr[0]));
  }
  for (const std::int32_t e : shell_elements) {
    if (e < 0 || static_cast<std::size_t>(e) >= mesh.n_elements())
      throw InputError("interface", 0, "shell element index " + std::to_string(e) + " out of range");
    if (mesh.elem_type[e] != fem::ElemType::kShell4)
      throw InputError("interface", 0, "element " + std::to_string(mesh.elem_id[e]) +
                                           " is listed as a shell but is not a shell4 (use the face set)");
    add_shell(mesh, e, s.out);
    s.mark(0, s.gone_at(e));
  }
}

// The listed elements (all elements when none are listed).
std::vector<char> selected_elements(const fem::Mesh& mesh, const std::vector<std::int32_t>& shell_elements) {
  std::vector<char> selected(mesh.n_elements(), shell_elements.empty() ? 1 : 0);
  for (const std::int32_t e : shell_elements) {
    if (e < 0 || static_cast<std::size_t>(e) >= mesh.n_elements())
      throw InputError("interface", 0, "element index " + std::to_string(e) + " out of range");
    if (mesh.elem_type[e] == fem::ElemType::kQuad4)
      throw InputError("interface", 0, "element " + std::to_string(mesh.elem_id[e]) + " is a 2-D quad4: no surface");
    selected[e] = 1;
  }
  return selected;
}

// Every face of a selected brick, with the other element sharing it (if any): the face is on
// the surface while its element is there and the other is not.
void add_brick_faces_over_removals(Surface& s, const std::vector<char>& selected) {
  const fem::Mesh& mesh = s.mesh;
  std::map<std::array<std::int32_t, 4>, std::vector<std::int32_t>> owners;
  for (std::size_t e = 0; e < mesh.n_elements(); ++e) {
    const std::size_t nf = fem::element_faces(mesh.elem_type[e]).size();
    for (std::size_t f = 0; f < nf; ++f) owners[fem::face_key(mesh, e, static_cast<int>(f))].push_back(static_cast<std::int32_t>(e));
  }
  for (std::size_t e = 0; e < mesh.n_elements(); ++e) {
    if (!selected[e] || !is_brick(mesh.elem_type[e])) continue;
    const std::size_t nf = fem::element_faces(mesh.elem_type[e]).size();
    for (std::size_t f = 0; f < nf; ++f) {
      const auto& o = owners[fem::face_key(mesh, e, static_cast<int>(f))];
      if (o.size() > 2) continue;  // not a simple face (three elements on it)
      const std::int32_t ee = static_cast<std::int32_t>(e);
      const std::int32_t other = o.size() == 2 ? (o[0] == ee ? o[1] : o[0]) : -1;
      const std::int32_t from = other < 0 ? 0 : s.gone_at(other), until = s.gone_at(ee);
      if (from >= until) continue;  // never on the surface
      add_face(mesh, ee, static_cast<std::int32_t>(f), s.out, "boundary");
      s.mark(from, until);
    }
  }
}

// The shell elements: every one when none are listed, else the listed ones.
void add_shells(Surface& s, const std::vector<std::int32_t>& shell_elements) {
  const fem::Mesh& mesh = s.mesh;
  if (shell_elements.empty()) {
    for (std::size_t e = 0; e < mesh.n_elements(); ++e)
      if (mesh.elem_type[e] == fem::ElemType::kShell4) {
        add_shell(mesh, static_cast<std::int32_t>(e), s.out);
        s.mark(0, s.gone_at(static_cast<std::int32_t>(e)));
      }
  } else {
    for (const std::int32_t e : shell_elements)
      if (mesh.elem_type[e] == fem::ElemType::kShell4) {
        add_shell(mesh, e, s.out);
        s.mark(0, s.gone_at(e));
      }
  }
}

}  // namespace

std::vector<InterfaceTriangle> make_interface(const fem::Mesh& mesh, const std::string& face_set,
                                              const std::vector<std::int32_t>& shell_elements) {
  std::vector<HoldRange> holds;
  return make_interface(mesh, face_set, shell_elements, {}, holds);
}

std::vector<InterfaceTriangle> make_interface(const fem::Mesh& mesh, const std::string& face_set,
                                              const std::vector<std::int32_t>& shell_elements,
                                              const std::vector<std::int32_t>& removed_at, std::vector<HoldRange>& holds) {
  if (mesh.dim != 3) throw InputError("interface", 0, "the FE-DEM interface needs a 3-D mesh");
  if (!removed_at.empty() && removed_at.size() != mesh.n_elements())
    throw std::invalid_argument("make_interface: removed_at must have one entry per element");
  std::vector<InterfaceTriangle> out;
  holds.clear();
  Surface s{mesh, removed_at, out, holds};
  if (!face_set.empty()) {
    add_face_set(s, face_set, shell_elements);
    return out;
  }
  // No face set: the surface of the listed elements (all elements when none are listed).
  const std::vector<char> selected = selected_elements(mesh, shell_elements);
  bool any_brick = false;
  for (std::size_t e = 0; e < mesh.n_elements(); ++e) any_brick = any_brick || (selected[e] && is_brick(mesh.elem_type[e]));
  if (any_brick && removed_at.empty()) {
    // boundary_faces also lists shell edges; keep the faces of selected bricks only.
    for (const auto& fr : fem::boundary_faces(mesh))
      if (selected[fr[0]] && is_brick(mesh.elem_type[fr[0]])) {
        add_face(mesh, fr[0], fr[1], out, "boundary");
        s.mark(0, HoldRange::kForever);
      }
  } else if (any_brick) {
    add_brick_faces_over_removals(s, selected);
  }
  add_shells(s, shell_elements);
  return out;
}

void corner_positions(const fem::Mesh& mesh, const std::vector<double>& u, const InterfaceTriangle& t,
                      Vec3 out[3]) {
  const bool has_u = !u.empty();
  for (int c = 0; c < 3; ++c) {
    Vec3 x{0, 0, 0};
    for (int k = 0; k < 4; ++k) {
      const std::int32_t n = t.nodes[c][k];
      if (n < 0) continue;
      const double w = t.weights[c][k];
      const std::size_t o = 3 * static_cast<std::size_t>(n);
      Vec3 xn{mesh.coords[o], mesh.coords[o + 1], mesh.coords[o + 2]};
      if (has_u) xn += Vec3{u[o], u[o + 1], u[o + 2]};
      x += w * xn;
    }
    out[c] = x;
  }
}

std::array<double, 3> barycentric(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& p) {
  return triangle_barycentric(a, b, c, p);
}

void distribute_force(const InterfaceTriangle& t, const Vec3 corners[3], const Vec3& p, const Vec3& F,
                      std::vector<std::pair<std::int32_t, Vec3>>& out) {
  const auto N = barycentric(corners[0], corners[1], corners[2], p);
  for (int c = 0; c < 3; ++c) {
    if (N[c] == 0.0) continue;
    for (int k = 0; k < 4; ++k) {
      const std::int32_t n = t.nodes[c][k];
      const double w = t.weights[c][k];
      if (n < 0 || w == 0.0) continue;
      out.emplace_back(n, (N[c] * w) * F);
    }
  }
}

std::vector<std::int32_t> interface_nodes(const std::vector<InterfaceTriangle>& tris) {
  std::vector<std::int32_t> out;
  for (const InterfaceTriangle& t : tris)
    for (const auto& c : t.nodes)
      for (std::int32_t n : c)
        if (n >= 0) out.push_back(n);
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

std::vector<double> interface_node_areas(const fem::Mesh& mesh, const std::vector<InterfaceTriangle>& tris) {
  const std::vector<std::int32_t> nodes = interface_nodes(tris);
  std::vector<double> area(nodes.size(), 0.0);
  for (const InterfaceTriangle& t : tris) {
    Vec3 x[3];
    corner_positions(mesh, {}, t, x);
    const double third = norm(cross(x[1] - x[0], x[2] - x[0])) / 6.0;
    for (int c = 0; c < 3; ++c)
      for (int k = 0; k < 4; ++k) {
        const std::int32_t n = t.nodes[c][k];
        if (n < 0) continue;
        const auto it = std::lower_bound(nodes.begin(), nodes.end(), n);
        area[static_cast<std::size_t>(it - nodes.begin())] += t.weights[c][k] * third;
      }
  }
  return area;
}

}  // namespace fdem::coupling
