#include "coupling/interface_exchange.hpp"

#include <utility>

#include <algorithm>
#include <cmath>

#include "base/exact_sum.hpp"
#include "base/petsc_check.hpp"

namespace fdem::coupling {
namespace {

/// This rank's largest |u| over the FE model's owned nodes.
double largest_owned_displacement(const fem::FeModel& model) {
  const std::vector<double> u = model.owned_displacements();
  const int dim = model.dim();
  double m = 0;
  for (std::size_t i = 0; i + dim <= u.size(); i += dim)
    m = std::max(m, u[i] * u[i] + u[i + 1] * u[i + 1] + u[i + 2] * u[i + 2]);
  return std::sqrt(m);
}

}  // namespace

InterfaceExchange::InterfaceExchange(MPI_Comm comm, fem::FeModel& model, std::size_t n_mesh_nodes,
                                     std::vector<PetscInt> global_of_node)
    : comm_(comm), model_(model), global_of_node_(std::move(global_of_node)), node_slot_(n_mesh_nodes, -1) {}

InterfaceExchange::~InterfaceExchange() {
  if (vel_) VecDestroy(&vel_);
  if (scatter_) VecScatterDestroy(&scatter_);
  if (local_) VecDestroy(&local_);
}

bool InterfaceExchange::any_rank(bool changed) const {
  int loc = changed ? 1 : 0, any = 0;
  MPI_Allreduce(&loc, &any, 1, MPI_INT, MPI_LOR, comm_);
  return any != 0;
}

double InterfaceExchange::max_displacement() const {
  const double m = largest_owned_displacement(model_);
  double g = 0;
  MPI_Allreduce(&m, &g, 1, MPI_DOUBLE, MPI_MAX, comm_);
  return g;
}

std::int64_t InterfaceExchange::sum_over_ranks(std::int64_t n) const {
  std::int64_t g = 0;
  MPI_Allreduce(&n, &g, 1, MPI_INT64_T, MPI_SUM, comm_);
  return g;
}

void InterfaceExchange::allreduce(exact::StepSums& sums) const { exact::allreduce(sums, comm_); }

double InterfaceExchange::max_over_ranks(double x) const {
  double g = 0;
  MPI_Allreduce(&x, &g, 1, MPI_DOUBLE, MPI_MAX, comm_);
  return g;
}

void InterfaceExchange::need_nodes(std::vector<std::int32_t> nodes) {
  // Remap the per-node data kept across rebuilds.
  std::vector<Vec3> disp(nodes.size()), vel(nodes.size());
  std::vector<F3> fsum(nodes.size(), F3{});
  for (std::size_t s = 0; s < nodes.size(); ++s) {
    const std::int32_t old = node_slot_[nodes[s]];
    if (old >= 0) { disp[s] = node_disp_[old]; vel[s] = node_vel_last_fe_[old]; fsum[s] = node_force_sum_[old]; }
  }
  // Forces summed this sub-cycle on nodes no longer needed are handed over at the next update.
  for (std::size_t s = 0; s < nodes_.size(); ++s) {
    if (node_force_sum_[s] == F3{}) continue;
    if (!std::binary_search(nodes.begin(), nodes.end(), nodes_[s])) {
      carried_nodes_.push_back(global(nodes_[s]));
      carried_forces_.push_back(node_force_sum_[s]);
    }
  }
  for (std::int32_t n : nodes_) node_slot_[n] = -1;
  nodes_.swap(nodes);
  nodes_changed_ = true;  // the next assembly (with the carried nodes) sets a new pattern
  for (std::size_t s = 0; s < nodes_.size(); ++s) node_slot_[nodes_[s]] = static_cast<std::int32_t>(s);
  node_disp_.swap(disp);
  node_vel_last_fe_.swap(vel);
  node_force_sum_.swap(fsum);
  global_node_.resize(nodes_.size());
  for (std::size_t s = 0; s < nodes_.size(); ++s) global_node_[s] = global(nodes_[s]);
  rebuild_scatter();
}

void InterfaceExchange::rebuild_scatter() {
  if (scatter_) VecScatterDestroy(&scatter_);
  if (local_) VecDestroy(&local_);
  const PetscInt nf = model_.node_dofs();
  std::vector<PetscInt> idx(3 * nodes_.size());
  for (std::size_t s = 0; s < nodes_.size(); ++s)
    for (int d = 0; d < 3; ++d) idx[3 * s + d] = global_node_[s] * nf + d;
  IS is;
  petsc_check(ISCreateGeneral(PETSC_COMM_SELF, static_cast<PetscInt>(idx.size()), idx.data(), PETSC_COPY_VALUES, &is),
              "ISCreateGeneral");
  petsc_check(VecCreateSeq(PETSC_COMM_SELF, static_cast<PetscInt>(idx.size()), &local_), "VecCreateSeq");
  petsc_check(VecScatterCreate(model_.displacement_vec(), is, local_, nullptr, &scatter_), "VecScatterCreate");
  petsc_check(ISDestroy(&is), "ISDestroy");
}

void InterfaceExchange::gather_displacements() {
  petsc_check(VecScatterBegin(scatter_, model_.displacement_vec(), local_, INSERT_VALUES, SCATTER_FORWARD),
              "VecScatterBegin");
  petsc_check(VecScatterEnd(scatter_, model_.displacement_vec(), local_, INSERT_VALUES, SCATTER_FORWARD),
              "VecScatterEnd");
  const PetscScalar* a;
  petsc_check(VecGetArrayRead(local_, &a), "VecGetArrayRead");
  for (std::size_t s = 0; s < nodes_.size(); ++s) node_disp_[s] = Vec3{a[3 * s], a[3 * s + 1], a[3 * s + 2]};
  petsc_check(VecRestoreArrayRead(local_, &a), "VecRestoreArrayRead");
}

double InterfaceExchange::gather_velocities(bool rigid) {
  if (!vel_) petsc_check(VecDuplicate(model_.displacement_vec(), &vel_), "VecDuplicate");
  const std::vector<double> v = model_.owned_velocities();
  const int dim = model_.dim(), nf = model_.node_dofs();
  PetscScalar* a;
  petsc_check(VecGetArray(vel_, &a), "VecGetArray");
  for (std::size_t i = 0; i < model_.n_owned(); ++i)
    for (int d = 0; d < nf; ++d) a[i * nf + d] = d < dim ? v[i * dim + d] : 0.0;
  petsc_check(VecRestoreArray(vel_, &a), "VecRestoreArray");
  petsc_check(VecScatterBegin(scatter_, vel_, local_, INSERT_VALUES, SCATTER_FORWARD), "VecScatterBegin");
  petsc_check(VecScatterEnd(scatter_, vel_, local_, INSERT_VALUES, SCATTER_FORWARD), "VecScatterEnd");
  const PetscScalar* b;
  petsc_check(VecGetArrayRead(local_, &b), "VecGetArrayRead");
  double loc = 0;
  for (std::size_t s = 0; s < nodes_.size(); ++s) {
    node_vel_last_fe_[s] = rigid ? Vec3{} : Vec3{b[3 * s], b[3 * s + 1], b[3 * s + 2]};
    loc = std::max(loc, norm2(node_vel_last_fe_[s]));
  }
  petsc_check(VecRestoreArrayRead(local_, &b), "VecRestoreArrayRead");
  return loc;
}

std::array<double, 3> InterfaceExchange::local_motion() const {
  std::array<double, 3> loc{0, 0, 0};
  for (std::size_t s = 0; s < node_disp_.size(); ++s) {
    loc[0] = std::max(loc[0], norm2(node_disp_[s] - node_disp_at_build_[s]));
    loc[2] = std::max(loc[2], norm2(node_vel_last_fe_[s]));
  }
  loc[0] = std::sqrt(loc[0]);
  loc[2] = std::sqrt(loc[2]);
  loc[1] = largest_owned_displacement(model_);
  return loc;
}

void InterfaceExchange::clear_node_velocities() {
  for (Vec3& v : node_vel_last_fe_) v = Vec3{};
}

void InterfaceExchange::collect_vertex_sums(const InterfaceSurface& s, const std::vector<std::int32_t>& verts,
                                            std::vector<F3>& vertex_sums) {
  for (std::int32_t v : verts) {
    F3& a = vertex_sums[v];
    if (a == F3{}) continue;
    for (const std::int32_t n : s.vertex(v).nodes) {
      if (n < 0) continue;
      F3& f = node_force_sum_[node_slot_[n]];
      for (int d = 0; d < 3; ++d) f[d] += a[d];
    }
    a = F3{};
  }
}

std::vector<exact::Int> InterfaceExchange::assemble_forces(double inv, std::vector<F3>& group_sums) {
  // Exact sums (fixed point): the FE receives the same forces on any number of ranks.
  std::vector<PetscInt> g(global_node_);
  std::vector<exact::Int> f(3 * (nodes_.size() + carried_nodes_.size()));
  const std::size_t ng = group_sums.size();
  std::vector<exact::Int> tot(3 + 3 * ng, 0);  // total, then per group
  for (std::size_t s = 0; s < nodes_.size(); ++s)
    for (int d = 0; d < 3; ++d) { f[3 * s + d] = node_force_sum_[s][d]; tot[d] += node_force_sum_[s][d]; }
  for (std::size_t c = 0; c < carried_nodes_.size(); ++c) {
    g.push_back(carried_nodes_[c]);
    for (int d = 0; d < 3; ++d) {
      f[3 * (nodes_.size() + c) + d] = carried_forces_[c][d];
      tot[d] += carried_forces_[c][d];
    }
  }
  model_.set_interface_forces_exact(g, f, inv, !nodes_changed_);  // (need_nodes is collective)
  nodes_changed_ = false;
  for (std::size_t k = 0; k < ng; ++k)
    for (int d = 0; d < 3; ++d) tot[3 + 3 * k + d] = group_sums[k][d];
  for (F3& gs : group_sums) gs = F3{};
  carried_nodes_.clear();
  carried_forces_.clear();
  std::fill(node_force_sum_.begin(), node_force_sum_.end(), F3{});
  return tot;
}

void InterfaceExchange::totals_from(const exact::Int* tot, std::size_t n_groups, double inv, Vec3& total,
                                    std::vector<Vec3>& groups) {
  total = {inv * exact::from_fixed(tot[0]), inv * exact::from_fixed(tot[1]), inv * exact::from_fixed(tot[2])};
  groups.resize(n_groups);
  for (std::size_t k = 0; k < n_groups; ++k)
    groups[k] = {inv * exact::from_fixed(tot[3 + 3 * k]), inv * exact::from_fixed(tot[4 + 3 * k]),
                 inv * exact::from_fixed(tot[5 + 3 * k])};
}

}  // namespace fdem::coupling
