#pragma once
// Which rank wants each of a set of keys, when no rank knows the whole map (issue 20: a restart's
// FE state read by rows -- each rank reads 1/P of the rows, then sends each row to the rank that
// owns its node or element). A rendezvous: every rank tells each key's directory rank (key * P /
// n_keys, a block of the keys each) the keys it wants; the holders of keys ask the directories,
// which answer. Only keys travel (8 bytes each), and a directory holds its block of the keys:
// no rank holds the whole map. Then the rows themselves move once, straight to their owners
// (send_rows).
#include <mpi.h>

#include <cstdint>
#include <vector>

namespace fdem {

/// For each of `keys` (any order, repeats allowed, each in [0, n_keys)), the rank that has it in
/// its `want` (keys in [0, n_keys), any order); -1 when no rank wants it. A key in the `want` of
/// several ranks goes to the lowest of them. Collective; throws std::invalid_argument for a key
/// outside [0, n_keys) (check the keys before: the other ranks would wait).
std::vector<int> owners_of(const std::vector<std::int64_t>& keys, const std::vector<std::int64_t>& want,
                           std::int64_t n_keys, MPI_Comm comm);

/// Rows of `width` doubles to ranks: row i (written by put(i, out), width doubles) goes to rank
/// dest[i] (-1: dropped). Returns the rows this rank receives, by sender rank, each sender's in
/// its order. The send buffer is the one copy made (grouped by destination). Collective.
template <class Put>
std::vector<double> send_rows(const std::vector<int>& dest, int width, Put put, MPI_Comm comm);

/// The MPI_Alltoallv of send_rows (counts in doubles per rank).
std::vector<double> exchange_doubles(const std::vector<double>& send, const std::vector<int>& count, MPI_Comm comm);

template <class Put>
std::vector<double> send_rows(const std::vector<int>& dest, int width, Put put, MPI_Comm comm) {
  int size = 1;
  MPI_Comm_size(comm, &size);
  std::vector<int> count(static_cast<std::size_t>(size), 0);
  for (int d : dest)
    if (d >= 0) count[static_cast<std::size_t>(d)] += width;
  std::vector<std::size_t> at(static_cast<std::size_t>(size), 0);
  for (int k = 1; k < size; ++k) at[k] = at[k - 1] + static_cast<std::size_t>(count[k - 1]);
  std::vector<double> send(at.empty() ? 0 : at.back() + static_cast<std::size_t>(count.back()));
  for (std::size_t i = 0; i < dest.size(); ++i)
    if (dest[i] >= 0) {
      put(i, &send[at[static_cast<std::size_t>(dest[i])]]);
      at[static_cast<std::size_t>(dest[i])] += static_cast<std::size_t>(width);
    }
  return exchange_doubles(send, count, comm);
}

}  // namespace fdem
