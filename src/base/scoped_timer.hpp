#pragma once
// Adds the wall time of a scope to an accumulator (per-stage timings of the engine and coupler).
#include <mpi.h>

namespace fdem {

struct ScopedTimer {
  double& acc;
  double t0;
  explicit ScopedTimer(double& a) : acc(a), t0(MPI_Wtime()) {}
  ~ScopedTimer() { acc += MPI_Wtime() - t0; }
  ScopedTimer(const ScopedTimer&) = delete;
  ScopedTimer& operator=(const ScopedTimer&) = delete;
};

}  // namespace fdem
