#pragma once
// MPI_Allgatherv of a vector of trivially copyable records (as bytes): every rank gets the
// concatenation of all ranks' vectors, in rank order.
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

}  // namespace fdem
