#include "partition/scatter.hpp"

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <numeric>
#include <type_traits>
#include <unordered_map>

#include "base/alltoall.hpp"

namespace fdem {

namespace {

static_assert(std::is_trivially_copyable_v<ContactRecord>);

/// One field of the store sent to the owners: its values in `order` (grouped by destination
/// rank, `count` per rank), the old field released before the exchange, the values received
/// (in rank order) becoming the field. Field by field, the exchange holds the store plus two
/// copies of one field (8-24 bytes per particle), not a second store and its send buffer.
template <class T>
void send_field(std::vector<T>& field, const std::vector<std::uint32_t>& order, const std::vector<int>& count,
                MPI_Comm comm, double room) {
  std::vector<T> send(order.size());
  for (std::size_t k = 0; k < order.size(); ++k) send[k] = field[order[k]];
  field = std::vector<T>{};
  field = alltoallv(send, count, comm, room);
}

struct Owner {
  std::int64_t id;
  std::int32_t rank;
};

/// The rank that keeps the directory entry of a particle id.
int directory_of(std::int64_t id, int size) {
  return static_cast<int>(static_cast<std::uint64_t>(id) % static_cast<std::uint64_t>(size));
}

}  // namespace

void scatter_to_owners(const Decomposition& dd, ParticleStore& p, std::vector<ContactRecord>& records, double room) {
  const int size = dd.size;
  std::vector<int> count;
  // 1. Particles to the owners of their centres, one field at a time (send_field): the store
  //    plus two copies of one field at any moment.
  if (size == 1) {  // one rank owns them all: sorted by id in place, one array at a time
    p.n_owned = std::min(p.n_owned, p.size());
    std::vector<std::size_t> order(p.n_owned);
    std::iota(order.begin(), order.end(), std::size_t{0});
    std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return p.id[a] < p.id[b]; });
    p.permute_owned(order);
    p.n_owned = p.size();
  } else {
    p.n_owned = std::min(p.n_owned, p.size());
    p.clear_ghosts();
    const std::size_t n = p.size();
    p.f = std::vector<Vec3>{};  // not sent: the step's forces start from zero
    p.t = std::vector<Vec3>{};
    if (n > std::numeric_limits<std::uint32_t>::max())
      throw std::length_error("scatter_to_owners: more than 2^32 particles on one rank");
    std::vector<std::uint32_t> order = group_by_rank<std::uint32_t>(
        n, size, [&](std::size_t i) { return dd.owner_of(p.x[i]); },
        [](std::size_t i) { return static_cast<std::uint32_t>(i); }, count);
    // The position last: the destinations are computed from it above, once.
    send_field(p.v, order, count, dd.comm, room);
    send_field(p.w, order, count, dd.comm, room);
    send_field(p.x0, order, count, dd.comm, room);
    send_field(p.r, order, count, dd.comm, room);
    send_field(p.m, order, count, dd.comm, room);
    send_field(p.id, order, count, dd.comm, room);
    send_field(p.key, order, count, dd.comm, room);
    send_field(p.mat, order, count, dd.comm, room);
    send_field(p.blocked, order, count, dd.comm, room);
    send_field(p.x, order, count, dd.comm, room);
    order = std::vector<std::uint32_t>{};
    const std::size_t mine = p.x.size();
    p.f.reserve(p.x.capacity());
    p.f.assign(mine, Vec3{});
    p.t.reserve(p.x.capacity());
    p.t.assign(mine, Vec3{});
    p.n_owned = mine;
    std::vector<std::size_t> by_id(mine);
    std::iota(by_id.begin(), by_id.end(), std::size_t{0});
    std::sort(by_id.begin(), by_id.end(), [&](std::size_t a, std::size_t b) { return p.id[a] < p.id[b]; });
    p.permute_owned(by_id);
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
