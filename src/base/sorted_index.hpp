#pragma once
// The position of a value in an ascending vector (a part's local index of a whole mesh's index).
#include <algorithm>
#include <cstdint>
#include <vector>

namespace fdem {

/// The index of `x` in the ascending `v`, -1 if absent.
template <class T, class U>
std::int32_t find_sorted(const std::vector<T>& v, U x) {
  const auto it = std::lower_bound(v.begin(), v.end(), static_cast<T>(x));
  return it != v.end() && *it == static_cast<T>(x) ? static_cast<std::int32_t>(it - v.begin()) : -1;
}

}  // namespace fdem
