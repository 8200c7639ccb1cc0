// make_geogrid (src/fem/mesh_geogrid.cpp) against the thesis's two grids (Tran 2013):
//  SS-1 (pullout, ch. 4, fig. 4-6): 8 longitudinal x 19 transverse ribs, rib 4 mm wide, 0.9 mm
//    thick; ribbed part 0.52 m x 0.27 m; apertures 25 mm (along x, between transverse ribs) and
//    33 mm (along y); clamp 0.1 m; first transverse rib 30 mm from the front wall (= clamp end).
//  SS-0 (footing, ch. 5, fig. 5-1): 11 x 21 ribs, 0.76 m x 0.3 m, rib 4 mm, 0.9 mm thick, no
//    clamp; its apertures come out 33.8 mm along x and 25.6 mm along y (figure: 33 and 25 mm).
// Checked: rib counts (connected components), apertures against the thesis values (tolerance
// 1.5 mm: the figures give the overall sizes to 10 mm), bounding box, volume = analytic rib volume
// (junctions once), unique node coordinates, conformity (every face shared by at most 2 elements,
// total boundary area = analytic surface area), face sets' areas, positive Jacobians.
#include <gtest/gtest.h>

#include <algorithm>
#include <functional>
#include <array>
#include <cmath>
#include <map>
#include <numeric>
#include <set>

#include "fem/mesh.hpp"
#include "fem/topology.hpp"
#include "base/errors.hpp"

using namespace fdem;
using namespace fdem::fem;

namespace {

constexpr double kMm = 1e-3;
constexpr double kApertureTol = 1.5 * kMm;

GeogridSpec ss1() {
  GeogridSpec s;
  s.clamp_length = 0.1;
  s.clamp_gap = 0.03;
  s.length = 0.1 + 0.03 + 0.52;  // clamp + lead-in + ribbed part
  s.width = 0.27;
  s.longitudinal_ribs = 8;
  s.transverse_ribs = 19;
  s.rib_width = 4 * kMm;
  s.thickness = 0.9 * kMm;
  s.max_element_length = 8.5 * kMm;
  return s;
}

GeogridSpec ss0() {
  GeogridSpec s;
  s.length = 0.76;
  s.width = 0.3;
  s.longitudinal_ribs = 11;
  s.transverse_ribs = 21;
  s.rib_width = 4 * kMm;
  s.thickness = 0.9 * kMm;
  s.max_element_length = 8.5 * kMm;
  return s;
}

/// Gauss (2x2x2) volume of a trilinear brick and the smallest corner Jacobian.
double hex_volume(const Mesh& m, std::size_t e, double* min_detj = nullptr) {
  static const int q[8][3] = {{-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1},
                              {-1, -1, 1},  {1, -1, 1},  {1, 1, 1},  {-1, 1, 1}};
  const std::int32_t* n;
  m.nodes_of(e, n);
  auto detj = [&](double r, double s, double t) {
    double J[3][3] = {};
    for (int i = 0; i < 8; ++i) {
      const double d[3] = {0.125 * q[i][0] * (1 + s * q[i][1]) * (1 + t * q[i][2]),
                           0.125 * q[i][1] * (1 + r * q[i][0]) * (1 + t * q[i][2]),
                           0.125 * q[i][2] * (1 + r * q[i][0]) * (1 + s * q[i][1])};
      for (int a = 0; a < 3; ++a)
        for (int c = 0; c < 3; ++c) J[a][c] += d[a] * m.coords[3 * n[i] + c];
    }
    return J[0][0] * (J[1][1] * J[2][2] - J[1][2] * J[2][1]) - J[0][1] * (J[1][0] * J[2][2] - J[1][2] * J[2][0]) +
           J[0][2] * (J[1][0] * J[2][1] - J[1][1] * J[2][0]);
  };
  const double g = 1 / std::sqrt(3.0);
  double v = 0;
  for (int i = 0; i < 8; ++i) v += detj(g * q[i][0], g * q[i][1], g * q[i][2]);
  if (min_detj) {
    *min_detj = 1e300;
    for (int i = 0; i < 8; ++i) *min_detj = std::min(*min_detj, detj(q[i][0], q[i][1], q[i][2]));
  }
  return v;
}

/// Connected components (through shared nodes) of a set of elements.
int components(const Mesh& m, const std::vector<std::int32_t>& elems) {
  std::vector<int> parent(m.n_nodes());
  std::iota(parent.begin(), parent.end(), 0);
  std::function<int(int)> find = [&](int a) { return parent[a] == a ? a : parent[a] = find(parent[a]); };
  std::set<int> used;
  for (auto e : elems) {
    const std::int32_t* n;
    const int nn = m.nodes_of(e, n);
    for (int i = 0; i < nn; ++i) {
      parent[find(n[i])] = find(n[0]);
      used.insert(n[i]);
    }
  }
  std::set<int> roots;
  for (int u : used) roots.insert(find(u));
  return static_cast<int>(roots.size());
}

double set_area(const Mesh& m, const std::string& name, int axis, int sign) {
  double a = 0;
  for (const auto& f : m.face_sets.at(name)) {
    const auto n = face_area_normal(m, f[0], f[1]);
    EXPECT_GT(n[axis] * sign, 0) << name;
    a += std::abs(n[axis]);
  }
  return a;
}

/// Every check that does not depend on the particular grid. `plan`, `volume`, `surface`: the
/// analytic plan area, solid volume and total surface area.
void check_grid(const Mesh& m, const GeogridSpec& s, double plan, double volume, double surface) {
  ASSERT_GT(m.n_elements(), 0u);
  EXPECT_EQ(m.dim, 3);
  // bounding box
  double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
  for (std::size_t i = 0; i < m.n_nodes(); ++i)
    for (int c = 0; c < 3; ++c) {
      lo[c] = std::min(lo[c], m.coords[3 * i + c]);
      hi[c] = std::max(hi[c], m.coords[3 * i + c]);
    }
  const double tj = s.junction_thickness > 0 ? s.junction_thickness : s.thickness;
  const double ext[3] = {s.length, s.width, tj};
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(lo[c], s.origin[c], 1e-12) << "axis " << c;
    EXPECT_NEAR(hi[c], s.origin[c] + ext[c], 1e-12) << "axis " << c;
  }
  // unique coordinates (no duplicate nodes)
  std::set<std::array<long long, 3>> pts;
  for (std::size_t i = 0; i < m.n_nodes(); ++i)
    pts.insert({std::llround(m.coords[3 * i] * 1e9), std::llround(m.coords[3 * i + 1] * 1e9),
                std::llround(m.coords[3 * i + 2] * 1e9)});
  EXPECT_EQ(pts.size(), m.n_nodes());
  // every node used
  std::vector<int> use(m.n_nodes(), 0);
  for (auto n : m.elem_nodes) ++use[n];
  EXPECT_EQ(std::count(use.begin(), use.end(), 0), 0);
  // volume and Jacobians
  double v = 0;
  int bad = 0;
  for (std::size_t e = 0; e < m.n_elements(); ++e) {
    EXPECT_EQ(m.elem_type[e], ElemType::kHex8);
    double dj;
    v += hex_volume(m, e, &dj);
    bad += !(dj > 0);
  }
  EXPECT_EQ(bad, 0) << "elements with a non-positive corner Jacobian";
  EXPECT_NEAR(v, volume, 1e-9 * volume);
  // conforming: a face map over all element faces; each face in 1 (boundary) or 2 elements, and
  // the boundary adds up to the analytic surface (a hanging node would leave extra boundary)
  std::map<std::array<std::int32_t, 4>, int> faces;
  for (std::size_t e = 0; e < m.n_elements(); ++e)
    for (int f = 0; f < 6; ++f) ++faces[face_key(m, e, f)];
  int over = 0, interior = 0;
  for (const auto& kv : faces) {
    over += kv.second > 2;
    interior += kv.second == 2;
  }
  EXPECT_EQ(over, 0);
  EXPECT_EQ(faces.size() - interior, boundary_faces(m).size());
  EXPECT_EQ(6 * m.n_elements(), faces.size() + interior);
  double area = 0;
  for (const auto& f : boundary_faces(m)) {
    const auto n = face_area_normal(m, f[0], f[1]);
    area += std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  }
  EXPECT_NEAR(area, surface, 1e-9 * surface);
  // element sets partition the mesh
  std::vector<int> in(m.n_elements(), 0);
  for (auto name : {"clamp", "longitudinal", "transverse", "junction"})
    for (auto e : m.element_sets.at(name)) ++in[e];
  EXPECT_EQ(std::count(in.begin(), in.end(), 1), static_cast<long>(m.n_elements()));
  // top/bottom face sets: the plan area, on the top/bottom planes of ribs and junctions
  EXPECT_NEAR(set_area(m, "top", 2, +1), plan, 1e-9 * plan);
  EXPECT_NEAR(set_area(m, "bottom", 2, -1), plan, 1e-9 * plan);
  // rib counts: connected components of (transverse + junction) and (longitudinal + junction)
  auto join = [&](const char* a, const char* b) {
    auto v = m.element_sets.at(a);
    v.insert(v.end(), m.element_sets.at(b).begin(), m.element_sets.at(b).end());
    return v;
  };
  EXPECT_EQ(components(m, join("transverse", "junction")), s.transverse_ribs);
  EXPECT_EQ(components(m, join("longitudinal", "junction")), s.longitudinal_ribs);
  EXPECT_EQ(components(m, m.element_sets.at("junction")), s.transverse_ribs * s.longitudinal_ribs);
}

}  // namespace

TEST(Geogrid, SS1PulloutGrid) {
  const GeogridSpec s = ss1();
  GeogridInfo g;
  const Mesh m = make_geogrid(s, g);
  // thesis fig. 4-6: apertures 25 mm along the pull (x) and 33 mm across (y)
  EXPECT_NEAR(g.aperture_x, 25 * kMm, kApertureTol);
  EXPECT_NEAR(g.aperture_y, 33 * kMm, kApertureTol);
  EXPECT_NEAR(g.aperture_x, (0.52 - 19 * 0.004) / 18, 1e-12);  // 24.67 mm
  EXPECT_NEAR(g.aperture_y, (0.27 - 8 * 0.004) / 7, 1e-12);    // 34.0 mm
  EXPECT_DOUBLE_EQ(g.clamp_gap, 0.03);
  ASSERT_EQ(g.transverse_x.size(), 19u);
  EXPECT_NEAR(g.transverse_x.front(), 0.13, 1e-12);               // 30 mm behind the clamp
  EXPECT_NEAR(g.transverse_x.back() + 0.004, s.length, 1e-12);     // the grid ends with a rib
  EXPECT_NEAR(g.transverse_x.back() + 0.004 - g.transverse_x.front(), 0.52, 1e-12);  // ribbed length
  const double w = 0.004, t = 0.0009, W = 0.27, L = s.length, c = 0.1, gap = 0.03;
  const double ax = g.aperture_x, ay = g.aperture_y;
  const double plan = c * W + 8 * w * gap + 19 * w * W + 8 * w * 18 * ax;
  EXPECT_NEAR(g.plan_area, plan, 1e-15);
  const double perimeter = 2 * (L + W) + 18 * 7 * 2 * (ax + ay) + 7 * 2 * (gap + ay);
  check_grid(m, s, plan, plan * t, 2 * plan + t * perimeter);
  EXPECT_NEAR(g.volume, plan * t, 1e-15);
  // clamp: the solid strip [0, 0.1] x [0, 0.27]; node set = its front face x = 0
  double clamp_v = 0;
  for (auto e : m.element_sets.at("clamp")) clamp_v += hex_volume(m, e);
  EXPECT_NEAR(clamp_v, c * W * t, 1e-12 * clamp_v);
  int at_front = 0;
  for (std::size_t i = 0; i < m.n_nodes(); ++i) at_front += m.coords[3 * i] == 0.0;
  const auto& cn = m.node_sets.at("clamp");
  EXPECT_EQ(static_cast<int>(cn.size()), at_front);
  for (auto i : cn) EXPECT_EQ(m.coords[3 * i], 0.0);
  // transverse_front: the -x faces of the 19 transverse ribs between the longitudinal ribs
  EXPECT_NEAR(set_area(m, "transverse_front", 0, -1), 19 * 7 * ay * t, 1e-9);
  // ... and per rib, transverse_front_1 (the front rib) ... transverse_front_19, each at its rib's x
  std::size_t nfaces = 0;
  for (int k = 1; k <= 19; ++k) {
    const std::string name = "transverse_front_" + std::to_string(k);
    ASSERT_TRUE(m.face_sets.count(name)) << name;
    EXPECT_NEAR(set_area(m, name, 0, -1), 7 * ay * t, 1e-9) << name;
    nfaces += m.face_sets.at(name).size();
  }
  EXPECT_FALSE(m.face_sets.count("transverse_front_20"));
  EXPECT_EQ(nfaces, m.face_sets.at("transverse_front").size());
  // mesh size: ~4 elements per aperture (max 8.5 mm), 1 across a rib, 1 through the thickness
  const std::size_t ribbed = m.n_elements() - m.element_sets.at("clamp").size();
  EXPECT_EQ(m.element_sets.at("junction").size(), 152u);
  EXPECT_EQ(ribbed, 152u + 19 * 7 * 4 + 8 * 18 * 3 + 8 * 4);  // junctions, transverse, longitudinal, lead-in
}

// A slice of the SS-1 grid between two planes of symmetry through the middle of its apertures
// (cases/geogrid_pullout/slice.yaml): two longitudinal ribs, the transverse ribs and the clamp
// running on half an aperture to the planes.
TEST(Geogrid, SliceWithSideOverhangs) {
  GeogridSpec s;
  s.length = 0.656; s.width = 0.074; s.side_overhang = 0.0165;
  s.longitudinal_ribs = 2; s.transverse_ribs = 19; s.rib_width = 0.004; s.thickness = 0.0009;
  s.clamp_length = 0.1; s.clamp_gap = 0.03; s.max_element_length = 0.0085;
  GeogridInfo g;
  const Mesh m = make_geogrid(s, g);
  const double w = 0.004, t = 0.0009, W = 0.074, c = 0.1, gap = 0.03, o = 0.0165;
  EXPECT_NEAR(g.aperture_y, 0.033, 1e-15);  // the pitch 37 mm of the full grid
  EXPECT_NEAR(g.aperture_x, 0.025, 1e-15);
  ASSERT_EQ(g.longitudinal_y.size(), 2u);
  EXPECT_NEAR(g.longitudinal_y[0], o, 1e-15);
  EXPECT_NEAR(g.longitudinal_y[1] + w, W - o, 1e-15);
  const double ax = g.aperture_x;
  const double plan = c * W + 2 * w * gap + 19 * w * W + 2 * w * 18 * ax;
  EXPECT_NEAR(g.plan_area, plan, 1e-15);
  // outline: clamp front, back (less the two lead-in ribs) and sides; the lead-in ribs' sides;
  // the transverse ribs' fronts and backs (less the longitudinal ribs; the last back whole) and
  // cut ends; the longitudinal ribs' sides in the 18 apertures
  const double perimeter = W + (W - 2 * w) + 2 * c + 4 * gap + 19 * (W - 2 * w) + 18 * (W - 2 * w) + W + 19 * 2 * w +
                           18 * 2 * 2 * ax;
  check_grid(m, s, plan, plan * t, 2 * plan + t * perimeter);
  // each rib bears across the whole slice but for the two longitudinal ribs
  for (int k = 1; k <= 19; ++k)
    EXPECT_NEAR(set_area(m, "transverse_front_" + std::to_string(k), 0, -1), (W - 2 * w) * t, 1e-12) << k;
  // the cut sides: node sets ymin / ymax hold every node on y = 0 / y = W (clamp and rib ends)
  for (const char* side : {"ymin", "ymax"}) {
    const double y = side[1] == 'm' && side[2] == 'i' ? 0.0 : W;
    int on = 0;
    for (std::size_t i = 0; i < m.n_nodes(); ++i) on += std::abs(m.coords[3 * i + 1] - y) < 1e-12;
    ASSERT_TRUE(m.node_sets.count(side));
    EXPECT_EQ(static_cast<int>(m.node_sets.at(side).size()), on) << side;
    EXPECT_EQ(on, (2 * 19 + 13) * 2) << side;  // x lines: 2 per rib, 13 of the clamp; 2 z levels
    for (auto n : m.node_sets.at(side)) EXPECT_NEAR(m.coords[3 * n + 1], y, 1e-12);
  }
  // a side overhang of half the width or more leaves no room
  s.side_overhang = 0.037;
  EXPECT_THROW(geogrid_layout(s), InputError);
}

TEST(Geogrid, SS0FootingGrid) {
  const GeogridSpec s = ss0();
  GeogridInfo g;
  const Mesh m = make_geogrid(s, g);
  // thesis fig. 5-1 labels 33 mm and 25 mm; with 0.76 m x 0.3 m and 21 x 11 ribs the 33 mm
  // aperture is along x (33.8 mm) and the 25 mm one along y (25.6 mm)
  EXPECT_NEAR(g.aperture_x, 33 * kMm, kApertureTol);
  EXPECT_NEAR(g.aperture_y, 25 * kMm, kApertureTol);
  EXPECT_NEAR(g.aperture_x, (0.76 - 21 * 0.004) / 20, 1e-12);
  EXPECT_NEAR(g.aperture_y, (0.3 - 11 * 0.004) / 10, 1e-12);
  EXPECT_EQ(g.clamp_gap, 0.0);
  EXPECT_EQ(g.transverse_x.front(), 0.0);
  const double w = 0.004, t = 0.0009, W = 0.3, L = 0.76, ax = g.aperture_x, ay = g.aperture_y;
  const double plan = 21 * w * W + 11 * w * 20 * ax;
  const double perimeter = 2 * (L + W) + 20 * 10 * 2 * (ax + ay);
  check_grid(m, s, plan, plan * t, 2 * plan + t * perimeter);
  EXPECT_TRUE(m.element_sets.at("clamp").empty());
  // no clamp: the node set holds the front ends of the 11 longitudinal ribs (x = 0, y on a rib)
  const auto& cn = m.node_sets.at("clamp");
  EXPECT_EQ(cn.size(), 11u * 2 * 2);
  for (auto i : cn) {
    EXPECT_EQ(m.coords[3 * i], 0.0);
    const double y = m.coords[3 * i + 1];
    const double r = std::fmod(y + 1e-12, g.pitch_y);
    EXPECT_LE(r, w + 2e-12) << "y = " << y;
  }
  // the first rib sits at the front end: its whole front face is exposed
  EXPECT_NEAR(set_area(m, "transverse_front", 0, -1), W * t + 20 * 10 * ay * t, 1e-9);
  // thesis: "over 1900 finite elements"; 4 elements per aperture give 231 + 210*4 + 220*4
  EXPECT_EQ(m.n_elements(), 1951u);
}

TEST(Geogrid, DenserMeshThickJunctionsOffsetOrigin) {
  GeogridSpec s = ss1();
  s.longitudinal_ribs = 4;
  s.transverse_ribs = 5;
  s.width = 0.12;
  s.length = 0.1 + 0.03 + 0.15;
  s.junction_thickness = 2 * s.thickness;
  s.elements_per_rib_width = 2;
  s.elements_through_thickness = 2;
  s.max_element_length = 0.006;
  s.origin = {-0.3, 0.05, 0.2};
  GeogridInfo g;
  const Mesh m = make_geogrid(s, g);
  const double w = s.rib_width, t = s.thickness, tj = 2 * t, W = s.width, L = s.length, c = 0.1, gap = 0.03;
  const double ax = g.aperture_x, ay = g.aperture_y;
  EXPECT_NEAR(ax, (0.15 - 5 * w) / 4, 1e-12);
  EXPECT_NEAR(ay, (0.12 - 4 * w) / 3, 1e-12);
  const double plan = c * W + 4 * w * gap + 5 * w * W + 4 * w * 4 * ax;
  const double jv = 20 * w * w * (tj - t);
  // surface: the rib layer as before, plus the junctions' extra layers (4 sides each, above and below)
  const double perimeter = 2 * (L + W) + 4 * 3 * 2 * (ax + ay) + 3 * 2 * (gap + ay);
  const double surface = 2 * plan + t * perimeter + 20 * 4 * w * (tj - t);
  check_grid(m, s, plan, plan * t + jv, surface);
  EXPECT_NEAR(g.volume, plan * t + jv, 1e-15);
  // junction thickness is symmetric about the ribs' mid-plane
  double zmin_rib = 1e300;
  for (auto e : m.element_sets.at("longitudinal")) {
    const std::int32_t* n;
    m.nodes_of(e, n);
    for (int i = 0; i < 8; ++i) zmin_rib = std::min(zmin_rib, m.coords[3 * n[i] + 2]);
  }
  EXPECT_NEAR(zmin_rib, 0.2 + 0.5 * (tj - t), 1e-12);
  EXPECT_EQ(m.element_sets.at("junction").size(), 20u * 2 * 2 * (2 + 2));  // 2x2 across, 2 rib + 2 extra layers
}

TEST(Geogrid, DefaultClampGapIsOneAperture) {
  GeogridSpec s = ss1();
  s.clamp_gap = -1;
  GeogridInfo g;
  const Mesh m = make_geogrid(s, g);
  EXPECT_NEAR(g.aperture_x, (s.length - 0.1 - 19 * 0.004) / 19, 1e-12);
  EXPECT_NEAR(g.clamp_gap, g.aperture_x, 1e-15);
  EXPECT_NEAR(g.transverse_x[0], 0.1 + g.aperture_x, 1e-12);
  const double w = 0.004, t = 0.0009, W = 0.27, L = s.length, ax = g.aperture_x, ay = g.aperture_y;
  const double plan = 0.1 * W + 8 * w * ax + 19 * w * W + 8 * w * 18 * ax;
  const double perimeter = 2 * (L + W) + 19 * 7 * 2 * (ax + ay);
  check_grid(m, s, plan, plan * t, 2 * plan + t * perimeter);
}

TEST(Geogrid, ImpossibleSpecsAreInputErrors) {
  GeogridSpec s = ss0();
  s.width = 0.04;  // 11 ribs of 4 mm do not fit
  EXPECT_THROW(make_geogrid(s), InputError);
  s = ss0();
  s.transverse_ribs = 1;
  EXPECT_THROW(make_geogrid(s), InputError);
  s = ss0();
  s.thickness = 0;
  EXPECT_THROW(make_geogrid(s), InputError);
  s = ss0();
  s.junction_thickness = 0.5 * s.thickness;
  EXPECT_THROW(make_geogrid(s), InputError);
  s = ss1();
  s.clamp_gap = 0.6;  // no room left for the ribs
  try {
    make_geogrid(s);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("no room for 19 transverse ribs"), std::string::npos) << e.what();
  }
}
