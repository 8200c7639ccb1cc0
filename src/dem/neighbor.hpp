#pragma once
// Linked-cell neighbour search with a Verlet skin (no MPI).
//
// build_pairs() returns the candidate contact pairs among the local particles (owned and
// ghosts) whose surfaces are closer than `skin`, keeping only pairs with at least one owned
// particle. Pairs are oriented (id[a] < id[b]) and sorted by (key[a], id[a], key[b], id[b]),
// key the particles' order keys (particles.hpp, order_key: fixed per particle, following space):
// accumulating forces in this order sums every particle's contacts in an order fixed by its
// partners' (key, id), the same on any number of ranks (DESIGN.md section 3, determinism), and
// walks the particles in space order (cache locality).
#include <cstdint>
#include <vector>

#include "base/vec3.hpp"

namespace fdem {

struct PairList {
  std::vector<std::uint32_t> a, b;  // local indices, id[a] < id[b]; (key, id) order
  std::size_t size() const { return a.size(); }
};

void build_pairs(const std::vector<Vec3>& x, const std::vector<double>& r,
                 const std::vector<std::int64_t>& id, const std::vector<std::int64_t>& key,
                 std::size_t n_owned, double skin, PairList& out);

/// Brute-force reference of build_pairs (O(N^2)), for tests.
void build_pairs_brute(const std::vector<Vec3>& x, const std::vector<double>& r,
                       const std::vector<std::int64_t>& id, const std::vector<std::int64_t>& key,
                       std::size_t n_owned, double skin, PairList& out);

}  // namespace fdem
