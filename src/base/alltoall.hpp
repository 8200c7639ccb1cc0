#pragma once
// MPI_Alltoallv of trivially copyable records: rank r sends count[k] records of `send` (grouped
// by destination, in rank order) to rank k and gets back the concatenation, in rank order, of
// what every rank sent it. Counts are in records (one MPI datatype of sizeof(T) bytes), so a
// message may exceed 2^31 bytes. `room`: the returned vector's capacity is (1 + room) times what
// it holds (a store that will grow: its arrays are not allocated twice).
#include <mpi.h>

#include <cstddef>
#include <stdexcept>
#include <type_traits>
#include <vector>

namespace fdem {

template <class T>
std::vector<T> alltoallv(const std::vector<T>& send, const std::vector<int>& count, MPI_Comm comm, double room = 0) {
  static_assert(std::is_trivially_copyable_v<T>, "alltoallv: records must be trivially copyable");
  int size = 1;
  MPI_Comm_size(comm, &size);
  if (static_cast<int>(count.size()) != size) throw std::logic_error("alltoallv: one count per rank expected");
  if (send.size() > static_cast<std::size_t>(2147483647)) throw std::length_error("alltoallv: more than 2^31 records");
  std::vector<int> sdispl(size), rcount(size), rdispl(size);
  std::size_t n = 0;
  for (int k = 0; k < size; ++k) {
    sdispl[k] = static_cast<int>(n);
    n += static_cast<std::size_t>(count[k]);
  }
  if (n != send.size()) throw std::logic_error("alltoallv: the counts do not add up to the records");
  MPI_Alltoall(count.data(), 1, MPI_INT, rcount.data(), 1, MPI_INT, comm);
  std::size_t total = 0;
  for (int k = 0; k < size; ++k) {
    if (total > static_cast<std::size_t>(2147483647)) throw std::length_error("alltoallv: more than 2^31 records");
    rdispl[k] = static_cast<int>(total);
    total += static_cast<std::size_t>(rcount[k]);
  }
  std::vector<T> recv;
  recv.reserve(total + static_cast<std::size_t>(room * static_cast<double>(total)));
  recv.resize(total);
  MPI_Datatype type;
  MPI_Type_contiguous(static_cast<int>(sizeof(T)), MPI_BYTE, &type);
  MPI_Type_commit(&type);
  MPI_Alltoallv(send.data(), count.data(), sdispl.data(), type, recv.data(), rcount.data(), rdispl.data(), type, comm);
  MPI_Type_free(&type);
  return recv;
}

/// Records grouped by destination rank without a second copy: count them (`dest(i)` for each
/// of n items), then place each where its destination's block is.
template <class T, class Dest, class Make>
std::vector<T> group_by_rank(std::size_t n, int size, Dest dest, Make make, std::vector<int>& count) {
  count.assign(static_cast<std::size_t>(size), 0);
  for (std::size_t i = 0; i < n; ++i) ++count[static_cast<std::size_t>(dest(i))];
  std::vector<std::size_t> at(static_cast<std::size_t>(size), 0);
  for (int k = 1; k < size; ++k) at[k] = at[k - 1] + static_cast<std::size_t>(count[k - 1]);
  std::vector<T> out(n);
  for (std::size_t i = 0; i < n; ++i) out[at[static_cast<std::size_t>(dest(i))]++] = make(i);
  return out;
}

}  // namespace fdem
