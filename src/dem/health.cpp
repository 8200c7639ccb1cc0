#include "dem/health.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <tuple>
#include <unordered_map>

namespace fdem {

OverlapPair deepest_overlap(const std::vector<Vec3>& x, const std::vector<double>& r, double limit) {
  OverlapPair best;
  const std::size_t n = std::min(x.size(), r.size());
  double rmax = 0;
  for (std::size_t i = 0; i < n; ++i)
    if (std::isfinite(r[i])) rmax = std::max(rmax, r[i]);
  if (n < 2 || !(rmax > 0)) return best;
  const double h = 2 * rmax;  // cell size: every touching pair is in neighbouring cells
  auto cell = [&](const Vec3& p, int d) { return static_cast<std::int64_t>(std::floor(p[d] / h)); };
  auto key = [](std::int64_t a, std::int64_t b, std::int64_t c) {
    return static_cast<std::uint64_t>(a & 0x1fffff) | (static_cast<std::uint64_t>(b & 0x1fffff) << 21) |
           (static_cast<std::uint64_t>(c & 0x1fffff) << 42);
  };
  std::unordered_map<std::uint64_t, std::vector<std::size_t>> cells;
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(x[i].x) || !std::isfinite(x[i].y) || !std::isfinite(x[i].z)) continue;
    cells[key(cell(x[i], 0), cell(x[i], 1), cell(x[i], 2))].push_back(i);
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(x[i].x) || !std::isfinite(x[i].y) || !std::isfinite(x[i].z)) continue;
    const std::int64_t c0 = cell(x[i], 0), c1 = cell(x[i], 1), c2 = cell(x[i], 2);
    for (std::int64_t a = c0 - 1; a <= c0 + 1; ++a)
      for (std::int64_t b = c1 - 1; b <= c1 + 1; ++b)
        for (std::int64_t c = c2 - 1; c <= c2 + 1; ++c) {
          auto it = cells.find(key(a, b, c));
          if (it == cells.end()) continue;
          for (std::size_t j : it->second) {
            if (j <= i) continue;
            // (the key wraps around at 2^21 cells: a far particle in the same bucket has no overlap)
            const double delta = r[i] + r[j] - norm(x[j] - x[i]);
            const double q = delta / std::min(r[i], r[j]);
            if (!(q > limit)) continue;
            if (q > best.ratio || (q == best.ratio && std::tie(i, j) < std::tie(best.i, best.j))) best = {i, j, q};
          }
        }
  }
  return best;
}

}  // namespace fdem
