// The Mesh container's methods and the small helpers the mesh readers and generators share
// (fem/mesh_detail.hpp): text parsing, the shape check of a read element (through the element
// kernels' shape functions, fem/element.hpp), interval subdivision. The readers live in
// mesh_thesis.cpp (the thesis's text formats) and mesh_gmsh.cpp (Gmsh .msh 4.1 ASCII), the
// generators in mesh_generate.cpp (block, cylinder shell) and mesh_geogrid.cpp. Formats,
// conventions and error messages: docs/mesh-formats.md.
#include "fem/mesh.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "base/errors.hpp"
#include "base/files.hpp"
#include "fem/mesh_detail.hpp"

namespace fdem::fem {

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

namespace detail {

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
// shape check of a read element

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
  const double dj = element_min_nodal_detj(m.elem_type[e], X.data(), where);
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
    // and the Jacobian determinant positive at the 2x2x2 Gauss points (where the element
    // integrates), numbered like the corners: natural coordinates kHexCorner[q] / sqrt(3)
    const double g = 1 / std::sqrt(3.0);
    for (int q = 0; q < 8; ++q) {
      const double r[3] = {kHexCorner[q][0] * g, kHexCorner[q][1] * g, kHexCorner[q][2] * g};
      const double dq = element_detj_at(ElemType::kHex20, X.data(), r);
      if (!(dq > 1e-12 * std::pow(0.5 * size, 3)))
        throw InputError(file, line, "element " + std::to_string(m.elem_id[e]) + " is distorted: Jacobian determinant " +
                                         fmt(dq) + " at Gauss point " + std::to_string(q + 1) +
                                         " (must be positive; check the mid-edge nodes, hex20 as in docs/mesh-formats.md)");
    }
  }
}

// ---------------------------------------------------------------------------------------------
// generators

/// Subdivision of [a, b] into n equal parts (the last point exactly b).
void append_points(std::vector<double>& xs, double a, double b, int n) {
  for (int k = 1; k <= n; ++k) xs.push_back(k == n ? b : a + (b - a) * k / n);
}

int parts(double len, double h) { return std::max(1, static_cast<int>(std::ceil(len / h - 1e-9))); }

}  // namespace detail
}  // namespace fdem::fem
