#pragma once
// A hash grid of triangles for candidate searches (rigid facet walls, the FE-DE interface): cubic
// cells of side h from an origin, each cell listing the triangles entered into it, keyed by its
// three cell indices packed 21 bits each into one 64-bit key (indices wrap modulo 2^21: distant
// cells may share a list, which only adds candidates).
#include <cmath>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "base/vec3.hpp"

namespace fdem {

struct FacetGrid {
  double h = 0;   // cell side (m); 0: no grid
  Vec3 origin;    // a cell corner
  std::unordered_map<std::uint64_t, std::vector<std::int32_t>> cells;

  /// Index of the cell holding coordinate c along axis d.
  std::int64_t cell(double c, int d) const { return static_cast<std::int64_t>(std::floor((c - origin[d]) / h)); }
  static std::uint64_t key(std::int64_t i, std::int64_t j, std::int64_t k) {
    return static_cast<std::uint64_t>((i & 0x1FFFFF) | ((j & 0x1FFFFF) << 21) | ((k & 0x1FFFFF) << 42));
  }
  /// Enter triangle t into the cells a[d] <= index[d] <= b[d].
  void add(const std::int64_t a[3], const std::int64_t b[3], std::int32_t t) {
    for (std::int64_t i = a[0]; i <= b[0]; ++i)
      for (std::int64_t j = a[1]; j <= b[1]; ++j)
        for (std::int64_t k = a[2]; k <= b[2]; ++k) cells[key(i, j, k)].push_back(t);
  }
  /// The triangles of the cell holding x, in the order entered (nullptr: none).
  const std::vector<std::int32_t>* at(const Vec3& x) const {
    const auto it = cells.find(key(cell(x.x, 0), cell(x.y, 1), cell(x.z, 2)));
    return it == cells.end() ? nullptr : &it->second;
  }
};

}  // namespace fdem
