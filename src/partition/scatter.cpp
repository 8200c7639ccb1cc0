#include "partition/scatter.hpp"

#include <algorithm>
#include <numeric>
#include <type_traits>
#include <unordered_map>

#include "base/alltoall.hpp"

namespace fdem {

namespace {

/// One particle as it travels (every field a ParticleStore keeps but the step's force and torque).
struct ParticleRow {
  Vec3 x, v, w, x0;
  double r, m;
  std::int64_t id;
  std::int32_t mat;
  std::uint8_t blocked;
};
static_assert(std::is_trivially_copyable_v<ParticleRow>);
static_assert(std::is_trivially_copyable_v<ContactRecord>);

struct Owner {
  std::int64_t id;
  std::int32_t rank;
};

/// The rank that keeps the directory entry of a particle id.
int directory_of(std::int64_t id, int size) {
  return static_cast<int>(static_cast<std::uint64_t>(id) % static_cast<std::uint64_t>(size));
}

}  // namespace

void scatter_to_owners(const Decomposition& dd, ParticleStore& p, std::vector<ContactRecord>& records) {
  const int size = dd.size;
  // 1. Particles to the owners of their centres.
  {
    std::vector<std::vector<ParticleRow>> to(static_cast<std::size_t>(size));
    const std::size_t n = std::min(p.n_owned, p.size());
    for (std::size_t i = 0; i < n; ++i)
      to[static_cast<std::size_t>(dd.owner_of(p.x[i]))].push_back(
          {p.x[i], p.v[i], p.w[i], p.x0[i], p.r[i], p.m[i], p.id[i], p.mat[i], p.blocked[i]});
    p = ParticleStore{};
    std::vector<ParticleRow> mine = alltoallv(to, dd.comm);
    to.clear();
    to.shrink_to_fit();
    std::sort(mine.begin(), mine.end(), [](const ParticleRow& a, const ParticleRow& b) { return a.id < b.id; });
    for (const ParticleRow& q : mine) p.push_back(q.x, q.v, q.w, q.r, q.m, q.id, q.mat, q.blocked, q.x0);
    p.n_owned = p.size();
  }
  // 2. The directory: each id's owner, kept by rank id mod size.
  std::unordered_map<std::int64_t, std::int32_t> owner;
  {
    std::vector<std::vector<Owner>> to(static_cast<std::size_t>(size));
    for (std::size_t i = 0; i < p.n_owned; ++i)
      to[static_cast<std::size_t>(directory_of(p.id[i], size))].push_back({p.id[i], dd.rank});
    const std::vector<Owner> entries = alltoallv(to, dd.comm);
    owner.reserve(entries.size());
    for (const Owner& o : entries) owner.emplace(o.id, o.rank);
  }
  // 3. Records to the directory of each particle they involve, which forwards them to its owner.
  std::vector<std::vector<ContactRecord>> to(static_cast<std::size_t>(size));
  for (const ContactRecord& r : records) {
    to[static_cast<std::size_t>(directory_of(r.a, size))].push_back(r);
    if (r.kind == 0 && directory_of(r.b, size) != directory_of(r.a, size))
      to[static_cast<std::size_t>(directory_of(r.b, size))].push_back(r);
  }
  records.clear();
  records.shrink_to_fit();
  const std::vector<ContactRecord> at_directory = alltoallv(to, dd.comm);
  for (auto& v : to) v.clear();
  for (const ContactRecord& r : at_directory) {
    // this rank is the directory of r.a, of r.b (kind 0), or of both
    int ra = -1, rb = -1;
    if (directory_of(r.a, size) == dd.rank) {
      auto it = owner.find(r.a);
      if (it != owner.end()) ra = it->second;
    }
    if (r.kind == 0 && directory_of(r.b, size) == dd.rank) {
      auto it = owner.find(r.b);
      if (it != owner.end()) rb = it->second;
    }
    if (ra >= 0) to[static_cast<std::size_t>(ra)].push_back(r);
    if (rb >= 0 && rb != ra) to[static_cast<std::size_t>(rb)].push_back(r);
  }
  records = alltoallv(to, dd.comm);
}

}  // namespace fdem
