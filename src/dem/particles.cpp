#include "dem/particles.hpp"

#include <algorithm>
#include <cmath>

namespace fdem {

// The permuted values are copied back into `a`, which keeps its capacity (the room for the
// ghosts): the temporary of one field is freed and reused by the next, none of the store's
// arrays is allocated again.
template <class T>
static void apply_perm(std::vector<T>& a, const std::vector<std::size_t>& perm) {
  std::vector<T> b(perm.size());
  for (std::size_t i = 0; i < perm.size(); ++i) b[i] = a[perm[i]];
  a.resize(b.size());
  std::copy(b.begin(), b.end(), a.begin());
}

void ParticleStore::permute_owned(const std::vector<std::size_t>& perm) {
  clear_ghosts();
  // A compaction (perm increasing: the particles that stay, in their order; the common case of a
  // migration) moves them down in place; the identity moves nothing.
  bool increasing = true;
  for (std::size_t i = 1; i < perm.size() && increasing; ++i) increasing = perm[i] > perm[i - 1];
  if (increasing && (perm.empty() || perm.back() < size())) {
    for (std::size_t j = 0; j < perm.size(); ++j)
      if (perm[j] != j) copy(perm[j], j);  // (perm[j] > j: slot perm[j] is not written yet)
    resize(perm.size());
    return;
  }
  apply_perm(x, perm); apply_perm(v, perm); apply_perm(w, perm); apply_perm(f, perm);
  apply_perm(t, perm); apply_perm(x0, perm); apply_perm(r, perm); apply_perm(m, perm);
  apply_perm(id, perm); apply_perm(mat, perm); apply_perm(blocked, perm);
  apply_perm(key, perm);
}

namespace {
// The 17 low bits of c spread to every third bit.
std::uint64_t spread3(std::uint64_t c) {
  c &= 0x1ffff;
  c = (c | (c << 32)) & 0x1f00000000ffffULL;
  c = (c | (c << 16)) & 0x1f0000ff0000ffULL;
  c = (c | (c << 8)) & 0x100f00f00f00f00fULL;
  c = (c | (c << 4)) & 0x10c30c30c30c30c3ULL;
  c = (c | (c << 2)) & 0x1249249249249249ULL;
  return c;
}
}  // namespace

std::int64_t order_key(const Vec3& x, const Vec3& lo, const Vec3& hi) {
  constexpr double kCells = 131072.0;  // 2^17
  std::uint64_t c[3];
  for (int d = 0; d < 3; ++d) {
    const double ext = hi[d] - lo[d];
    double s = ext > 0 ? (x[d] - lo[d]) / ext * kCells : 0.0;
    if (!(s >= 0)) s = 0;  // below the domain, or NaN (the run-health check reports it)
    c[d] = static_cast<std::uint64_t>(std::min(s, kCells - 1));
  }
  return static_cast<std::int64_t>(spread3(c[0]) | (spread3(c[1]) << 1) | (spread3(c[2]) << 2));
}

}  // namespace fdem
