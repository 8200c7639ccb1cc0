// Mesh generators: a block of Hex8 bricks (optionally with a void box), a flat plate and a
// cylindrical shell of Shell4 elements. The geogrid generator: mesh_geogrid.cpp.
#include <cmath>
#include <string>

#include "base/errors.hpp"
#include "fem/mesh.hpp"
#include "fem/mesh_detail.hpp"

namespace fdem::fem {
namespace {

/// Face sets of the six sides of a structured brick index space, and node sets xmin..zmax.
const char* const kSideNames[6] = {"xmin", "xmax", "ymin", "ymax", "zmin", "zmax"};

}  // namespace

Mesh make_cylinder_shell(const std::array<double, 3>& base, double radius, double length, int n_around, int n_along,
                         int axis) {
  if (!(radius > 0) || !(length > 0) || n_around < 3 || n_along < 1)
    throw InputError("cylinder", 0, "radius and length must be positive, n_around >= 3, n_along >= 1");
  if (axis < 0 || axis > 2) throw InputError("cylinder", 0, "the axis must be 0, 1 or 2");
  // angle a from in-plane axis p towards q, (p, q, axis) right-handed: e_theta x e_axis = e_r
  const int p = (axis + 1) % 3, q = (axis + 2) % 3;
  Mesh m;
  m.dim = 3;
  for (int j = 0; j <= n_along; ++j)
    for (int i = 0; i < n_around; ++i) {
      const double a = 2 * M_PI * i / n_around;
      std::array<double, 3> x = base;
      x[p] += radius * std::cos(a);
      x[q] += radius * std::sin(a);
      x[axis] += length * j / n_along;
      m.node_id.push_back(static_cast<std::int64_t>(m.node_id.size()) + 1);
      m.coords.insert(m.coords.end(), {x[0], x[1], x[2]});
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
    detail::append_points(g[c], lo[c], hi[c], n[c]);
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

Mesh make_shell_plate(const std::array<double, 3>& lo, const std::array<double, 3>& hi, int flat_axis, int n_a, int n_b) {
  if (flat_axis < 0 || flat_axis > 2) throw InputError("plate", 0, "the flat axis must be 0, 1 or 2");
  if (n_a < 1 || n_b < 1) throw InputError("plate", 0, "the divisions in the plane must be at least 1");
  const int a = (flat_axis + 1) % 3, b = (flat_axis + 2) % 3;  // e_a x e_b = e_flat: the normal's direction
  if (!(hi[a] > lo[a]) || !(hi[b] > lo[b]))
    throw InputError("plate", 0, "the plate needs a positive extent in both in-plane directions");
  std::vector<double> ga{lo[a]}, gb{lo[b]};
  detail::append_points(ga, lo[a], hi[a], n_a);
  detail::append_points(gb, lo[b], hi[b], n_b);
  Mesh m;
  m.dim = 3;
  auto nidx = [&](int i, int j) { return static_cast<std::int32_t>(i + (n_a + 1) * j); };
  for (int j = 0; j <= n_b; ++j)
    for (int i = 0; i <= n_a; ++i) {
      std::array<double, 3> x{};
      x[flat_axis] = lo[flat_axis];
      x[a] = ga[i];
      x[b] = gb[j];
      m.node_id.push_back(static_cast<std::int64_t>(m.node_id.size()) + 1);
      m.coords.insert(m.coords.end(), {x[0], x[1], x[2]});
      if (i == 0) m.node_sets[kSideNames[2 * a]].push_back(nidx(i, j));
      if (i == n_a) m.node_sets[kSideNames[2 * a + 1]].push_back(nidx(i, j));
      if (j == 0) m.node_sets[kSideNames[2 * b]].push_back(nidx(i, j));
      if (j == n_b) m.node_sets[kSideNames[2 * b + 1]].push_back(nidx(i, j));
    }
  for (int j = 0; j < n_b; ++j)
    for (int i = 0; i < n_a; ++i) {
      const auto e = static_cast<std::int32_t>(m.n_elements());
      // counter-clockwise about +e_flat: the element normal points along +flat_axis
      m.add_element(e + 1, ElemType::kShell4, {nidx(i, j), nidx(i + 1, j), nidx(i + 1, j + 1), nidx(i, j + 1)}, 0);
      m.element_sets["all"].push_back(e);
    }
  return m;
}

}  // namespace fdem::fem
