// The coupler's pure parts without MPI: the interface surface (src/coupling/interface_surface),
// the facet contacts (src/coupling/facet_contacts) and the shared closest point with weights
// (src/dem/facet_geometry.hpp).
#include <gtest/gtest.h>

#include <random>

#include "coupling/facet_contacts.hpp"
#include "coupling/interface.hpp"
#include "coupling/interface_surface.hpp"
#include "dem/facet_geometry.hpp"
#include "fem/mesh.hpp"

using fdem::Vec3;
namespace cp = fdem::coupling;
namespace fem = fdem::fem;

namespace {

// The top face of a 2 x 2 x 1 Hex8 block (0..1 x 0..1 x 0..0.5): 4 quads, 16 triangles.
struct Top {
  fem::Mesh mesh = fem::make_block({0, 0, 0}, {1, 1, 0.5}, 2, 2, 1);
  cp::InterfaceSurface surface{mesh, cp::make_interface(mesh, "zmax")};
  std::vector<std::int32_t> all;
  Top() {
    for (std::int32_t t = 0; t < static_cast<std::int32_t>(surface.n_triangles()); ++t) all.push_back(t);
    const std::vector<std::int32_t> nodes = surface.nodes_of(all);
    std::vector<std::int32_t> slot(mesh.n_nodes(), -1);
    for (std::size_t s = 0; s < nodes.size(); ++s) slot[nodes[s]] = static_cast<std::int32_t>(s);
    surface.place_at_fe(all, surface.vertices_of(all), std::vector<Vec3>(nodes.size()), slot);
  }
};

}  // namespace

TEST(InterfaceSurface, VerticesTopologyAndPlanes) {
  Top top;
  const cp::InterfaceSurface& s = top.surface;
  ASSERT_EQ(s.n_triangles(), 16u);
  EXPECT_EQ(s.n_vertices(), 9u + 4u);  // the face's 9 nodes and the 4 quad centres
  int centres = 0, inner = 0, border = 0;
  for (std::int32_t v = 0; v < static_cast<std::int32_t>(s.n_vertices()); ++v)
    if (s.node_count(v) == 4) {
      ++centres;
      EXPECT_EQ(s.node_weight(v), 0.25);
    } else {
      EXPECT_EQ(s.node_count(v), 1);
      EXPECT_EQ(s.node_weight(v), 1.0);
    }
  EXPECT_EQ(centres, 4);
  for (std::size_t t = 0; t < s.n_triangles(); ++t) {
    for (int k = 0; k < 3; ++k) (s.opposite(t)[k] >= 0 ? inner : border) += 1;
    const cp::TrianglePlane& pl = s.plane(t);
    EXPECT_NEAR(pl.normal.z, 1.0, 1e-15);  // out of the block
    EXPECT_NEAR(pl.offset, 0.5, 1e-15);
  }
  EXPECT_EQ(border, 8);  // the square's boundary: 8 quad edges, one triangle each
  EXPECT_EQ(inner, 16 * 3 - 8);
  EXPECT_TRUE(cp::cannot_touch(s.plane(0), {0.1, 0.1, 0.7}, 0.1));
  EXPECT_FALSE(cp::cannot_touch(s.plane(0), s.plane(0).centroid + Vec3{0, 0, 0.05}, 0.1));
}

TEST(InterfaceSurface, ExtrapolatesFromTheFePositions) {
  Top top;
  cp::InterfaceSurface& s = top.surface;
  const std::vector<std::int32_t> verts = s.vertices_of(top.all);
  const Vec3 x0 = s.position(verts[3]);
  s.extrapolate(verts, 0.1);  // at rest: stays
  EXPECT_EQ(s.position(verts[3]).z, x0.z);
  s.return_to_fe(verts, top.all);
  EXPECT_EQ(s.position(verts[3]).x, x0.x);
}

TEST(FacetGeometry, WeightsMatchTheClosestPoint) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 2.0);
  const Vec3 a{0, 0, 0}, b{1.0, 0.1, 0.2}, c{0.2, 0.9, -0.1};
  for (int k = 0; k < 2000; ++k) {
    const Vec3 p{u(rng), u(rng), u(rng)};
    int r1 = -1, r2 = -2;
    std::array<double, 3> N;
    const Vec3 q1 = fdem::closest_on_triangle(p, a, b, c, r1);
    const Vec3 q2 = fdem::closest_on_triangle(p, a, b, c, r2, N);
    // The same point and region, bit for bit, with and without the weights.
    ASSERT_EQ(r1, r2);
    ASSERT_EQ(q1.x, q2.x);
    ASSERT_EQ(q1.y, q2.y);
    ASSERT_EQ(q1.z, q2.z);
    const Vec3 back = N[0] * a + N[1] * b + N[2] * c;
    EXPECT_NEAR(norm(back - q1), 0.0, 1e-12);
    EXPECT_NEAR(N[0] + N[1] + N[2], 1.0, 1e-14);
    const std::array<double, 3> B = fdem::triangle_barycentric(a, b, c, p);
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(N[i], B[i], 1e-12);
    // Exact on an edge (the opposite N is 0) and at a vertex (its N is 1).
    if (r1 >= 1 && r1 <= 3) EXPECT_EQ(N[(r1 + 1) % 3], 0.0);
    if (r1 >= 4) EXPECT_EQ(N[r1 - 4], 1.0);
  }
}

TEST(FacetContacts, OneContactOnAFlatSurface) {
  Top top;
  const cp::InterfaceSurface& s = top.surface;
  // A sphere resting on the centre node (0.5, 0.5): 8 triangles meet there, one contact counts.
  fdem::ParticleStore p;
  const double r = 0.05;
  const Vec3 x{0.5, 0.5, 0.5 + 0.99 * r};
  p.push_back(x, {}, {}, r, 1.0, 42, 0, 0, x);
  p.n_owned = 1;
  cp::FacetContacts fc;
  fc.build(p, s, top.all, {0, 0, 0}, {1, 1, 1}, 0.01, {});
  EXPECT_EQ(fc.n_candidates(), 8u);
  fc.scan(p, s, 0.0, 0.0);
  fc.select(p, s);
  const cp::TouchingContacts& tc = fc.touching();
  ASSERT_EQ(tc.particle.size(), 1u);
  ASSERT_EQ(tc.begin[1] - tc.begin[0], 8u);
  int accepted = 0;
  for (std::uint32_t u = tc.begin[0]; u < tc.begin[1]; ++u)
    if (tc.accept[u]) {
      ++accepted;
      EXPECT_EQ(tc.weight[u], 1.0);
      EXPECT_NEAR(tc.geo[u].n.z, -1.0, 1e-15);
      EXPECT_NEAR(tc.geo[u].delta, 0.01 * r, 1e-15);
    }
  EXPECT_EQ(accepted, 1);
  EXPECT_EQ(fc.n_active(), 1u);
  std::vector<fdem::ContactRecord> out;
  fc.save_history(p, out);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].a, 42);
  EXPECT_EQ(out[0].kind, 2);
}

// set_active: a triangle taken out shares no edge with the rest -- the opposite vertex across an
// edge it shared becomes -1 (a border), and back when it is active again; the topology's edge
// groups follow, and the search for triangles near a box skips it.
TEST(InterfaceSurface, ActiveTrianglesOnly) {
  Top top;
  cp::InterfaceSurface& s = top.surface;
  const auto borders = [&]() {
    int b = 0;
    for (std::size_t t = 0; t < s.n_triangles(); ++t)
      if (s.active(t))
        for (int k = 0; k < 3; ++k) b += s.opposite(t)[k] == -1;
    return b;
  };
  ASSERT_EQ(borders(), 8);
  EXPECT_EQ(s.n_active_triangles(), 16u);
  // take out the 4 triangles of the first quad: its 4 inner edges (2 shared with the other quads)
  // become borders of the triangles next to them; the rest keep theirs
  std::vector<std::uint8_t> a(16, 1);
  for (int t = 0; t < 4; ++t) a[t] = 0;
  s.set_active(a);
  EXPECT_EQ(s.n_active_triangles(), 12u);
  EXPECT_EQ(borders(), 8 - 2 + 2);  // the quad's 2 outer border edges gone, its 2 shared edges now borders
  for (std::int32_t t : s.triangles_near({-1, -1, -1}, {2, 2, 2}, 0)) EXPECT_GE(t, 4);
  EXPECT_EQ(s.triangles_near({-1, -1, -1}, {2, 2, 2}, 0).size(), 12u);
  s.set_active(std::vector<std::uint8_t>(16, 1));
  EXPECT_EQ(borders(), 8);
  EXPECT_EQ(s.triangles_near({-1, -1, -1}, {2, 2, 2}, 0).size(), 16u);
}
