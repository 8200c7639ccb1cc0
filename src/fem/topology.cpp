// Local faces of the element types and boundary-face extraction. See topology.hpp.
#include "fem/topology.hpp"

#include <algorithm>
#include <map>

#include "fem/mesh.hpp"

namespace fdem::fem {
namespace {

// Hex8 faces, counter-clockwise seen from outside (corner order shared with Hex20).
const std::vector<std::vector<int>> kHex8Faces = {
    {0, 4, 7, 3},  // xi = -1
    {1, 2, 6, 5},  // xi = +1
    {0, 1, 5, 4},  // eta = -1
    {3, 7, 6, 2},  // eta = +1
    {0, 3, 2, 1},  // zeta = -1
    {4, 5, 6, 7},  // zeta = +1
};

// Hex20 mid-edge node 8 + k lies on corner edge kHex20Edge[k] (fem/element_types.hpp).
int hex20_edge_node(int a, int b) {
  for (int k = 0; k < 12; ++k)
    if ((kHex20Edge[k][0] == a && kHex20Edge[k][1] == b) || (kHex20Edge[k][0] == b && kHex20Edge[k][1] == a))
      return 8 + k;
  return -1;
}

std::vector<std::vector<int>> make_hex20_faces() {
  std::vector<std::vector<int>> f;
  for (const auto& c : kHex8Faces) {
    std::vector<int> nodes(c);
    for (int k = 0; k < 4; ++k) nodes.push_back(hex20_edge_node(c[k], c[(k + 1) % 4]));
    f.push_back(nodes);
  }
  return f;
}

const std::vector<std::vector<int>> kHex20Faces = make_hex20_faces();

// Quad4 edges (counter-clockwise element): outward normal (t_y, -t_x).
const std::vector<std::vector<int>> kQuad4Faces = {
    {3, 0},  // xi = -1
    {1, 2},  // xi = +1
    {0, 1},  // eta = -1
    {2, 3},  // eta = +1
};

}  // namespace

const std::vector<std::vector<int>>& element_faces(ElemType t) {
  switch (t) {
    case ElemType::kHex8:
    case ElemType::kHex8R:
    case ElemType::kHex8I: return kHex8Faces;
    case ElemType::kHex20: return kHex20Faces;
    case ElemType::kQuad4:
    case ElemType::kShell4: return kQuad4Faces;  // a shell's "faces" are its edges
  }
  return kHex8Faces;
}

int face_corner_count(ElemType t) { return element_traits(t).face_corners; }

int topology_node_count(ElemType t) { return element_traits(t).nodes; }

int topology_dim(ElemType t) { return element_traits(t).dim; }

std::array<std::int32_t, 4> face_key(const Mesh& mesh, std::size_t element, int face) {
  const std::int32_t* n;
  mesh.nodes_of(element, n);
  const auto& f = element_faces(mesh.elem_type[element])[face];
  const int nc = face_corner_count(mesh.elem_type[element]);
  std::array<std::int32_t, 4> key{-1, -1, -1, -1};
  for (int k = 0; k < nc; ++k) {  // insertion sort (std::sort trips a GCC 12 -Warray-bounds false positive)
    std::int32_t v = n[f[k]];
    int j = k;
    for (; j > 0 && key[j - 1] > v; --j) key[j] = key[j - 1];
    key[j] = v;
  }
  return key;
}

std::vector<FaceRef> boundary_faces(const Mesh& mesh) {
  // key: sorted corner node indices (a 2-node edge padded with -1)
  std::map<std::array<std::int32_t, 4>, std::pair<int, FaceRef>> count;
  for (std::size_t e = 0; e < mesh.n_elements(); ++e) {
    const std::size_t nf = element_faces(mesh.elem_type[e]).size();
    for (std::size_t f = 0; f < nf; ++f) {
      const auto key = face_key(mesh, e, static_cast<int>(f));
      auto it = count.find(key);
      if (it == count.end())
        count.emplace(key, std::make_pair(1, FaceRef{static_cast<std::int32_t>(e), static_cast<std::int32_t>(f)}));
      else
        ++it->second.first;
    }
  }
  std::vector<FaceRef> out;
  for (const auto& kv : count)
    if (kv.second.first == 1) out.push_back(kv.second.second);
  std::sort(out.begin(), out.end());
  return out;
}

std::array<double, 3> face_area_normal(const Mesh& mesh, std::int32_t element, int face) {
  const std::int32_t* n;
  mesh.nodes_of(element, n);
  const ElemType t = mesh.elem_type[element];
  const auto& f = element_faces(t)[face];
  const int d = mesh.dim;
  auto X = [&](int local, int c) { return c < d ? mesh.coords[static_cast<std::size_t>(n[local]) * d + c] : 0.0; };
  if (t == ElemType::kQuad4) {
    const double tx = X(f[1], 0) - X(f[0], 0), ty = X(f[1], 1) - X(f[0], 1);
    return {ty, -tx, 0.0};
  }
  double d1[3], d2[3];
  for (int c = 0; c < 3; ++c) {
    d1[c] = X(f[2], c) - X(f[0], c);
    d2[c] = X(f[3], c) - X(f[1], c);
  }
  return {0.5 * (d1[1] * d2[2] - d1[2] * d2[1]), 0.5 * (d1[2] * d2[0] - d1[0] * d2[2]),
          0.5 * (d1[0] * d2[1] - d1[1] * d2[0])};
}

}  // namespace fdem::fem
