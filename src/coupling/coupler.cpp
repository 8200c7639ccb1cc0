#include "coupling/coupler.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "base/scoped_timer.hpp"

namespace fdem::coupling {
namespace {

using Timer = ScopedTimer;

/// `mesh`, after the checks of the coupler's arguments.
const fem::Mesh& checked(const fem::Mesh& mesh, const CouplerParams& prm, double dt_dem) {
  if (prm.subcycle < 1)
    throw std::invalid_argument("Coupler: subcycle must be at least 1, got " + std::to_string(prm.subcycle));
  if (!(dt_dem > 0)) throw std::invalid_argument("Coupler: the DEM step must be positive");
  if (mesh.dim != 3) throw std::invalid_argument("Coupler: the FE mesh must be 3-D");
  return mesh;
}

}  // namespace

std::vector<std::pair<const char*, double>> CouplerTimings::stages() const {
  return {{"coupling_contacts", contacts}, {"coupling_candidates", candidates}, {"coupling_scan", scan},
          {"coupling_select", select},    {"coupling_law", law},               {"coupling_distribute", distribute},
          {"coupling_reduce", reduce},    {"coupling_fe", fe},                 {"coupling_scatter", scatter}};
}

int Coupler::auto_subcycle(double dt_fe_stable, double dt_dem) {
  if (!(dt_dem > 0)) throw std::invalid_argument("auto_subcycle: the DEM step must be positive");
  const double q = dt_fe_stable / dt_dem;
  if (!(q >= 1)) return 1;
  return static_cast<int>(std::min(q * (1 + 1e-12), 1e9));
}

Coupler::Coupler(MPI_Comm comm, const fem::Mesh& mesh, fem::FeModel& model, std::vector<InterfaceTriangle> tris,
                 const CouplerParams& prm, double dt_dem, std::vector<PetscInt> global_of_node)
    : model_(model), prm_(prm), dt_dem_(dt_dem), n_(prm.subcycle), rigid_(prm.rigid),
      surface_(checked(mesh, prm, dt_dem), std::move(tris)),
      forces_(surface_.n_vertices(), surface_.n_groups()),
      exchange_(comm, model, mesh.n_nodes(), std::move(global_of_node)),
      last_group_force_(surface_.n_groups()) {
  group_material_ = prm.group_material;
  if (group_material_.size() > static_cast<std::size_t>(surface_.n_groups()))
    throw std::invalid_argument("Coupler: more group materials than surface groups");
  group_material_.resize(surface_.n_groups(), prm.material);  // (groups without their own: `material`)
  // The largest displacement so far (a restarted model may be deformed already).
  max_fe_disp_ = exchange_.max_displacement();
}

bool Coupler::extrapolating() const { return !rigid_ && n_ > 1 && vmax_ > 0; }

void Coupler::build(const ParticleStore& p, const Vec3& lo, const Vec3& hi, double margin, const HistoryMap& history) {
  // The candidates' vertices change below: their force sums go to the nodes first.
  exchange_.collect_vertex_sums(surface_, contacts_.candidate_vertices(), forces_.vertex_sums());
  double rmax = 0;
  for (std::size_t i = 0; i < p.n_owned; ++i) rmax = std::max(rmax, p.r[i]);
  update_seen(lo, hi, rmax + margin);
  exchange_.mark_build();
  // Between FE updates the surface is extrapolated (see compute()): it may move dt_FE v_max
  // within one sub-cycle without any FE update.
  moved_ = extrapolating() ? dt_fe() * vmax_ : 0.0;
  // The whole seen surface where it is now (extrapolated within the sub-cycle; compute() then
  // moves only the candidates' triangles).
  if (extrapolating()) surface_.extrapolate(seen_vertices_, substeps_ * dt_dem_);
  Timer all(timing_.contacts);
  Timer tm(timing_.candidates);
  contacts_.build(p, surface_, seen_, lo, hi, margin, history);
}

void Coupler::update_seen(const Vec3& lo, const Vec3& hi, double reach) {
  std::vector<std::int32_t> seen = surface_.triangles_near(lo, hi, reach + max_fe_disp_);
  const bool changed = seen != seen_ || !exchange_.has_scatter();
  seen_.swap(seen);
  if (!exchange_.any_rank(changed)) return;
  {
    Timer tm(timing_.scatter);
    seen_vertices_ = surface_.vertices_of(seen_);
    exchange_.need_nodes(surface_.nodes_of(seen_));
  }
  // Positions, then the nodal velocities of the last FE step: the FE's own velocity, which is
  // exactly its last displacement increment / dt_FE (also for prescribed dofs), so newly seen
  // nodes and a restarted run get the same surface velocity as an uninterrupted run.
  gather_positions();
  gather_velocities();
}

void Coupler::gather_positions() {
  Timer tm(timing_.scatter);
  exchange_.gather_displacements();
  surface_.place_at_fe(seen_, seen_vertices_, exchange_.node_disp(), exchange_.node_slot());
}

void Coupler::gather_velocities(bool reduce_vmax) {
  Timer tm(timing_.scatter);
  const double loc = exchange_.gather_velocities(rigid_);
  // Vertex velocities of the seen triangles (always the FE's own velocity: a finite difference
  // of positions would differ from it in the last bits, and on a rank whose scatter was just
  // rebuilt the two would mix -- results would then depend on the number of ranks).
  surface_.set_velocities(seen_, exchange_.node_vel_last_fe(), exchange_.node_slot());
  if (!reduce_vmax) return;  // the caller reduces it with other maxima
  vmax_ = exchange_.max_over_ranks(std::sqrt(loc));
}

void Coupler::set_active_triangles(const std::vector<std::uint8_t>& active) {
  bool same = active.size() == surface_.n_triangles();
  for (std::size_t t = 0; same && t < active.size(); ++t) same = surface_.active(t) == (active[t] != 0);
  if (same) return;
  surface_.set_active(active);
  moved_ = std::numeric_limits<double>::infinity();  // the engine rebuilds before its next step
}

void Coupler::refresh_positions() {
  // Collective: every rank rebuilds (its seen set is unchanged) and reads the FE state.
  if (!exchange_.has_scatter()) return;
  gather_positions();
  moved_ = std::numeric_limits<double>::infinity();  // unknown motion: no quick rejection, rebuild
}

void Coupler::compute(ParticleStore& p, const MaterialTable& mats, double dt) {
  Timer all(timing_.contacts);
  {
    Timer tm(timing_.scan);
    // Sub-step k of a sub-cycle sees the surface where the last FE velocity carries it,
    // x = x_FE + k dt_DE v_FE, instead of frozen for n steps and then jumping by dt_FE v_FE:
    // the jump at the next FE update is then only O(dt_FE^2 a).
    if (extrapolating()) surface_.extrapolate(contacts_.candidate_vertices(), substeps_ * dt_dem_);
    // The quick rejection uses the planes of the FE positions: the extrapolated triangle is
    // within s v_max of them.
    const double slack = extrapolating() ? substeps_ * dt_dem_ * vmax_ : 0.0;
    contacts_.scan(p, surface_, moved_, slack);
  }
  {
    Timer tm(timing_.select);
    contacts_.select(p, surface_);
  }
  {
    Timer tm(timing_.law);
    forces_.apply_law(p, mats, group_material_, surface_, contacts_, dt);
  }
  {
    Timer tm(timing_.distribute);
    forces_.distribute(surface_, contacts_);
  }
  ++substeps_;
}

void Coupler::end_step(std::int64_t step, exact::StepSums& sums) {
  pending_.active = false;
  if (step % n_ == 0) pending_.active = fe_update_start(sums);
}

void Coupler::finish_step(const exact::StepSums& sums) {
  if (pending_.active) fe_update_finish(sums);
  pending_.active = false;
}

void Coupler::fe_update() {
  exact::StepSums sums;
  if (!fe_update_start(sums)) return;
  {
    Timer tm(timing_.reduce);
    exchange_.allreduce(sums);
  }
  fe_update_finish(sums);
}

bool Coupler::fe_update_start(exact::StepSums& sums) {
  // Every rank computes every DEM step (compute() is collective in effect), so substeps_ is the
  // same on all ranks: no collective is needed to agree on it.
  if (substeps_ == 0) return false;
  {
    Timer tm(timing_.reduce);
    exchange_.collect_vertex_sums(surface_, contacts_.candidate_vertices(), forces_.vertex_sums());
    pending_.inv = 1.0 / substeps_;
    const std::vector<exact::Int> tot = exchange_.assemble_forces(pending_.inv, forces_.group_sums());
    pending_.totals = sums.add_sums(tot.data(), tot.size());
    last_substeps_ = substeps_;
    substeps_ = 0;
  }
  pending_.has_motion = false;
  if (rigid_) {
    exchange_.clear_node_velocities();
    surface_.clear_velocities();
    // Back to the FE positions if the surface was being extrapolated when it was made rigid.
    if (vmax_ > 0) {
      surface_.return_to_fe(seen_vertices_, seen_);
      vmax_ = 0;
    }
    return true;
  }
  {
    Timer tm(timing_.fe);
    model_.step(dt_fe());
    ++fe_steps_;
  }
  gather_positions();
  gather_velocities(false);  // vmax_ from the maxima below
  // The largest vertex motion since the last build, FE displacement and node speed: maxima over
  // the ranks, reduced with the totals.
  const std::array<double, 3> loc = exchange_.local_motion();
  pending_.motion = sums.add_max(loc[0]);
  sums.add_max(loc[1]);
  sums.add_max(loc[2]);
  pending_.has_motion = true;
  return true;
}

void Coupler::fe_update_finish(const exact::StepSums& sums) {
  std::vector<exact::Int> tot(3 + 3 * last_group_force_.size());
  for (std::size_t k = 0; k < tot.size(); ++k) tot[k] = sums.sum(pending_.totals + k);
  InterfaceExchange::totals_from(tot.data(), last_group_force_.size(), pending_.inv, last_update_force_,
                                 last_group_force_);
  if (!pending_.has_motion) return;
  const SurfaceMotion motion{sums.max(pending_.motion), sums.max(pending_.motion + 1), sums.max(pending_.motion + 2)};
  vmax_ = motion.max_speed;
  // Node motion since the build, plus the extrapolation at the build and from now on.
  moved_ = motion.moved + (extrapolating() ? 2 * dt_fe() * vmax_ : 0.0);
  max_fe_disp_ = std::max(max_fe_disp_, motion.max_disp);
}

void Coupler::save_history(const ParticleStore& p, std::vector<ContactRecord>& out) const {
  contacts_.save_history(p, out);
}

std::int64_t Coupler::global_active() {
  return exchange_.sum_over_ranks(static_cast<std::int64_t>(n_active()));
}

}  // namespace fdem::coupling
