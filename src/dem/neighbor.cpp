#include "dem/neighbor.hpp"

#include "dem/particles.hpp"  // key_id_before

#include <algorithm>
#include <cmath>
#include <numeric>

namespace fdem {

namespace {

// Sort raw oriented pairs canonically: bucket by the rank of particle a among all local particles
// in (key, id) order (counting sort), then sort each bucket by (key, id) of b.
void canonical_sort(const std::vector<std::int64_t>& id, const std::vector<std::int64_t>& key,
                    std::vector<std::uint32_t>& ra, std::vector<std::uint32_t>& rb, PairList& out) {
  const std::size_t n = id.size();
  auto before = [&](std::uint32_t i, std::uint32_t j) {
    return key_id_before(key[i], id[i], key[j], id[j]);
  };
  std::vector<std::uint32_t> order(n);
  std::iota(order.begin(), order.end(), 0u);
  sort_by_key_id(order, key.data(), id.data());  // the owned particles are in order already
  std::vector<std::uint32_t> rank(n);
  for (std::size_t k = 0; k < n; ++k) rank[order[k]] = static_cast<std::uint32_t>(k);
  std::vector<std::size_t> start(n + 1, 0);
  for (std::uint32_t a : ra) ++start[rank[a] + 1];
  for (std::size_t k = 0; k < n; ++k) start[k + 1] += start[k];
  out.a.resize(ra.size());
  out.b.resize(ra.size());
  std::vector<std::size_t> fill(start.begin(), start.end() - 1);
  for (std::size_t k = 0; k < ra.size(); ++k) {
    const std::size_t pos = fill[rank[ra[k]]]++;
    out.a[pos] = ra[k];
    out.b[pos] = rb[k];
  }
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t s = start[k], e = start[k + 1];
    if (e - s > 1) std::sort(out.b.begin() + s, out.b.begin() + e, before);
  }
}

inline void consider(std::uint32_t i, std::uint32_t j, const std::vector<Vec3>& x,
                     const std::vector<double>& r, const std::vector<std::int64_t>& id,
                     std::size_t n_owned, double skin, std::vector<std::uint32_t>& ra,
                     std::vector<std::uint32_t>& rb) {
  if (i >= n_owned && j >= n_owned) return;
  const double reach = r[i] + r[j] + skin;
  const Vec3 d = x[j] - x[i];
  if (norm2(d) >= reach * reach) return;
  if (id[i] < id[j]) { ra.push_back(i); rb.push_back(j); }
  else { ra.push_back(j); rb.push_back(i); }
}

}  // namespace

void build_pairs(const std::vector<Vec3>& x, const std::vector<double>& r,
                 const std::vector<std::int64_t>& id, const std::vector<std::int64_t>& key,
                 std::size_t n_owned, double skin, PairList& out) {
  const std::size_t n = x.size();
  out.a.clear();
  out.b.clear();
  if (n == 0) return;
  Vec3 lo = x[0], hi = x[0];
  double rmax = 0;
  for (std::size_t i = 0; i < n; ++i) {
    for (int d = 0; d < 3; ++d) { lo[d] = std::min(lo[d], x[i][d]); hi[d] = std::max(hi[d], x[i][d]); }
    rmax = std::max(rmax, r[i]);
  }
  double cell = 2 * rmax + skin;
  int nc[3];
  auto count_cells = [&]() {
    double total = 1;
    for (int d = 0; d < 3; ++d) {
      nc[d] = std::max(1, static_cast<int>(std::floor((hi[d] - lo[d]) / cell)) + 1);
      total *= nc[d];
    }
    return total;
  };
  // Keep the cell count at most ~2 per particle (sparse clouds in a big box).
  while (count_cells() > 2.0 * n + 27) cell *= 1.26;
  const double inv = 1.0 / cell;
  const std::size_t ncell = static_cast<std::size_t>(nc[0]) * nc[1] * nc[2];
  std::vector<std::uint32_t> cell_of(n);
  std::vector<std::uint32_t> start(ncell + 1, 0);
  for (std::size_t i = 0; i < n; ++i) {
    int c[3];
    for (int d = 0; d < 3; ++d)
      c[d] = std::min(nc[d] - 1, static_cast<int>((x[i][d] - lo[d]) * inv));
    cell_of[i] = static_cast<std::uint32_t>(c[0] + nc[0] * (c[1] + static_cast<std::size_t>(nc[1]) * c[2]));
    ++start[cell_of[i] + 1];
  }
  for (std::size_t c = 0; c < ncell; ++c) start[c + 1] += start[c];
  std::vector<std::uint32_t> items(n);
  {
    std::vector<std::uint32_t> fill(start.begin(), start.end() - 1);
    for (std::size_t i = 0; i < n; ++i) items[fill[cell_of[i]]++] = static_cast<std::uint32_t>(i);
  }
  std::vector<std::uint32_t> ra, rb;
  ra.reserve(8 * n);
  rb.reserve(8 * n);
  // Half stencil: the cell itself plus the 13 "forward" neighbours.
  static const int stencil[13][3] = {{1, 0, 0},  {-1, 1, 0}, {0, 1, 0},  {1, 1, 0},  {-1, -1, 1},
                                     {0, -1, 1}, {1, -1, 1}, {-1, 0, 1}, {0, 0, 1},  {1, 0, 1},
                                     {-1, 1, 1}, {0, 1, 1},  {1, 1, 1}};
  for (int cz = 0; cz < nc[2]; ++cz)
    for (int cy = 0; cy < nc[1]; ++cy)
      for (int cx = 0; cx < nc[0]; ++cx) {
        const std::size_t c = cx + nc[0] * (cy + static_cast<std::size_t>(nc[1]) * cz);
        for (std::uint32_t s = start[c]; s < start[c + 1]; ++s) {
          const std::uint32_t i = items[s];
          for (std::uint32_t t = s + 1; t < start[c + 1]; ++t)
            consider(i, items[t], x, r, id, n_owned, skin, ra, rb);
          for (const auto& o : stencil) {
            const int ox = cx + o[0], oy = cy + o[1], oz = cz + o[2];
            if (ox < 0 || oy < 0 || oz < 0 || ox >= nc[0] || oy >= nc[1] || oz >= nc[2]) continue;
            const std::size_t c2 = ox + nc[0] * (oy + static_cast<std::size_t>(nc[1]) * oz);
            for (std::uint32_t t = start[c2]; t < start[c2 + 1]; ++t)
              consider(i, items[t], x, r, id, n_owned, skin, ra, rb);
          }
        }
      }
  canonical_sort(id, key, ra, rb, out);
}

void build_pairs_brute(const std::vector<Vec3>& x, const std::vector<double>& r,
                       const std::vector<std::int64_t>& id, const std::vector<std::int64_t>& key,
                       std::size_t n_owned, double skin, PairList& out) {
  std::vector<std::uint32_t> ra, rb;
  for (std::uint32_t i = 0; i < x.size(); ++i)
    for (std::uint32_t j = i + 1; j < x.size(); ++j) consider(i, j, x, r, id, n_owned, skin, ra, rb);
  canonical_sort(id, key, ra, rb, out);
}

}  // namespace fdem
