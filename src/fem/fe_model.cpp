#include "fem/fe_model.hpp"

#include "base/errors.hpp"
#include "base/exact_sum.hpp"
#include "base/petsc_check.hpp"
#include "base/sorted_index.hpp"

#include "fem/shell.hpp"
#include "base/allgather.hpp"

#include <petscmat.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <string>
#include <unordered_set>

namespace fdem::fem {

namespace {


constexpr int kMaxNodes = 20;

}  // namespace

FeModel::FeModel(MPI_Comm comm, const Mesh& mesh, const FePartition& part, std::vector<FeMaterial> materials,
                 const FeParams& prm)
    : comm_(comm), mesh_(mesh), mats_(std::move(materials)), prm_(prm) {
  if (prm_.damping >= 0) c_last_ = prm_.damping;  // a fixed damping is in effect from the start
  MPI_Comm_rank(comm, &rank_);
  MPI_Comm_size(comm, &size_);
  FDEM_VERIFY(part.nparts == size_, "FeModel: partition has " + std::to_string(part.nparts) + " parts for " +
                                        std::to_string(size_) + " ranks");
  dim_ = mesh.dim;
  nf_ = dim_;  // dofs per node: 6 as soon as the mesh has shells (rotations)
  for (ElemType t : mesh.elem_type) nf_ = std::max(nf_, element_node_dofs(t));
  MPI_Allreduce(MPI_IN_PLACE, &nf_, 1, MPI_INT, MPI_MAX, comm_);  // (a part may have no shell)
  node_index_ = part.node_index;
  elem_index_ = part.elem_index;
  FDEM_VERIFY((node_index_.empty() || node_index_.size() == mesh.n_nodes()) &&
                  (elem_index_.empty() || elem_index_.size() == mesh.n_elements()),
              "FeModel: the partition's node or element index does not match the mesh");
  n_nodes_global_ = 0;
  for (std::int32_t c : part.owned_count) n_nodes_global_ += c;
  build_local_numbering(part);
  // (the mesh may be this rank's part of it: partition/mesh_distribute.hpp)
  n_elems_global_ = static_cast<std::int64_t>(elems_.size());
  MPI_Allreduce(MPI_IN_PLACE, &n_elems_global_, 1, MPI_INT64_T, MPI_SUM, comm_);
  create_vectors(part);
  assemble_mass_and_body();
  prepare_elements();
}

std::int32_t FeModel::part_node(std::int64_t n) const {
  if (node_index_.empty()) return n >= 0 && static_cast<std::size_t>(n) < mesh_.n_nodes() ? static_cast<std::int32_t>(n) : -1;
  return find_sorted(node_index_, n);
}

std::int32_t FeModel::part_elem(std::int64_t e) const {
  if (elem_index_.empty()) return e >= 0 && static_cast<std::size_t>(e) < mesh_.n_elements() ? static_cast<std::int32_t>(e) : -1;
  return find_sorted(elem_index_, e);
}

void FeModel::prepare_elements() {
  double X[kMaxNodes * 3];
  for (std::size_t le = 0; le < elems_.size(); ++le) {
    const std::int32_t e = elems_[le];
    const FeMaterial& m = mats_[mesh_.elem_material[e]];
    const int n = element_prepared_size(mesh_.elem_type[e], m);
    prep_.resize(prep_.size() + static_cast<std::size_t>(n));
    prep_off_.push_back(static_cast<std::int64_t>(prep_.size()));
    if (n == 0) continue;
    gather_element(le, X, nullptr, nullptr);
    element_prepare(mesh_.elem_type[e], X, m, prep_.data() + prep_off_[le]);
  }
}

void FeModel::build_local_numbering(const FePartition& part) {
  const Mesh& mesh = mesh_;
  const std::size_t nn = mesh.n_nodes();
  std::vector<std::uint8_t> touched(nn, 0);
  for (std::size_t e = 0; e < mesh.n_elements(); ++e) {
    if (part.elem_part[e] != rank_) continue;
    elems_.push_back(static_cast<std::int32_t>(e));
    const std::int32_t* nodes;
    const int n = mesh.nodes_of(e, nodes);
    for (int k = 0; k < n; ++k) touched[nodes[k]] = 1;
  }
  std::vector<std::int32_t> owned, ghosts;
  for (std::size_t i = 0; i < nn; ++i) {
    if (part.node_owner[i] == rank_) owned.push_back(static_cast<std::int32_t>(i));
    else if (touched[i]) ghosts.push_back(static_cast<std::int32_t>(i));
  }
  auto by_global = [&](std::int32_t a, std::int32_t b) { return part.node_global[a] < part.node_global[b]; };
  std::sort(owned.begin(), owned.end(), by_global);
  std::sort(ghosts.begin(), ghosts.end(), by_global);
  n_owned_ = owned.size();
  local_of_.assign(nn, -1);
  for (std::int32_t i : owned) { local_of_[i] = static_cast<std::int32_t>(mesh_of_.size()); mesh_of_.push_back(i); }
  for (std::int32_t i : ghosts) { local_of_[i] = static_cast<std::int32_t>(mesh_of_.size()); mesh_of_.push_back(i); }
  for (std::int32_t i : mesh_of_) global_of_.push_back(part.node_global[i]);
  for (std::int32_t e : elems_) {
    const std::int32_t* nodes;
    const int n = mesh.nodes_of(e, nodes);
    for (int k = 0; k < n; ++k) elem_conn_.push_back(local_of_[nodes[k]]);
    elem_off_.push_back(static_cast<std::int32_t>(elem_conn_.size()));
    gp_off_.push_back(gp_off_.back() + element_gauss_points(mesh.elem_type[e]));
  }
  gp_.assign(gp_off_.back(), GaussState{});
  active_.assign(elems_.size(), 1);
}

void FeModel::create_vectors(const FePartition& part) {
  // Ghosted Vecs (block size dim).
  std::vector<PetscInt> ghost_blocks(global_of_.begin() + n_owned_, global_of_.end());
  PetscInt N = 0;
  for (int r = 0; r < size_; ++r) N += part.owned_count[r];
  petsc_check(VecCreateGhostBlock(comm_, nf_, static_cast<PetscInt>(n_owned_ * nf_), N * nf_,
                            static_cast<PetscInt>(ghost_blocks.size()), ghost_blocks.data(), &u_),
        "VecCreateGhostBlock");
  petsc_check(VecDuplicate(u_, &f_), "VecDuplicate");
  petsc_check(VecSet(u_, 0.0), "VecSet");
  // The limb Vec of the exact assembly (base/exact_sum.hpp): 4 limbs per dof.
  petsc_check(VecCreateGhostBlock(comm_, exact::kLimbs * nf_, static_cast<PetscInt>(n_owned_ * nf_ * exact::kLimbs),
                            N * nf_ * exact::kLimbs, static_cast<PetscInt>(ghost_blocks.size()), ghost_blocks.data(), &f4_),
        "VecCreateGhostBlock");
  const std::size_t nd = n_owned_ * nf_;
  v_.assign(nd, 0.0);
  fext_.assign(nd, 0.0);
  iface_.assign(nd, 0.0);
  node_global_.assign(part.node_global.begin(), part.node_global.end());
  presc_.assign(nd, 0.0);
  fixed_.assign(nd, 0);
}

void FeModel::assemble_mass_and_body(bool active_only) {
  const Mesh& mesh = mesh_;
  const std::size_t nd = n_owned_ * nf_;
  // Lumped mass and body load: element contributions summed exactly over ranks.
  double X[kMaxNodes * 3];
  mass_.assign(nd, 0.0);
  assemble_exact(
      [&](std::size_t le, double* out) {
        const ElemType t = mesh.elem_type[elems_[le]];
        const int n = element_nodes(t);
        gather_element(le, X, nullptr, nullptr);
        const FeMaterial& m = mats_[mesh.elem_material[elems_[le]]];
        double me[kMaxNodes], jr[kMaxNodes];
        if (t == ElemType::kShell4) shell4_lumped_mass(X, m.density, m.thickness, me, jr);
        else element_lumped_mass(t, X, m.density, me);
        const int ed = t == ElemType::kShell4 ? 6 : dim_;
        for (int k = 0; k < n; ++k) {
          for (int d = 0; d < dim_; ++d) out[k * ed + d] = me[k];  // translations
          for (int d = dim_; d < ed; ++d) out[k * ed + d] = jr[k];  // shell rotations
        }
        return ed;
      },
      mass_.data(), true, active_only);
  assemble_body(active_only);
}

void FeModel::assemble_body(bool active_only) {
  const Mesh& mesh = mesh_;
  double X[kMaxNodes * 3];
  body_.assign(n_owned_ * nf_, 0.0);
  assemble_exact(
      [&](std::size_t le, double* out) {
        const ElemType t = mesh.elem_type[elems_[le]];
        gather_element(le, X, nullptr, nullptr);
        const FeMaterial& m = mats_[mesh.elem_material[elems_[le]]];
        double b[3];
        for (int d = 0; d < 3; ++d) b[d] = m.unit_weight * prm_.gravity_dir[d];
        if (t == ElemType::kShell4) {
          double area_w[4], jr[4];  // t * int N_a dA (density 1)
          shell4_lumped_mass(X, 1.0, m.thickness, area_w, jr);
          for (int k = 0; k < 4; ++k)
            for (int d = 0; d < 3; ++d) out[k * 3 + d] = b[d] * area_w[k];
        } else {
          element_body_force(t, X, b, out);
        }
        return dim_;
      },
      body_.data(), false, active_only);
}

template <class F>
void FeModel::assemble_exact(F&& per_element, double* out, bool dynamic_shift, bool active_only) {
  // Pass 1: every element's nodal values (and the largest, for the shift).
  const std::size_t ne = elems_.size(), stride = static_cast<std::size_t>(kMaxNodes) * 6;
  ebuf_.resize(ne * stride);
  eed_.assign(ne, 0);
  double mx = 0;
  for (std::size_t le = 0; le < ne; ++le) {
    if (active_only && !active_[le]) continue;
    double* v = &ebuf_[le * stride];
    const int ed = per_element(le, v);
    eed_[le] = static_cast<std::int8_t>(ed);
    const int n = element_nodes(mesh_.elem_type[elems_[le]]) * ed;
    for (int i = 0; i < n; ++i) mx = std::max(mx, std::fabs(v[i]));
  }
  int shift = exact::kForceShift;
  if (dynamic_shift) {
    double g = 0;
    MPI_Allreduce(&mx, &g, 1, MPI_DOUBLE, MPI_MAX, comm_);
    shift = exact::shift_for(g);
  }
  // Pass 2: exact integer sums per local dof, in any order.
  acc_.assign(mesh_of_.size() * static_cast<std::size_t>(nf_), 0);
  for (std::size_t le = 0; le < ne; ++le) {
    const int ed = eed_[le];
    if (ed == 0) continue;
    const int n = element_nodes(mesh_.elem_type[elems_[le]]);
    const double* v = &ebuf_[le * stride];
    for (int k = 0; k < n; ++k) {
      const std::size_t ln = static_cast<std::size_t>(elem_conn_[elem_off_[le] + k]);
      for (int d = 0; d < ed; ++d) acc_[ln * nf_ + d] += exact::to_fixed(v[k * ed + d], shift);
    }
  }
  // Across ranks: the limbs through the reverse ghost scatter (exact), merged by the owner.
  Vec l;
  PetscScalar* a;
  petsc_check(VecGhostGetLocalForm(f4_, &l), "VecGhostGetLocalForm");
  petsc_check(VecGetArray(l, &a), "VecGetArray");
  for (std::size_t i = 0; i < acc_.size(); ++i) exact::split(acc_[i], &a[exact::kLimbs * i]);
  petsc_check(VecRestoreArray(l, &a), "VecRestoreArray");
  petsc_check(VecGhostRestoreLocalForm(f4_, &l), "VecGhostRestoreLocalForm");
  petsc_check(VecGhostUpdateBegin(f4_, ADD_VALUES, SCATTER_REVERSE), "VecGhostUpdateBegin");
  petsc_check(VecGhostUpdateEnd(f4_, ADD_VALUES, SCATTER_REVERSE), "VecGhostUpdateEnd");
  const PetscScalar* r;
  petsc_check(VecGetArrayRead(f4_, &r), "VecGetArrayRead");
  for (std::size_t i = 0; i < n_owned_ * static_cast<std::size_t>(nf_); ++i)
    out[i] = exact::from_fixed(exact::merge(&r[exact::kLimbs * i]), shift);
  petsc_check(VecRestoreArrayRead(f4_, &r), "VecRestoreArrayRead");
}

FeModel::~FeModel() {
  if (u_) VecDestroy(&u_);
  if (f_) VecDestroy(&f_);
  if (fi_) VecDestroy(&fi_);
  if (f4_) VecDestroy(&f4_);
}

void FeModel::gather_element(std::size_t le, double* X, double* u, const double* ua) const {
  const std::int32_t e = elems_[le];
  const std::int32_t* nodes;
  const int n = mesh_.nodes_of(e, nodes);
  for (int k = 0; k < n; ++k) {
    for (int d = 0; d < dim_; ++d) X[k * dim_ + d] = mesh_.coords[static_cast<std::size_t>(nodes[k]) * dim_ + d];
    if (u) {
      const std::int32_t ln = elem_conn_[elem_off_[le] + k];
      const int ed = element_node_dofs(mesh_.elem_type[e]);
      for (int d = 0; d < ed; ++d) u[k * ed + d] = ua[ln * nf_ + d];
    }
  }
}

template <class F>
void FeModel::for_each_stiffness(F&& f) const {
  double X[kMaxNodes * 3];
  std::vector<double> K(static_cast<std::size_t>(kMaxNodes * 3) * kMaxNodes * 3);
  for (std::size_t le = 0; le < elems_.size(); ++le) {
    if (!active_[le]) continue;
    const std::int32_t e = elems_[le];
    const ElemType t = mesh_.elem_type[e];
    const int n = element_nodes(t);
    gather_element(le, X, nullptr, nullptr);
    element_stiffness(t, X, mats_[mesh_.elem_material[e]], K.data());
    f(le, n, element_node_dofs(t), K.data());
  }
}

void FeModel::restrain(std::int32_t node, const std::array<bool, 3>& fixed, const std::array<double, 3>& disp) {
  const std::int32_t ln = local_of_[node];
  if (ln < 0 || static_cast<std::size_t>(ln) >= n_owned_) return;
  for (int d = 0; d < dim_; ++d)
    if (fixed[d]) { fixed_[ln * nf_ + d] = 1; presc_[ln * nf_ + d] = disp[d]; }
}

void FeModel::restrain_rotations(std::int32_t node, const std::array<bool, 3>& fixed) {
  const std::int32_t ln = local_of_[node];
  if (ln < 0 || static_cast<std::size_t>(ln) >= n_owned_ || nf_ < 6) return;
  for (int d = 0; d < 3; ++d)
    if (fixed[d]) { fixed_[ln * nf_ + 3 + d] = 1; presc_[ln * nf_ + 3 + d] = 0; }
}

std::vector<double> FeModel::owned_velocities() const {
  std::vector<double> out(n_owned_ * dim_);
  for (std::size_t i = 0; i < n_owned_; ++i)
    for (int d = 0; d < dim_; ++d) out[i * dim_ + d] = v_[i * nf_ + d];
  return out;
}

void FeModel::add_load(std::int32_t node, const std::array<double, 3>& force) {
  const std::int32_t ln = local_of_[node];
  if (ln < 0 || static_cast<std::size_t>(ln) >= n_owned_) return;
  for (int d = 0; d < dim_; ++d) fext_[ln * nf_ + d] += force[d];
}

void FeModel::remove_elements(const std::vector<std::int32_t>& elems) {
  std::unordered_set<std::int64_t> gone(removed_.begin(), removed_.end());
  for (std::int32_t e : elems)
    if (gone.insert(e).second) removed_.push_back(e);
  for (std::size_t le = 0; le < elems_.size(); ++le)
    if (gone.count(whole_elem(elems_[le]))) active_[le] = 0;
  have_prev_ = false;
  assemble_masses_after_removal();
}

void FeModel::assemble_masses_after_removal() {
  // The removed elements' weight goes with them; a node no active element uses any more holds
  // still (its mass from the active elements is 0, exactly, on every rank).
  assemble_mass_and_body(false);
  if (removed_.empty()) return;
  const std::vector<double> mass_all = mass_;
  assemble_mass_and_body(true);
  for (std::size_t k = 0; k < mass_.size(); ++k) {
    if (mass_[k] <= 0) v_[k] = 0;
    else mass_[k] = mass_all[k];
  }
}

void FeModel::set_density_scale(double s) {
  if (!(s > 0) || !std::isfinite(s)) throw std::invalid_argument("FeModel::set_density_scale: s must be positive");
  if (density0_.empty())
    for (const FeMaterial& m : mats_) density0_.push_back(m.density);
  for (std::size_t i = 0; i < mats_.size(); ++i) mats_[i].density = density0_[i] * s;
  have_prev_ = false;  // (the adaptive damping's last increment was of the other masses)
  assemble_masses_after_removal();
}

void FeModel::internal_force(bool commit) {
  // Element forces summed exactly (base/exact_sum.hpp): the same nodal forces on any
  // number of ranks, to the last bit. Only the owned entries of f_ are set.
  Vec ul;
  const PetscScalar* ua;
  PetscScalar* fa;
  petsc_check(VecGhostGetLocalForm(u_, &ul), "VecGhostGetLocalForm");
  petsc_check(VecGetArrayRead(ul, &ua), "VecGetArrayRead");
  petsc_check(VecGetArray(f_, &fa), "VecGetArray");
  double X[kMaxNodes * 3], ue[kMaxNodes * 3];
  assemble_exact(
      [&](std::size_t le, double* out) {
        const std::int32_t e = elems_[le];
        const ElemType t = mesh_.elem_type[e];
        gather_element(le, X, ue, ua);
        const double* prep = prep_off_[le + 1] > prep_off_[le] ? prep_.data() + prep_off_[le] : nullptr;
        element_internal_force(t, X, ue, mats_[mesh_.elem_material[e]], &gp_[gp_off_[le]], commit, out, prep);
        return element_node_dofs(t);
      },
      fa, false, true);
  petsc_check(VecRestoreArray(f_, &fa), "VecRestoreArray");
  petsc_check(VecRestoreArrayRead(ul, &ua), "VecRestoreArrayRead");
  petsc_check(VecGhostRestoreLocalForm(u_, &ul), "VecGhostRestoreLocalForm");
}

double FeModel::critical_dt(const std::vector<std::int32_t>& extra_nodes, double k_extra) {
  return critical_dt(extra_nodes, std::vector<double>(k_extra > 0 ? extra_nodes.size() : 0, k_extra));
}

double FeModel::critical_dt(const std::vector<std::int32_t>& extra_nodes, const std::vector<double>& k_extra) {
  if (!k_extra.empty() && k_extra.size() != extra_nodes.size())
    throw std::invalid_argument("FeModel::critical_dt: one stiffness per extra node expected");
  // Gershgorin: row sums of |K_e| assembled (exactly) per dof, divided by the lumped mass.
  std::vector<double> rows(static_cast<std::size_t>(kMaxNodes) * 6 * elems_.size(), 0.0);
  const std::size_t stride = static_cast<std::size_t>(kMaxNodes) * 6;
  for_each_stiffness([&](std::size_t le, int n, int ed, const double* K) {
    const int nd = n * ed;
    for (int i = 0; i < nd; ++i) {
      double s = 0;
      for (int j = 0; j < nd; ++j) s += std::abs(K[static_cast<std::size_t>(i) * nd + j]);
      rows[le * stride + i] = s;
    }
  });
  std::vector<double> rowsum(n_owned_ * nf_, 0.0);
  assemble_exact(
      [&](std::size_t le, double* out) {
        const ElemType t = mesh_.elem_type[elems_[le]];
        const int nd = element_nodes(t) * element_node_dofs(t);
        std::copy(&rows[le * stride], &rows[le * stride] + nd, out);
        return element_node_dofs(t);
      },
      rowsum.data(), true, true);
  const double* ro = rowsum.data();
  std::vector<double> extra;
  if (!k_extra.empty()) {
    extra.assign(n_owned_, 0.0);
    for (std::size_t j = 0; j < extra_nodes.size(); ++j) {
      const std::int32_t l = local_of_[extra_nodes[j]];
      if (l >= 0 && static_cast<std::size_t>(l) < n_owned_) extra[l] = std::max(extra[l], k_extra[j]);
    }
  }
  double lam = 0;
  for (std::size_t i = 0; i < n_owned_; ++i)
    for (int d = 0; d < nf_; ++d) {
      const double add = (d < 3 && !extra.empty()) ? extra[i] : 0.0;
      if (mass_[i * nf_ + d] > 0) lam = std::max(lam, (ro[i * nf_ + d] + add) / mass_[i * nf_ + d]);
    }
  double g = 0;
  MPI_Allreduce(&lam, &g, 1, MPI_DOUBLE, MPI_MAX, comm_);
  return g > 0 ? 2.0 / std::sqrt(g) : 0.0;
}

void FeModel::step(double dt) {
  internal_force(true);
  const PetscScalar* fa;
  PetscScalar* ua;
  petsc_check(VecGetArrayRead(f_, &fa), "VecGetArrayRead");
  petsc_check(VecGetArray(u_, &ua), "VecGetArray");
  const std::size_t nd = n_owned_ * nf_;
  // Damping: fixed, or adaptive from the Rayleigh quotient of the last increment.
  double c = prm_.damping;
  if (c < 0) {
    exact::ExactSums sums(2);  // the same on any number of ranks
    if (have_prev_)
      for (std::size_t k = 0; k < nd; ++k) {
        if (fixed_[k]) continue;
        const double du = ua[k] - u_prev_[k];
        sums.add(0, du * (fa[k] - f_prev_[k]));
        sums.add(1, du * du * mass_[k]);
      }
    const std::vector<double> g = sums.sums(comm_);
    c = (g[1] > 0 && g[0] > 0) ? 2.0 * std::sqrt(g[0] / g[1]) : c_last_;
    u_prev_.assign(ua, ua + nd);
    f_prev_.assign(fa, fa + nd);
    have_prev_ = true;
  }
  c_last_ = c;
  const double a = 1.0 - 0.5 * c * dt, b = 1.0 / (1.0 + 0.5 * c * dt);
  for (std::size_t k = 0; k < nd; ++k) {
    if (fixed_[k]) {
      const double target = disp_factor_ * presc_[k];
      v_[k] = (target - ua[k]) / dt;
      ua[k] = target;
      continue;
    }
    const double m = mass_[k];
    if (m <= 0) continue;
    const double r = load_factor_ * fext_[k] + body_[k] + iface_[k] - fa[k];
    v_[k] = (a * v_[k] + dt * r / m) * b;
    ua[k] += dt * v_[k];
  }
  petsc_check(VecRestoreArray(u_, &ua), "VecRestoreArray");
  petsc_check(VecRestoreArrayRead(f_, &fa), "VecRestoreArrayRead");
  petsc_check(VecGhostUpdateBegin(u_, INSERT_VALUES, SCATTER_FORWARD), "VecGhostUpdateBegin");
  petsc_check(VecGhostUpdateEnd(u_, INSERT_VALUES, SCATTER_FORWARD), "VecGhostUpdateEnd");
}

double FeModel::unbalanced() { return unbalanced_measures()[0]; }

std::array<double, 2> FeModel::unbalanced_measures() { return worst(part_balance()); }

std::array<double, 2> FeModel::worst(const std::vector<PartBalance>& parts) {
  if (parts.size() == 1) return {parts[0].norm, parts[0].resultant};  // as it always was, NaN included
  std::array<double, 2> w{0.0, 0.0};
  for (const PartBalance& p : parts) {
    w[0] = std::isnan(p.norm) || std::isnan(w[0]) ? p.norm + w[0] : std::max(w[0], p.norm);
    w[1] = std::isnan(p.resultant) || std::isnan(w[1]) ? p.resultant + w[1] : std::max(w[1], p.resultant);
  }
  return w;
}

std::vector<FeModel::PartBalance> FeModel::part_balance() {
  internal_force(false);
  const PetscScalar* fa;
  petsc_check(VecGetArrayRead(f_, &fa), "VecGetArrayRead");
  // Per node group (group-major, kSums each): [0..2] squared norms (free residual, free external,
  // restrained reactions); [3..5] resultant of the free residual, [6] sum over nodes of |free
  // external force|, [7..9] resultant of the reactions; [10] sum over the nodes of m |v|^2 (the
  // free translational dofs' velocities) and [11] of their masses m (nodes with a free one);
  // [12] of m |u - u_check|^2 over the same dofs (the drift since mark_check).
  constexpr std::size_t kSums = 13;
  const PetscScalar* ua;
  petsc_check(VecGetArrayRead(u_, &ua), "VecGetArrayRead");
  exact::ExactSums sums(kSums * static_cast<std::size_t>(n_groups_));  // the same on any number of ranks
  for (std::size_t i = 0; i < n_owned_; ++i) {
    const std::size_t o = group_.empty() ? 0 : kSums * static_cast<std::size_t>(group_[i]);
    double fnode[3] = {0, 0, 0};
    double mv2 = 0, mdu2 = 0, mnode = 0;  // the node's m |v|^2, m |du|^2 over its free translational dofs, its mass
    for (int d = 0; d < nf_; ++d) {
      const std::size_t k = i * static_cast<std::size_t>(nf_) + static_cast<std::size_t>(d);
      const double ext = load_factor_ * fext_[k] + body_[k] + iface_[k];
      if (fixed_[k]) {
        sums.add(o + 2, (fa[k] - ext) * (fa[k] - ext));
        if (d < dim_) sums.add(o + 7 + static_cast<std::size_t>(d), fa[k] - ext);
      } else {
        sums.add(o + 0, (ext - fa[k]) * (ext - fa[k]));
        sums.add(o + 1, ext * ext);
        if (d < dim_) {
          sums.add(o + 3 + static_cast<std::size_t>(d), ext - fa[k]);
          fnode[d] = ext;
          if (mass_[k] > 0) {
            mv2 += mass_[k] * v_[k] * v_[k];
            if (have_check_) mdu2 += mass_[k] * (ua[k] - u_check_[k]) * (ua[k] - u_check_[k]);
            mnode = std::max(mnode, mass_[k]);
          }
        }
      }
    }
    sums.add(o + 6, std::sqrt(fnode[0] * fnode[0] + fnode[1] * fnode[1] + fnode[2] * fnode[2]));
    if (mnode > 0) {
      sums.add(o + 10, mv2);
      sums.add(o + 11, mnode);
      sums.add(o + 12, mdu2);
    }
  }
  petsc_check(VecRestoreArrayRead(f_, &fa), "VecRestoreArrayRead");
  petsc_check(VecRestoreArrayRead(u_, &ua), "VecRestoreArrayRead");
  const std::vector<double> all = sums.sums(comm_);
  std::vector<PartBalance> out(static_cast<std::size_t>(n_groups_));
  for (int grp = 0; grp < n_groups_; ++grp) {
    const double* g = all.data() + kSums * static_cast<std::size_t>(grp);
    const double scale = std::sqrt(std::max(g[1], g[2]));
    auto len = [&](int i) { return std::sqrt(g[i] * g[i] + g[i + 1] * g[i + 1] + g[i + 2] * g[i + 2]); };
    const double rscale = std::max(g[6], len(7));
    PartBalance& p = out[static_cast<std::size_t>(grp)];
    p.norm = scale > 0 ? std::sqrt(g[0]) / scale : std::sqrt(g[0]);
    p.resultant = rscale > 0 ? len(3) / rscale : len(3);
    p.speed = g[11] > 0 ? std::sqrt(g[10] / g[11]) : 0.0;
    if (have_check_) p.drift = g[11] > 0 ? std::sqrt(g[12] / g[11]) : 0.0;
    p.load = rscale;
    p.mass = g[11];
  }
  return out;
}

void FeModel::set_damping(double c) {
  if (!(c >= 0) || !std::isfinite(c)) throw std::invalid_argument("FeModel::set_damping: c must be finite and >= 0");
  prm_.damping = c;
  c_last_ = c;  // (the damping in effect: what a checkpoint keeps)
}

void FeModel::mark_check() {
  const PetscScalar* ua;
  petsc_check(VecGetArrayRead(u_, &ua), "VecGetArrayRead");
  u_check_.assign(ua, ua + n_owned_ * nf_);
  petsc_check(VecRestoreArrayRead(u_, &ua), "VecRestoreArrayRead");
  have_check_ = true;  // (called on every rank: the same everywhere)
}

void FeModel::set_node_groups(const std::vector<std::int32_t>& group_of_node) {
  group_.clear();
  n_groups_ = 1;
  if (group_of_node.empty()) return;
  if (group_of_node.size() != mesh_.n_nodes())
    throw std::invalid_argument("FeModel::set_node_groups: one group per mesh node expected");
  for (std::int32_t v : group_of_node) {
    if (v < 0) throw std::invalid_argument("FeModel::set_node_groups: negative group");
    n_groups_ = std::max(n_groups_, v + 1);
  }
  // (a part of the mesh, fem.distribute, may lack the last groups: the count is every rank's)
  MPI_Allreduce(MPI_IN_PLACE, &n_groups_, 1, MPI_INT, MPI_MAX, comm_);
  group_.resize(n_owned_);
  for (std::size_t i = 0; i < n_owned_; ++i) group_[i] = group_of_node[static_cast<std::size_t>(mesh_of_[i])];
}

std::int64_t FeModel::relax(double dt, double tol, std::int64_t max_steps, int check_every) {
  std::int64_t k = 0;
  while (k < max_steps) {
    step(dt);
    ++k;
    if (k % check_every == 0 && unbalanced() < tol) break;
  }
  return k;
}

namespace {

/// The mean |diagonal| of A over its nonzero entries (1 if none); collective.
double mean_abs_diagonal(Mat A, PetscInt nloc, MPI_Comm comm) {
  double held_diag = 1.0;
  Vec dg;
  petsc_check(MatCreateVecs(A, nullptr, &dg), "MatCreateVecs");
  petsc_check(MatGetDiagonal(A, dg), "MatGetDiagonal");
  const PetscScalar* da;
  petsc_check(VecGetArrayRead(dg, &da), "VecGetArrayRead");
  double s[2] = {0, 0};
  for (PetscInt k = 0; k < nloc; ++k)
    if (std::abs(da[k]) > 0) { s[0] += std::abs(da[k]); s[1] += 1; }
  petsc_check(VecRestoreArrayRead(dg, &da), "VecRestoreArrayRead");
  VecDestroy(&dg);
  MPI_Allreduce(MPI_IN_PLACE, s, 2, MPI_DOUBLE, MPI_SUM, comm);
  if (s[1] > 0) held_diag = s[0] / s[1];
  return held_diag;
}

/// CG + GAMG for the static solve (PETSc options apply); its preconditioner in `pc`.
KSP create_static_ksp(MPI_Comm comm, Mat A, double rtol, bool shells, PC& pc) {
  KSP ksp;
  petsc_check(KSPCreate(comm, &ksp), "KSPCreate");
  petsc_check(KSPSetOperators(ksp, A, A), "KSPSetOperators");
  petsc_check(KSPSetType(ksp, KSPCG), "KSPSetType");
  petsc_check(KSPGetPC(ksp, &pc), "KSPGetPC");
  petsc_check(PCSetType(pc, PCGAMG), "PCSetType");
  petsc_check(KSPSetTolerances(ksp, rtol, 1e-300, PETSC_DEFAULT, 10000), "KSPSetTolerances");
  petsc_check(KSPSetInitialGuessNonzero(ksp, PETSC_TRUE), "KSPSetInitialGuessNonzero");
  if (shells) {
    // Shells with bricks: GAMG's Chebyshev smoothers estimate the largest eigenvalue too low
    // (the default safety 1.1) and break down (DIVERGED_INDEFINITE_PC after 2 iterations on a
    // pipe tied to Hex20 soil); 1.5 solves it (134 iterations). A user's own setting wins.
    PetscBool set = PETSC_FALSE;
    petsc_check(PetscOptionsHasName(nullptr, nullptr, "-mg_levels_ksp_chebyshev_esteig", &set), "PetscOptionsHasName");
    if (!set) petsc_check(PetscOptionsSetValue(nullptr, "-mg_levels_ksp_chebyshev_esteig", "0,0.05,0,1.5"), "PetscOptionsSetValue");
  }
  petsc_check(KSPSetFromOptions(ksp), "KSPSetFromOptions");
  petsc_check(KSPSetComputeSingularValues(ksp, PETSC_TRUE), "KSPSetComputeSingularValues");
  return ksp;
}

/// The answer's guarantees (FeModel::StaticSolveInfo) after a converged solve.
void static_solve_quality(KSP ksp, PC pc, Mat A, Vec b, Vec x, PetscInt its, FeModel::StaticSolveInfo& info) {
  PetscReal rt = 0, at = 0, dt = 0, rnorm = 0, bnorm = 0, emax = 1, emin = 1;
  PetscInt mit = 0;
  petsc_check(KSPGetTolerances(ksp, &rt, &at, &dt, &mit), "KSPGetTolerances");
  // The true preconditioned residual |B (b - A x)| of the answer, not CG's recursively updated
  // one, which drifts from it by round-off near rtol 1e-12; relative to |B b|, the reference of
  // PETSc's default test (left preconditioning, the CG default).
  Vec r, br;
  petsc_check(VecDuplicate(b, &r), "VecDuplicate");
  petsc_check(VecDuplicate(b, &br), "VecDuplicate");
  petsc_check(MatMult(A, x, r), "MatMult");
  petsc_check(VecAYPX(r, -1.0, b), "VecAYPX");
  petsc_check(PCApply(pc, r, br), "PCApply");
  petsc_check(VecNorm(br, NORM_2, &rnorm), "VecNorm");
  petsc_check(PCApply(pc, b, br), "PCApply");
  petsc_check(VecNorm(br, NORM_2, &bnorm), "VecNorm");
  VecDestroy(&r);
  VecDestroy(&br);
  if (its > 0) petsc_check(KSPComputeExtremeSingularValues(ksp, &emax, &emin), "KSPComputeExtremeSingularValues");
  info.rtol = static_cast<double>(rt);
  info.residual = bnorm > 0 ? static_cast<double>(rnorm / bnorm) : 0.0;
  info.condition = emin > 0 ? std::max(1.0, static_cast<double>(emax / emin)) : 1.0;
}

}  // namespace

Mat FeModel::assemble_stiffness(PetscInt nloc) const {
  // The nonzero pattern first, from a dry run of the assembly (PETSc's MATPREALLOCATOR): each rank
  // enters the dof blocks of its own elements and the diagonal of every row it owns; rows owned
  // elsewhere go to their owners at the assembly. It needs no element but this rank's, so the
  // mesh may be a part (fem.distribute). Every diagonal is in the pattern: the held rows' value
  // (solve_static) must not add a nonzero after the assembly -- a reallocation per row: dofs
  // without stiffness, e.g. the rotations of nodes that only bricks use in a mesh with shells,
  // made a static solve with shells take minutes -- and a node of no element (tied to another,
  // fem.ties) has its row.
  std::vector<PetscInt> idx(kMaxNodes * 6);
  std::vector<PetscScalar> zeros(idx.size() * idx.size(), 0.0);
  auto element_dofs = [&](std::size_t le, int ed) {
    const int n = element_nodes(mesh_.elem_type[elems_[le]]);
    for (int k = 0; k < n; ++k)
      for (int d = 0; d < ed; ++d) idx[k * ed + d] = global_of_[elem_conn_[elem_off_[le] + k]] * nf_ + d;
    return n * ed;
  };
  Mat P;
  petsc_check(MatCreate(comm_, &P), "MatCreate");
  petsc_check(MatSetType(P, MATPREALLOCATOR), "MatSetType");
  petsc_check(MatSetSizes(P, nloc, nloc, PETSC_DETERMINE, PETSC_DETERMINE), "MatSetSizes");
  petsc_check(MatSetBlockSize(P, nf_), "MatSetBlockSize");
  petsc_check(MatSetUp(P), "MatSetUp");
  PetscInt r0 = 0;
  petsc_check(MatGetOwnershipRange(P, &r0, nullptr), "MatGetOwnershipRange");
  for (PetscInt r = r0; r < r0 + nloc; ++r) petsc_check(MatSetValue(P, r, r, 0.0, ADD_VALUES), "MatSetValue");
  for (std::size_t le = 0; le < elems_.size(); ++le) {
    if (!active_[le]) continue;
    const int nd = element_dofs(le, element_node_dofs(mesh_.elem_type[elems_[le]]));
    petsc_check(MatSetValues(P, nd, idx.data(), nd, idx.data(), zeros.data(), ADD_VALUES), "MatSetValues");
  }
  petsc_check(MatAssemblyBegin(P, MAT_FINAL_ASSEMBLY), "MatAssemblyBegin");
  petsc_check(MatAssemblyEnd(P, MAT_FINAL_ASSEMBLY), "MatAssemblyEnd");
  Mat A;
  petsc_check(MatCreate(comm_, &A), "MatCreate");
  petsc_check(MatSetType(A, MATAIJ), "MatSetType");
  petsc_check(MatSetSizes(A, nloc, nloc, PETSC_DETERMINE, PETSC_DETERMINE), "MatSetSizes");
  petsc_check(MatSetBlockSize(A, nf_), "MatSetBlockSize");
  petsc_check(MatPreallocatorPreallocate(P, PETSC_TRUE, A), "MatPreallocatorPreallocate");  // (the pattern, zeros)
  petsc_check(MatDestroy(&P), "MatDestroy");
  petsc_check(MatSetOption(A, MAT_NEW_NONZERO_LOCATION_ERR, PETSC_TRUE), "MatSetOption");
  for_each_stiffness([&](std::size_t le, int n, int ed, const double* K) {
    const int nd = element_dofs(le, ed);
    (void)n;
    petsc_check(MatSetValues(A, nd, idx.data(), nd, idx.data(), K, ADD_VALUES), "MatSetValues");
  });
  petsc_check(MatAssemblyBegin(A, MAT_FINAL_ASSEMBLY), "MatAssemblyBegin");
  petsc_check(MatAssemblyEnd(A, MAT_FINAL_ASSEMBLY), "MatAssemblyEnd");
  return A;
}

void FeModel::fill_static_system(Vec b, Vec x, std::vector<PetscInt>& held_rows) const {
  PetscScalar *ba, *xa;
  petsc_check(VecGetArray(b, &ba), "VecGetArray");
  petsc_check(VecGetArray(x, &xa), "VecGetArray");
  PetscInt first = 0;
  petsc_check(VecGetOwnershipRange(b, &first, nullptr), "VecGetOwnershipRange");
  for (std::size_t k = 0; k < n_owned_ * nf_; ++k) {
    // Dofs without mass have no stiffness either (rotations of nodes that only bricks use).
    const bool held = fixed_[k] || mass_[k] <= 0;
    ba[k] = load_factor_ * fext_[k] + body_[k] + iface_[k];
    xa[k] = fixed_[k] ? disp_factor_ * presc_[k] : 0.0;
    if (held) held_rows.push_back(first + static_cast<PetscInt>(k));
  }
  petsc_check(VecRestoreArray(x, &xa), "VecRestoreArray");
  petsc_check(VecRestoreArray(b, &ba), "VecRestoreArray");
}

MatNullSpace FeModel::set_near_null_space(Mat A, Vec x, Vec& coords) const {
  MatNullSpace nsp = nullptr;
  if (nf_ == dim_) {
    petsc_check(VecDuplicate(x, &coords), "VecDuplicate");
    petsc_check(VecSetBlockSize(coords, dim_), "VecSetBlockSize");
    PetscScalar* ca;
    petsc_check(VecGetArray(coords, &ca), "VecGetArray");
    for (std::size_t i = 0; i < n_owned_; ++i)
      for (int d = 0; d < dim_; ++d) ca[i * dim_ + d] = mesh_.coords[static_cast<std::size_t>(mesh_of_[i]) * dim_ + d];
    petsc_check(VecRestoreArray(coords, &ca), "VecRestoreArray");
    petsc_check(MatNullSpaceCreateRigidBody(coords, &nsp), "MatNullSpaceCreateRigidBody");
    petsc_check(MatSetNearNullSpace(A, nsp), "MatSetNearNullSpace");
  } else if (nf_ == 6 && dim_ == 3) {
    nsp = set_shell_near_null_space(A, x);
  }
  return nsp;
}

MatNullSpace FeModel::set_shell_near_null_space(Mat A, Vec x) const {
  // With shells (6 dofs per node): the six rigid-body modes with their rotations -- translation
  // e_k; rotation about axis k: u = e_k x (X - c), theta = e_k -- orthonormalised. Without them
  // GAMG's default (constants per dof) mis-coarsened a pipe of shells tied to bricks and its
  // Chebyshev smoothers broke down (DIVERGED_INDEFINITE_PC).
  MatNullSpace nsp = nullptr;
  double c[3] = {0, 0, 0}, cnt = static_cast<double>(n_owned_);
  for (std::size_t i = 0; i < n_owned_; ++i)
    for (int d = 0; d < 3; ++d) c[d] += mesh_.coords[static_cast<std::size_t>(mesh_of_[i]) * 3 + d];
  MPI_Allreduce(MPI_IN_PLACE, c, 3, MPI_DOUBLE, MPI_SUM, comm_);
  MPI_Allreduce(MPI_IN_PLACE, &cnt, 1, MPI_DOUBLE, MPI_SUM, comm_);
  for (double& v : c) v /= std::max(1.0, cnt);
  Vec modes[6];
  for (int m = 0; m < 6; ++m) {
    petsc_check(VecDuplicate(x, &modes[m]), "VecDuplicate");
    PetscScalar* ma;
    petsc_check(VecGetArray(modes[m], &ma), "VecGetArray");
    for (std::size_t i = 0; i < n_owned_; ++i) {
      double* r = ma + i * 6;
      for (int d = 0; d < 6; ++d) r[d] = 0;
      const double* X = &mesh_.coords[static_cast<std::size_t>(mesh_of_[i]) * 3];
      const double p[3] = {X[0] - c[0], X[1] - c[1], X[2] - c[2]};
      if (m < 3) {
        r[m] = 1;
      } else {
        const int k = m - 3, a = (k + 1) % 3, b = (k + 2) % 3;  // e_k x p
        r[a] = -p[b];
        r[b] = p[a];
        r[3 + k] = 1;
      }
    }
    petsc_check(VecRestoreArray(modes[m], &ma), "VecRestoreArray");
    // Gram-Schmidt against the earlier modes (twice, for round-off)
    for (int pass = 0; pass < 2; ++pass)
      for (int q = 0; q < m; ++q) {
        PetscScalar dot;
        petsc_check(VecDot(modes[m], modes[q], &dot), "VecDot");
        petsc_check(VecAXPY(modes[m], -dot, modes[q]), "VecAXPY");
      }
    petsc_check(VecNormalize(modes[m], nullptr), "VecNormalize");
  }
  petsc_check(MatNullSpaceCreate(comm_, PETSC_FALSE, 6, modes, &nsp), "MatNullSpaceCreate");
  petsc_check(MatSetNearNullSpace(A, nsp), "MatSetNearNullSpace");
  for (Vec& v : modes) VecDestroy(&v);
  return nsp;
}

void FeModel::copy_into_displacements(Vec x) {
  const PetscScalar* xr;
  PetscScalar* ua;
  petsc_check(VecGetArrayRead(x, &xr), "VecGetArrayRead");
  petsc_check(VecGetArray(u_, &ua), "VecGetArray");
  for (std::size_t k = 0; k < n_owned_ * nf_; ++k) ua[k] = xr[k];
  petsc_check(VecRestoreArray(u_, &ua), "VecRestoreArray");
  petsc_check(VecRestoreArrayRead(x, &xr), "VecRestoreArrayRead");
  petsc_check(VecGhostUpdateBegin(u_, INSERT_VALUES, SCATTER_FORWARD), "VecGhostUpdateBegin");
  petsc_check(VecGhostUpdateEnd(u_, INSERT_VALUES, SCATTER_FORWARD), "VecGhostUpdateEnd");
}

FeModel::StaticSolveInfo FeModel::solve_static(double rtol) {
  const PetscInt nloc = static_cast<PetscInt>(n_owned_ * nf_);
  Mat A = assemble_stiffness(nloc);
  Vec b, x;
  petsc_check(MatCreateVecs(A, &x, &b), "MatCreateVecs");
  std::vector<PetscInt> rows;
  fill_static_system(b, x, rows);
  // Rigid-body modes as the near-null space for GAMG (translational dofs only; not with shells).
  Vec coords = nullptr;
  MatNullSpace nsp = set_near_null_space(A, x, coords);
  // The held rows' diagonal: the mean of the stiffness diagonal, not 1 -- a unit entry among
  // stiffnesses of 1e8 N/m spreads the spectrum, and GAMG's Chebyshev smoothers, whose largest
  // eigenvalue estimate then falls short, broke down (DIVERGED_INDEFINITE_PC) on a mesh of
  // shells tied to bricks. The answer does not depend on it (x = the prescribed value there).
  const double held_diag = mean_abs_diagonal(A, nloc, comm_);
  petsc_check(MatZeroRowsColumns(A, static_cast<PetscInt>(rows.size()), rows.data(), held_diag, x, b), "MatZeroRowsColumns");
  PC pc;
  KSP ksp = create_static_ksp(comm_, A, rtol, nf_ == 6, pc);
  petsc_check(KSPSolve(ksp, b, x), "KSPSolve");
  KSPConvergedReason reason;
  PetscInt its = 0;
  petsc_check(KSPGetConvergedReason(ksp, &reason), "KSPGetConvergedReason");
  petsc_check(KSPGetIterationNumber(ksp, &its), "KSPGetIterationNumber");
  auto destroy = [&]() {
    if (nsp) MatNullSpaceDestroy(&nsp);
    if (coords) VecDestroy(&coords);
    KSPDestroy(&ksp);
    VecDestroy(&b);
    VecDestroy(&x);
    MatDestroy(&A);
  };
  if (reason < 0) {
    destroy();  // first: the caller reports the failure and the run goes on to end cleanly
    throw std::runtime_error(std::string("static solve did not converge (KSP reason ") + KSPConvergedReasons[reason] +
                             " after " + std::to_string(its) + " iterations)");
  }
  StaticSolveInfo info;
  info.iterations = static_cast<int>(its);
  static_solve_quality(ksp, pc, A, b, x, its, info);
  copy_into_displacements(x);
  destroy();
  // The integration points' stress and strain of the answer (elastic: from the total strain),
  // for the output; before, a static run wrote zeros there.
  internal_force(true);
  return info;
}

FeState FeModel::state() const {
  FeState s;
  const PetscScalar* uo;
  petsc_check(VecGetArrayRead(u_, &uo), "VecGetArrayRead");
  s.u.assign(uo, uo + n_owned_ * nf_);
  petsc_check(VecRestoreArrayRead(u_, &uo), "VecRestoreArrayRead");
  for (std::size_t i = 0; i < n_owned_; ++i) s.node.push_back(whole_node(mesh_of_[i]));
  s.v = v_;
  for (std::size_t le = 0; le < elems_.size(); ++le)
    for (std::int32_t g = gp_off_[le]; g < gp_off_[le + 1]; ++g) {
      s.gp_elem.push_back(whole_elem(elems_[le]));
      s.gp_k.push_back(g - gp_off_[le]);
      const GaussState& q = gp_[g];
      s.gp_data.insert(s.gp_data.end(), q.stress, q.stress + 6);
      s.gp_data.insert(s.gp_data.end(), q.strain, q.strain + 6);
      s.gp_data.insert(s.gp_data.end(), q.plastic_strain, q.plastic_strain + 6);
      s.gp_data.push_back(q.yielded ? 1.0 : 0.0);
    }
  s.removed = removed_;
  s.c_last = c_last_;
  s.has_prev = have_prev_ ? 1 : 0;
  if (have_prev_) {
    s.u_prev = u_prev_;
    s.f_prev = f_prev_;
  }
  s.has_check = have_check_ ? 1 : 0;
  if (have_check_) s.u_check = u_check_;
  return s;
}

void FeModel::restore(const FeState& s) {
  PetscScalar* ua;
  petsc_check(VecGetArray(u_, &ua), "VecGetArray");
  // (the local node of a state row: -1 where this rank does not own it)
  std::vector<std::int32_t> row_node(s.node.size(), -1);
  for (std::size_t k = 0; k < s.node.size(); ++k) {
    const std::int32_t n = part_node(s.node[k]);
    const std::int32_t ln = n < 0 ? -1 : local_of_[n];
    if (ln >= 0 && static_cast<std::size_t>(ln) < n_owned_) row_node[k] = ln;
  }
  for (std::size_t k = 0; k < s.node.size(); ++k) {
    const std::int32_t ln = row_node[k];
    if (ln < 0) continue;
    for (int d = 0; d < nf_; ++d) {
      ua[ln * nf_ + d] = s.u[k * nf_ + d];
      v_[ln * nf_ + d] = s.v[k * nf_ + d];
    }
  }
  petsc_check(VecRestoreArray(u_, &ua), "VecRestoreArray");
  petsc_check(VecGhostUpdateBegin(u_, INSERT_VALUES, SCATTER_FORWARD), "VecGhostUpdateBegin");
  petsc_check(VecGhostUpdateEnd(u_, INSERT_VALUES, SCATTER_FORWARD), "VecGhostUpdateEnd");
  std::vector<std::int32_t> local_elem(mesh_.n_elements(), -1);
  for (std::size_t le = 0; le < elems_.size(); ++le) local_elem[elems_[le]] = static_cast<std::int32_t>(le);
  for (std::size_t r = 0; r < s.gp_elem.size(); ++r) {
    const std::int32_t e = part_elem(s.gp_elem[r]);
    const std::int32_t le = e < 0 ? -1 : local_elem[e];
    if (le < 0 || s.gp_k[r] >= gp_off_[le + 1] - gp_off_[le]) continue;
    GaussState& q = gp_[gp_off_[le] + s.gp_k[r]];
    const double* d = &s.gp_data[r * 19];
    std::copy(d, d + 6, q.stress);
    std::copy(d + 6, d + 12, q.strain);
    std::copy(d + 12, d + 18, q.plastic_strain);
    q.yielded = d[18] != 0.0;
  }
  std::vector<std::int32_t> rem(s.removed.begin(), s.removed.end());
  removed_.clear();
  active_.assign(elems_.size(), 1);
  remove_elements(rem);
  c_last_ = s.c_last;
  have_prev_ = s.has_prev != 0 && s.u_prev.size() == s.u.size() && s.f_prev.size() == s.u.size();
  if (have_prev_) {
    u_prev_.assign(n_owned_ * nf_, 0.0);
    f_prev_.assign(n_owned_ * nf_, 0.0);
    for (std::size_t k = 0; k < s.node.size(); ++k) {
      const std::int32_t ln = row_node[k];
      if (ln < 0) continue;
      for (int d = 0; d < nf_; ++d) {
        u_prev_[ln * nf_ + d] = s.u_prev[k * nf_ + d];
        f_prev_[ln * nf_ + d] = s.f_prev[k * nf_ + d];
      }
    }
  }
  have_check_ = s.has_check != 0 && s.u_check.size() == s.u.size();
  u_check_.clear();
  if (have_check_) {
    u_check_.assign(n_owned_ * nf_, 0.0);
    for (std::size_t k = 0; k < s.node.size(); ++k)
      if (row_node[k] >= 0)
        for (int d = 0; d < nf_; ++d) u_check_[row_node[k] * nf_ + d] = s.u_check[k * nf_ + d];
  }
}

std::vector<double> FeModel::owned_displacements() const {
  const PetscScalar* ua;
  petsc_check(VecGetArrayRead(u_, &ua), "VecGetArrayRead");
  std::vector<double> out(n_owned_ * dim_);
  for (std::size_t i = 0; i < n_owned_; ++i)
    for (int d = 0; d < dim_; ++d) out[i * dim_ + d] = ua[i * nf_ + d];
  petsc_check(VecRestoreArrayRead(u_, &ua), "VecRestoreArrayRead");
  return out;
}

FeModel::Health FeModel::health() const {
  const PetscScalar* ua;
  petsc_check(VecGetArrayRead(u_, &ua), "VecGetArrayRead");
  long long bad = std::numeric_limits<long long>::max();
  struct { double v; int node; } mx{0.0, std::numeric_limits<int>::max()}, gmx;
  for (std::size_t i = 0; i < n_owned_; ++i) {
    const long long node = whole_node(mesh_of_[i]);
    double s = 0;
    bool finite = true;
    for (int d = 0; d < nf_; ++d) {
      const double u = ua[i * nf_ + d], v = v_[i * nf_ + d];
      finite = finite && std::isfinite(u) && std::isfinite(v);
      if (d < dim_) s += u * u;
    }
    if (!finite || !std::isfinite(s)) { bad = std::min(bad, node); continue; }
    const double m = std::sqrt(s);
    if (m > mx.v || (m == mx.v && node < mx.node)) mx = {m, static_cast<int>(node)};
  }
  petsc_check(VecRestoreArrayRead(u_, &ua), "VecRestoreArrayRead");
  long long gbad = 0;
  MPI_Allreduce(&bad, &gbad, 1, MPI_LONG_LONG, MPI_MIN, comm_);
  MPI_Allreduce(&mx, &gmx, 1, MPI_DOUBLE_INT, MPI_MAXLOC, comm_);
  Health h;
  h.nonfinite_node = gbad == std::numeric_limits<long long>::max() ? -1 : gbad;
  h.max_u = gmx.v;
  h.max_node = gmx.node == std::numeric_limits<int>::max() ? -1 : gmx.node;
  return h;
}

std::vector<double> FeModel::gather_displacements() const {
  const PetscScalar* ua;
  petsc_check(VecGetArrayRead(u_, &ua), "VecGetArrayRead");
  std::vector<double> loc;
  loc.reserve(n_owned_ * (dim_ + 1));
  for (std::size_t i = 0; i < n_owned_; ++i) {
    loc.push_back(static_cast<double>(whole_node(mesh_of_[i])));
    for (int d = 0; d < dim_; ++d) loc.push_back(ua[i * nf_ + d]);
  }
  petsc_check(VecRestoreArrayRead(u_, &ua), "VecRestoreArrayRead");
  const std::vector<double> all = allgather(loc, comm_);
  std::vector<double> out(static_cast<std::size_t>(n_nodes_global_) * dim_, 0.0);
  for (std::size_t k = 0; k < all.size(); k += dim_ + 1) {
    const auto node = static_cast<std::size_t>(all[k]);
    for (int d = 0; d < dim_; ++d) out[node * dim_ + d] = all[k + 1 + d];
  }
  return out;
}

std::array<double, 3> FeModel::reaction(const std::vector<std::int32_t>& nodes) const {
  // Uses the internal forces of the last step/unbalanced() call.
  const PetscScalar* fa;
  petsc_check(VecGetArrayRead(f_, &fa), "VecGetArrayRead");
  exact::ExactSums sums(3);  // the same sum on any number of ranks
  for (std::int32_t node : nodes) {
    const std::int32_t ln = local_of_[node];
    if (ln < 0 || static_cast<std::size_t>(ln) >= n_owned_) continue;
    for (int d = 0; d < dim_; ++d) {
      const std::size_t k = static_cast<std::size_t>(ln) * nf_ + d;
      if (fixed_[k]) sums.add(static_cast<std::size_t>(d), fa[k] - load_factor_ * fext_[k] - body_[k] - iface_[k]);
    }
  }
  petsc_check(VecRestoreArrayRead(f_, &fa), "VecRestoreArrayRead");
  const std::vector<double> g = sums.sums(comm_);
  return {g[0], g[1], g[2]};
}

void FeModel::set_interface_forces(const std::vector<PetscInt>& global_nodes, const std::vector<double>& forces) {
  std::vector<exact::Int> f(forces.size());
  for (std::size_t k = 0; k < forces.size(); ++k) f[k] = exact::to_fixed(forces[k]);
  set_interface_forces_exact(global_nodes, f, 1.0);
}

void FeModel::set_interface_forces_exact(const std::vector<PetscInt>& global_nodes, const std::vector<exact::Int>& forces,
                                         double scale, bool same_nodes) {
  // Each value as 4 integer limbs (exact in doubles); VecSetValues(ADD_VALUES) + VecAssembly sum
  // them across ranks in whatever order -- exactly; the owner merges them.
  constexpr int L = exact::kLimbs;
  if (!fi_) {
    petsc_check(VecCreateMPI(comm_, static_cast<PetscInt>(n_owned_ * 3 * L), PETSC_DETERMINE, &fi_), "VecCreateMPI");
    petsc_check(VecSetBlockSize(fi_, 3 * L), "VecSetBlockSize");
  }
  if (!same_nodes) {  // a new pattern: turning the option off and on makes the next assembly its first
    petsc_check(VecSetOption(fi_, VEC_SUBSET_OFF_PROC_ENTRIES, PETSC_FALSE), "VecSetOption");
    petsc_check(VecSetOption(fi_, VEC_SUBSET_OFF_PROC_ENTRIES, PETSC_TRUE), "VecSetOption");
  }
  petsc_check(VecSet(fi_, 0.0), "VecSet");
  std::vector<PetscInt> idx;
  std::vector<PetscScalar> val;
  idx.reserve(3 * L * global_nodes.size());
  val.reserve(3 * L * global_nodes.size());
  double limbs[L];
  for (std::size_t k = 0; k < global_nodes.size(); ++k)
    for (int d = 0; d < 3; ++d) {
      exact::split(forces[3 * k + d], limbs);
      for (int l = 0; l < L; ++l) {
        idx.push_back((global_nodes[k] * 3 + d) * L + l);
        val.push_back(limbs[l]);
      }
    }
  petsc_check(VecSetValues(fi_, static_cast<PetscInt>(idx.size()), idx.data(), val.data(), ADD_VALUES), "VecSetValues");
  petsc_check(VecAssemblyBegin(fi_), "VecAssemblyBegin");
  petsc_check(VecAssemblyEnd(fi_), "VecAssemblyEnd");
  const PetscScalar* a;
  petsc_check(VecGetArrayRead(fi_, &a), "VecGetArrayRead");
  iface_.assign(n_owned_ * nf_, 0.0);
  for (std::size_t i = 0; i < n_owned_; ++i)
    for (int d = 0; d < 3; ++d)
      iface_[i * nf_ + d] = scale * exact::from_fixed(exact::merge(&a[(i * 3 + d) * L]));
  petsc_check(VecRestoreArrayRead(fi_, &a), "VecRestoreArrayRead");
}

std::array<double, 3> FeModel::interface_force_total() const {
  exact::ExactSums sums(3);
  for (std::size_t i = 0; i < n_owned_; ++i)
    for (int d = 0; d < 3 && d < nf_; ++d) sums.add(static_cast<std::size_t>(d), iface_[i * nf_ + d]);
  const std::vector<double> g = sums.sums(comm_);
  return {g[0], g[1], g[2]};
}

}  // namespace fdem::fem
