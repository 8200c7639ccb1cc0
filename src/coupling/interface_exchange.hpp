#pragma once
// InterfaceExchange: the FE side of the coupling's communication (DESIGN.md 3, 4.4) -- the only
// code of src/coupling that touches PETSc or MPI.
//
// * Gather: the displacements and velocities of the FE nodes this rank needs (those of the
//   interface triangles it sees) from the FE model's distributed Vecs through one VecScatter,
//   rebuilt (collectively) when the set of needed nodes changes on any rank.
// * Reduce: the nodal forces summed over a sub-cycle (exact fixed-point sums, in the slot order of
//   the needed nodes) go into the FE model's interface-force Vec with VecSetValues(ADD_VALUES) +
//   VecAssembly (FeModel::set_interface_forces_exact: the cross-rank sum); the totals, overall and
//   per surface group, are returned for the step's one reduction (exact::StepSums).
// * Maxima over ranks of the surface's motion (what the rebuild check and the seen sets need).
// All members but the accessors are collective over the FE model's communicator.
#include <mpi.h>
#include <petscvec.h>

#include <array>
#include <cstdint>
#include <vector>

#include "base/step_sums.hpp"
#include "coupling/interface_forces.hpp"
#include "coupling/interface_surface.hpp"
#include "fem/fe_model.hpp"

namespace fdem::coupling {

/// The surface's motion, as maxima over ranks (m, m/s).
struct SurfaceMotion {
  double moved = 0;      // largest needed-node displacement since the last build
  double max_disp = 0;   // largest FE displacement (every node)
  double max_speed = 0;  // largest needed-node velocity of the last FE step
};

class InterfaceExchange {
 public:
  /// `model` must outlive the exchange; `n_mesh_nodes` the node count of the mesh the interface
  /// triangles index. `global_of_node`: the FE model's global node number of each of those nodes
  /// when that mesh is not the model's (the interface's own nodes, fem.distribute); empty: the
  /// model's mesh, numbered by model.global_node().
  InterfaceExchange(MPI_Comm comm, fem::FeModel& model, std::size_t n_mesh_nodes,
                    std::vector<PetscInt> global_of_node = {});
  ~InterfaceExchange();
  InterfaceExchange(const InterfaceExchange&) = delete;
  InterfaceExchange& operator=(const InterfaceExchange&) = delete;

  /// Whether `changed` is true on any rank.
  bool any_rank(bool changed) const;
  /// The largest FE displacement over all ranks (m).
  double max_displacement() const;
  /// Collective count of `n` over the ranks.
  std::int64_t sum_over_ranks(std::int64_t n) const;

  /// Need the FE nodes `nodes` (mesh indices, ascending) from now on: rebuild the VecScatter;
  /// keep the gathered values and force sums of the nodes still needed; the force sums of the
  /// nodes no longer needed are handed over at the next assemble_forces().
  void need_nodes(std::vector<std::int32_t> nodes);
  bool has_scatter() const { return scatter_ != nullptr; }
  /// Gather the needed nodes' displacements (node_disp()).
  void gather_displacements();
  /// Gather the needed nodes' FE velocities (node_vel_last_fe(); zero when `rigid`); returns this
  /// rank's largest squared node speed.
  double gather_velocities(bool rigid);
  /// Reduce `sums` over the ranks (exact::allreduce; collective).
  void allreduce(exact::StepSums& sums) const;
  /// The maximum of x over the ranks.
  double max_over_ranks(double x) const;
  /// This rank's part of the surface's motion -- {moved, max_disp, max_speed}: needed nodes
  /// against their build positions, the FE displacement, the FE velocity -- to be maximised over
  /// the ranks (with the step's other reductions, exact::StepSums).
  std::array<double, 3> local_motion() const;
  /// Remember the needed nodes' displacements as those at a build.
  void mark_build() { node_disp_at_build_ = node_disp_; }

  /// Add the vertex sums of `verts` to their nodes' force sums, and zero them.
  void collect_vertex_sums(const InterfaceSurface& s, const std::vector<std::int32_t>& verts,
                           std::vector<F3>& vertex_sums);
  /// The force sums (scaled by inv, e.g. 1 / sub-steps) into the FE model (collective); returns
  /// this rank's fixed-point totals of the forces and of `group_sums` (3, then 3 per group,
  /// unscaled) for the caller to sum over ranks (exact::StepSums); totals_from() converts the
  /// summed ones. All three sums zeroed.
  std::vector<exact::Int> assemble_forces(double inv, std::vector<F3>& group_sums);
  static void totals_from(const exact::Int* tot, std::size_t n_groups, double inv, Vec3& total,
                          std::vector<Vec3>& groups);

  /// The needed nodes (mesh indices, ascending), each node's slot in them (-1: not needed), and
  /// their displacements and last FE velocities in slot order.
  const std::vector<std::int32_t>& nodes() const { return nodes_; }
  const std::vector<std::int32_t>& node_slot() const { return node_slot_; }
  const std::vector<Vec3>& node_disp() const { return node_disp_; }
  const std::vector<Vec3>& node_vel_last_fe() const { return node_vel_last_fe_; }
  void clear_node_velocities();

 private:
  void rebuild_scatter();
  PetscInt global(std::int32_t n) const { return global_of_node_.empty() ? model_.global_node(n) : global_of_node_[n]; }

  MPI_Comm comm_;
  fem::FeModel& model_;
  bool nodes_changed_ = true;  // need_nodes since the last assembly (on every rank alike)
  std::vector<std::int32_t> nodes_;                  // needed mesh nodes, ascending
  std::vector<PetscInt> global_of_node_;             // (empty: model_.global_node)
  std::vector<std::int32_t> node_slot_;              // mesh node -> slot in nodes_ (-1)
  std::vector<PetscInt> global_node_;                // slot -> global FE node number
  std::vector<Vec3> node_disp_;                      // slot -> displacement
  std::vector<Vec3> node_vel_last_fe_;               // slot -> velocity of the last FE step
  std::vector<Vec3> node_disp_at_build_;
  std::vector<F3> node_force_sum_;                   // slot -> force sum over the sub-cycle
  std::vector<PetscInt> carried_nodes_;              // force sums on nodes dropped at a rebuild
  std::vector<F3> carried_forces_;
  VecScatter scatter_ = nullptr;
  Vec local_ = nullptr;
  Vec vel_ = nullptr;                                // FE velocities in the displacement layout
};

}  // namespace fdem::coupling
