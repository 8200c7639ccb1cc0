// Shared GoogleTest main for MPI tests: MPI_Init -> RUN_ALL_TESTS -> MPI_Finalize.
// Only rank 0 prints gtest's report; a failure on any rank fails the test binary.
#include <gtest/gtest.h>
#include <mpi.h>
#include <petscsys.h>

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  PetscInitializeNoArguments();  // FE tests use PETSc; it takes MPI as initialised
  ::testing::InitGoogleTest(&argc, argv);
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  if (rank != 0) {
    auto& listeners = ::testing::UnitTest::GetInstance()->listeners();
    delete listeners.Release(listeners.default_result_printer());
  }
  int local = RUN_ALL_TESTS();
  int global = 0;
  MPI_Allreduce(&local, &global, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  PetscFinalize();
  MPI_Finalize();
  return global;
}
