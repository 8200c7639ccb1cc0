// The thesis's text formats (docs/mesh-formats.md): nodes "id x y (z)", elements "id n1 n2 ...",
// restraints "id rx ry (rz)" and nodal vectors (loads, displacements) "id vx vy (vz)"; '#'
// comments, commas as blanks.
#include <cmath>
#include <unordered_map>

#include "base/errors.hpp"
#include "fem/mesh.hpp"
#include "fem/mesh_detail.hpp"
#include "fem/topology.hpp"

namespace fdem::fem {

using detail::check_element_shape;
using detail::parse_double;
using detail::parse_int;
using detail::read_lines;
using detail::thesis_tokens;
using detail::type_name;

void read_thesis_nodes(const std::string& path, int dim, Mesh& mesh) {
  if (dim != 2 && dim != 3) throw InputError(path, 0, "nodes file: dim must be 2 or 3, got " + std::to_string(dim));
  if (mesh.n_nodes() > 0 && mesh.dim != dim)
    throw InputError(path, 0, "nodes file: dim " + std::to_string(dim) + " does not match the mesh's dim " +
                                  std::to_string(mesh.dim));
  const auto lines = read_lines(path, "nodes");
  mesh.dim = dim;
  std::unordered_map<std::int64_t, int> seen;  // id -> line (0: defined before this file)
  for (auto id : mesh.node_id) seen.emplace(id, 0);
  std::size_t added = 0;
  for (std::size_t k = 0; k < lines.size(); ++k) {
    const int ln = static_cast<int>(k + 1);
    const auto tok = thesis_tokens(lines[k]);
    if (tok.empty()) continue;
    if (static_cast<int>(tok.size()) != 1 + dim)
      throw InputError(path, ln, "expected " + std::to_string(1 + dim) + " values 'id x y" + (dim == 3 ? " z" : "") +
                                     "', got " + std::to_string(tok.size()));
    std::int64_t id;
    if (!parse_int(tok[0], id) || id < 0)
      throw InputError(path, ln, "the node id must be a non-negative integer, got '" + tok[0] + "'");
    double x[3];
    for (int c = 0; c < dim; ++c)
      if (!parse_double(tok[1 + c], x[c]))
        throw InputError(path, ln, std::string("column ") + std::to_string(c + 2) + " (" + "xyz"[c] +
                                       ") is not a finite number: '" + tok[1 + c] + "'");
    auto ins = seen.emplace(id, ln);
    if (!ins.second)
      throw InputError(path, ln, "duplicate node id " + std::to_string(id) +
                                     (ins.first->second > 0 ? " (first defined on line " + std::to_string(ins.first->second) + ")"
                                                            : " (already in the mesh)"));
    mesh.node_id.push_back(id);
    for (int c = 0; c < dim; ++c) mesh.coords.push_back(x[c]);
    ++added;
  }
  if (added == 0) throw InputError(path, 0, "nodes file has no nodes");
}

void read_thesis_elements(const std::string& path, ElemType t, Mesh& mesh, int material) {
  const int nn = topology_node_count(t);
  if (mesh.n_nodes() == 0) throw InputError(path, 0, "elements file read before any nodes");
  // the mesh's space, not the element's parametric one: a shell4 is a 2-D element in 3-D space
  const int space = element_traits(t).space_dim;
  if (mesh.dim != space)
    throw InputError(path, 0, type_name(t) + " elements need a " + std::to_string(space) + "-D mesh, the nodes are " +
                                  std::to_string(mesh.dim) + "-D");
  const auto lines = read_lines(path, "elements");
  std::unordered_map<std::int64_t, int> seen;
  for (auto id : mesh.elem_id) seen.emplace(id, 0);
  std::size_t added = 0;
  std::vector<std::int32_t> conn(nn);
  for (std::size_t k = 0; k < lines.size(); ++k) {
    const int ln = static_cast<int>(k + 1);
    const auto tok = thesis_tokens(lines[k]);
    if (tok.empty()) continue;
    if (static_cast<int>(tok.size()) != 1 + nn)
      throw InputError(path, ln, "expected " + std::to_string(1 + nn) + " values (element id and " + std::to_string(nn) +
                                     " node ids of a " + type_name(t) + "), got " + std::to_string(tok.size()));
    std::int64_t id;
    if (!parse_int(tok[0], id) || id < 0)
      throw InputError(path, ln, "the element id must be a non-negative integer, got '" + tok[0] + "'");
    for (int i = 0; i < nn; ++i) {
      std::int64_t nid;
      if (!parse_int(tok[1 + i], nid))
        throw InputError(path, ln, "element " + std::to_string(id) + ": node " + std::to_string(i + 1) +
                                       " is not an integer id: '" + tok[1 + i] + "'");
      conn[i] = mesh.node_index(nid);
      if (conn[i] < 0)
        throw InputError(path, ln, "element " + std::to_string(id) + ": unknown node id " + std::to_string(nid));
    }
    auto ins = seen.emplace(id, ln);
    if (!ins.second)
      throw InputError(path, ln, "duplicate element id " + std::to_string(id) +
                                     (ins.first->second > 0 ? " (first defined on line " + std::to_string(ins.first->second) + ")"
                                                            : " (already in the mesh)"));
    mesh.add_element(id, t, conn, material);
    check_element_shape(mesh, mesh.n_elements() - 1, path, ln);
    ++added;
  }
  if (added == 0) throw InputError(path, 0, "elements file has no elements");
}

namespace {

/// Shared loop of the nodal files: 'id v1 .. vdim' per line; calls f(line, node index, tokens).
template <class F>
void read_nodal_file(const std::string& path, const Mesh& mesh, const char* what, const char* columns, F f) {
  const int dim = mesh.dim;
  const auto lines = read_lines(path, what);
  std::unordered_map<std::int32_t, int> seen;
  for (std::size_t k = 0; k < lines.size(); ++k) {
    const int ln = static_cast<int>(k + 1);
    const auto tok = thesis_tokens(lines[k]);
    if (tok.empty()) continue;
    if (static_cast<int>(tok.size()) != 1 + dim)
      throw InputError(path, ln, "expected " + std::to_string(1 + dim) + " values 'id " + std::string(columns, 0, 3 * dim - 1) +
                                     "' (the mesh is " + std::to_string(dim) + "-D), got " + std::to_string(tok.size()));
    std::int64_t id;
    if (!parse_int(tok[0], id)) throw InputError(path, ln, "the node id must be an integer, got '" + tok[0] + "'");
    const std::int32_t node = mesh.node_index(id);
    if (node < 0) throw InputError(path, ln, "unknown node id " + std::to_string(id));
    auto ins = seen.emplace(node, ln);
    if (!ins.second)
      throw InputError(path, ln, "node id " + std::to_string(id) + " is listed twice (first on line " +
                                     std::to_string(ins.first->second) + ")");
    f(ln, node, tok);
  }
  if (seen.empty())
    throw InputError(path, 0, std::string(what) + " file has no entries (expected lines 'id " +
                                  std::string(columns, 0, 3 * dim - 1) + "')");
}

}  // namespace

std::vector<NodalRestraint> read_thesis_restraints(const std::string& path, const Mesh& mesh) {
  std::vector<NodalRestraint> out;
  read_nodal_file(path, mesh, "restraints", "rx ry rz", [&](int ln, std::int32_t node, const std::vector<std::string>& tok) {
    NodalRestraint r{node, {false, false, false}};
    for (int c = 0; c < mesh.dim; ++c) {
      if (tok[1 + c] == "1") r.fixed[c] = true;
      else if (tok[1 + c] != "0")
        throw InputError(path, ln, std::string("restraint r") + "xyz"[c] + " must be 0 (free) or 1 (fixed), got '" +
                                       tok[1 + c] + "'");
    }
    out.push_back(r);
  });
  return out;
}

std::vector<NodalVector> read_thesis_nodal_vectors(const std::string& path, const Mesh& mesh) {
  std::vector<NodalVector> out;
  read_nodal_file(path, mesh, "nodal values", "vx vy vz", [&](int ln, std::int32_t node, const std::vector<std::string>& tok) {
    NodalVector v{node, {0, 0, 0}};
    for (int c = 0; c < mesh.dim; ++c)
      if (!parse_double(tok[1 + c], v.value[c]))
        throw InputError(path, ln, std::string("column ") + std::to_string(c + 2) + " (" + "xyz"[c] +
                                       " component) is not a finite number: '" + tok[1 + c] + "'");
      else if (std::fabs(v.value[c]) > 1e12)  // the range of fem.loads.total (docs/case-format.md#ranges)
        throw InputError(path, ln, std::string("column ") + std::to_string(c + 2) + " (" + "xyz"[c] +
                                       " component) is out of range: " + tok[1 + c] + "; at most 1e12 in magnitude");
    out.push_back(v);
  });
  return out;
}

}  // namespace fdem::fem
