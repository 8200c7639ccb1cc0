#pragma once
// MPI_Alltoallv of trivially copyable records: rank r sends to[k] to rank k and gets back the
// concatenation, in rank order, of what every rank sent it. Counts are in records (one MPI
// datatype of sizeof(T) bytes), so a message may exceed 2^31 bytes.
#include <mpi.h>

#include <cstddef>
#include <stdexcept>
#include <type_traits>
#include <vector>

namespace fdem {

template <class T>
std::vector<T> alltoallv(const std::vector<std::vector<T>>& to, MPI_Comm comm) {
  static_assert(std::is_trivially_copyable_v<T>, "alltoallv: records must be trivially copyable");
  int size = 1;
  MPI_Comm_size(comm, &size);
  if (static_cast<int>(to.size()) != size) throw std::logic_error("alltoallv: one buffer per rank expected");
  std::vector<int> scount(size), sdispl(size), rcount(size), rdispl(size);
  std::vector<T> send;
  std::size_t n = 0;
  for (const auto& v : to) n += v.size();
  send.reserve(n);
  for (int k = 0; k < size; ++k) {
    if (to[k].size() > static_cast<std::size_t>(2147483647) || send.size() > static_cast<std::size_t>(2147483647))
      throw std::length_error("alltoallv: more than 2^31 records");
    scount[k] = static_cast<int>(to[k].size());
    sdispl[k] = static_cast<int>(send.size());
    send.insert(send.end(), to[k].begin(), to[k].end());
  }
  MPI_Alltoall(scount.data(), 1, MPI_INT, rcount.data(), 1, MPI_INT, comm);
  std::size_t total = 0;
  for (int k = 0; k < size; ++k) {
    rdispl[k] = static_cast<int>(total);
    total += static_cast<std::size_t>(rcount[k]);
  }
  std::vector<T> recv(total);
  MPI_Datatype type;
  MPI_Type_contiguous(static_cast<int>(sizeof(T)), MPI_BYTE, &type);
  MPI_Type_commit(&type);
  MPI_Alltoallv(send.data(), scount.data(), sdispl.data(), type, recv.data(), rcount.data(), rdispl.data(), type,
                comm);
  MPI_Type_free(&type);
  return recv;
}

}  // namespace fdem
