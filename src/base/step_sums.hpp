#pragma once
// StepSums: the per-step reductions of a DEM step and its coupling gathered into one buffer, so
// that a step needs one MPI_Allreduce (exact::allreduce, base/exact_sum.hpp) instead of one per
// quantity -- a small coupled step is latency-bound. Exact fixed-point sums (128-bit integers:
// the same on any number of ranks) and maxima of doubles share the buffer; every slot says which
// it is, so the reduction operator needs no layout (and an MPI library may split the buffer).
// No MPI here: the DEM layer adds its local values without it.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "base/fixed_point.hpp"

namespace fdem::exact {

class StepSums {
 public:
  struct Slot {
    Int sum = 0;           // kind 0: summed over ranks
    double max = 0;        // kind 1: the largest over ranks (NaN wins)
    std::int64_t kind = 0;
  };
  void clear() { slots_.clear(); }
  bool empty() const { return slots_.empty(); }
  /// n integers to sum; returns the first slot.
  std::size_t add_sums(const Int* v, std::size_t n) {
    const std::size_t at = slots_.size();
    for (std::size_t i = 0; i < n; ++i) slots_.push_back(Slot{v[i], 0.0, 0});
    return at;
  }
  /// A double whose largest value over ranks is wanted; returns its slot.
  std::size_t add_max(double x) {
    slots_.push_back(Slot{0, x, 1});
    return slots_.size() - 1;
  }
  Int sum(std::size_t slot) const { return slots_[slot].sum; }
  double max(std::size_t slot) const { return slots_[slot].max; }
  std::vector<Slot>& slots() { return slots_; }

  /// The reduction of two slots (MPI's operator and the tests).
  static void combine(const Slot& in, Slot& inout) {
    if (inout.kind == 0) inout.sum += in.sum;
    else if (std::isnan(in.max) || in.max > inout.max) inout.max = in.max;
  }

 private:
  std::vector<Slot> slots_;
};

}  // namespace fdem::exact
