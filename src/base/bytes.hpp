#pragma once
// Plain data as one byte message (a mesh part, resolved boundary conditions): put() appends
// vectors of trivially copyable values, strings and sizes; get() reads them back in the same
// order; bcast_bytes / send_bytes / recv_bytes move the message between ranks in pieces (MPI
// counts are int).
#include <mpi.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

namespace fdem {

class Bytes {
 public:
  template <class T>
  void put(const std::vector<T>& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    put_size(v.size());
    const auto* p = reinterpret_cast<const char*>(v.data());
    b_.insert(b_.end(), p, p + v.size() * sizeof(T));
  }
  void put(const std::string& s) {
    put_size(s.size());
    b_.insert(b_.end(), s.begin(), s.end());
  }
  void put_size(std::uint64_t n) {
    const auto* p = reinterpret_cast<const char*>(&n);
    b_.insert(b_.end(), p, p + sizeof n);
  }
  template <class T>
  void get(std::vector<T>& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    v.resize(get_size());
    take(v.data(), v.size() * sizeof(T));
  }
  void get(std::string& s) {
    s.resize(get_size());
    take(s.data(), s.size());
  }
  std::uint64_t get_size() {
    std::uint64_t n = 0;
    take(&n, sizeof n);
    return n;
  }
  std::vector<char>& data() { return b_; }

 private:
  void take(void* to, std::size_t n) {
    if (at_ + n > b_.size()) throw std::runtime_error("Bytes: a message ended early");
    if (n) std::memcpy(to, b_.data() + at_, n);
    at_ += n;
  }
  std::vector<char> b_;
  std::size_t at_ = 0;
};

namespace bytes_detail {
constexpr std::size_t kChunk = std::size_t{1} << 30;  // 1 GiB pieces
}

inline void send_bytes(std::vector<char>& b, int to, MPI_Comm comm) {
  std::uint64_t n = b.size();
  MPI_Send(&n, 1, MPI_UINT64_T, to, 0, comm);
  for (std::size_t off = 0; off < b.size(); off += bytes_detail::kChunk)
    MPI_Send(b.data() + off, static_cast<int>(std::min(bytes_detail::kChunk, b.size() - off)), MPI_BYTE, to, 1, comm);
}

inline void recv_bytes(std::vector<char>& b, int from, MPI_Comm comm) {
  std::uint64_t n = 0;
  MPI_Recv(&n, 1, MPI_UINT64_T, from, 0, comm, MPI_STATUS_IGNORE);
  b.resize(n);
  for (std::size_t off = 0; off < b.size(); off += bytes_detail::kChunk)
    MPI_Recv(b.data() + off, static_cast<int>(std::min(bytes_detail::kChunk, b.size() - off)), MPI_BYTE, from, 1, comm,
             MPI_STATUS_IGNORE);
}

/// Collective: `b` of rank `root` on every rank.
inline void bcast_bytes(std::vector<char>& b, int root, MPI_Comm comm) {
  std::uint64_t n = b.size();
  MPI_Bcast(&n, 1, MPI_UINT64_T, root, comm);
  b.resize(n);
  for (std::size_t off = 0; off < b.size(); off += bytes_detail::kChunk)
    MPI_Bcast(b.data() + off, static_cast<int>(std::min(bytes_detail::kChunk, b.size() - off)), MPI_BYTE, root, comm);
}

}  // namespace fdem
