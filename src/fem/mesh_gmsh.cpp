// Gmsh .msh 4.1 ASCII (docs/mesh-formats.md): the sections are read one by one into MshData
// (read_sections: one reader per section), then the mesh is built from it: its dimension and
// element types, the nodes its elements use, the elements with their physical groups as element
// sets, and the lower-dimensional groups as node sets and face sets.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <set>
#include <unordered_map>
#include <utility>

#include "base/errors.hpp"
#include "fem/mesh.hpp"
#include "fem/mesh_detail.hpp"
#include "fem/topology.hpp"

namespace fdem::fem {
namespace {

using detail::check_element_shape;
using detail::fmt;
using detail::parse_double;
using detail::parse_int;
using detail::read_lines;
using detail::split;

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


/// What the sections of a file hold.
struct MshData {
  std::map<std::pair<int, int>, std::string> phys_names;        // (dim, physical tag) -> name
  std::map<std::pair<int, int>, std::vector<int>> entity_phys;  // (dim, entity tag) -> physical tags
  std::vector<std::int64_t> node_tags;
  std::vector<double> node_xyz;
  std::unordered_map<std::int64_t, int> node_line;              // tag -> line
  std::vector<MshBlock> blocks;
};

void read_mesh_format(MshCursor& cur, const std::string& sec) {
  auto tok = cur.record(sec, "'version file-type data-size'");
  cur.need(tok, 3, "version file-type data-size");
  if (tok[0] != "4.1")
    throw InputError(cur.path(), cur.line(), "unsupported .msh version " + tok[0] +
                                                 ": only 4.1 is read (in Gmsh: Mesh.MshFileVersion = 4.1, or gmsh -format msh41)");
  if (tok[1] != "0")
    throw InputError(cur.path(), cur.line(), "binary .msh files are not supported: save as ASCII (Mesh.Binary = 0)");
  cur.expect_end(sec);
}

void read_physical_names(MshCursor& cur, const std::string& sec, MshData& d) {
  auto tok = cur.record(sec, "the number of names");
  cur.need(tok, 1, "numPhysicalNames");
  const auto n = cur.to_int(tok[0], "numPhysicalNames");
  for (std::int64_t k = 0; k < n; ++k) {
    const std::string l = cur.next_line(sec);
    const auto t = split(l);
    const auto q1 = l.find('"'), q2 = l.rfind('"');
    if (t.size() < 3 || q1 == std::string::npos || q2 == q1)
      throw InputError(cur.path(), cur.line(), "expected 'dimension physicalTag \"name\"', got '" + l.substr(0, 60) + "'");
    const int dim = static_cast<int>(cur.to_int(t[0], "the physical group's dimension"));
    const int tag = static_cast<int>(cur.to_int(t[1], "the physical tag"));
    d.phys_names[{dim, tag}] = l.substr(q1 + 1, q2 - q1 - 1);
  }
  cur.expect_end(sec);
}

void read_entities(MshCursor& cur, const std::string& sec, MshData& d) {
  auto tok = cur.record(sec, "'numPoints numCurves numSurfaces numVolumes'");
  cur.need(tok, 4, "numPoints numCurves numSurfaces numVolumes");
  for (int dim = 0; dim < 4; ++dim) {
    const auto n = cur.to_int(tok[dim], "an entity count");
    for (std::int64_t k = 0; k < n; ++k) {
      const auto t = cur.record(sec, "an entity");
      const std::size_t first = dim == 0 ? 4 : 7;  // tag + X Y Z, or tag + bounding box
      cur.need_at_least(t, first + 1, dim == 0 ? "pointTag X Y Z numPhysicalTags ..." : "tag minX minY minZ maxX maxY maxZ numPhysicalTags ...");
      const int tag = static_cast<int>(cur.to_int(t[0], "the entity tag"));
      const auto np = cur.to_int(t[first], "numPhysicalTags");
      if (np < 0 || t.size() < first + 1 + static_cast<std::size_t>(np))
        throw InputError(cur.path(), cur.line(), "entity " + std::to_string(tag) + ": fewer physical tags than numPhysicalTags");
      auto& v = d.entity_phys[{dim, tag}];
      for (std::int64_t p = 0; p < np; ++p) v.push_back(static_cast<int>(cur.to_int(t[first + 1 + p], "a physical tag")));
    }
  }
  cur.expect_end(sec);
}

/// One block of $Nodes: its header, the tags, then the coordinates.
void read_node_block(MshCursor& cur, const std::string& sec, MshData& d) {
  auto h = cur.record(sec, "a node block header 'entityDim entityTag parametric numNodesInBlock'");
  cur.need(h, 4, "entityDim entityTag parametric numNodesInBlock");
  if (cur.to_int(h[2], "parametric") != 0)
    throw InputError(cur.path(), cur.line(), "parametric node coordinates are not supported (save without Mesh.SaveParametric)");
  const auto n = cur.to_int(h[3], "numNodesInBlock");
  const std::size_t first = d.node_tags.size();
  for (std::int64_t k = 0; k < n; ++k) {
    auto t = cur.record(sec, "a node tag");
    cur.need(t, 1, "nodeTag");
    const auto tag = cur.to_int(t[0], "the node tag");
    auto ins = d.node_line.emplace(tag, cur.line());
    if (!ins.second)
      throw InputError(cur.path(), cur.line(), "duplicate node tag " + std::to_string(tag) + " (first on line " +
                                                   std::to_string(ins.first->second) + ")");
    d.node_tags.push_back(tag);
  }
  for (std::int64_t k = 0; k < n; ++k) {
    auto t = cur.record(sec, "node coordinates 'x y z'");
    cur.need(t, 3, "x y z of node " + std::to_string(d.node_tags[first + k]));
    for (int c = 0; c < 3; ++c) d.node_xyz.push_back(cur.to_double(t[c], std::string("coordinate ") + "xyz"[c]));
  }
}

void read_nodes(MshCursor& cur, const std::string& sec, MshData& d) {
  auto tok = cur.record(sec, "'numEntityBlocks numNodes minNodeTag maxNodeTag'");
  cur.need(tok, 4, "numEntityBlocks numNodes minNodeTag maxNodeTag");
  const auto nblocks = cur.to_int(tok[0], "numEntityBlocks");
  const auto nnodes = cur.to_int(tok[1], "numNodes");
  for (std::int64_t b = 0; b < nblocks; ++b) read_node_block(cur, sec, d);
  if (static_cast<std::int64_t>(d.node_tags.size()) != nnodes)
    throw InputError(cur.path(), cur.line(), "$Nodes announces " + std::to_string(nnodes) + " nodes but its blocks hold " +
                                                 std::to_string(d.node_tags.size()));
  cur.expect_end(sec);
}

/// One block of $Elements; elem_line: tag -> line over the whole section (duplicates).
MshBlock read_element_block(MshCursor& cur, const std::string& sec, std::unordered_map<std::int64_t, int>& elem_line) {
  auto h = cur.record(sec, "an element block header 'entityDim entityTag elementType numElementsInBlock'");
  cur.need(h, 4, "entityDim entityTag elementType numElementsInBlock");
  MshBlock blk;
  blk.dim = static_cast<int>(cur.to_int(h[0], "entityDim"));
  blk.entity = static_cast<int>(cur.to_int(h[1], "entityTag"));
  blk.type = static_cast<int>(cur.to_int(h[2], "elementType"));
  blk.line = cur.line();
  GmshType g;
  if (!gmsh_type(blk.type, g)) throw InputError(cur.path(), cur.line(), "unknown Gmsh element type " + h[2]);
  const auto n = cur.to_int(h[3], "numElementsInBlock");
  for (std::int64_t k = 0; k < n; ++k) {
    auto t = cur.record(sec, "an element 'tag node ...'");
    cur.need(t, 1 + g.nodes, std::string("element tag and ") + std::to_string(g.nodes) + " node tags of a " + g.name);
    MshElement el;
    el.tag = cur.to_int(t[0], "the element tag");
    el.line = cur.line();
    auto ins = elem_line.emplace(el.tag, cur.line());
    if (!ins.second)
      throw InputError(cur.path(), cur.line(), "duplicate element tag " + std::to_string(el.tag) + " (first on line " +
                                                   std::to_string(ins.first->second) + ")");
    for (int i = 0; i < g.nodes; ++i) el.nodes.push_back(cur.to_int(t[1 + i], "a node tag"));
    blk.elems.push_back(std::move(el));
  }
  return blk;
}

void read_elements(MshCursor& cur, const std::string& sec, MshData& d) {
  auto tok = cur.record(sec, "'numEntityBlocks numElements minElementTag maxElementTag'");
  cur.need(tok, 4, "numEntityBlocks numElements minElementTag maxElementTag");
  const auto nblocks = cur.to_int(tok[0], "numEntityBlocks");
  const auto nelem = cur.to_int(tok[1], "numElements");
  std::int64_t count = 0;
  std::unordered_map<std::int64_t, int> elem_line;
  for (std::int64_t b = 0; b < nblocks; ++b) {
    d.blocks.push_back(read_element_block(cur, sec, elem_line));
    count += static_cast<std::int64_t>(d.blocks.back().elems.size());
  }
  if (count != nelem)
    throw InputError(cur.path(), cur.line(), "$Elements announces " + std::to_string(nelem) + " elements but its blocks hold " +
                                                 std::to_string(count));
  cur.expect_end(sec);
}

/// An unknown or unused section ($NodeData, $Periodic, ...): skip to its end.
void skip_section(MshCursor& cur, const std::string& sec) {
  for (;;) {
    const std::string l = cur.next_line(sec);
    if (l == "$End" + sec) break;
  }
}

/// All sections of the file; throws if $MeshFormat is not first or a needed section is missing.
MshData read_sections(const std::string& path) {
  MshCursor cur(path, read_lines(path, "Gmsh mesh"));
  MshData d;
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
      read_mesh_format(cur, sec);
      have_format = true;
    } else if (sec == "PhysicalNames") {
      read_physical_names(cur, sec, d);
    } else if (sec == "Entities") {
      read_entities(cur, sec, d);
    } else if (sec == "Nodes") {
      read_nodes(cur, sec, d);
      have_nodes = true;
    } else if (sec == "Elements") {
      read_elements(cur, sec, d);
      have_elements = true;
    } else {
      skip_section(cur, sec);
    }
  }
  if (!have_format) throw InputError(path, 0, "not a Gmsh .msh file: no $MeshFormat section");
  if (!have_nodes) throw InputError(path, 0, "no $Nodes section");
  if (!have_elements) throw InputError(path, 0, "no $Elements section");
  return d;
}

int block_dim(const MshBlock& b) {
  GmshType g;
  gmsh_type(b.type, g);
  return g.dim;
}

/// The mesh's dimension: the highest dimension of its elements, whose types must be supported.
int mesh_dimension(const std::string& path, const std::vector<MshBlock>& blocks) {
  int top = -1;
  for (const auto& b : blocks) top = std::max(top, block_dim(b));
  if (top < 2) throw InputError(path, 0, "the mesh has no 2-D or 3-D elements");
  for (const auto& b : blocks) {
    GmshType g;
    gmsh_type(b.type, g);
    if (g.dim == top && !(top == 3 && (b.type == 5 || b.type == 17)) && !(top == 2 && b.type == 3))
      throw InputError(path, b.line, std::string("element type ") + std::to_string(b.type) + " (" + g.name +
                                         ") is not supported: use 8- or 20-node hexahedra (3-D) or 4-node quadrangles (2-D)");
  }
  return top;
}

/// The nodes of the top-dimension elements into m, in $Nodes order; index: tag -> node index.
/// Every element's node tags must exist; a 2-D mesh must lie in a plane z = const.
void add_used_nodes(const std::string& path, MshData& d, int top, Mesh& m,
                    std::unordered_map<std::int64_t, std::int32_t>& index) {
  std::unordered_map<std::int64_t, std::size_t> tag_pos;
  for (std::size_t i = 0; i < d.node_tags.size(); ++i) tag_pos.emplace(d.node_tags[i], i);
  std::vector<char> used(d.node_tags.size(), 0);
  for (const auto& b : d.blocks)
    for (const auto& e : b.elems)
      for (auto nt : e.nodes) {
        auto it = tag_pos.find(nt);
        if (it == tag_pos.end())
          throw InputError(path, e.line, "element " + std::to_string(e.tag) + ": unknown node tag " + std::to_string(nt));
        if (block_dim(b) == top) used[it->second] = 1;
      }
  double zref = 0;
  bool zset = false;
  for (std::size_t i = 0; i < d.node_tags.size(); ++i) {
    if (!used[i]) continue;
    index.emplace(d.node_tags[i], static_cast<std::int32_t>(m.node_id.size()));
    m.node_id.push_back(d.node_tags[i]);
    for (int c = 0; c < top; ++c) m.coords.push_back(d.node_xyz[3 * i + c]);
    if (top == 2) {
      const double z = d.node_xyz[3 * i + 2];
      if (!zset) { zref = z; zset = true; }
      else if (std::abs(z - zref) > 1e-9 * (1 + std::abs(zref)))
        throw InputError(path, d.node_line[d.node_tags[i]], "2-D (quadrangle) mesh: node " + std::to_string(d.node_tags[i]) +
                                                              " is not in the plane z = " + fmt(zref));
    }
  }
}

/// The names of an entity's physical groups (the tag where a group has no name).
std::vector<std::string> group_names(const MshData& d, int dim, int entity) {
  std::vector<std::string> names;
  auto it = d.entity_phys.find({dim, entity});
  if (it == d.entity_phys.end()) return names;
  for (int p : it->second) {
    auto nt = d.phys_names.find({dim, p});
    names.push_back(nt != d.phys_names.end() ? nt->second : std::to_string(p));
  }
  return names;
}

using NodeIndex = std::unordered_map<std::int64_t, std::int32_t>;
using NodeSets = std::map<std::string, std::set<std::int32_t>>;

/// The top-dimension elements, checked, with their groups as element sets (and node sets).
void add_elements(const std::string& path, const MshData& d, int top, ElemType hex8_as, const NodeIndex& index,
                  Mesh& m, NodeSets& nsets) {
  std::vector<std::int32_t> conn;
  for (const auto& b : d.blocks) {
    if (block_dim(b) != top) continue;
    const ElemType t = b.type == 17 ? ElemType::kHex20 : b.type == 3 ? ElemType::kQuad4 : hex8_as;
    const auto names = group_names(d, b.dim, b.entity);
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
}

using FaceMap = std::map<std::array<std::int32_t, 4>, std::vector<FaceRef>>;

/// Every element face of m by its sorted corner indices (fem/topology's face_key).
FaceMap make_face_map(const Mesh& m) {
  FaceMap face_map;
  for (std::size_t e = 0; e < m.n_elements(); ++e) {
    const std::size_t nf = element_faces(m.elem_type[e]).size();
    for (std::size_t f = 0; f < nf; ++f)
      face_map[face_key(m, e, static_cast<int>(f))].push_back({static_cast<std::int32_t>(e), static_cast<std::int32_t>(f)});
  }
  return face_map;
}

/// The element faces a lower-dimensional element covers (by its nc corners), or null.
const std::vector<FaceRef>* covered_faces(const MshElement& e, int nc, const NodeIndex& index, const FaceMap& face_map) {
  std::array<std::int32_t, 4> key{-1, -1, -1, -1};
  for (int k = 0; k < nc; ++k) {
    auto it = index.find(e.nodes[k]);
    if (it == index.end()) return nullptr;
    key[k] = it->second;
  }
  for (int a = 1; a < nc; ++a)
    for (int b = a; b > 0 && key[b - 1] > key[b]; --b) std::swap(key[b - 1], key[b]);
  auto it = face_map.find(key);
  return it == face_map.end() ? nullptr : &it->second;
}

/// Lower-dimensional groups: node sets, and face sets where the element matches element faces.
void add_lower_groups(const MshData& d, int top, const NodeIndex& index, Mesh& m, NodeSets& nsets) {
  FaceMap face_map;
  bool face_map_built = false;
  for (const auto& b : d.blocks) {
    const int bdim = block_dim(b);
    if (bdim == top) continue;
    const auto names = group_names(d, b.dim, b.entity);
    if (names.empty()) continue;
    const bool facelike = bdim == top - 1 && (top == 3 ? (b.type == 3 || b.type == 10 || b.type == 16)
                                                       : (b.type == 1 || b.type == 8 || b.type == 26));
    if (facelike && !face_map_built) {
      face_map = make_face_map(m);
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
      const std::vector<FaceRef>* faces = covered_faces(e, top == 3 ? 4 : 2, index, face_map);
      if (!faces) continue;
      for (const auto& nm : names) {
        auto& fs = m.face_sets[nm];
        fs.insert(fs.end(), faces->begin(), faces->end());
      }
    }
  }
}

}  // namespace

void read_gmsh(const std::string& path, Mesh& mesh, ElemType hex8_as) {
  MshData d = read_sections(path);
  const int top = mesh_dimension(path, d.blocks);
  Mesh m;
  m.dim = top;
  NodeIndex index;
  add_used_nodes(path, d, top, m, index);
  NodeSets nsets;
  add_elements(path, d, top, hex8_as, index, m, nsets);
  add_lower_groups(d, top, index, m, nsets);
  for (auto& kv : nsets) m.node_sets[kv.first].assign(kv.second.begin(), kv.second.end());
  if (m.n_elements() == 0) throw InputError(path, 0, "the mesh has no elements");
  mesh = std::move(m);
}

}  // namespace fdem::fem
