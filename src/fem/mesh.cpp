// Mesh container, readers (thesis text formats, Gmsh .msh 4.1 ASCII) and generators (geogrid,
// block). Formats, conventions and error messages: docs/mesh-formats.md.
//
// This file deliberately does not call the element kernels (fem/element.hpp): the Jacobian
// check of the readers uses its own small shape-function derivatives (corner/mid-edge nodes of
// Hex8/Hex20, corners of Quad4), and node counts come from fem/topology.
#include "fem/mesh.hpp"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>
#include <unordered_map>

#include "fem/topology.hpp"
#include "base/files.hpp"
#include "base/errors.hpp"

namespace fdem::fem {
namespace {

// ---------------------------------------------------------------------------------------------
// small text helpers

std::string type_name(ElemType t) { return element_name(t); }

std::vector<std::string> split(const std::string& s) {
  std::vector<std::string> out;
  std::istringstream is(s);
  std::string tok;
  while (is >> tok) out.push_back(tok);
  return out;
}

/// Tokens of a thesis-format line: '#' starts a comment; commas count as blanks.
std::vector<std::string> thesis_tokens(std::string line) {
  const auto hash = line.find('#');
  if (hash != std::string::npos) line.erase(hash);
  for (char& c : line)
    if (c == ',' || c == '\r' || c == '\t') c = ' ';
  return split(line);
}

bool parse_int(const std::string& s, std::int64_t& v) {
  if (s.empty()) return false;
  errno = 0;
  char* end = nullptr;
  const long long x = std::strtoll(s.c_str(), &end, 10);
  if (errno != 0 || end != s.c_str() + s.size()) return false;
  v = x;
  return true;
}

bool parse_double(const std::string& s, double& v) {
  if (s.empty()) return false;
  errno = 0;
  char* end = nullptr;
  const double x = std::strtod(s.c_str(), &end);
  if (errno == ERANGE || end != s.c_str() + s.size() || !std::isfinite(x)) return false;
  v = x;
  return true;
}

std::string fmt(double x) {
  std::ostringstream os;
  os.precision(6);
  os << x;
  return os.str();
}

std::vector<std::string> read_lines(const std::string& path, const char* what) {
  // stat first: a directory, FIFO (would block) or device is refused before opening
  const std::string problem = input_file_problem(path);
  if (!problem.empty() && problem.rfind("cannot read", 0) != 0)
    throw InputError(path, 0, std::string(what) + " file '" + path + "' " + problem);
  std::ifstream in(path);
  if (!in) throw InputError(path, 0, std::string("cannot read ") + what + " file '" + path + "'");
  std::vector<std::string> lines;
  std::string line;
  while (std::getline(in, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    lines.push_back(line);
  }
  if (in.bad()) throw InputError(path, static_cast<int>(lines.size()), "read error");
  return lines;
}

// ---------------------------------------------------------------------------------------------
// Jacobian check (private; the element kernels live elsewhere)

// The brick corners and Hex20 edges: kHexCorner, kHex20Edge (fem/element_types.hpp).

/// Natural coordinates of node i of a brick (Hex20 mid-edge nodes: 0 along their edge).
void hex_node_natural(int i, double r[3]) {
  if (i < 8) {
    for (int c = 0; c < 3; ++c) r[c] = kHexCorner[i][c];
  } else {
    const int a = kHex20Edge[i - 8][0], b = kHex20Edge[i - 8][1];
    for (int c = 0; c < 3; ++c) r[c] = 0.5 * (kHexCorner[a][c] + kHexCorner[b][c]);
  }
}

/// Derivatives dN_i/d(xi, eta, zeta) of the brick shape functions at r (n = 8 or 20).
void hex_dshape(int n, const double r[3], double* dN /* n x 3 */) {
  for (int i = 0; i < n; ++i) {
    double p[3];
    hex_node_natural(i, p);
    if (n == 8) {
      const double f[3] = {1 + r[0] * p[0], 1 + r[1] * p[1], 1 + r[2] * p[2]};
      dN[3 * i + 0] = 0.125 * p[0] * f[1] * f[2];
      dN[3 * i + 1] = 0.125 * p[1] * f[0] * f[2];
      dN[3 * i + 2] = 0.125 * p[2] * f[0] * f[1];
    } else if (i < 8) {  // serendipity corner
      const double f[3] = {1 + r[0] * p[0], 1 + r[1] * p[1], 1 + r[2] * p[2]};
      const double s = r[0] * p[0] + r[1] * p[1] + r[2] * p[2];
      for (int a = 0; a < 3; ++a) {
        const int b = (a + 1) % 3, c = (a + 2) % 3;
        dN[3 * i + a] = 0.125 * p[a] * f[b] * f[c] * (s + r[a] * p[a] - 1);
      }
    } else {  // mid-edge node: p[k] == 0
      int k = 0;
      while (p[k] != 0) ++k;
      const int b = (k + 1) % 3, c = (k + 2) % 3;
      const double g = 1 - r[k] * r[k], fb = 1 + r[b] * p[b], fc = 1 + r[c] * p[c];
      dN[3 * i + k] = -0.5 * r[k] * fb * fc;
      dN[3 * i + b] = 0.25 * g * p[b] * fc;
      dN[3 * i + c] = 0.25 * g * fb * p[c];
    }
  }
}

/// Smallest Jacobian determinant over the nodes (and the centre) of an element, and the local
/// node where it occurs (-1: the centre). X: n x dim coordinates.
double min_nodal_detj(ElemType t, const double* X, int& where) {
  double best = std::numeric_limits<double>::infinity();
  where = -1;
  if (t == ElemType::kShell4) {
    // A flat-ish quad in space: at each corner, the corner's edge cross product projected on the
    // element normal (X2 - X0) x (X3 - X1) must be positive (convex, consistently ordered).
    auto P = [&](int i, int c) { return X[3 * i + c]; };
    double nrm[3], d1[3], d2[3];
    for (int c = 0; c < 3; ++c) { d1[c] = P(2, c) - P(0, c); d2[c] = P(3, c) - P(1, c); }
    nrm[0] = d1[1] * d2[2] - d1[2] * d2[1];
    nrm[1] = d1[2] * d2[0] - d1[0] * d2[2];
    nrm[2] = d1[0] * d2[1] - d1[1] * d2[0];
    const double ln = std::sqrt(nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2]);
    if (!(ln > 0)) return 0.0;
    for (int a = 0; a < 4; ++a) {
      double e1[3], e2[3];
      for (int c = 0; c < 3; ++c) { e1[c] = P((a + 1) % 4, c) - P(a, c); e2[c] = P((a + 3) % 4, c) - P(a, c); }
      const double cr[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
      const double v = (cr[0] * nrm[0] + cr[1] * nrm[1] + cr[2] * nrm[2]) / ln;
      if (v < best) { best = v; where = a; }
    }
    return best;
  }
  if (t == ElemType::kQuad4) {
    constexpr int q[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
    for (int s = 0; s <= 4; ++s) {  // corners, then the centre
      const int at = s < 4 ? s : -1;
      const double xi = at < 0 ? 0 : q[at][0], eta = at < 0 ? 0 : q[at][1];
      double J[2][2] = {{0, 0}, {0, 0}};
      for (int i = 0; i < 4; ++i) {
        const double dx = 0.25 * q[i][0] * (1 + eta * q[i][1]), de = 0.25 * q[i][1] * (1 + xi * q[i][0]);
        for (int c = 0; c < 2; ++c) {
          J[0][c] += dx * X[2 * i + c];
          J[1][c] += de * X[2 * i + c];
        }
      }
      const double d = J[0][0] * J[1][1] - J[0][1] * J[1][0];
      if (d < best) { best = d; where = at; }
    }
    return best;
  }
  const int n = topology_node_count(t);
  std::vector<double> dN(3 * n);
  for (int s = 0; s <= n; ++s) {  // nodes, then the centre
    const int at = s < n ? s : -1;
    double r[3] = {0, 0, 0};
    if (at >= 0) hex_node_natural(at, r);
    hex_dshape(n, r, dN.data());
    double J[3][3] = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
    for (int i = 0; i < n; ++i)
      for (int a = 0; a < 3; ++a)
        for (int c = 0; c < 3; ++c) J[a][c] += dN[3 * i + a] * X[3 * i + c];
    const double d = J[0][0] * (J[1][1] * J[2][2] - J[1][2] * J[2][1]) -
                     J[0][1] * (J[1][0] * J[2][2] - J[1][2] * J[2][0]) +
                     J[0][2] * (J[1][0] * J[2][1] - J[1][1] * J[2][0]);
    if (d < best) { best = d; where = at; }
  }
  return best;
}

/// Throws if element e (just appended) is inverted or degenerate.
void check_element_shape(const Mesh& m, std::size_t e, const std::string& file, int line) {
  const std::int32_t* n;
  const int nn = m.nodes_of(e, n);
  const int d = m.dim;
  std::vector<double> X(static_cast<std::size_t>(nn) * d);
  double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
  for (int i = 0; i < nn; ++i)
    for (int c = 0; c < d; ++c) {
      X[i * d + c] = m.coords[static_cast<std::size_t>(n[i]) * d + c];
      lo[c] = std::min(lo[c], X[i * d + c]);
      hi[c] = std::max(hi[c], X[i * d + c]);
    }
  double size = 0;
  for (int c = 0; c < d; ++c) size = std::max(size, hi[c] - lo[c]);
  for (int i = 0; i < nn; ++i)
    for (int j = i + 1; j < nn; ++j)
      if (n[i] == n[j])
        throw InputError(file, line, "element " + std::to_string(m.elem_id[e]) + " is degenerate: node id " +
                                         std::to_string(m.node_id[n[i]]) + " appears twice");
  int where;
  const double dj = min_nodal_detj(m.elem_type[e], X.data(), where);
  const double tol = 1e-12 * std::pow(0.5 * size, d);
  if (!(dj > tol)) {
    std::string at = where < 0 ? std::string("its centre")
                               : "its node " + std::to_string(where + 1) + " (id " + std::to_string(m.node_id[n[where]]) + ")";
    throw InputError(file, line, "element " + std::to_string(m.elem_id[e]) + " is " +
                                     (dj < -tol ? "inverted" : "degenerate") + ": Jacobian determinant " + fmt(dj) +
                                     " at " + at + " (must be positive; check the node order, " + type_name(m.elem_type[e]) +
                                     " as in docs/mesh-formats.md)");
  }
  if (m.elem_type[e] == ElemType::kHex20) {
    // A mid-edge node far from the middle of its edge makes the element fold over inside
    // (docs/mesh-formats.md): at most 0.5 edge lengths from the midpoint of the corners.
    for (int k = 0; k < 12; ++k) {
      const int a = kHex20Edge[k][0], b = kHex20Edge[k][1];
      double len2 = 0, off2 = 0;
      for (int c = 0; c < 3; ++c) {
        const double edge = X[b * 3 + c] - X[a * 3 + c];
        const double off = X[(8 + k) * 3 + c] - 0.5 * (X[a * 3 + c] + X[b * 3 + c]);
        len2 += edge * edge;
        off2 += off * off;
      }
      if (!(off2 <= 0.25 * len2))
        throw InputError(file, line, "element " + std::to_string(m.elem_id[e]) + ": mid-edge node " + std::to_string(9 + k) +
                                         " (id " + std::to_string(m.node_id[n[8 + k]]) + ") lies " + fmt(std::sqrt(off2)) +
                                         " from the middle of its edge (length " + fmt(std::sqrt(len2)) +
                                         "); at most 0.5 edge lengths allowed");
    }
    // and the Jacobian determinant positive at the 2x2x2 Gauss points (where the element integrates)
    const double g = 1 / std::sqrt(3.0);
    std::vector<double> dN(3 * 20);
    for (int q = 0; q < 8; ++q) {
      const double r[3] = {kHexCorner[q][0] * g, kHexCorner[q][1] * g, kHexCorner[q][2] * g};
      hex_dshape(20, r, dN.data());
      double J[3][3] = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
      for (int i = 0; i < 20; ++i)
        for (int a = 0; a < 3; ++a)
          for (int c = 0; c < 3; ++c) J[a][c] += dN[3 * i + a] * X[3 * i + c];
      const double dq = J[0][0] * (J[1][1] * J[2][2] - J[1][2] * J[2][1]) - J[0][1] * (J[1][0] * J[2][2] - J[1][2] * J[2][0]) +
                        J[0][2] * (J[1][0] * J[2][1] - J[1][1] * J[2][0]);
      if (!(dq > 1e-12 * std::pow(0.5 * size, 3)))
        throw InputError(file, line, "element " + std::to_string(m.elem_id[e]) + " is distorted: Jacobian determinant " +
                                         fmt(dq) + " at Gauss point " + std::to_string(q + 1) +
                                         " (must be positive; check the mid-edge nodes, hex20 as in docs/mesh-formats.md)");
    }
  }
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Mesh

void Mesh::add_element(std::int64_t id, ElemType t, const std::vector<std::int32_t>& nodes, int material) {
  elem_id.push_back(id);
  elem_type.push_back(t);
  elem_nodes.insert(elem_nodes.end(), nodes.begin(), nodes.end());
  elem_offset.push_back(static_cast<std::int32_t>(elem_nodes.size()));
  elem_material.push_back(material);
}

std::int32_t Mesh::node_index(std::int64_t id) const {
  if (node_lookup_.size() != node_id.size()) {
    node_lookup_.clear();
    for (std::size_t i = 0; i < node_id.size(); ++i) node_lookup_.emplace(node_id[i], static_cast<std::int32_t>(i));
  }
  auto it = node_lookup_.find(id);
  return it == node_lookup_.end() ? -1 : it->second;
}

// ---------------------------------------------------------------------------------------------
// thesis text formats

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
  if (mesh.dim != topology_dim(t))
    throw InputError(path, 0, type_name(t) + " elements need a " + std::to_string(topology_dim(t)) +
                                  "-D mesh, the nodes are " + std::to_string(mesh.dim) + "-D");
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

// ---------------------------------------------------------------------------------------------
// Gmsh .msh 4.1 ASCII

namespace {

struct GmshType { int nodes; int dim; const char* name; };

bool gmsh_type(int type, GmshType& g) {
  static const std::map<int, GmshType> table = {
      {1, {2, 1, "2-node line"}},          {2, {3, 2, "3-node triangle"}},      {3, {4, 2, "4-node quadrangle"}},
      {4, {4, 3, "4-node tetrahedron"}},   {5, {8, 3, "8-node hexahedron"}},    {6, {6, 3, "6-node prism"}},
      {7, {5, 3, "5-node pyramid"}},       {8, {3, 1, "3-node line"}},          {9, {6, 2, "6-node triangle"}},
      {10, {9, 2, "9-node quadrangle"}},   {11, {10, 3, "10-node tetrahedron"}}, {12, {27, 3, "27-node hexahedron"}},
      {13, {18, 3, "18-node prism"}},      {14, {14, 3, "14-node pyramid"}},    {15, {1, 0, "point"}},
      {16, {8, 2, "8-node quadrangle"}},   {17, {20, 3, "20-node hexahedron"}}, {18, {15, 3, "15-node prism"}},
      {19, {13, 3, "13-node pyramid"}},    {20, {9, 2, "9-node triangle"}},     {21, {10, 2, "10-node triangle"}},
      {26, {4, 1, "4-node line"}},         {27, {5, 1, "5-node line"}},         {28, {6, 1, "6-node line"}},
      {29, {20, 3, "20-node tetrahedron"}}};
  auto it = table.find(type);
  if (it == table.end()) return false;
  g = it->second;
  return true;
}

/// Line-oriented cursor over the sections of a .msh file.
class MshCursor {
 public:
  MshCursor(std::string path, std::vector<std::string> lines) : path_(std::move(path)), lines_(std::move(lines)) {}
  const std::string& path() const { return path_; }
  int line() const { return cur_; }  // 1-based line of the last record returned
  bool eof() { skip_blank(); return pos_ >= lines_.size(); }
  /// Next non-blank line (trimmed), or throws if the file ends.
  std::string next_line(const std::string& section) {
    skip_blank();
    if (pos_ >= lines_.size())
      throw InputError(path_, static_cast<int>(lines_.size()), "unexpected end of file in $" + section + " (missing $End" + section + "?)");
    cur_ = static_cast<int>(pos_ + 1);
    return trim(lines_[pos_++]);
  }
  /// Next record of a section: the tokens of the next line; a '$' line is an error.
  std::vector<std::string> record(const std::string& section, const std::string& expected) {
    const std::string l = next_line(section);
    if (!l.empty() && l[0] == '$')
      throw InputError(path_, cur_, "$" + section + " ends early ('" + l + "'): expected " + expected);
    return split(l);
  }
  void expect_end(const std::string& section) {
    const std::string l = next_line(section);
    if (l != "$End" + section) throw InputError(path_, cur_, "expected $End" + section + ", got '" + l.substr(0, 60) + "'");
  }
  std::int64_t to_int(const std::string& s, const std::string& what) const {
    std::int64_t v;
    if (!parse_int(s, v)) throw InputError(path_, cur_, what + " must be an integer, got '" + s + "'");
    return v;
  }
  double to_double(const std::string& s, const std::string& what) const {
    double v;
    if (!parse_double(s, v)) throw InputError(path_, cur_, what + " must be a finite number, got '" + s + "'");
    return v;
  }
  void need(const std::vector<std::string>& tok, std::size_t n, const std::string& what) const {
    if (tok.size() != n)
      throw InputError(path_, cur_, "expected " + std::to_string(n) + " values (" + what + "), got " + std::to_string(tok.size()));
  }
  void need_at_least(const std::vector<std::string>& tok, std::size_t n, const std::string& what) const {
    if (tok.size() < n)
      throw InputError(path_, cur_, "expected at least " + std::to_string(n) + " values (" + what + "), got " +
                                        std::to_string(tok.size()));
  }

 private:
  static std::string trim(const std::string& s) {
    std::size_t a = 0, b = s.size();
    while (a < b && std::isspace(static_cast<unsigned char>(s[a]))) ++a;
    while (b > a && std::isspace(static_cast<unsigned char>(s[b - 1]))) --b;
    return s.substr(a, b - a);
  }
  void skip_blank() {
    while (pos_ < lines_.size() && trim(lines_[pos_]).empty()) ++pos_;
  }
  std::string path_;
  std::vector<std::string> lines_;
  std::size_t pos_ = 0;
  int cur_ = 0;
};

struct MshElement { std::int64_t tag; int line; std::vector<std::int64_t> nodes; };
struct MshBlock { int dim; int entity; int type; int line; std::vector<MshElement> elems; };

}  // namespace

void read_gmsh(const std::string& path, Mesh& mesh, ElemType hex8_as) {
  MshCursor cur(path, read_lines(path, "Gmsh mesh"));
  std::map<std::pair<int, int>, std::string> phys_names;               // (dim, physical tag) -> name
  std::map<std::pair<int, int>, std::vector<int>> entity_phys;         // (dim, entity tag) -> physical tags
  std::vector<std::int64_t> node_tags;
  std::vector<double> node_xyz;
  std::unordered_map<std::int64_t, int> node_line;                     // tag -> line
  std::vector<MshBlock> blocks;
  bool have_format = false, have_nodes = false, have_elements = false;

  while (!cur.eof()) {
    const std::string head = cur.next_line("file");
    if (!have_format && head != "$MeshFormat")
      throw InputError(path, cur.line(), "not a Gmsh .msh file: the first section must be $MeshFormat, got '" +
                                             head.substr(0, 60) + "'");
    if (head.empty() || head[0] != '$' || head.compare(0, 4, "$End") == 0)
      throw InputError(path, cur.line(), "expected a section header like $Nodes, got '" + head.substr(0, 60) + "'");
    const std::string sec = head.substr(1);
    if (sec == "MeshFormat") {
      auto tok = cur.record(sec, "'version file-type data-size'");
      cur.need(tok, 3, "version file-type data-size");
      if (tok[0] != "4.1")
        throw InputError(path, cur.line(), "unsupported .msh version " + tok[0] +
                                               ": only 4.1 is read (in Gmsh: Mesh.MshFileVersion = 4.1, or gmsh -format msh41)");
      if (tok[1] != "0")
        throw InputError(path, cur.line(), "binary .msh files are not supported: save as ASCII (Mesh.Binary = 0)");
      cur.expect_end(sec);
      have_format = true;
    } else if (sec == "PhysicalNames") {
      auto tok = cur.record(sec, "the number of names");
      cur.need(tok, 1, "numPhysicalNames");
      const auto n = cur.to_int(tok[0], "numPhysicalNames");
      for (std::int64_t k = 0; k < n; ++k) {
        const std::string l = cur.next_line(sec);
        const auto t = split(l);
        const auto q1 = l.find('"'), q2 = l.rfind('"');
        if (t.size() < 3 || q1 == std::string::npos || q2 == q1)
          throw InputError(path, cur.line(), "expected 'dimension physicalTag \"name\"', got '" + l.substr(0, 60) + "'");
        const int d = static_cast<int>(cur.to_int(t[0], "the physical group's dimension"));
        const int tag = static_cast<int>(cur.to_int(t[1], "the physical tag"));
        phys_names[{d, tag}] = l.substr(q1 + 1, q2 - q1 - 1);
      }
      cur.expect_end(sec);
    } else if (sec == "Entities") {
      auto tok = cur.record(sec, "'numPoints numCurves numSurfaces numVolumes'");
      cur.need(tok, 4, "numPoints numCurves numSurfaces numVolumes");
      for (int d = 0; d < 4; ++d) {
        const auto n = cur.to_int(tok[d], "an entity count");
        for (std::int64_t k = 0; k < n; ++k) {
          const auto t = cur.record(sec, "an entity");
          const std::size_t first = d == 0 ? 4 : 7;  // tag + X Y Z, or tag + bounding box
          cur.need_at_least(t, first + 1, d == 0 ? "pointTag X Y Z numPhysicalTags ..." : "tag minX minY minZ maxX maxY maxZ numPhysicalTags ...");
          const int tag = static_cast<int>(cur.to_int(t[0], "the entity tag"));
          const auto np = cur.to_int(t[first], "numPhysicalTags");
          if (np < 0 || t.size() < first + 1 + static_cast<std::size_t>(np))
            throw InputError(path, cur.line(), "entity " + std::to_string(tag) + ": fewer physical tags than numPhysicalTags");
          auto& v = entity_phys[{d, tag}];
          for (std::int64_t p = 0; p < np; ++p) v.push_back(static_cast<int>(cur.to_int(t[first + 1 + p], "a physical tag")));
        }
      }
      cur.expect_end(sec);
    } else if (sec == "Nodes") {
      auto tok = cur.record(sec, "'numEntityBlocks numNodes minNodeTag maxNodeTag'");
      cur.need(tok, 4, "numEntityBlocks numNodes minNodeTag maxNodeTag");
      const auto nblocks = cur.to_int(tok[0], "numEntityBlocks");
      const auto nnodes = cur.to_int(tok[1], "numNodes");
      for (std::int64_t b = 0; b < nblocks; ++b) {
        auto h = cur.record(sec, "a node block header 'entityDim entityTag parametric numNodesInBlock'");
        cur.need(h, 4, "entityDim entityTag parametric numNodesInBlock");
        if (cur.to_int(h[2], "parametric") != 0)
          throw InputError(path, cur.line(), "parametric node coordinates are not supported (save without Mesh.SaveParametric)");
        const auto n = cur.to_int(h[3], "numNodesInBlock");
        const std::size_t first = node_tags.size();
        for (std::int64_t k = 0; k < n; ++k) {
          auto t = cur.record(sec, "a node tag");
          cur.need(t, 1, "nodeTag");
          const auto tag = cur.to_int(t[0], "the node tag");
          auto ins = node_line.emplace(tag, cur.line());
          if (!ins.second)
            throw InputError(path, cur.line(), "duplicate node tag " + std::to_string(tag) + " (first on line " +
                                                   std::to_string(ins.first->second) + ")");
          node_tags.push_back(tag);
        }
        for (std::int64_t k = 0; k < n; ++k) {
          auto t = cur.record(sec, "node coordinates 'x y z'");
          cur.need(t, 3, "x y z of node " + std::to_string(node_tags[first + k]));
          for (int c = 0; c < 3; ++c) node_xyz.push_back(cur.to_double(t[c], std::string("coordinate ") + "xyz"[c]));
        }
      }
      if (static_cast<std::int64_t>(node_tags.size()) != nnodes)
        throw InputError(path, cur.line(), "$Nodes announces " + std::to_string(nnodes) + " nodes but its blocks hold " +
                                               std::to_string(node_tags.size()));
      cur.expect_end(sec);
      have_nodes = true;
    } else if (sec == "Elements") {
      auto tok = cur.record(sec, "'numEntityBlocks numElements minElementTag maxElementTag'");
      cur.need(tok, 4, "numEntityBlocks numElements minElementTag maxElementTag");
      const auto nblocks = cur.to_int(tok[0], "numEntityBlocks");
      const auto nelem = cur.to_int(tok[1], "numElements");
      std::int64_t count = 0;
      std::unordered_map<std::int64_t, int> elem_line;
      for (std::int64_t b = 0; b < nblocks; ++b) {
        auto h = cur.record(sec, "an element block header 'entityDim entityTag elementType numElementsInBlock'");
        cur.need(h, 4, "entityDim entityTag elementType numElementsInBlock");
        MshBlock blk;
        blk.dim = static_cast<int>(cur.to_int(h[0], "entityDim"));
        blk.entity = static_cast<int>(cur.to_int(h[1], "entityTag"));
        blk.type = static_cast<int>(cur.to_int(h[2], "elementType"));
        blk.line = cur.line();
        GmshType g;
        if (!gmsh_type(blk.type, g)) throw InputError(path, cur.line(), "unknown Gmsh element type " + h[2]);
        const auto n = cur.to_int(h[3], "numElementsInBlock");
        for (std::int64_t k = 0; k < n; ++k) {
          auto t = cur.record(sec, "an element 'tag node ...'");
          cur.need(t, 1 + g.nodes, std::string("element tag and ") + std::to_string(g.nodes) + " node tags of a " + g.name);
          MshElement el;
          el.tag = cur.to_int(t[0], "the element tag");
          el.line = cur.line();
          auto ins = elem_line.emplace(el.tag, cur.line());
          if (!ins.second)
            throw InputError(path, cur.line(), "duplicate element tag " + std::to_string(el.tag) + " (first on line " +
                                                   std::to_string(ins.first->second) + ")");
          for (int i = 0; i < g.nodes; ++i) el.nodes.push_back(cur.to_int(t[1 + i], "a node tag"));
          blk.elems.push_back(std::move(el));
          ++count;
        }
        blocks.push_back(std::move(blk));
      }
      if (count != nelem)
        throw InputError(path, cur.line(), "$Elements announces " + std::to_string(nelem) + " elements but its blocks hold " +
                                               std::to_string(count));
      cur.expect_end(sec);
      have_elements = true;
    } else {
      // unknown or unused section ($NodeData, $Periodic, ...): skip to its end
      for (;;) {
        const std::string l = cur.next_line(sec);
        if (l == "$End" + sec) break;
      }
    }
  }
  if (!have_format) throw InputError(path, 0, "not a Gmsh .msh file: no $MeshFormat section");
  if (!have_nodes) throw InputError(path, 0, "no $Nodes section");
  if (!have_elements) throw InputError(path, 0, "no $Elements section");

  // the mesh's dimension: the highest dimension of its elements
  int top = -1;
  for (const auto& b : blocks) {
    GmshType g;
    gmsh_type(b.type, g);
    top = std::max(top, g.dim);
  }
  if (top < 2) throw InputError(path, 0, "the mesh has no 2-D or 3-D elements");
  for (const auto& b : blocks) {
    GmshType g;
    gmsh_type(b.type, g);
    if (g.dim == top && !(top == 3 && (b.type == 5 || b.type == 17)) && !(top == 2 && b.type == 3))
      throw InputError(path, b.line, std::string("element type ") + std::to_string(b.type) + " (" + g.name +
                                         ") is not supported: use 8- or 20-node hexahedra (3-D) or 4-node quadrangles (2-D)");
  }

  // nodes used by the top-dimension elements, in $Nodes order
  std::unordered_map<std::int64_t, std::size_t> tag_pos;
  for (std::size_t i = 0; i < node_tags.size(); ++i) tag_pos.emplace(node_tags[i], i);
  std::vector<char> used(node_tags.size(), 0);
  for (const auto& b : blocks)
    for (const auto& e : b.elems)
      for (auto nt : e.nodes) {
        auto it = tag_pos.find(nt);
        if (it == tag_pos.end())
          throw InputError(path, e.line, "element " + std::to_string(e.tag) + ": unknown node tag " + std::to_string(nt));
        GmshType g;
        gmsh_type(b.type, g);
        if (g.dim == top) used[it->second] = 1;
      }
  Mesh m;
  m.dim = top;
  std::unordered_map<std::int64_t, std::int32_t> index;
  double zref = 0;
  bool zset = false;
  for (std::size_t i = 0; i < node_tags.size(); ++i) {
    if (!used[i]) continue;
    index.emplace(node_tags[i], static_cast<std::int32_t>(m.node_id.size()));
    m.node_id.push_back(node_tags[i]);
    for (int c = 0; c < top; ++c) m.coords.push_back(node_xyz[3 * i + c]);
    if (top == 2) {
      const double z = node_xyz[3 * i + 2];
      if (!zset) { zref = z; zset = true; }
      else if (std::abs(z - zref) > 1e-9 * (1 + std::abs(zref)))
        throw InputError(path, node_line[node_tags[i]], "2-D (quadrangle) mesh: node " + std::to_string(node_tags[i]) +
                                                            " is not in the plane z = " + fmt(zref));
    }
  }
  auto group_names = [&](int dim, int entity) {
    std::vector<std::string> names;
    auto it = entity_phys.find({dim, entity});
    if (it == entity_phys.end()) return names;
    for (int p : it->second) {
      auto nt = phys_names.find({dim, p});
      names.push_back(nt != phys_names.end() ? nt->second : std::to_string(p));
    }
    return names;
  };
  std::map<std::string, std::set<std::int32_t>> nsets;
  std::vector<std::int32_t> conn;
  for (const auto& b : blocks) {
    GmshType g;
    gmsh_type(b.type, g);
    if (g.dim != top) continue;
    const ElemType t = b.type == 17 ? ElemType::kHex20 : b.type == 3 ? ElemType::kQuad4 : hex8_as;
    const auto names = group_names(b.dim, b.entity);
    for (const auto& e : b.elems) {
      conn.clear();
      for (auto nt : e.nodes) conn.push_back(index.at(nt));
      m.add_element(e.tag, t, conn);
      check_element_shape(m, m.n_elements() - 1, path, e.line);
      for (const auto& nm : names) {
        m.element_sets[nm].push_back(static_cast<std::int32_t>(m.n_elements() - 1));
        nsets[nm].insert(conn.begin(), conn.end());
      }
    }
  }
  // lower-dimensional groups: node sets, and face sets where the element matches element faces
  std::map<std::array<std::int32_t, 4>, std::vector<FaceRef>> face_map;
  bool face_map_built = false;
  for (const auto& b : blocks) {
    GmshType g;
    gmsh_type(b.type, g);
    if (g.dim == top) continue;
    const auto names = group_names(b.dim, b.entity);
    if (names.empty()) continue;
    const bool facelike = g.dim == top - 1 && (top == 3 ? (b.type == 3 || b.type == 10 || b.type == 16)
                                                        : (b.type == 1 || b.type == 8 || b.type == 26));
    if (facelike && !face_map_built) {
      for (std::size_t e = 0; e < m.n_elements(); ++e) {
        const std::size_t nf = element_faces(m.elem_type[e]).size();
        for (std::size_t f = 0; f < nf; ++f)
          face_map[face_key(m, e, static_cast<int>(f))].push_back({static_cast<std::int32_t>(e), static_cast<std::int32_t>(f)});
      }
      face_map_built = true;
    }
    for (const auto& e : b.elems) {
      for (const auto& nm : names) {
        auto& s = nsets[nm];
        for (auto nt : e.nodes) {
          auto it = index.find(nt);
          if (it != index.end()) s.insert(it->second);
        }
      }
      if (!facelike) continue;
      const int nc = top == 3 ? 4 : 2;
      std::array<std::int32_t, 4> key{-1, -1, -1, -1};
      bool ok = true;
      for (int k = 0; k < nc; ++k) {
        auto it = index.find(e.nodes[k]);
        if (it == index.end()) { ok = false; break; }
        key[k] = it->second;
      }
      if (!ok) continue;
      for (int a = 1; a < nc; ++a)
        for (int b = a; b > 0 && key[b - 1] > key[b]; --b) std::swap(key[b - 1], key[b]);
      auto it = face_map.find(key);
      if (it == face_map.end()) continue;
      for (const auto& nm : names) {
        auto& fs = m.face_sets[nm];
        fs.insert(fs.end(), it->second.begin(), it->second.end());
      }
    }
  }
  for (auto& kv : nsets) m.node_sets[kv.first].assign(kv.second.begin(), kv.second.end());
  if (m.n_elements() == 0) throw InputError(path, 0, "the mesh has no elements");
  mesh = std::move(m);
}

// ---------------------------------------------------------------------------------------------
// generators

namespace {

/// Subdivision of [a, b] into n equal parts (the last point exactly b).
void append_points(std::vector<double>& xs, double a, double b, int n) {
  for (int k = 1; k <= n; ++k) xs.push_back(k == n ? b : a + (b - a) * k / n);
}

int parts(double len, double h) { return std::max(1, static_cast<int>(std::ceil(len / h - 1e-9))); }

/// Face sets of the six sides of a structured brick index space, and node sets xmin..zmax.
const char* const kSideNames[6] = {"xmin", "xmax", "ymin", "ymax", "zmin", "zmax"};

}  // namespace

GeogridInfo geogrid_layout(const GeogridSpec& s) {
  auto bad = [](const std::string& what) { return InputError("geogrid", 0, what); };
  if (!(s.length > 0) || !(s.width > 0)) throw bad("length and width must be positive");
  if (!(s.rib_width > 0)) throw bad("rib_width must be positive");
  if (!(s.thickness > 0)) throw bad("thickness must be positive");
  if (s.longitudinal_ribs < 2 || s.transverse_ribs < 2) throw bad("at least 2 longitudinal and 2 transverse ribs are needed");
  if (s.junction_thickness != 0 && !(s.junction_thickness >= s.thickness))
    throw bad("junction_thickness must be 0 (same as the ribs) or at least the rib thickness");
  if (!(s.clamp_length >= 0) || !(s.clamp_length < s.length)) throw bad("clamp_length must be in [0, length)");
  if (s.elements_per_rib_width < 1 || s.elements_through_thickness < 1)
    throw bad("elements_per_rib_width and elements_through_thickness must be at least 1");
  if (!(s.max_element_length >= 0)) throw bad("max_element_length must be >= 0");
  if (!(s.side_overhang >= 0) || !(2 * s.side_overhang < s.width)) throw bad("side_overhang must be in [0, width / 2)");
  GeogridInfo g;
  const double w = s.rib_width, c = s.clamp_length;
  const int nl = s.longitudinal_ribs, nt = s.transverse_ribs;
  const double o = s.side_overhang;
  g.aperture_y = (s.width - 2 * o - nl * w) / (nl - 1);
  if (s.clamp_gap < 0) {
    if (c > 0) {
      g.aperture_x = (s.length - c - nt * w) / nt;
      g.clamp_gap = g.aperture_x;
    } else {
      g.aperture_x = (s.length - nt * w) / (nt - 1);
      g.clamp_gap = 0;
    }
  } else {
    g.clamp_gap = s.clamp_gap;
    g.aperture_x = (s.length - c - s.clamp_gap - nt * w) / (nt - 1);
  }
  if (!(g.aperture_x > 1e-9 * s.length))
    throw bad("no room for " + std::to_string(nt) + " transverse ribs of width " + fmt(w) + " in length " + fmt(s.length) +
              " (clamp " + fmt(c) + ", gap " + fmt(g.clamp_gap) + "): aperture along x would be " + fmt(g.aperture_x));
  if (!(g.aperture_y > 1e-9 * s.width))
    throw bad("no room for " + std::to_string(nl) + " longitudinal ribs of width " + fmt(w) + " in width " + fmt(s.width) +
              (o > 0 ? " (side overhangs " + fmt(o) + ")" : std::string()) + ": aperture along y would be " +
              fmt(g.aperture_y));
  g.pitch_x = g.aperture_x + w;
  g.pitch_y = g.aperture_y + w;
  g.junction_thickness = s.junction_thickness > 0 ? s.junction_thickness : s.thickness;
  for (int k = 0; k < nt; ++k) g.transverse_x.push_back(s.origin[0] + c + g.clamp_gap + k * g.pitch_x);
  for (int m = 0; m < nl; ++m) g.longitudinal_y.push_back(s.origin[1] + o + m * g.pitch_y);
  g.plan_area = c * s.width + nl * w * g.clamp_gap + nt * w * s.width + nl * w * (nt - 1) * g.aperture_x;
  g.volume = g.plan_area * s.thickness + nl * nt * w * w * (g.junction_thickness - s.thickness);
  return g;
}

Mesh make_geogrid(const GeogridSpec& s) {
  GeogridInfo info;
  return make_geogrid(s, info);
}

Mesh make_geogrid(const GeogridSpec& s, GeogridInfo& info) {
  info = geogrid_layout(s);
  const double w = s.rib_width;
  const double h = s.max_element_length > 0 ? s.max_element_length : w;
  const int epr = s.elements_per_rib_width, ett = s.elements_through_thickness;
  const double x0 = s.origin[0], y0 = s.origin[1], z0 = s.origin[2];
  // x intervals: kind 0 clamp, 1 rib-free stretch (gap/aperture), 2 transverse rib
  std::vector<double> xs{x0};
  std::vector<int> xkind;
  auto add_x = [&](double a, double b, int n, int kind) {
    append_points(xs, a, b, n);
    xkind.insert(xkind.end(), n, kind);
  };
  if (s.clamp_length > 0) add_x(x0, x0 + s.clamp_length, parts(s.clamp_length, h), 0);
  if (info.clamp_gap > 0) add_x(xs.back(), info.transverse_x[0], parts(info.clamp_gap, h), 1);
  for (int k = 0; k < s.transverse_ribs; ++k) {
    const double a = info.transverse_x[k];
    const double b = k + 1 == s.transverse_ribs ? x0 + s.length : a + w;
    xs.back() = a;  // exact rib position (equal to the previous end up to round-off)
    add_x(a, b, epr, 2);
    if (k + 1 < s.transverse_ribs) add_x(b, info.transverse_x[k + 1], parts(info.aperture_x, h), 1);
  }
  // y intervals: kind 0 aperture (or side overhang), 1 longitudinal rib
  std::vector<double> ys{y0};
  std::vector<int> ykind;
  const double o = s.side_overhang;
  if (o > 0) {
    const int n = parts(o, h);
    append_points(ys, y0, info.longitudinal_y[0], n);
    ykind.insert(ykind.end(), n, 0);
  }
  for (int m = 0; m < s.longitudinal_ribs; ++m) {
    const double a = info.longitudinal_y[m];
    const double b = m + 1 == s.longitudinal_ribs ? (o > 0 ? a + w : y0 + s.width) : a + w;
    ys.back() = a;
    append_points(ys, a, b, epr);
    ykind.insert(ykind.end(), epr, 1);
    if (m + 1 < s.longitudinal_ribs) {
      const int n = parts(info.aperture_y, h);
      append_points(ys, b, info.longitudinal_y[m + 1], n);
      ykind.insert(ykind.end(), n, 0);
    }
  }
  if (o > 0) {
    const int n = parts(o, h);
    append_points(ys, ys.back(), y0 + s.width, n);
    ykind.insert(ykind.end(), n, 0);
  }
  // z levels: ribs [rz0, rz0 + t] in ett layers; thicker junctions get one more layer each side
  const double extra = 0.5 * (info.junction_thickness - s.thickness);
  const bool thick = extra > 1e-12 * s.thickness;
  std::vector<double> zs;
  if (thick) zs.push_back(z0);
  const double rz0 = z0 + (thick ? extra : 0);
  zs.push_back(rz0);
  append_points(zs, rz0, rz0 + s.thickness, ett);
  if (thick) zs.push_back(z0 + info.junction_thickness);
  const int rib_k0 = thick ? 1 : 0, rib_k1 = rib_k0 + ett;  // rib layers [rib_k0, rib_k1)
  const int nzl = static_cast<int>(zs.size()) - 1;

  enum Kind { kNone = -1, kClamp = 0, kLong = 1, kTrans = 2, kJunc = 3 };
  const int NX = static_cast<int>(xkind.size()), NY = static_cast<int>(ykind.size());
  std::vector<int> cell(static_cast<std::size_t>(NX) * NY, kNone);
  for (int i = 0; i < NX; ++i)
    for (int j = 0; j < NY; ++j) {
      int k = kNone;
      if (xkind[i] == 0) k = kClamp;
      else if (xkind[i] == 2) k = ykind[j] == 1 ? kJunc : kTrans;
      else if (ykind[j] == 1) k = kLong;
      cell[static_cast<std::size_t>(i) * NY + j] = k;
    }
  auto layers = [&](int kind, int& k0, int& k1) {
    if (kind == kJunc) { k0 = 0; k1 = nzl; }
    else { k0 = rib_k0; k1 = rib_k1; }
  };
  // nodes: every grid point touched by an element, numbered x-major
  const std::size_t NPX = NX + 1, NPY = NY + 1, NPZ = nzl + 1;
  std::vector<std::int32_t> nid(NPX * NPY * NPZ, -1);
  auto pid = [&](int i, int j, int k) { return (static_cast<std::size_t>(i) * NPY + j) * NPZ + k; };
  for (int i = 0; i < NX; ++i)
    for (int j = 0; j < NY; ++j) {
      const int kind = cell[static_cast<std::size_t>(i) * NY + j];
      if (kind == kNone) continue;
      int k0, k1;
      layers(kind, k0, k1);
      for (int di = 0; di < 2; ++di)
        for (int dj = 0; dj < 2; ++dj)
          for (int k = k0; k <= k1; ++k) nid[pid(i + di, j + dj, k)] = 0;
    }
  Mesh m;
  m.dim = 3;
  for (int i = 0; i < static_cast<int>(NPX); ++i)
    for (int j = 0; j < static_cast<int>(NPY); ++j)
      for (int k = 0; k < static_cast<int>(NPZ); ++k) {
        auto& n = nid[pid(i, j, k)];
        if (n < 0) continue;
        n = static_cast<std::int32_t>(m.node_id.size());
        m.node_id.push_back(n + 1);
        m.coords.insert(m.coords.end(), {xs[i], ys[j], zs[k]});
      }
  static const char* const kSetName[4] = {"clamp", "longitudinal", "transverse", "junction"};
  for (auto nm : kSetName) m.element_sets[nm];
  std::set<std::int32_t> clamp_nodes;
  std::vector<int> ekind;
  for (int i = 0; i < NX; ++i)
    for (int j = 0; j < NY; ++j) {
      const int kind = cell[static_cast<std::size_t>(i) * NY + j];
      if (kind == kNone) continue;
      int k0, k1;
      layers(kind, k0, k1);
      for (int k = k0; k < k1; ++k) {
        std::vector<std::int32_t> c = {nid[pid(i, j, k)],         nid[pid(i + 1, j, k)],     nid[pid(i + 1, j + 1, k)],
                                       nid[pid(i, j + 1, k)],     nid[pid(i, j, k + 1)],     nid[pid(i + 1, j, k + 1)],
                                       nid[pid(i + 1, j + 1, k + 1)], nid[pid(i, j + 1, k + 1)]};
        m.element_sets[kSetName[kind]].push_back(static_cast<std::int32_t>(m.n_elements()));
        m.add_element(static_cast<std::int64_t>(m.n_elements()) + 1, ElemType::kHex8, c);
        ekind.push_back(kind);
        if (i == 0 && kind != kTrans)  // front face x = origin.x of the clamp / the longitudinal ribs
          for (int q : {0, 3, 4, 7}) clamp_nodes.insert(c[q]);
      }
    }
  m.node_sets["clamp"].assign(clamp_nodes.begin(), clamp_nodes.end());
  // the two sides y = origin.y and y = origin.y + width (with side overhangs: the cut ends of
  // the transverse ribs and the clamp, where a symmetry plane holds u_y = 0)
  for (int side = 0; side < 2; ++side) {
    const std::size_t j = side == 0 ? 0 : NPY - 1;
    auto& set = m.node_sets[side == 0 ? "ymin" : "ymax"];
    for (std::size_t i = 0; i < NPX; ++i)
      for (std::size_t k = 0; k < NPZ; ++k)
        if (nid[pid(static_cast<int>(i), static_cast<int>(j), static_cast<int>(k))] >= 0)
          set.push_back(nid[pid(static_cast<int>(i), static_cast<int>(j), static_cast<int>(k))]);
    std::sort(set.begin(), set.end());
  }
  auto& top = m.face_sets["top"];
  auto& bottom = m.face_sets["bottom"];
  auto& front = m.face_sets["transverse_front"];
  for (const auto& f : boundary_faces(m)) {
    const auto n = face_area_normal(m, f[0], f[1]);
    const double a = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (n[2] > 0.9 * a) top.push_back(f);
    else if (n[2] < -0.9 * a) bottom.push_back(f);
    else if (n[0] < -0.9 * a && (ekind[f[0]] == kTrans || ekind[f[0]] == kJunc)) {
      front.push_back(f);
      // ... and per rib, numbered from the front (1-based): the face's x is the rib's front x.
      const std::vector<int>& lf = element_faces(m.elem_type[f[0]])[f[1]];
      double x = 0;
      for (int q : lf) x += m.coords[3 * static_cast<std::size_t>(m.elem_nodes[m.elem_offset[f[0]] + q])];
      x /= static_cast<double>(lf.size());
      for (std::size_t k = 0; k < info.transverse_x.size(); ++k)
        if (std::abs(x - info.transverse_x[k]) < 0.25 * s.rib_width) {
          m.face_sets["transverse_front_" + std::to_string(k + 1)].push_back(f);
          break;
        }
    }
  }
  return m;
}

Mesh make_cylinder_shell(const std::array<double, 3>& base, double radius, double length, int n_around, int n_along) {
  if (!(radius > 0) || !(length > 0) || n_around < 3 || n_along < 1)
    throw InputError("cylinder", 0, "radius and length must be positive, n_around >= 3, n_along >= 1");
  Mesh m;
  m.dim = 3;
  for (int j = 0; j <= n_along; ++j)
    for (int i = 0; i < n_around; ++i) {
      const double a = 2 * M_PI * i / n_around;
      m.node_id.push_back(static_cast<std::int64_t>(m.node_id.size()) + 1);
      m.coords.insert(m.coords.end(), {base[0] + radius * std::cos(a), base[1] + radius * std::sin(a),
                                       base[2] + length * j / n_along});
      if (j == 0) m.node_sets["start"].push_back(j * n_around + i);
      if (j == n_along) m.node_sets["end"].push_back(j * n_around + i);
    }
  for (int j = 0; j < n_along; ++j)
    for (int i = 0; i < n_around; ++i) {
      const std::int32_t i1 = (i + 1) % n_around;
      // Counter-clockwise seen from outside: the element normal points away from the axis.
      m.add_element(j * n_around + i + 1, ElemType::kShell4,
                    {j * n_around + i, j * n_around + i1, (j + 1) * n_around + i1, (j + 1) * n_around + i}, 0);
    }
  for (std::size_t e = 0; e < m.n_elements(); ++e) m.element_sets["all"].push_back(static_cast<std::int32_t>(e));
  return m;
}

Mesh make_block(const std::array<double, 3>& lo, const std::array<double, 3>& hi, int nx, int ny, int nz,
                const std::array<double, 3>* void_lo, const std::array<double, 3>* void_hi) {
  if (nx < 1 || ny < 1 || nz < 1) throw InputError("block", 0, "nx, ny, nz must be at least 1");
  for (int c = 0; c < 3; ++c)
    if (!(hi[c] > lo[c])) throw InputError("block", 0, std::string("hi.") + "xyz"[c] + " must be greater than lo." + "xyz"[c]);
  if ((void_lo == nullptr) != (void_hi == nullptr)) throw InputError("block", 0, "a void box needs both corners");
  const int n[3] = {nx, ny, nz};
  std::vector<double> g[3];
  for (int c = 0; c < 3; ++c) {
    g[c].push_back(lo[c]);
    append_points(g[c], lo[c], hi[c], n[c]);
  }
  Mesh m;
  m.dim = 3;
  auto nidx = [&](int i, int j, int k) { return static_cast<std::int32_t>(i + (nx + 1) * (j + (ny + 1) * k)); };
  for (int k = 0; k <= nz; ++k)
    for (int j = 0; j <= ny; ++j)
      for (int i = 0; i <= nx; ++i) {
        m.node_id.push_back(static_cast<std::int64_t>(m.node_id.size()) + 1);
        m.coords.insert(m.coords.end(), {g[0][i], g[1][j], g[2][k]});
        const int ijk[3] = {i, j, k};
        for (int c = 0; c < 3; ++c) {
          if (ijk[c] == 0) m.node_sets[kSideNames[2 * c]].push_back(nidx(i, j, k));
          if (ijk[c] == n[c]) m.node_sets[kSideNames[2 * c + 1]].push_back(nidx(i, j, k));
        }
      }
  if (void_lo) { m.element_sets["void"]; m.element_sets["solid"]; }
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        const auto e = static_cast<std::int32_t>(m.n_elements());
        m.add_element(e + 1, ElemType::kHex8,
                      {nidx(i, j, k), nidx(i + 1, j, k), nidx(i + 1, j + 1, k), nidx(i, j + 1, k), nidx(i, j, k + 1),
                       nidx(i + 1, j, k + 1), nidx(i + 1, j + 1, k + 1), nidx(i, j + 1, k + 1)});
        const int ijk[3] = {i, j, k};
        for (int c = 0; c < 3; ++c) {
          if (ijk[c] == 0) m.face_sets[kSideNames[2 * c]].push_back({e, 2 * c});
          if (ijk[c] == n[c] - 1) m.face_sets[kSideNames[2 * c + 1]].push_back({e, 2 * c + 1});
        }
        if (void_lo) {
          const double ctr[3] = {0.5 * (g[0][i] + g[0][i + 1]), 0.5 * (g[1][j] + g[1][j + 1]), 0.5 * (g[2][k] + g[2][k + 1])};
          bool in = true;
          for (int c = 0; c < 3; ++c) in = in && ctr[c] >= (*void_lo)[c] && ctr[c] <= (*void_hi)[c];
          m.element_sets[in ? "void" : "solid"].push_back(e);
        }
      }
  return m;
}

}  // namespace fdem::fem
