// The geogrid generator (docs/mesh-formats.md): geogrid_layout() places the ribs, make_geogrid()
// meshes them with Hex8 bricks on a structured grid -- its grid lines (x, y intervals by kind, z
// levels), the kind of each (x, y) cell column, the nodes the elements touch, the elements with
// their sets, the side node sets and the face sets.
#include <algorithm>
#include <cmath>
#include <set>
#include <string>

#include "base/errors.hpp"
#include "fem/mesh.hpp"
#include "fem/mesh_detail.hpp"
#include "fem/topology.hpp"

namespace fdem::fem {

using detail::append_points;
using detail::fmt;
using detail::parts;

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

namespace {

/// The grid lines of the mesh.
struct GridLines {
  std::vector<double> xs, ys, zs;
  std::vector<int> xkind;   // x intervals: 0 clamp, 1 rib-free stretch (gap/aperture), 2 transverse rib
  std::vector<int> ykind;   // y intervals: 0 aperture (or side overhang), 1 longitudinal rib
  int rib_k0 = 0, rib_k1 = 0;  // rib layers [rib_k0, rib_k1) of the z levels
  int nzl = 0;                 // z layers
};

void x_lines(const GeogridSpec& s, const GeogridInfo& info, double h, GridLines& L) {
  const double w = s.rib_width;
  const double x0 = s.origin[0];
  std::vector<double>& xs = L.xs;
  xs.push_back(x0);
  auto add_x = [&](double a, double b, int n, int kind) {
    append_points(xs, a, b, n);
    L.xkind.insert(L.xkind.end(), n, kind);
  };
  if (s.clamp_length > 0) add_x(x0, x0 + s.clamp_length, parts(s.clamp_length, h), 0);
  if (info.clamp_gap > 0) add_x(xs.back(), info.transverse_x[0], parts(info.clamp_gap, h), 1);
  for (int k = 0; k < s.transverse_ribs; ++k) {
    const double a = info.transverse_x[k];
    const double b = k + 1 == s.transverse_ribs ? x0 + s.length : a + w;
    xs.back() = a;  // exact rib position (equal to the previous end up to round-off)
    add_x(a, b, s.elements_per_rib_width, 2);
    if (k + 1 < s.transverse_ribs) add_x(b, info.transverse_x[k + 1], parts(info.aperture_x, h), 1);
  }
}

void y_lines(const GeogridSpec& s, const GeogridInfo& info, double h, GridLines& L) {
  const double w = s.rib_width;
  const int epr = s.elements_per_rib_width;
  const double y0 = s.origin[1];
  std::vector<double>& ys = L.ys;
  std::vector<int>& ykind = L.ykind;
  ys.push_back(y0);
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
}

/// z levels: ribs [rz0, rz0 + t] in ett layers; thicker junctions get one more layer each side.
void z_levels(const GeogridSpec& s, const GeogridInfo& info, GridLines& L) {
  const double z0 = s.origin[2];
  const int ett = s.elements_through_thickness;
  const double extra = 0.5 * (info.junction_thickness - s.thickness);
  const bool thick = extra > 1e-12 * s.thickness;
  std::vector<double>& zs = L.zs;
  if (thick) zs.push_back(z0);
  const double rz0 = z0 + (thick ? extra : 0);
  zs.push_back(rz0);
  append_points(zs, rz0, rz0 + s.thickness, ett);
  if (thick) zs.push_back(z0 + info.junction_thickness);
  L.rib_k0 = thick ? 1 : 0;
  L.rib_k1 = L.rib_k0 + ett;
  L.nzl = static_cast<int>(zs.size()) - 1;
}

enum Kind { kNone = -1, kClamp = 0, kLong = 1, kTrans = 2, kJunc = 3 };
const char* const kSetName[4] = {"clamp", "longitudinal", "transverse", "junction"};

/// The structured index space: the kind of each (x, y) cell column and the node numbering.
struct GridCells {
  int NX = 0, NY = 0;
  std::size_t NPX = 0, NPY = 0, NPZ = 0;
  int rib_k0 = 0, rib_k1 = 0, nzl = 0;
  std::vector<int> cell;            // Kind of cell column (i, j), at i * NY + j
  std::vector<std::int32_t> nid;    // node index of grid point pid(i, j, k); -1: no node
  std::size_t pid(int i, int j, int k) const { return (static_cast<std::size_t>(i) * NPY + j) * NPZ + k; }
  int kind(int i, int j) const { return cell[static_cast<std::size_t>(i) * NY + j]; }
  /// The z layers [k0, k1) of a column of this kind: junctions run through, ribs their layers.
  void layers(int kind, int& k0, int& k1) const {
    if (kind == kJunc) { k0 = 0; k1 = nzl; }
    else { k0 = rib_k0; k1 = rib_k1; }
  }
};

GridCells classify_cells(const GridLines& L) {
  GridCells G;
  G.NX = static_cast<int>(L.xkind.size());
  G.NY = static_cast<int>(L.ykind.size());
  G.rib_k0 = L.rib_k0;
  G.rib_k1 = L.rib_k1;
  G.nzl = L.nzl;
  G.cell.assign(static_cast<std::size_t>(G.NX) * G.NY, kNone);
  for (int i = 0; i < G.NX; ++i)
    for (int j = 0; j < G.NY; ++j) {
      int k = kNone;
      if (L.xkind[i] == 0) k = kClamp;
      else if (L.xkind[i] == 2) k = L.ykind[j] == 1 ? kJunc : kTrans;
      else if (L.ykind[j] == 1) k = kLong;
      G.cell[static_cast<std::size_t>(i) * G.NY + j] = k;
    }
  G.NPX = G.NX + 1;
  G.NPY = G.NY + 1;
  G.NPZ = G.nzl + 1;
  return G;
}

/// Nodes: every grid point touched by an element, numbered x-major (ids from 1).
void add_nodes(const GridLines& L, GridCells& G, Mesh& m) {
  G.nid.assign(G.NPX * G.NPY * G.NPZ, -1);
  for (int i = 0; i < G.NX; ++i)
    for (int j = 0; j < G.NY; ++j) {
      const int kind = G.kind(i, j);
      if (kind == kNone) continue;
      int k0, k1;
      G.layers(kind, k0, k1);
      for (int di = 0; di < 2; ++di)
        for (int dj = 0; dj < 2; ++dj)
          for (int k = k0; k <= k1; ++k) G.nid[G.pid(i + di, j + dj, k)] = 0;
    }
  for (int i = 0; i < static_cast<int>(G.NPX); ++i)
    for (int j = 0; j < static_cast<int>(G.NPY); ++j)
      for (int k = 0; k < static_cast<int>(G.NPZ); ++k) {
        auto& n = G.nid[G.pid(i, j, k)];
        if (n < 0) continue;
        n = static_cast<std::int32_t>(m.node_id.size());
        m.node_id.push_back(n + 1);
        m.coords.insert(m.coords.end(), {L.xs[i], L.ys[j], L.zs[k]});
      }
}

/// The bricks, x-major, with element sets by kind; node set "clamp". Returns each element's kind.
std::vector<int> add_elements(const GridCells& G, Mesh& m) {
  for (auto nm : kSetName) m.element_sets[nm];
  std::set<std::int32_t> clamp_nodes;
  std::vector<int> ekind;
  const auto& nid = G.nid;
  for (int i = 0; i < G.NX; ++i)
    for (int j = 0; j < G.NY; ++j) {
      const int kind = G.kind(i, j);
      if (kind == kNone) continue;
      int k0, k1;
      G.layers(kind, k0, k1);
      for (int k = k0; k < k1; ++k) {
        std::vector<std::int32_t> c = {nid[G.pid(i, j, k)],         nid[G.pid(i + 1, j, k)],     nid[G.pid(i + 1, j + 1, k)],
                                       nid[G.pid(i, j + 1, k)],     nid[G.pid(i, j, k + 1)],     nid[G.pid(i + 1, j, k + 1)],
                                       nid[G.pid(i + 1, j + 1, k + 1)], nid[G.pid(i, j + 1, k + 1)]};
        m.element_sets[kSetName[kind]].push_back(static_cast<std::int32_t>(m.n_elements()));
        m.add_element(static_cast<std::int64_t>(m.n_elements()) + 1, ElemType::kHex8, c);
        ekind.push_back(kind);
        if (i == 0 && kind != kTrans)  // front face x = origin.x of the clamp / the longitudinal ribs
          for (int q : {0, 3, 4, 7}) clamp_nodes.insert(c[q]);
      }
    }
  m.node_sets["clamp"].assign(clamp_nodes.begin(), clamp_nodes.end());
  return ekind;
}

/// Node sets "ymin", "ymax": the two sides y = origin.y and y = origin.y + width (with side
/// overhangs: the cut ends of the transverse ribs and the clamp, where a symmetry plane holds u_y = 0).
void add_side_sets(const GridCells& G, Mesh& m) {
  for (int side = 0; side < 2; ++side) {
    const std::size_t j = side == 0 ? 0 : G.NPY - 1;
    auto& set = m.node_sets[side == 0 ? "ymin" : "ymax"];
    for (std::size_t i = 0; i < G.NPX; ++i)
      for (std::size_t k = 0; k < G.NPZ; ++k)
        if (G.nid[G.pid(static_cast<int>(i), static_cast<int>(j), static_cast<int>(k))] >= 0)
          set.push_back(G.nid[G.pid(static_cast<int>(i), static_cast<int>(j), static_cast<int>(k))]);
    std::sort(set.begin(), set.end());
  }
}

/// Face sets "top", "bottom", "transverse_front" and "transverse_front_<k>" (per rib, from the front).
void add_face_sets(const GeogridSpec& s, const GeogridInfo& info, const std::vector<int>& ekind, Mesh& m) {
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
}

}  // namespace

Mesh make_geogrid(const GeogridSpec& s, GeogridInfo& info) {
  info = geogrid_layout(s);
  const double h = s.max_element_length > 0 ? s.max_element_length : s.rib_width;
  GridLines L;
  x_lines(s, info, h, L);
  y_lines(s, info, h, L);
  z_levels(s, info, L);
  GridCells G = classify_cells(L);
  Mesh m;
  m.dim = 3;
  add_nodes(L, G, m);
  const std::vector<int> ekind = add_elements(G, m);
  add_side_sets(G, m);
  add_face_sets(s, info, ekind, m);
  return m;
}

}  // namespace fdem::fem
