#pragma once
// ParticleStore: the DEM spheres of one rank in structure-of-arrays form.
//
// Ownership rule (the one place it is written): indices [0, n_owned) are the particles this
// rank owns (their centres lie in its subdomain); indices [n_owned, size()) are ghosts, copies
// of neighbours' particles within the ghost layer, refreshed every step by the halo. Only owned
// particles are integrated, output and checkpointed; forces accumulated on ghosts are discarded.
//
// Units SI: positions m, velocities m/s, angular velocities rad/s, forces N, torques N m,
// radii m, masses kg, moments of inertia kg m^2.
#include <algorithm>
#include <cstdint>
#include <vector>

#include "base/vec3.hpp"

namespace fdem {

/// Blocked degrees of freedom (bit set). A blocked DOF keeps its velocity (YADE's blockedDOFs):
/// zero for a fixed particle, or the prescribed velocity it was given.
enum Dof : std::uint8_t {
  kDofX = 1, kDofY = 2, kDofZ = 4, kDofRX = 8, kDofRY = 16, kDofRZ = 32,
  kDofAll = 63
};

/// An order key not yet assigned (the DemEngine assigns one from the position it first sees).
constexpr std::int64_t kNoKey = -1;

struct ParticleStore {
  // Per-particle fields, one array each.
  std::vector<Vec3> x;      // centre position
  std::vector<Vec3> v;      // velocity (at the half step of the leapfrog)
  std::vector<Vec3> w;      // angular velocity
  std::vector<Vec3> f;      // force of the current step (contacts + walls + gravity)
  std::vector<Vec3> t;      // torque of the current step
  std::vector<Vec3> x0;     // reference position for the displacement field
  std::vector<double> r;    // radius
  std::vector<double> m;    // mass
  std::vector<std::int64_t> id;   // global id, unique over all ranks, never reused
  std::vector<std::int32_t> mat;  // material index into the MaterialTable
  std::vector<std::uint8_t> blocked;  // Dof bit set
  std::vector<std::int64_t> key;  // order key (kNoKey until the engine assigns it; see order_key)

  std::size_t n_owned = 0;

  std::size_t size() const { return x.size(); }
  std::size_t n_ghost() const { return x.size() - n_owned; }

  /// Append one particle (as owned if no ghosts are present yet, else as a ghost).
  void push_back(const Vec3& xi, const Vec3& vi, const Vec3& wi, double ri, double mi,
                 std::int64_t idi, std::int32_t mati, std::uint8_t blk, const Vec3& x0i,
                 std::int64_t keyi = kNoKey) {
    x.push_back(xi); v.push_back(vi); w.push_back(wi); f.push_back({}); t.push_back({});
    x0.push_back(x0i); r.push_back(ri); m.push_back(mi); id.push_back(idi); mat.push_back(mati);
    blocked.push_back(blk); key.push_back(keyi);
  }
  void resize(std::size_t n) {
    x.resize(n); v.resize(n); w.resize(n); f.resize(n); t.resize(n); x0.resize(n);
    r.resize(n); m.resize(n); id.resize(n); mat.resize(n); blocked.resize(n); key.resize(n, kNoKey);
  }
  void reserve(std::size_t n) {
    x.reserve(n); v.reserve(n); w.reserve(n); f.reserve(n); t.reserve(n); x0.reserve(n);
    r.reserve(n); m.reserve(n); id.reserve(n); mat.reserve(n); blocked.reserve(n); key.reserve(n);
  }
  /// Capacity for `n` particles: if the arrays hold fewer, they grow to n + n / 16 (not
  /// push_back's doubling, which would leave up to twice the store allocated).
  void make_room(std::size_t n) {
    if (x.capacity() < n) reserve(n + n / 16);
  }
  /// Drop all ghosts.
  void clear_ghosts() { resize(n_owned); }
  /// Copy particle `from` over slot `to` (both indices valid).
  void copy(std::size_t from, std::size_t to) {
    x[to] = x[from]; v[to] = v[from]; w[to] = w[from]; f[to] = f[from]; t[to] = t[from];
    x0[to] = x0[from]; r[to] = r[from]; m[to] = m[from]; id[to] = id[from]; mat[to] = mat[from];
    blocked[to] = blocked[from]; key[to] = key[from];
  }
  /// Reorder the owned particles by the permutation `perm` (new i = old perm[i]); no ghosts.
  void permute_owned(const std::vector<std::size_t>& perm);
};

/// The order key of a particle at `x` in the domain [lo, hi]: its Morton (Z-curve) index on a
/// grid of 2^17 cells per direction (51 bits: exact as a double in the halo's buffers). The
/// engine keeps particles and contact pairs ordered by (key, id), so neighbours in space are
/// neighbours in memory; the key is given once (where the engine first sees the particle) and
/// then travels with it (migration, ghosts, checkpoints), so the order, and with it every sum's
/// rounding, is the same on any number of ranks and across a restart. Positions outside the
/// domain are clamped to its faces.
std::int64_t order_key(const Vec3& x, const Vec3& lo, const Vec3& hi);

/// The engine's particle order: by order key, then by id (ids are unique). Owned particles are
/// kept in it, and contact pairs by (a, then b) in it (dem/neighbor.hpp).
inline bool key_id_before(std::int64_t key_a, std::int64_t id_a, std::int64_t key_b, std::int64_t id_b) {
  return key_a < key_b || (key_a == key_b && id_a < id_b);
}

/// Sorts the indices `order` of particles by (key, id). The order is unique (ids are), so the
/// result does not depend on how it is reached: a prefix already in order (the owned particles
/// of the last rebuild that stayed, before those that arrived; the owned particles before the
/// ghosts) is kept and only the rest sorted and merged in, O(n + t log t) for a tail of t.
template <class Index>
void sort_by_key_id(std::vector<Index>& order, const std::int64_t* key, const std::int64_t* id) {
  auto before = [&](Index a, Index b) { return key_id_before(key[a], id[a], key[b], id[b]); };
  const auto mid = std::is_sorted_until(order.begin(), order.end(), before);
  if (mid == order.end()) return;
  std::sort(mid, order.end(), before);
  std::inplace_merge(order.begin(), mid, order.end(), before);
}

/// Moment of inertia of a solid sphere.
inline double sphere_inertia(double m, double r) { return 0.4 * m * r * r; }

}  // namespace fdem
