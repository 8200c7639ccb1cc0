#pragma once
// Contact history records: the state of one contact keyed by what touches what, used to carry
// history across neighbour-list rebuilds, migrations and checkpoints.
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "dem/contact_law.hpp"

namespace fdem {

/// kind 0: particle-particle (a < b, particle ids); kind 1: particle-wall (a particle id,
/// b wall index, sub the wall's triangle index or -1).
struct ContactRecord {
  std::int64_t a = 0, b = 0;
  std::int32_t kind = 0, sub = -1;
  ContactState state;
};

/// Key of a contact record, unique over the run.
struct ContactKey {
  std::int64_t a, b;
  std::int32_t kind, sub;
  bool operator==(const ContactKey& o) const {
    return a == o.a && b == o.b && kind == o.kind && sub == o.sub;
  }
};
struct ContactKeyHash {
  std::size_t operator()(const ContactKey& k) const {
    std::uint64_t h = static_cast<std::uint64_t>(k.a) * 0x9E3779B97F4A7C15ull;
    h ^= static_cast<std::uint64_t>(k.b) + 0x7F4A7C159E3779B9ull + (h << 6) + (h >> 2);
    h ^= (static_cast<std::uint64_t>(k.kind) << 32 | static_cast<std::uint32_t>(k.sub)) +
         (h << 6) + (h >> 2);
    return static_cast<std::size_t>(h);
  }
};

using HistoryMap = std::unordered_map<ContactKey, ContactState, ContactKeyHash>;

inline ContactKey key_of(const ContactRecord& r) { return {r.a, r.b, r.kind, r.sub}; }

}  // namespace fdem
