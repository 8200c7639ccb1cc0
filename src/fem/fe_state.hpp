#pragma once
// FeState: the restartable state of an FE model (FeModel::state / restore, fem/fe_model.hpp), as
// the checkpoint (io/fe_checkpoint.hpp) stores it. Plain data: no PETSc, no MPI.
#include <cstdint>
#include <vector>

namespace fdem::fem {

/// The restartable state of an FE model, keyed by mesh indices (independent of the partition).
/// From state(): this rank's owned nodes and local elements; restore() accepts any superset.
struct FeState {
  std::vector<std::int64_t> node;      // mesh node index
  std::vector<double> u, v;            // dim values per node
  std::vector<std::int64_t> gp_elem;   // mesh element index of each Gauss-point row
  std::vector<std::int32_t> gp_k;      // Gauss point within the element
  std::vector<double> gp_data;         // 19 per row: stress[6], strain[6], plastic_strain[6], yielded
  std::vector<std::int64_t> removed;   // removed elements (mesh indices), all of them
  double c_last = 0;                   // damping of the last step
  // The adaptive damping's last increment (u and internal force before the last step, dim
  // values per node as u), so a restart continues exactly; empty when there was none.
  std::int32_t has_prev = 0;
  std::vector<double> u_prev, f_prev;
  // The displacements at the last convergence check (FeModel::mark_check; dim values per node as
  // u), the reference of the parts' drift; empty when there was none.
  std::int32_t has_check = 0;
  std::vector<double> u_check;
};

}  // namespace fdem::fem
