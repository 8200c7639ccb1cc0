#pragma once
// Fixed-point (128-bit integer) representation of doubles behind the exact sums (base/exact_sum.hpp):
// conversion to and from 2^-shift units and the four-limb split. No MPI: usable by the physics
// layers (dem, fem) that accumulate local sums; the reduction across ranks is in exact_sum.hpp.

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <vector>

namespace fdem::exact {

using Int = __int128;

constexpr int kForceShift = 64;
constexpr int kLimbs = 4;

/// 2^k as a double, for -1022 <= k <= 1023 (exact; no libm call).
inline double pow2(int k) {
  const std::uint64_t b = static_cast<std::uint64_t>(k + 1023) << 52;
  double d;
  std::memcpy(&d, &b, sizeof d);
  return d;
}

/// x in units of 2^-shift, truncated toward zero: static_cast<Int>(std::ldexp(x, shift)) for
/// |x| 2^shift < 2^126, without branches or libm / libgcc calls (this is on the hot path of every
/// interface contact and FE assembly): with h = trunc(x 2^(shift-63)) (one hardware conversion,
/// |h| < 2^63) and the exact remainder lo = x - h 2^(63-shift), |lo 2^shift| < 2^63 and lo has
/// the sign of x, so trunc(x 2^shift) = h 2^63 + trunc(lo 2^shift). Powers of two scale exactly
/// (a product that underflows only for |x 2^shift| < 1, where the result is 0 either way).
inline Int to_fixed(double x, int shift = kForceShift) {
  const std::int64_t h = static_cast<std::int64_t>(x * pow2(shift - 63));
  const double lo = x - static_cast<double>(h) * pow2(63 - shift);
  return static_cast<Int>(h) * (static_cast<Int>(1) << 63) + static_cast<std::int64_t>(lo * pow2(shift));
}
inline double from_fixed(Int v, int shift = kForceShift) { return std::ldexp(static_cast<double>(v), -shift); }

/// The shift that puts terms up to |x| <= max_abs at 2^100: sums of up to 2^26 of them fit.
inline int shift_for(double max_abs) { return max_abs > 0 && std::isfinite(max_abs) ? 100 - std::ilogb(max_abs) : 0; }

/// v = l[0] + l[1] 2^32 + l[2] 2^64 + l[3] 2^96 with l[0..2] in [0, 2^32) and l[3] signed.
inline void split(Int v, double* l) {
  const Int mask = (static_cast<Int>(1) << 32) - 1;
  l[0] = static_cast<double>(static_cast<std::int64_t>(v & mask));
  l[1] = static_cast<double>(static_cast<std::int64_t>((v >> 32) & mask));
  l[2] = static_cast<double>(static_cast<std::int64_t>((v >> 64) & mask));
  l[3] = static_cast<double>(static_cast<std::int64_t>(v >> 96));
}
/// Inverse of split for sums of split values (each limb an exact integer below 2^53).
inline Int merge(const double* l) {
  return static_cast<Int>(static_cast<std::int64_t>(l[0])) + (static_cast<Int>(static_cast<std::int64_t>(l[1])) << 32) +
         (static_cast<Int>(static_cast<std::int64_t>(l[2])) << 64) +
         static_cast<Int>(static_cast<std::int64_t>(l[3])) * (static_cast<Int>(1) << 96);  // l[3] < 0: no <<
}

}  // namespace fdem::exact
