#pragma once
// A temporary directory shared by all ranks of MPI_COMM_WORLD: rank 0 creates it (mkdtemp) and
// broadcasts the path; the destructor waits for every rank, then rank 0 removes it.
#include <mpi.h>
#include <stdlib.h>

#include <cstring>
#include <filesystem>
#include <string>

namespace fdem::testing {

struct TempDir {
  std::string path;
  explicit TempDir(const std::string& prefix = "fdem_test") {
    int rank = 0;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    char buf[4096] = {0};
    if (rank == 0) {
      std::string t = (std::filesystem::temp_directory_path() / (prefix + "_XXXXXX")).string();
      std::strncpy(buf, t.c_str(), sizeof buf - 1);
      if (!mkdtemp(buf)) buf[0] = 0;
    }
    MPI_Bcast(buf, sizeof buf, MPI_CHAR, 0, MPI_COMM_WORLD);
    path = buf;
  }
  ~TempDir() {
    MPI_Barrier(MPI_COMM_WORLD);
    int rank = 0;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    if (rank == 0 && !path.empty()) std::filesystem::remove_all(path);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
};

}  // namespace fdem::testing
