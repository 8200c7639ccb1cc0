// FE-DEM interface triangles (src/coupling/interface): tiling, orientation, force distribution.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <random>

#include "coupling/interface.hpp"
#include "fem/topology.hpp"
#include "base/errors.hpp"

using fdem::Vec3;
using fdem::coupling::InterfaceTriangle;
namespace fem = fdem::fem;
namespace cp = fdem::coupling;

namespace {

Vec3 tri_area_normal(const Vec3 x[3]) { return 0.5 * cross(x[1] - x[0], x[2] - x[0]); }

Vec3 node_x(const fem::Mesh& m, std::int32_t n) { return {m.coords[3 * n], m.coords[3 * n + 1], m.coords[3 * n + 2]}; }

// Sum of the nodal forces and their moment about the origin (node positions from the mesh + u).
void resultants(const fem::Mesh& m, const std::vector<std::pair<std::int32_t, Vec3>>& f, Vec3& sum, Vec3& mom) {
  sum = {0, 0, 0};
  mom = {0, 0, 0};
  for (const auto& [n, F] : f) {
    sum += F;
    mom += cross(node_x(m, n), F);
  }
}

// One Hex8 element whose top face (zeta = +1) is flat but skewed and tilted.
fem::Mesh skewed_hex8() {
  fem::Mesh m;
  const double xy[4][2] = {{0.0, 0.0}, {1.3, 0.2}, {1.1, 0.9}, {-0.2, 1.2}};
  auto ztop = [](double x, double y) { return 2.0 + 0.3 * x - 0.2 * y; };
  for (int k = 0; k < 2; ++k)
    for (int i = 0; i < 4; ++i) {
      m.node_id.push_back(static_cast<std::int64_t>(m.node_id.size()) + 1);
      m.coords.insert(m.coords.end(), {xy[i][0], xy[i][1], k == 0 ? 0.0 : ztop(xy[i][0], xy[i][1])});
    }
  m.add_element(1, fem::ElemType::kHex8, {0, 1, 2, 3, 4, 5, 6, 7});
  m.face_sets["top"] = {{0, fem::kFaceZetaPlus}};
  return m;
}

}  // namespace

TEST(Interface, Hex8BlockFaceSetTilesFaceOutward) {
  const fem::Mesh m = fem::make_block({0, 0, 0}, {2.0, 1.5, 1.0}, 4, 3, 2);
  const struct { const char* name; Vec3 n; double area; } sides[] = {
      {"zmax", {0, 0, 1}, 3.0}, {"zmin", {0, 0, -1}, 3.0}, {"xmin", {-1, 0, 0}, 1.5},
      {"xmax", {1, 0, 0}, 1.5}, {"ymin", {0, -1, 0}, 2.0}, {"ymax", {0, 1, 0}, 2.0}};
  for (const auto& s : sides) {
    SCOPED_TRACE(s.name);
    const auto tris = cp::make_interface(m, s.name);
    const std::size_t nfaces = m.face_sets.at(s.name).size();
    ASSERT_EQ(tris.size(), 4 * nfaces);
    double area = 0;
    for (const auto& t : tris) {
      Vec3 x[3];
      cp::corner_positions(m, {}, t, x);
      const Vec3 an = tri_area_normal(x);
      area += norm(an);
      EXPECT_NEAR(dot(an, s.n), norm(an), 1e-14);  // along the outward normal
      EXPECT_GT(norm(an), 0.0);
      // corners 0, 1 are real nodes, corner 2 the centre of the quad
      EXPECT_EQ(t.nodes[0][1], -1);
      EXPECT_DOUBLE_EQ(t.weights[0][0], 1.0);
      for (int k = 0; k < 4; ++k) EXPECT_DOUBLE_EQ(t.weights[2][k], 0.25);
    }
    EXPECT_NEAR(area, s.area, 1e-12);
  }
  // zmax: 12 faces -> 48 triangles; each quad's centre at the face centre
  const auto tris = cp::make_interface(m, "zmax");
  EXPECT_EQ(tris.size(), 48u);
  Vec3 x[3];
  cp::corner_positions(m, {}, tris[0], x);
  EXPECT_NEAR(x[2].x, 0.25, 1e-15);
  EXPECT_NEAR(x[2].y, 0.25, 1e-15);
  EXPECT_NEAR(x[2].z, 1.0, 1e-15);
}

TEST(Interface, WholeSurfaceWhenNoFaceSet) {
  const fem::Mesh m = fem::make_block({0, 0, 0}, {1.0, 1.0, 1.0}, 2, 2, 2);
  const auto tris = cp::make_interface(m, "");
  ASSERT_EQ(tris.size(), 6u * 4u * 4u);
  double area = 0;
  const Vec3 centre{0.5, 0.5, 0.5};
  for (const auto& t : tris) {
    Vec3 x[3];
    cp::corner_positions(m, {}, t, x);
    const Vec3 an = tri_area_normal(x);
    area += norm(an);
    EXPECT_GT(dot(an, (1.0 / 3.0) * (x[0] + x[1] + x[2]) - centre), 0.0);
  }
  EXPECT_NEAR(area, 6.0, 1e-12);
  // the surface of a chosen element only: element 0 has 3 boundary faces
  EXPECT_EQ(cp::make_interface(m, "", {0}).size(), 12u);
}

// Node areas (the integral of each node's interface shape function): a 0.3 x 0.2 top face of
// 3 x 2 quads: they add up to the face's area; a corner of the face gets a quarter of its one
// quad (area/6 from its two triangles + a quarter of the centre's area/3), an interior node a
// quarter of each of its four quads, an edge node a quarter of each of its two.
TEST(Interface, NodeAreasAreShapeFunctionIntegrals) {
  const fem::Mesh m = fem::make_block({0, 0, 0}, {0.3, 0.2, 0.05}, 3, 2, 1);
  const auto tris = cp::make_interface(m, "zmax");
  const std::vector<std::int32_t> nodes = cp::interface_nodes(tris);
  const std::vector<double> area = cp::interface_node_areas(m, tris);
  ASSERT_EQ(nodes.size(), 12u);
  ASSERT_EQ(area.size(), nodes.size());
  double sum = 0;
  const double q = 0.1 * 0.1;  // one quad
  for (std::size_t k = 0; k < nodes.size(); ++k) {
    sum += area[k];
    const double* X = &m.coords[3 * static_cast<std::size_t>(nodes[k])];
    const bool ex = std::abs(X[0]) < 1e-12 || std::abs(X[0] - 0.3) < 1e-12;
    const bool ey = std::abs(X[1]) < 1e-12 || std::abs(X[1] - 0.2) < 1e-12;
    const double quads = ex && ey ? 1 : (ex || ey ? 2 : 4);
    EXPECT_NEAR(area[k], quads * q / 4, 1e-15) << "node at " << X[0] << ", " << X[1];
  }
  EXPECT_NEAR(sum, 0.06, 1e-15);
  // the whole surface of the block: the shares add up to its area
  const auto all = cp::make_interface(m, "");
  double total = 0;
  for (double a : cp::interface_node_areas(m, all)) total += a;
  EXPECT_NEAR(total, 2 * (0.3 * 0.2 + 0.3 * 0.05 + 0.2 * 0.05), 1e-14);
}

TEST(Interface, Hex20UsesEveryFaceNode) {
  fem::Mesh m;
  const double c[8][3] = {{0, 0, 0}, {2, 0, 0}, {2, 1, 0}, {0, 1, 0}, {0, 0, 3}, {2, 0, 3}, {2, 1, 3}, {0, 1, 3}};
  const int edges[12][2] = {{0, 1}, {0, 3}, {0, 4}, {1, 2}, {1, 5}, {2, 3}, {2, 6}, {3, 7}, {4, 5}, {4, 7}, {5, 6}, {6, 7}};
  for (int i = 0; i < 8; ++i) m.coords.insert(m.coords.end(), {c[i][0], c[i][1], c[i][2]});
  for (const auto& e : edges)
    for (int d = 0; d < 3; ++d) m.coords.push_back(0.5 * (c[e[0]][d] + c[e[1]][d]));
  for (int i = 0; i < 20; ++i) m.node_id.push_back(i + 1);
  std::vector<std::int32_t> conn(20);
  for (int i = 0; i < 20; ++i) conn[i] = i;
  m.add_element(1, fem::ElemType::kHex20, conn);
  for (int f = 0; f < 6; ++f) m.face_sets["all"].push_back({0, f});
  const auto tris = cp::make_interface(m, "all");
  ASSERT_EQ(tris.size(), 48u);  // 8 per face
  double area = 0;
  for (const auto& t : tris) {
    Vec3 x[3];
    cp::corner_positions(m, {}, t, x);
    const Vec3 an = tri_area_normal(x);
    area += norm(an);
    const auto fn = fem::face_area_normal(m, t.element, t.face);
    EXPECT_NEAR(dot(an, Vec3{fn[0], fn[1], fn[2]}), norm(an) * std::sqrt(fn[0] * fn[0] + fn[1] * fn[1] + fn[2] * fn[2]),
                1e-12);
    EXPECT_GT(dot(an, (1.0 / 3.0) * (x[0] + x[1] + x[2]) - Vec3{1.0, 0.5, 1.5}), 0.0);
  }
  EXPECT_NEAR(area, 2 * (2 * 1 + 2 * 3 + 1 * 3), 1e-12);
  // A uniform pressure on the top face (z = 3, area 2): A/24 to each corner, 5A/24 to each of its
  // mid-edge nodes, nothing to the other nodes.
  fem::Mesh top = m;
  top.face_sets["top"] = {{0, fem::kFaceZetaPlus}};
  const auto top_tris = cp::make_interface(top, "top");
  const auto nodes = cp::interface_nodes(top_tris);
  const auto shares = cp::interface_node_areas(top, top_tris);
  ASSERT_EQ(nodes.size(), 8u);
  ASSERT_EQ(shares.size(), 8u);
  double sum = 0;
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    const int n = nodes[i];
    EXPECT_NEAR(top.coords[3 * n + 2], 3, 1e-12) << "node " << n << " is not on the top face";
    EXPECT_NEAR(shares[i], n < 8 ? 2.0 / 24 : 10.0 / 24, 1e-14) << "node " << n;
    sum += shares[i];
  }
  EXPECT_NEAR(sum, 2, 1e-14);
}

TEST(Interface, ShellElementsGiveFourTrianglesAlongShellNormal) {
  const int n_around = 12, n_along = 3;
  const double R = 0.5, L = 1.2;
  const fem::Mesh m = fem::make_cylinder_shell({0, 0, 0}, R, L, n_around, n_along);
  const auto& all = m.element_sets.at("all");
  const auto tris = cp::make_interface(m, "", all);
  ASSERT_EQ(tris.size(), 4 * all.size());
  double area = 0;
  for (std::size_t i = 0; i < tris.size(); ++i) {
    const auto& t = tris[i];
    EXPECT_EQ(t.element, all[i / 4]);
    EXPECT_EQ(t.face, -1);
    Vec3 x[3];
    cp::corner_positions(m, {}, t, x);
    const Vec3 an = tri_area_normal(x);
    area += norm(an);
    const Vec3 g = (1.0 / 3.0) * (x[0] + x[1] + x[2]);
    EXPECT_GT(an.x * g.x + an.y * g.y, 0.0);  // outwards, like the shell normal
  }
  const double chord = 2 * R * std::sin(M_PI / n_around);
  EXPECT_NEAR(area, n_around * chord * L, 1e-12);
  // same with no face set and no list: all shell elements
  EXPECT_EQ(cp::make_interface(m, "").size(), tris.size());
}

TEST(Interface, BadInputThrows) {
  const fem::Mesh m = fem::make_block({0, 0, 0}, {1, 1, 1}, 1, 1, 1);
  EXPECT_THROW(cp::make_interface(m, "nosuch"), fdem::InputError);
  EXPECT_THROW(cp::make_interface(m, "zmax", {0}), fdem::InputError);  // a brick is not a shell
  fem::Mesh bad = m;
  bad.face_sets["bad"] = {{0, 6}};
  EXPECT_THROW(cp::make_interface(bad, "bad"), fdem::InputError);
}

TEST(Interface, CornerPositionsFollowDisplacements) {
  const fem::Mesh m = skewed_hex8();
  const auto tris = cp::make_interface(m, "top");
  const Vec3 d{0.1, -0.25, 0.7};
  std::vector<double> u(3 * m.n_nodes());
  for (std::size_t n = 0; n < m.n_nodes(); ++n) {
    u[3 * n] = d.x;
    u[3 * n + 1] = d.y;
    u[3 * n + 2] = d.z;
  }
  for (const auto& t : tris) {
    Vec3 x0[3], x1[3];
    cp::corner_positions(m, {}, t, x0);
    cp::corner_positions(m, u, t, x1);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(norm(x1[c] - x0[c] - d), 0.0, 1e-15);
  }
  // a non-uniform displacement: one node moved, the centre moves by a quarter of it
  std::vector<double> u1(3 * m.n_nodes(), 0.0);
  u1[3 * 4 + 2] = 0.8;  // node 4 (a top corner) up
  Vec3 x0[3], x1[3];
  cp::corner_positions(m, {}, tris[0], x0);
  cp::corner_positions(m, u1, tris[0], x1);
  EXPECT_NEAR(x1[0].z - x0[0].z, 0.8, 1e-15);  // corner 0 of the first triangle is node 4
  EXPECT_NEAR(x1[2].z - x0[2].z, 0.2, 1e-15);
}

TEST(Interface, DistributeForceSumAndMoment) {
  const fem::Mesh m = skewed_hex8();
  const auto tris = cp::make_interface(m, "top");
  ASSERT_EQ(tris.size(), 4u);
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> U(0.0, 1.0), S(-10.0, 10.0);
  for (int it = 0; it < 400; ++it) {
    const auto& t = tris[it % 4];
    Vec3 x[3];
    cp::corner_positions(m, {}, t, x);
    double a = U(rng), b = U(rng);
    if (a + b > 1) { a = 1 - a; b = 1 - b; }
    const Vec3 p = x[0] + a * (x[1] - x[0]) + b * (x[2] - x[0]);
    const Vec3 F{S(rng), S(rng), S(rng)};
    std::vector<std::pair<std::int32_t, Vec3>> out;
    cp::distribute_force(t, x, p, F, out);
    Vec3 sum, mom;
    resultants(m, out, sum, mom);
    EXPECT_LE(norm(sum - F), 1e-14 * norm(F));
    EXPECT_LE(norm(mom - cross(p, F)), 1e-12 * norm(p) * norm(F));
    for (const auto& nf : out) EXPECT_GE(nf.first, 4);  // top-face nodes only
  }
  // about another point too (a shifted origin): preserved as well
  {
    const Vec3 o{3.0, -2.0, 5.0};
    Vec3 x[3];
    cp::corner_positions(m, {}, tris[1], x);
    const Vec3 p = 0.2 * x[0] + 0.5 * x[1] + 0.3 * x[2];
    const Vec3 F{1.0, -2.0, 0.5};
    std::vector<std::pair<std::int32_t, Vec3>> out;
    cp::distribute_force(tris[1], x, p, F, out);
    Vec3 mom{0, 0, 0};
    for (const auto& [n, f] : out) mom += cross(node_x(m, n) - o, f);
    EXPECT_LE(norm(mom - cross(p - o, F)), 1e-12 * norm(p - o) * norm(F));
  }
}

TEST(Interface, DistributeForceCornerAndCentre) {
  const fem::Mesh m = skewed_hex8();
  const auto tris = cp::make_interface(m, "top");
  const Vec3 F{0.3, -1.7, 2.9};
  // at a corner node: everything to that node (exactly)
  for (const auto& t : tris) {
    Vec3 x[3];
    cp::corner_positions(m, {}, t, x);
    for (int c = 0; c < 2; ++c) {
      std::vector<std::pair<std::int32_t, Vec3>> out;
      cp::distribute_force(t, x, x[c], F, out);
      std::map<std::int32_t, Vec3> per_node;
      for (const auto& [n, f] : out) per_node[n] += f;
      ASSERT_EQ(per_node.size(), 1u);
      EXPECT_EQ(per_node.begin()->first, t.nodes[c][0]);
      EXPECT_EQ(per_node.begin()->second.x, F.x);
      EXPECT_EQ(per_node.begin()->second.y, F.y);
      EXPECT_EQ(per_node.begin()->second.z, F.z);
    }
    // at the centre: F/4 to each of the quad's 4 corners
    std::vector<std::pair<std::int32_t, Vec3>> out;
    cp::distribute_force(t, x, x[2], F, out);
    std::map<std::int32_t, Vec3> per_node;
    for (const auto& [n, f] : out) per_node[n] += f;
    ASSERT_EQ(per_node.size(), 4u);
    for (const auto& [n, f] : per_node) {
      EXPECT_GE(n, 4);
      EXPECT_NEAR(norm(f - 0.25 * F), 0.0, 1e-15);
    }
  }
  // on an edge midpoint between two real corners: half to each (the point may be classified
  // as inside the face by round-off, so the other nodes may get a share of order 1e-16 F)
  Vec3 x[3];
  cp::corner_positions(m, {}, tris[0], x);
  std::vector<std::pair<std::int32_t, Vec3>> out;
  cp::distribute_force(tris[0], x, 0.5 * (x[0] + x[1]), F, out);
  std::map<std::int32_t, Vec3> per_node;
  for (const auto& [n, f] : out) per_node[n] += f;
  for (const auto& [n, f] : per_node) {
    const bool edge_node = n == tris[0].nodes[0][0] || n == tris[0].nodes[1][0];
    EXPECT_NEAR(norm(f - (edge_node ? 0.5 : 0.0) * F), 0.0, 1e-14 * norm(F));
  }
  EXPECT_NEAR(norm(per_node[tris[0].nodes[0][0]] - 0.5 * F), 0.0, 1e-14 * norm(F));
  EXPECT_NEAR(norm(per_node[tris[0].nodes[1][0]] - 0.5 * F), 0.0, 1e-14 * norm(F));
}

TEST(Interface, BarycentricOffTriangleUsesClosestPoint) {
  const Vec3 a{0, 0, 0}, b{1, 0, 0}, c{0, 1, 0};
  auto N = cp::barycentric(a, b, c, {0.25, 0.25, 0.7});  // above the face
  EXPECT_NEAR(N[0], 0.5, 1e-15);
  EXPECT_NEAR(N[1], 0.25, 1e-15);
  EXPECT_NEAR(N[2], 0.25, 1e-15);
  N = cp::barycentric(a, b, c, {2.0, -1.0, 0.3});  // beyond vertex b
  EXPECT_EQ(N[1], 1.0);
  N = cp::barycentric(a, b, c, {0.5, -1.0, 0.0});  // outside edge ab
  EXPECT_EQ(N[2], 0.0);
  EXPECT_NEAR(N[0], 0.5, 1e-15);
}

// The surface through element removals (fem.remove in a coupled run): a 3 x 1 x 2 block whose
// top middle element goes at hold 2. Before: the block's 6 faces (22 quads); from hold 2: its top
// face and its two outer side faces (y) leave, its bottom face and the two faces it shared with
// its x neighbours join (the pit's floor and walls), each facing into the pit; with no removals
// the triangles are make_interface's, in its order.
TEST(Interface, SurfaceThroughRemovals) {
  const fem::Mesh m = fem::make_block({0, 0, 0}, {3.0, 1.0, 2.0}, 3, 1, 2);
  // the element whose centre is (1.5, 0.5, 1.5)
  std::int32_t pit = -1;
  for (std::size_t e = 0; e < m.n_elements(); ++e) {
    const std::int32_t* n;
    m.nodes_of(e, n);
    Vec3 c{0, 0, 0};
    for (int k = 0; k < 8; ++k) c += 0.125 * node_x(m, n[k]);
    if (std::abs(c.x - 1.5) < 1e-9 && std::abs(c.z - 1.5) < 1e-9) pit = static_cast<std::int32_t>(e);
  }
  ASSERT_GE(pit, 0);
  std::vector<cp::HoldRange> none;
  const auto plain = cp::make_interface(m, "", {}, {}, none);
  const auto ref = cp::make_interface(m, "");
  ASSERT_EQ(plain.size(), ref.size());
  for (std::size_t t = 0; t < ref.size(); ++t) {
    EXPECT_EQ(plain[t].element, ref[t].element);
    EXPECT_EQ(plain[t].face, ref[t].face);
    EXPECT_TRUE(none[t].at(0) && none[t].at(1000000));
  }
  std::vector<std::int32_t> removed_at(m.n_elements(), -1);
  removed_at[pit] = 2;
  std::vector<cp::HoldRange> holds;
  const auto tris = cp::make_interface(m, "", {}, removed_at, holds);
  ASSERT_EQ(holds.size(), tris.size());
  EXPECT_EQ(ref.size(), 22u * 4u);
  EXPECT_EQ(tris.size(), (22u + 3u) * 4u);  // + the pit's floor and two walls
  auto area_at = [&](int hold, Vec3& an_sum, int& n) {
    double a = 0;
    an_sum = {0, 0, 0};
    n = 0;
    for (std::size_t t = 0; t < tris.size(); ++t) {
      if (!holds[t].at(hold)) continue;
      Vec3 x[3];
      cp::corner_positions(m, {}, tris[t], x);
      const Vec3 an = tri_area_normal(x);
      a += norm(an);
      an_sum += an;
      ++n;
    }
    return a;
  };
  Vec3 s0, s2;
  int n0 = 0, n2 = 0;
  // before: the box 3 x 1 x 2 (area 22); after: minus the pit's top (1) and its y sides (2 x 1),
  // plus its floor (1) and walls (2 x 1): 22 again, and still a closed surface (normals sum to 0)
  EXPECT_NEAR(area_at(0, s0, n0), 22.0, 1e-12);
  EXPECT_NEAR(area_at(1, s0, n0), 22.0, 1e-12);
  EXPECT_NEAR(area_at(2, s2, n2), 22.0, 1e-12);
  EXPECT_EQ(n0, 88);
  EXPECT_EQ(n2, 88);
  EXPECT_NEAR(norm(s0), 0.0, 1e-12);
  EXPECT_NEAR(norm(s2), 0.0, 1e-12);
  for (std::size_t t = 0; t < tris.size(); ++t) {
    if (holds[t].from != 2) continue;  // the pit's new faces: of its neighbours, facing into the pit
    EXPECT_NE(tris[t].element, pit);
    EXPECT_EQ(holds[t].until, cp::HoldRange::kForever);
    Vec3 x[3];
    cp::corner_positions(m, {}, tris[t], x);
    const Vec3 mid = (1.0 / 3.0) * (x[0] + x[1] + x[2]);
    EXPECT_GT(dot(tri_area_normal(x), Vec3{1.5, 0.5, 1.5} - mid), 0.0);
  }
  for (std::size_t t = 0; t < tris.size(); ++t)
    if (tris[t].element == pit) EXPECT_EQ(holds[t].until, 2);  // the pit's own faces, until hold 2
}
