#include "partition/wall_reduce.hpp"

#include <vector>

#include "base/exact_sum.hpp"

namespace fdem {

void reduce_wall_forces(WallSet& ws, MPI_Comm comm) {
  if (ws.walls.empty()) return;
  std::vector<exact::Int> sums = ws.local_sums();
  exact::allreduce_sum(sums.data(), static_cast<int>(sums.size()), comm);
  ws.set_reduced_sums(sums);
}

}  // namespace fdem
