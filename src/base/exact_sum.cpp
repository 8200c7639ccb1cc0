#include "base/exact_sum.hpp"

namespace fdem::exact {

namespace {

void sum_int128(void* in, void* inout, int* len, MPI_Datatype*) {
  auto* a = static_cast<Int*>(in);
  auto* b = static_cast<Int*>(inout);
  for (int i = 0; i < *len; ++i) b[i] += a[i];
}

void combine_slots(void* in, void* inout, int* len, MPI_Datatype*) {
  auto* a = static_cast<const StepSums::Slot*>(in);
  auto* b = static_cast<StepSums::Slot*>(inout);
  for (int i = 0; i < *len; ++i) StepSums::combine(a[i], b[i]);
}

}  // namespace

void allreduce(StepSums& s, MPI_Comm comm) {
  static MPI_Datatype type = MPI_DATATYPE_NULL;
  static MPI_Op op = MPI_OP_NULL;
  if (type == MPI_DATATYPE_NULL) {
    MPI_Type_contiguous(static_cast<int>(sizeof(StepSums::Slot)), MPI_BYTE, &type);
    MPI_Type_commit(&type);
    MPI_Op_create(&combine_slots, 1, &op);
  }
  std::vector<StepSums::Slot>& v = s.slots();
  MPI_Allreduce(MPI_IN_PLACE, v.data(), static_cast<int>(v.size()), type, op, comm);
}

void allreduce_sum(Int* v, int n, MPI_Comm comm) {
  static MPI_Datatype type = MPI_DATATYPE_NULL;
  static MPI_Op op = MPI_OP_NULL;
  if (type == MPI_DATATYPE_NULL) {
    MPI_Type_contiguous(static_cast<int>(sizeof(Int)), MPI_BYTE, &type);
    MPI_Type_commit(&type);
    MPI_Op_create(&sum_int128, 1, &op);
  }
  std::vector<Int> out(static_cast<std::size_t>(n));
  MPI_Allreduce(v, out.data(), n, type, op, comm);
  std::copy(out.begin(), out.end(), v);
}

std::vector<double> ExactSums::sums(MPI_Comm comm) const {
  const std::size_t n = terms_.size();
  std::vector<double> mx(n, 0.0), gmx(n);
  for (std::size_t i = 0; i < n; ++i)
    for (double x : terms_[i]) mx[i] = std::max(mx[i], std::fabs(x));
  MPI_Allreduce(mx.data(), gmx.data(), static_cast<int>(n), MPI_DOUBLE, MPI_MAX, comm);
  std::vector<Int> s(n, 0);
  std::vector<int> shift(n);
  for (std::size_t i = 0; i < n; ++i) {
    shift[i] = shift_for(gmx[i]);
    for (double x : terms_[i]) s[i] += to_fixed(x, shift[i]);
  }
  allreduce_sum(s.data(), static_cast<int>(n), comm);
  std::vector<double> out(n);
  for (std::size_t i = 0; i < n; ++i) out[i] = std::isfinite(gmx[i]) ? from_fixed(s[i], shift[i]) : gmx[i];
  return out;
}

}  // namespace fdem::exact
