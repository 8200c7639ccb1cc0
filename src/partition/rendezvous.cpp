// Owners of keys through a rendezvous, and rows sent to them (see rendezvous.hpp).
#include "partition/rendezvous.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

#include "base/alltoall.hpp"

namespace fdem {

namespace {

/// What each rank sends this one, in records (the counts of an alltoallv).
std::vector<int> received_counts(const std::vector<int>& count, MPI_Comm comm) {
  std::vector<int> got(count.size());
  MPI_Alltoall(count.data(), 1, MPI_INT, got.data(), 1, MPI_INT, comm);
  return got;
}

}  // namespace

std::vector<int> owners_of(const std::vector<std::int64_t>& keys, const std::vector<std::int64_t>& want,
                           std::int64_t n_keys, MPI_Comm comm) {
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  for (const std::vector<std::int64_t>* v : {&keys, &want})
    for (std::int64_t k : *v)
      if (k < 0 || k >= n_keys)
        throw std::invalid_argument("owners_of: key " + std::to_string(k) + " outside [0, " + std::to_string(n_keys) + ")");
  const std::int64_t n = std::max<std::int64_t>(1, n_keys);
  auto directory = [&](std::int64_t key) { return static_cast<int>((static_cast<__int128>(key) * size) / n); };
  // This rank's block of keys as a directory: [lo, hi).
  auto first_key = [&](int d) {  // the smallest key with directory(key) >= d
    return static_cast<std::int64_t>((static_cast<__int128>(d) * n + size - 1) / size);
  };
  const std::int64_t lo = first_key(rank), hi = std::min<std::int64_t>(n_keys, first_key(rank + 1));
  auto by_directory = [&](const std::vector<std::int64_t>& v, std::vector<int>& count) {
    return group_by_rank<std::int64_t>(v.size(), size, [&](std::size_t i) { return directory(v[i]); },
                                       [&](std::size_t i) { return v[i]; }, count);
  };

  // 1. The wanted keys to their directories: the owner of each key of the block.
  std::vector<int> count;
  std::vector<std::int64_t> sent = by_directory(want, count);
  std::vector<int> from = received_counts(count, comm);
  std::vector<std::int64_t> got = alltoallv(sent, count, comm);
  std::vector<int> owner(static_cast<std::size_t>(std::max<std::int64_t>(0, hi - lo)), -1);
  std::size_t at = 0;
  for (int r = 0; r < size; ++r)
    for (int q = 0; q < from[static_cast<std::size_t>(r)]; ++q, ++at) {
      int& o = owner[static_cast<std::size_t>(got[at] - lo)];
      if (o < 0) o = r;  // (the lowest rank: senders come in rank order)
    }

  // 2. The holders ask for their keys' owners; the directories answer in the order asked.
  sent = by_directory(keys, count);
  from = received_counts(count, comm);
  got = alltoallv(sent, count, comm);
  std::vector<int> answer(got.size());
  for (std::size_t i = 0; i < got.size(); ++i) answer[i] = owner[static_cast<std::size_t>(got[i] - lo)];
  const std::vector<int> owners = alltoallv(answer, from, comm);
  // The answers come grouped by directory, in the order sent: back to the keys' order.
  std::vector<std::size_t> pos(static_cast<std::size_t>(size), 0);
  for (int k = 1; k < size; ++k) pos[k] = pos[k - 1] + static_cast<std::size_t>(count[k - 1]);
  std::vector<int> out(keys.size());
  for (std::size_t i = 0; i < keys.size(); ++i) out[i] = owners[pos[static_cast<std::size_t>(directory(keys[i]))]++];
  return out;
}

std::vector<double> exchange_doubles(const std::vector<double>& send, const std::vector<int>& count, MPI_Comm comm) {
  return alltoallv(send, count, comm);
}

}  // namespace fdem
