#include "coupling/interface_surface.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>

namespace fdem::coupling {

InterfaceSurface::InterfaceSurface(const fem::Mesh& mesh, std::vector<InterfaceTriangle> triangles)
    : mesh_(mesh), triangles_(std::move(triangles)) {
  index_vertices();
  active_.assign(triangles_.size(), 1);
  topology_ = FacetTopology::build(corners_);
  node_weight_.assign(vertices_.size(), 0.0);
  node_count_.assign(vertices_.size(), 0);
  for (std::size_t v = 0; v < vertices_.size(); ++v)
    for (int k = 0; k < 4; ++k) {
      if (vertices_[v].nodes[k] < 0) continue;
      if (node_count_[v] > 0 && vertices_[v].weights[k] != node_weight_[v])
        throw std::invalid_argument("Coupler: the nodes of an interface corner must have equal weights");
      node_weight_[v] = vertices_[v].weights[k];
      ++node_count_[v];
    }
  find_opposite_vertices();
  for (const InterfaceTriangle& t : triangles_) {
    if (t.group < 0) throw std::invalid_argument("Coupler: negative surface group");
    n_groups_ = std::max(n_groups_, t.group + 1);
  }
  group_.resize(triangles_.size());
  for (std::size_t t = 0; t < triangles_.size(); ++t) group_[t] = triangles_[t].group;
  place_reference();
  planes_.resize(triangles_.size());
}

void InterfaceSurface::index_vertices() {
  // Unique corners, keyed by their sorted node list (a node, or a quad's 4 corners).
  std::map<std::array<std::int32_t, 4>, std::int32_t> index;
  corners_.resize(triangles_.size());
  for (std::size_t t = 0; t < triangles_.size(); ++t)
    for (int c = 0; c < 3; ++c) {
      const Vertex v{triangles_[t].nodes[c], triangles_[t].weights[c]};
      std::array<std::int32_t, 4> key = v.nodes;
      std::sort(key.begin(), key.end());
      auto it = index.find(key);
      if (it == index.end()) {
        it = index.emplace(key, static_cast<std::int32_t>(vertices_.size())).first;
        vertices_.push_back(v);
      }
      corners_[t][c] = it->second;
    }
}

void InterfaceSurface::find_opposite_vertices() {
  const FacetTopology& adj = topology_;
  opposite_.resize(triangles_.size());
  for (std::size_t t = 0; t < triangles_.size(); ++t) {
    const auto& tt = corners_[t];
    const bool distinct = tt[0] != tt[1] && tt[1] != tt[2] && tt[2] != tt[0];
    for (int k = 0; k < 3; ++k) {
      const std::int32_t grp = adj.edge_group[3 * t + k];
      const std::int32_t b = adj.group_off[grp], e = adj.group_off[grp + 1];
      std::int32_t o = -2;
      if (distinct && e - b == 1) {
        o = -1;
      } else if (distinct && e - b == 2) {
        const auto self = static_cast<std::int32_t>(t);
        const std::int32_t other = adj.group_tris[b] == self ? adj.group_tris[b + 1] : adj.group_tris[b];
        const auto& tf = corners_[other];
        const int a0 = tt[k], a1 = tt[(k + 1) % 3];
        const bool ok = other != self && tf[0] != tf[1] && tf[1] != tf[2] && tf[2] != tf[0];
        if (ok) o = tf[0] != a0 && tf[0] != a1 ? tf[0] : (tf[1] != a0 && tf[1] != a1 ? tf[1] : tf[2]);
      }
      opposite_[t][k] = o;
    }
  }
}

void InterfaceSurface::set_active(const std::vector<std::uint8_t>& active) {
  if (active.size() != triangles_.size()) throw std::invalid_argument("InterfaceSurface::set_active: wrong size");
  active_ = active;
  // An inactive triangle gets corners of its own (ids past the real vertices): it then shares no
  // edge and no vertex neighbourhood with the others, and no candidate ever names those ids.
  std::vector<std::array<int, 3>> c = corners_;
  int fresh = static_cast<int>(vertices_.size());
  for (std::size_t t = 0; t < c.size(); ++t)
    if (!active_[t])
      for (int k = 0; k < 3; ++k) c[t][k] = fresh++;
  topology_ = FacetTopology::build(c);
  find_opposite_vertices();
}

std::size_t InterfaceSurface::n_active_triangles() const {
  return static_cast<std::size_t>(std::count(active_.begin(), active_.end(), std::uint8_t{1}));
}

void InterfaceSurface::place_reference() {
  vertex_pos_.assign(vertices_.size(), Vec3{});
  vertex_vel_.assign(vertices_.size(), Vec3{});
  vertex_pos_fe_.assign(vertices_.size(), Vec3{});
  for (std::size_t v = 0; v < vertices_.size(); ++v)
    for (int k = 0; k < 4; ++k) {
      const std::int32_t n = vertices_[v].nodes[k];
      if (n < 0) continue;
      const double* X = &mesh_.coords[3 * static_cast<std::size_t>(n)];
      vertex_pos_[v] += vertices_[v].weights[k] * Vec3{X[0], X[1], X[2]};
    }
  reference_box_.resize(triangles_.size());
  for (std::size_t t = 0; t < triangles_.size(); ++t) {
    Vec3 lo = vertex_pos_[corners_[t][0]], hi = lo;
    for (int c = 1; c < 3; ++c)
      for (int d = 0; d < 3; ++d) {
        lo[d] = std::min(lo[d], vertex_pos_[corners_[t][c]][d]);
        hi[d] = std::max(hi[d], vertex_pos_[corners_[t][c]][d]);
      }
    reference_box_[t] = {lo, hi};
  }
}

std::vector<std::int32_t> InterfaceSurface::triangles_near(const Vec3& lo, const Vec3& hi, double grow) const {
  std::vector<std::int32_t> out;
  for (std::size_t t = 0; t < triangles_.size(); ++t) {
    if (!active_[t]) continue;
    const auto& b = reference_box_[t];
    bool overlap = true;
    for (int d = 0; d < 3; ++d)
      if (b[0][d] - grow > hi[d] || b[1][d] + grow < lo[d]) overlap = false;
    if (overlap) out.push_back(static_cast<std::int32_t>(t));
  }
  return out;
}

std::vector<std::int32_t> InterfaceSurface::nodes_of(const std::vector<std::int32_t>& tris) const {
  std::vector<std::int32_t> nodes;
  for (std::int32_t t : tris)
    for (int c = 0; c < 3; ++c)
      for (std::int32_t n : vertices_[corners_[t][c]].nodes)
        if (n >= 0) nodes.push_back(n);
  std::sort(nodes.begin(), nodes.end());
  nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
  return nodes;
}

std::vector<std::int32_t> InterfaceSurface::vertices_of(const std::vector<std::int32_t>& tris) const {
  std::vector<std::int32_t> verts;
  for (std::int32_t t : tris)
    for (int c = 0; c < 3; ++c) verts.push_back(corners_[t][c]);
  std::sort(verts.begin(), verts.end());
  verts.erase(std::unique(verts.begin(), verts.end()), verts.end());
  return verts;
}

void InterfaceSurface::place_at_fe(const std::vector<std::int32_t>& tris, const std::vector<std::int32_t>& verts,
                                   const std::vector<Vec3>& disp, const std::vector<std::int32_t>& slot) {
  for (std::int32_t t : tris)
    for (int c = 0; c < 3; ++c) {
      const std::int32_t v = corners_[t][c];
      Vec3 x;
      for (int k = 0; k < 4; ++k) {
        const std::int32_t n = vertices_[v].nodes[k];
        if (n < 0) continue;
        const double* X = &mesh_.coords[3 * static_cast<std::size_t>(n)];
        x += vertices_[v].weights[k] * (Vec3{X[0], X[1], X[2]} + disp[slot[n]]);
      }
      vertex_pos_[v] = x;
    }
  // Positions at this FE update (the sub-steps extrapolate from them).
  for (std::int32_t v : verts) vertex_pos_fe_[v] = vertex_pos_[v];
  update_planes(tris);
}

void InterfaceSurface::set_velocities(const std::vector<std::int32_t>& tris, const std::vector<Vec3>& vel,
                                      const std::vector<std::int32_t>& slot) {
  for (std::int32_t t : tris)
    for (int c = 0; c < 3; ++c) {
      const std::int32_t v = corners_[t][c];
      Vec3 w;
      for (int k = 0; k < 4; ++k)
        if (vertices_[v].nodes[k] >= 0) w += vertices_[v].weights[k] * vel[slot[vertices_[v].nodes[k]]];
      vertex_vel_[v] = w;
    }
}

void InterfaceSurface::clear_velocities() {
  for (Vec3& v : vertex_vel_) v = Vec3{};
}

void InterfaceSurface::extrapolate(const std::vector<std::int32_t>& verts, double s) {
  for (std::int32_t v : verts) vertex_pos_[v] = vertex_pos_fe_[v] + s * vertex_vel_[v];
}

void InterfaceSurface::return_to_fe(const std::vector<std::int32_t>& verts, const std::vector<std::int32_t>& tris) {
  for (std::int32_t v : verts) vertex_pos_[v] = vertex_pos_fe_[v];
  update_planes(tris);
}

void InterfaceSurface::update_planes(const std::vector<std::int32_t>& tris) {
  for (std::int32_t t : tris) {
    const Vec3 a = vertex_pos_[corners_[t][0]], b = vertex_pos_[corners_[t][1]], c = vertex_pos_[corners_[t][2]];
    const Vec3 nn = cross(b - a, c - a);
    const double l = norm(nn);
    // A degenerate triangle gets a NaN plane: the quick rejection never skips it.
    const Vec3 u = l > 0 ? (1.0 / l) * nn : Vec3{NAN, NAN, NAN};
    const Vec3 m = (1.0 / 3.0) * (a + b + c);
    const double R = std::sqrt(std::max({norm2(a - m), norm2(b - m), norm2(c - m)}));
    planes_[t] = {u, dot(u, a), m, R};
  }
}

}  // namespace fdem::coupling
