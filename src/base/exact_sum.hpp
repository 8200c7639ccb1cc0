#pragma once
// Exact, order-independent sums across ranks (results that do not depend on the number of
// ranks, not even in the last bit).
//
// A floating-point sum depends on the order of its terms, and the order depends on how the
// work is split over ranks: a force on an FE node summed from its elements, or from the contacts
// of particles owned by different ranks, differs in the last bits between 1 and 2 ranks -- and a
// granular system amplifies such differences until whole runs differ by percents. Here each
// term is converted to a 128-bit integer in units of 2^-shift (exact for |x| >= 2^-shift, the
// rest truncated, deterministically), integers are summed (associative: exact in any order) and
// the total is converted back once. Forces use the fixed shift kForceShift (2^-64 N resolution,
// up to 9e18 N); sums of quantities of unknown scale (energies, norms) use a shift from the
// global largest term (ExactSums).
//
// Across ranks the integers are reduced with an MPI user op, or -- to pass through PETSc's
// double-valued VecSetValues / ghost scatters -- split into four 32-bit limbs held in doubles
// (integer-valued doubles below 2^53 add exactly, in any order), merged back by the owner.
#include <mpi.h>

#include <cstddef>
#include <vector>

#include "base/fixed_point.hpp"
#include "base/step_sums.hpp"

namespace fdem::exact {

/// In-place MPI_Allreduce (sum) of 128-bit integers; collective.
void allreduce_sum(Int* v, int n, MPI_Comm comm);

/// In-place reduction of every slot of `s` over ranks in one MPI_Allreduce (sums exact, maxima);
/// collective: every rank must have added the same kinds in the same order.
void allreduce(StepSums& s, MPI_Comm comm);

/// Exact global sums of several quantities of unknown scale: add terms, then sums() (collective:
/// one MPI_Allreduce for the largest terms, one for the integer sums).
class ExactSums {
 public:
  explicit ExactSums(std::size_t n) : terms_(n) {}
  void add(std::size_t i, double x) { terms_[i].push_back(x); }
  std::vector<double> sums(MPI_Comm comm) const;

 private:
  std::vector<std::vector<double>> terms_;
};

}  // namespace fdem::exact
