// fdem-test-ranks: 1 2 3
// Rows sent from the ranks that read them to the ranks that own them (partition/rendezvous.hpp,
// the by-rows read of a restart's FE state): owners_of finds every key's owner through the
// directories, whatever the number of ranks, the layout of the holders and the owners; keys no
// rank wants get -1, keys wanted by two ranks the lower; send_rows delivers every row once.
#include <gtest/gtest.h>

#include "support/mpi_util.hpp"
#include <mpi.h>

#include <algorithm>
#include <cstdint>
#include <vector>

#include "partition/rendezvous.hpp"

using namespace fdem;

namespace {

constexpr std::int64_t kKeys = 1000;

// Rank r owns the keys k with (3 k) % P == r, except those divisible by 11 (no owner); the keys
// divisible by 13 are also wanted by the last rank (the lower one must win).
bool wants(std::int64_t k, int rank, int size) {
  if (k % 11 == 0) return false;
  return (k * 3) % size == rank || (k % 13 == 0 && rank == size - 1);
}
int owner(std::int64_t k, int size) {
  if (k % 11 == 0) return -1;
  return static_cast<int>((k * 3) % size);
}

}  // namespace

TEST(Rendezvous, OwnersOfScatteredKeysAndTheRowsSentThere) {
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  // Rank r holds the keys k with k % P == (r + 1) % P, in descending order, the keys divisible by
  // 7 twice (a corrupted file's repeated rows).
  std::vector<std::int64_t> keys, want;
  for (std::int64_t k = kKeys - 1; k >= 0; --k)
    if (k % size == (rank + 1) % size)
      for (int copy = 0; copy < (k % 7 == 0 ? 2 : 1); ++copy) keys.push_back(k);
  for (std::int64_t k = kKeys - 1; k >= 0; --k)
    if (wants(k, rank, size)) want.push_back(k);  // (any order)
  const std::vector<int> dest = owners_of(keys, want, kKeys, MPI_COMM_WORLD);
  ASSERT_EQ(dest.size(), keys.size());
  for (std::size_t i = 0; i < keys.size(); ++i) EXPECT_EQ(dest[i], owner(keys[i], size)) << "key " << keys[i];

  // The rows {key, 1.5 key, holder} to the owners.
  const std::vector<double> got = send_rows(dest, 3, [&](std::size_t i, double* out) {
    out[0] = static_cast<double>(keys[i]);
    out[1] = 1.5 * static_cast<double>(keys[i]);
    out[2] = rank;
  }, MPI_COMM_WORLD);
  ASSERT_EQ(got.size() % 3, 0u);
  std::vector<std::int64_t> received;
  for (std::size_t p = 0; p < got.size(); p += 3) {
    const auto k = static_cast<std::int64_t>(got[p]);
    received.push_back(k);
    EXPECT_EQ(owner(k, size), rank);
    EXPECT_EQ(got[p + 1], 1.5 * got[p]);
    EXPECT_EQ(static_cast<int>(got[p + 2]), static_cast<int>((k % size + size - 1) % size)) << "the holder";
  }
  std::vector<std::int64_t> expect;
  for (std::int64_t k = 0; k < kKeys; ++k)
    if (owner(k, size) == rank)
      for (int copy = 0; copy < (k % 7 == 0 ? 2 : 1); ++copy) expect.push_back(k);
  std::sort(received.begin(), received.end());
  EXPECT_EQ(received, expect);
  std::int64_t n = static_cast<std::int64_t>(received.size());
  MPI_Allreduce(MPI_IN_PLACE, &n, 1, MPI_INT64_T, MPI_SUM, MPI_COMM_WORLD);
  if (rank == 0) std::printf("%lld rows sent to their owners on %d rank(s)\n", static_cast<long long>(n), size);
}

TEST(Rendezvous, EmptyRanksAndOneHolder) {
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  // Rank 0 holds every key of 0..49; the last rank wants them all; the others have nothing.
  std::vector<std::int64_t> keys, want;
  if (rank == 0)
    for (int k = 0; k < 50; ++k) keys.push_back(k);
  if (rank == size - 1)
    for (int k = 0; k < 50; ++k) want.push_back(k);
  const std::vector<int> dest = owners_of(keys, want, 50, MPI_COMM_WORLD);
  for (int d : dest) EXPECT_EQ(d, size - 1);
  const std::vector<double> got =
      send_rows(dest, 1, [&](std::size_t i, double* out) { *out = static_cast<double>(keys[i]); }, MPI_COMM_WORLD);
  EXPECT_EQ(got.size(), rank == size - 1 ? 50u : 0u);
}
