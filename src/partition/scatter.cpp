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
  std::int64_t id, key;
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
  std::vector<int> count;
  // 1. Particles to the owners of their centres. (At most two copies of the particles at any
  //    moment: the store and the send buffer, then the receive buffer and the new store.)
  if (size == 1) {  // one rank owns them all: sorted by id in place, one array at a time
    p.n_owned = std::min(p.n_owned, p.size());
    std::vector<std::size_t> order(p.n_owned);
    std::iota(order.begin(), order.end(), std::size_t{0});
    std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return p.id[a] < p.id[b]; });
    p.permute_owned(order);
    p.n_owned = p.size();
  } else {
    const std::size_t n = std::min(p.n_owned, p.size());
    std::vector<ParticleRow> send = group_by_rank<ParticleRow>(
        n, size, [&](std::size_t i) { return dd.owner_of(p.x[i]); },
        [&](std::size_t i) {
          return ParticleRow{p.x[i], p.v[i], p.w[i], p.x0[i], p.r[i], p.m[i], p.id[i], p.key[i], p.mat[i], p.blocked[i]};
        },
        count);
    p = ParticleStore{};
    std::vector<ParticleRow> mine = alltoallv(send, count, dd.comm);
    send = std::vector<ParticleRow>{};
    std::sort(mine.begin(), mine.end(), [](const ParticleRow& a, const ParticleRow& b) { return a.id < b.id; });
    p.resize(mine.size());
    for (std::size_t i = 0; i < mine.size(); ++i) {
      const ParticleRow& q = mine[i];
      p.x[i] = q.x; p.v[i] = q.v; p.w[i] = q.w; p.x0[i] = q.x0; p.r[i] = q.r; p.m[i] = q.m;
      p.id[i] = q.id; p.key[i] = q.key; p.mat[i] = q.mat; p.blocked[i] = q.blocked;
    }
    p.n_owned = p.size();
  }
  // No records on any rank (a generated start): no directory either.
  long long any_records = static_cast<long long>(records.size());
  MPI_Allreduce(MPI_IN_PLACE, &any_records, 1, MPI_LONG_LONG, MPI_SUM, dd.comm);
  if (any_records == 0) return;
  // 2. The directory: each id's owner, kept by rank id mod size.
  std::unordered_map<std::int64_t, std::int32_t> owner;
  {
    std::vector<Owner> send = group_by_rank<Owner>(
        p.n_owned, size, [&](std::size_t i) { return directory_of(p.id[i], size); },
        [&](std::size_t i) { return Owner{p.id[i], dd.rank}; }, count);
    const std::vector<Owner> entries = alltoallv(send, count, dd.comm);
    owner.reserve(entries.size());
    for (const Owner& o : entries) owner.emplace(o.id, o.rank);
  }
  // 3. Records to the directory of each particle they involve (a particle-particle record to
  //    both, or once when they share it), which forwards them to the particles' owners.
  std::vector<std::pair<std::size_t, int>> route;  // (record, rank)
  for (std::size_t i = 0; i < records.size(); ++i) {
    const ContactRecord& r = records[i];
    route.push_back({i, directory_of(r.a, size)});
    if (r.kind == 0 && directory_of(r.b, size) != directory_of(r.a, size)) route.push_back({i, directory_of(r.b, size)});
  }
  std::vector<ContactRecord> send = group_by_rank<ContactRecord>(
      route.size(), size, [&](std::size_t k) { return route[k].second; },
      [&](std::size_t k) { return records[route[k].first]; }, count);
  records = std::vector<ContactRecord>{};
  const std::vector<ContactRecord> at_directory = alltoallv(send, count, dd.comm);
  send = std::vector<ContactRecord>{};
  route.clear();
  for (std::size_t i = 0; i < at_directory.size(); ++i) {
    const ContactRecord& r = at_directory[i];
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
    if (ra >= 0) route.push_back({i, ra});
    if (rb >= 0 && rb != ra) route.push_back({i, rb});
  }
  send = group_by_rank<ContactRecord>(
      route.size(), size, [&](std::size_t k) { return route[k].second; },
      [&](std::size_t k) { return at_directory[route[k].first]; }, count);
  records = alltoallv(send, count, dd.comm);
}

}  // namespace fdem
