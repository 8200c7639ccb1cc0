#pragma once
// Small MPI helpers for tests.
#include <mpi.h>

namespace fdem::testing {

/// A communicator of the first n ranks of MPI_COMM_WORLD (MPI_COMM_NULL on the others).
/// Collective over MPI_COMM_WORLD; free the result with MPI_Comm_free when not null.
inline MPI_Comm first_ranks(int n) {
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm c;
  MPI_Comm_split(MPI_COMM_WORLD, rank < n ? 0 : MPI_UNDEFINED, rank, &c);
  return c;
}

}  // namespace fdem::testing
