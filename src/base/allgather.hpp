#pragma once
// MPI_Allgatherv / MPI_Gatherv of a vector of trivially copyable records (as bytes): every rank
// (or the root only) gets the concatenation of all ranks' vectors, in rank order.
#include <mpi.h>

#include <cstddef>
#include <type_traits>
#include <vector>

namespace fdem {

template <class T>
std::vector<T> allgather(const std::vector<T>& mine, MPI_Comm comm) {
  static_assert(std::is_trivially_copyable_v<T>, "allgather: records must be trivially copyable");
  int size = 1;
  MPI_Comm_size(comm, &size);
  int n = static_cast<int>(mine.size() * sizeof(T));
  std::vector<int> counts(size), displs(size);
  MPI_Allgather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, comm);
  long total = 0;
  for (int r = 0; r < size; ++r) { displs[r] = static_cast<int>(total); total += counts[r]; }
  std::vector<T> all(static_cast<std::size_t>(total) / sizeof(T));
  MPI_Allgatherv(mine.data(), n, MPI_BYTE, all.data(), counts.data(), displs.data(), MPI_BYTE, comm);
  return all;
}

/// The concatenation of all ranks' vectors on `root` (empty elsewhere); collective. The total
/// must stay below 2 GiB (MPI's int counts of bytes).
template <class T>
std::vector<T> gather_to(int root, const std::vector<T>& mine, MPI_Comm comm) {
  static_assert(std::is_trivially_copyable_v<T>, "gather_to: records must be trivially copyable");
  int size = 1, rank = 0;
  MPI_Comm_size(comm, &size);
  MPI_Comm_rank(comm, &rank);
  int n = static_cast<int>(mine.size() * sizeof(T));
  std::vector<int> counts(rank == root ? size : 0), displs(rank == root ? size : 0);
  MPI_Gather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, root, comm);
  long total = 0;
  for (std::size_t r = 0; r < counts.size(); ++r) { displs[r] = static_cast<int>(total); total += counts[r]; }
  std::vector<T> all(static_cast<std::size_t>(total) / sizeof(T));
  MPI_Gatherv(mine.data(), n, MPI_BYTE, all.data(), counts.data(), displs.data(), MPI_BYTE, root, comm);
  return all;
}

}  // namespace fdem
