#pragma once
// Run-health helpers without MPI (the checks themselves: app/engine.cpp, DemEngine::step).
#include <cstddef>
#include <vector>

#include "base/vec3.hpp"

namespace fdem {

/// Two spheres i < j (indices into the arrays) whose overlap r_i + r_j - |x_j - x_i| is
/// `ratio` times the smaller radius.
struct OverlapPair {
  std::size_t i = 0, j = 0;
  double ratio = 0;
};

/// The deepest overlap above `limit` (a fraction of the smaller radius) among the spheres
/// (x, r), the lowest (i, j) on a tie; ratio 0 when there is none. Linked cells: O(n).
OverlapPair deepest_overlap(const std::vector<Vec3>& x, const std::vector<double>& r, double limit);

}  // namespace fdem
