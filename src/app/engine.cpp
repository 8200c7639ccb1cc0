#include "app/engine.hpp"

#include "base/exact_sum.hpp"

#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <string>
#include <unordered_set>

#include "dem/integrator.hpp"
#include "base/errors.hpp"
#include "base/scoped_timer.hpp"
#include "base/allgather.hpp"
#include "partition/scatter.hpp"

namespace fdem {

const char* stage_name(Stage s) {
  switch (s) {
    case Stage::kNeighbors: return "neighbours";
    case Stage::kGhosts: return "ghost_update";
    case Stage::kContacts: return "particle_contacts";
    case Stage::kWalls: return "wall_contacts";
    case Stage::kInterface: return "interface_contacts";
    case Stage::kCoupling: return "fe_update";
    case Stage::kIntegrate: return "integrate";
    case Stage::kReduce: return "reductions";
    default: return "?";
  }
}

double critical_dt(const ParticleStore& all, const MaterialTable& mats) {
  double dt = 1e300;
  for (std::size_t i = 0; i < all.size(); ++i)
    dt = std::min(dt, std::sqrt(all.m[i] / (2.0 * mats[all.mat[i]].young * all.r[i])));
  if (mats.any_hertz()) {
    // Hertz pairs have no stiffness before they overlap: bound the step by the Rayleigh time
    // step of each grain, pi r sqrt(rho/G) / (0.1631 nu + 0.8766) with G = E / (2 (1 + nu))
    // (the time a Rayleigh wave takes to cross it; Li et al. 2005, as YADE's and LIGGGHTS'
    // estimates), and keep the smaller of it and the linear spring's. The spring's 2 E r is
    // the stiffer for any overlap below about r (1 - nu^2)^2, and for a sphere with nu >= 0 the
    // Rayleigh step is >= 3.5 times the spring's: the linear estimate rules but for nu near -1
    // or a mass above the density's (mass scaling).
    for (std::size_t i = 0; i < all.size(); ++i) {
      const Material& m = mats[all.mat[i]];
      const double g = m.young / (2.0 * (1.0 + m.poisson));
      dt = std::min(dt, M_PI * all.r[i] * std::sqrt(m.density / g) / (0.1631 * m.poisson + 0.8766));
    }
  }
  return dt;
}

namespace {
using Timer = ScopedTimer;

// An active pair of the particle list before a rebuild, by ids, with the particles' order keys.
struct OldPair {
  std::int64_t ka, a, kb, b;
  Vec3 ft, rot;
};

// Position of a pair in the canonical order (neighbor.hpp): (key a, id a, key b, id b).
inline bool pair_before(const OldPair& o, std::int64_t ka, std::int64_t a, std::int64_t kb, std::int64_t b) {
  if (o.ka != ka || o.a != a) return key_id_before(o.ka, o.a, ka, a);
  return key_id_before(o.kb, o.b, kb, b);
}

// The active pairs of the old list, which is in the canonical order like the new one (the keys
// are fixed per particle), so the two are merged in one pass (restore_pair_history).
std::vector<OldPair> active_old_pairs(const ParticleStore& p, const PairList& pairs,
                                      const std::vector<std::uint8_t>& active, const std::vector<Vec3>& ft,
                                      const std::vector<Vec3>& rot) {
  std::vector<OldPair> old;
  for (std::size_t k = 0; k < pairs.size(); ++k)
    if (active[k]) {
      const std::uint32_t a = pairs.a[k], b = pairs.b[k];
      old.push_back({p.key[a], p.id[a], p.key[b], p.id[b], ft[k], rot.empty() ? Vec3{} : rot[k]});
    }
  return old;
}

// Cost of each owned particle for the load balance: 1 + its particle contacts.
std::vector<double> owned_costs(const ParticleStore& p, const PairList& pairs, const std::vector<std::uint8_t>& active) {
  std::vector<double> cost(p.n_owned, 1.0);
  for (std::size_t k = 0; k < pairs.size(); ++k)
    if (active[k]) {
      if (pairs.a[k] < p.n_owned) cost[pairs.a[k]] += 1;
      if (pairs.b[k] < p.n_owned) cost[pairs.b[k]] += 1;
    }
  return cost;
}

// Particles that left the domain: reported (ids appended to `removed`) and removed, never
// silently lost. Returns how many were removed here; `cost` follows the kept particles.
std::int64_t remove_escaped(ParticleStore& p, const EngineParams& prm, std::vector<std::int64_t>& removed,
                            std::vector<double>& cost) {
  std::vector<std::size_t> keep;
  keep.reserve(p.n_owned);
  std::int64_t removed_here = 0;
  for (std::size_t i = 0; i < p.n_owned; ++i) {
    bool inside = true;
    for (int d = 0; d < 3; ++d)
      if (!(p.x[i][d] >= prm.domain_min[d] && p.x[i][d] <= prm.domain_max[d])) inside = false;
    if (inside) keep.push_back(i);
    else { removed.push_back(p.id[i]); ++removed_here; }
  }
  if (removed_here) {
    p.permute_owned(keep);
    p.n_owned = p.size();
    std::vector<double> c(keep.size());
    for (std::size_t i = 0; i < keep.size(); ++i) c[i] = cost[keep[i]];
    cost.swap(c);
  }
  return removed_here;
}

// The old pairs of particles about to move to another rank go into the hash map (the Distributor
// sends them along).
void keep_leaving_history(const Decomposition& dd, const ParticleStore& p, const std::vector<OldPair>& old,
                          HistoryMap& history) {
  std::unordered_set<std::int64_t> leaving;
  for (std::size_t i = 0; i < p.n_owned; ++i)
    if (dd.owner_of(p.x[i]) != dd.rank) leaving.insert(p.id[i]);
  if (!leaving.empty())
    for (const OldPair& o : old)
      if (leaving.count(o.a) || leaving.count(o.b)) history[ContactKey{o.a, o.b, 0, -1}] = ContactState{o.ft, o.rot};
}

// Owned particles in (order key, id) order: neighbours in space are neighbours in memory, and
// the order is the same on any number of ranks.
void sort_owned_by_key(ParticleStore& p) {
  std::vector<std::size_t> order(p.n_owned);
  std::iota(order.begin(), order.end(), 0);
  sort_by_key_id(order, p.key.data(), p.id.data());
  std::size_t k = 0;
  while (k < order.size() && order[k] == k) ++k;
  if (k < order.size()) p.permute_owned(order);
  else p.clear_ghosts();  // already in order: nothing to move
  p.n_owned = p.size();
}

// The owned particles' smallest distance to the domain's faces (they are all inside now), squared.
double edge_distance2(const ParticleStore& p, const EngineParams& prm) {
  const Vec3 lo = prm.domain_min, hi = prm.domain_max;
  double e = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < p.n_owned; ++i) {
    const Vec3& xi = p.x[i];
    e = std::min({e, xi.x - lo.x, hi.x - xi.x, xi.y - lo.y, hi.y - xi.y, xi.z - lo.z, hi.z - xi.z});
  }
  return e > 0 ? e * e : 0.0;
}

// Contact history of the new pair list: from the old list (merged, both in the canonical order),
// else from the hash map. `rot` empty: no rolling resistance, no rolling rotations kept.
void restore_pair_history(const ParticleStore& p, const PairList& pairs, const std::vector<OldPair>& old,
                          const HistoryMap& history, std::vector<Vec3>& ft, std::vector<Vec3>& rot,
                          std::vector<std::uint8_t>& active) {
  std::size_t j = 0;
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    const std::int64_t a = p.id[pairs.a[k]], b = p.id[pairs.b[k]];
    const std::int64_t ka = p.key[pairs.a[k]], kb = p.key[pairs.b[k]];
    while (j < old.size() && pair_before(old[j], ka, a, kb, b)) ++j;
    if (j < old.size() && old[j].a == a && old[j].b == b) {
      ft[k] = old[j].ft;
      if (!rot.empty()) rot[k] = old[j].rot;
      active[k] = 1;
    } else if (!history.empty()) {
      auto h = history.find(ContactKey{a, b, 0, -1});
      if (h != history.end()) {
        ft[k] = h->second.ft;
        if (!rot.empty()) rot[k] = h->second.rot;
        active[k] = 1;
      }
    }
  }
}

// Largest displacement of an owned particle since the last rebuild, or infinity when a rebuild is
// due at once: a non-finite position (the run-health check at the rebuild reports it) or a
// particle outside the domain. The latter is removed by the next step's rebuild, not by whichever
// rebuild comes next: its removal step (and what it touches until then) must not depend on the
// rebuild schedule, which a restart changes (it rebuilds at its first step). No particle can
// have left while every displacement is below half the smallest distance of a particle to the
// domain's faces at the rebuild (edge2, squared): only then are positions tested.
inline double max_displacement(const ParticleStore& p, const std::vector<Vec3>& x_build, double edge2,
                               const EngineParams& prm) {
  double mp = 0, sum = 0;
  for (std::size_t i = 0; i < p.n_owned; ++i) {
    const double d2 = norm2(p.x[i] - x_build[i]);
    mp = d2 > mp ? d2 : mp;
    sum += d2;  // NaN if a position is
  }
  bool now = sum != sum;
  if (!now && mp >= 0.25 * edge2) {
    const Vec3 lo = prm.domain_min, hi = prm.domain_max;
    for (std::size_t i = 0; i < p.n_owned; ++i) {
      const Vec3& xi = p.x[i];
      now |= (xi.x < lo.x) | (xi.x > hi.x) | (xi.y < lo.y) | (xi.y > hi.y) | (xi.z < lo.z) | (xi.z > hi.z);
    }
  }
  return now ? std::numeric_limits<double>::infinity() : std::sqrt(mp);
}
}  // namespace

DemEngine::DemEngine(MPI_Comm comm, const EngineParams& prm, MaterialTable mats,
                     std::vector<Wall> walls, ParticleStore all,
                     const std::vector<ContactRecord>& history, std::int64_t step, double time,
                     ParticleInput input)
    : prm_(prm), mats_(std::move(mats)), time_(time), step_(step) {
  walls_.walls = std::move(walls);
  const bool share = input == ParticleInput::kShare;
  // Order keys: a particle without one (generated, read from a sphere file or an older
  // checkpoint) gets it from its position now; it then keeps it (particles.hpp, order_key).
  all.key.resize(all.size(), kNoKey);
  for (std::size_t i = 0; i < all.size(); ++i)
    if (all.key[i] == kNoKey) all.key[i] = order_key(all.x[i], prm.domain_min, prm.domain_max);
  // The largest radius, the critical step and the count: of every particle (a share: reduced;
  // a maximum, a minimum and an integer sum are exact, so any split gives the same values).
  double rmax = 0;
  for (double r : all.r) rmax = std::max(rmax, r);
  double dt_all = critical_dt(all, mats_);  // 1e300 for none
  std::int64_t count = static_cast<std::int64_t>(all.size());
  if (share) {
    MPI_Allreduce(MPI_IN_PLACE, &rmax, 1, MPI_DOUBLE, MPI_MAX, comm);
    MPI_Allreduce(MPI_IN_PLACE, &dt_all, 1, MPI_DOUBLE, MPI_MIN, comm);
    MPI_Allreduce(MPI_IN_PLACE, &count, 1, MPI_INT64_T, MPI_SUM, comm);
  }
  if (rmax <= 0) rmax = 1e-3 * norm(prm.domain_max - prm.domain_min);
  skin_ = prm.skin > 0 ? prm.skin : 0.3 * rmax;
  cutoff_ = 2 * rmax + skin_;
  try {
    dd_ = Decomposition::create(comm, prm.domain_min, prm.domain_max, cutoff_,
                                GridRequest{prm.grid, gravity_axis(prm.gravity)});
  } catch (const std::runtime_error& e) {  // every rank alike: rmax and the cutoff are global
    throw InputError(prm.grid_at.first, prm.grid_at.second, e.what());
  }
  start_step_ = step;
  dt_crit_ = count > 0 ? dt_all : 0.0;
  dt_ = prm.dt > 0 ? prm.dt : prm.dt_safety * dt_all;
  if (!(dt_ > 0) || !std::isfinite(dt_)) {
    if (count == 0) dt_ = prm.dt > 0 ? prm.dt : 1e-6;
    else throw std::runtime_error("could not determine a positive time step");
  }
  total_ = count;
  if (share) {
    // Route the shares to their owners (sorted by id; a rebuild sorts them by key). `all` is taken
    // over (moved from by the drivers): no second copy of the share.
    p_ = std::move(all);
    p_.n_owned = p_.size();
    std::vector<ContactRecord> mine = history;
    scatter_to_owners(dd_, p_, mine, dd_.ghost_share(cutoff_) + 1.0 / 16);
    for (const ContactRecord& r : mine) pending_.emplace(key_of(r), r.state);
    return;
  }
  // Keep the particles this rank owns (input order kept; rebuild sorts by order key).
  for (std::size_t i = 0; i < all.size(); ++i) {
    if (!dd_.owns(all.x[i])) continue;
    p_.push_back(all.x[i], all.v[i], all.w[i], all.r[i], all.m[i], all.id[i], all.mat[i],
                 all.blocked[i], all.x0[i], all.key[i]);
  }
  p_.n_owned = p_.size();
  for (const ContactRecord& r : history) {
    // Keep the records that involve a particle owned here (migration then keeps them right).
    pending_.emplace(key_of(r), r.state);
  }
}

void DemEngine::rebuild() {
  ++rebuilds_;
  scan_particle_health();  // before the removal below, which would take a NaN particle for an escaped one
  // Contact history across the rebuild. Particle pairs: the active pairs of the old list, merged
  // with the new one. The hash map holds only what cannot be merged that way: wall contacts,
  // records of particles about to move to another rank (the Distributor sends them along),
  // records received with arriving particles and, after a restart, the checkpoint's records.
  const std::vector<OldPair> old = active_old_pairs(p_, pairs_, pactive_, pft_, prot_);
  HistoryMap history;
  history.swap(pending_);
  {
    std::vector<ContactRecord> wr;
    walls_.save_history(p_, wr);
    if (extra_) extra_->save_history(p_, wr);
    for (const auto& r : wr) history[key_of(r)] = r.state;
  }
  std::vector<double> cost = owned_costs(p_, pairs_, pactive_);
  p_.clear_ghosts();
  const std::int64_t removed_here = remove_escaped(p_, prm_, removed_, cost);
  // Load balance: move the cut planes when the busiest rank's cost (particles + contacts) is
  // more than 10 % above the mean.
  if (dd_.size > 1 && (rebuilds_ == 1 || rebuilds_ % 10 == 0)) {
    double load = 0;
    for (double c : cost) load += c;
    if (Decomposition::imbalance(dd_.comm, load) > 1.10) dd_.rebalance(p_.x, p_.n_owned, cost.data());
  }
  if (dd_.size > 1) keep_leaving_history(dd_, p_, old, history);
  dist_.migrate(dd_, p_, history);
  sort_owned_by_key(p_);
  // Particle count check after migration: nothing lost, nothing duplicated.
  // (+ the run-health flags of this rank: a non-finite particle, an overlap beyond the limit)
  std::int64_t counts[4] = {static_cast<std::int64_t>(p_.n_owned), removed_here, bad_.id >= 0 ? 1 : 0,
                            ovl_.step >= 0 ? 1 : 0},
               global[4];
  MPI_Allreduce(counts, global, 4, MPI_INT64_T, MPI_SUM, dd_.comm);
  if (global[2] > 0 || global[3] > 0 ||
      (global[1] > HealthLimits::kMaxLostCount &&
       static_cast<double>(global[1]) > HealthLimits::kMaxLostShare * static_cast<double>(total_)))
    diverge(global[1], total_);
  FDEM_VERIFY(global[0] + global[1] == total_, "particle count changed in migration: " + std::to_string(total_) +
                                                  " before, " + std::to_string(global[0]) + " owned + " +
                                                  std::to_string(global[1]) + " removed after");
  total_ = global[0];
  removed_total_ += global[1];
  x_build_.assign(p_.x.begin(), p_.x.begin() + p_.n_owned);
  edge2_ = edge_distance2(p_, prm_);
  inv_m_.resize(p_.n_owned);
  inv_i_.resize(p_.n_owned);
  for (std::size_t i = 0; i < p_.n_owned; ++i) {
    inv_m_[i] = 1.0 / p_.m[i];
    inv_i_[i] = 1.0 / sphere_inertia(p_.m[i], p_.r[i]);
  }
  halo_.exchange(dd_, p_, cutoff_);
  rmin_here_ = p_.size() > 0 ? *std::min_element(p_.r.begin(), p_.r.end()) : 0.0;
  build_pairs(p_.x, p_.r, p_.id, p_.key, p_.n_owned, skin_, pairs_);
  pft_.assign(pairs_.size(), Vec3{});
  // (no pair with rolling resistance: contact_force never touches a rolling rotation, none is kept,
  // 24 bytes a candidate pair saved)
  prot_.assign(mats_.any_rolling() ? pairs_.size() : 0, Vec3{});
  pactive_.assign(pairs_.size(), 0);
  pfn_.assign(pairs_.size(), 0.0);
  restore_pair_history(p_, pairs_, old, history, pft_, prot_, pactive_);
  walls_.build(p_, skin_, history);
  if (extra_) extra_->build(p_, dd_.lo, dd_.hi, skin_, history);
  need_rebuild_ = false;
}

void DemEngine::compute_pairs() {
  const std::size_t np = pairs_.size();
  const std::uint32_t* pa = pairs_.a.data();
  const std::uint32_t* pb = pairs_.b.data();
  const Vec3* x = p_.x.data();
  const Vec3* v = p_.v.data();
  const Vec3* w = p_.w.data();
  const double* r = p_.r.data();
  const std::int32_t* mat = p_.mat.data();
  Vec3* f = p_.f.data();
  Vec3* t = p_.t.data();
  // Run health: an overlap beyond the limit (a fraction of the smaller radius). One comparison per
  // contact (no branch), against the limit times the smallest radius here; the exact test in a
  // second pass only when one was past it.
  const double ovl_gate = HealthLimits::kMaxOverlap * rmin_here_;
  bool over = false;
  Vec3* const rot = prot_.empty() ? nullptr : prot_.data();  // (null: no rolling resistance)
  Vec3 no_rot;  // stays zero: contact_force touches it only where beta_r > 0
  // The grains a contact reads are scattered in the store (b jumps along the pair list; a moves
  // slowly) and the loop waited on grain b's loads: ask for b's lines (x, r, v, w, f, t) kPrefetch
  // pairs ahead. Measured on the dense 100 k bed, 1 rank, paired (docs/performance.md): 16 pairs
  // ahead 25 % less time, 32 / 64 / 128 3 / 5 / 7 % less again, 256 no better. No result changes.
  constexpr std::size_t kPrefetch = 128;
  for (std::size_t k = 0; k < np; ++k) {
    const std::uint32_t a = pa[k], b = pb[k];
    if (k + kPrefetch < np) {
      const std::uint32_t c = pb[k + kPrefetch];
      __builtin_prefetch(&x[c]);
      __builtin_prefetch(&r[c]);
      __builtin_prefetch(&v[c]);
      __builtin_prefetch(&w[c]);
      __builtin_prefetch(&f[c], 1);
      __builtin_prefetch(&t[c], 1);
    }
    const Vec3 d = x[b] - x[a];
    const double rs = r[a] + r[b];
    const double dist2 = norm2(d);
    if (dist2 >= rs * rs) {
      if (pactive_[k]) {
        pft_[k] = Vec3{};
        if (rot) rot[k] = Vec3{};
        pactive_[k] = 0;
      }
      continue;
    }
    const double dist = std::sqrt(dist2);
    const Vec3 n = (1.0 / dist) * d;
    const double delta = rs - dist;
    over |= delta > ovl_gate;
    const Vec3 la = (r[a] - 0.5 * delta) * n;
    const Vec3 lb = -(r[b] - 0.5 * delta) * n;
    const Vec3 vrel = (v[b] + cross(w[b], lb)) - (v[a] + cross(w[a], la));
    const PairParams& pp = mats_.pair(mat[a], mat[b]);
    const NormalLaw nl = normal_law(pp, mats_[mat[a]].young, r[a], mats_[mat[b]].young, r[b],
                                    effective_radius(r[a], r[b]), delta);
    const ContactForce cf = contact_force(n, nl.fn, nl.kt, la, lb, vrel, w[a] - w[b], 0.5 * rs, pp, dt_,
                                          pft_[k], rot ? rot[k] : no_rot);
    pactive_[k] = 1;
    pfn_[k] = cf.fn;
    f[a] -= cf.force_b;
    f[b] += cf.force_b;
    t[a] += cf.torque_a;
    t[b] += cf.torque_b;
  }
  if (over)
    for (std::size_t k = 0; k < np; ++k) {
      const std::uint32_t a = pa[k], b = pb[k];
      const double rmin = std::min(r[a], r[b]);
      const double delta = r[a] + r[b] - norm(x[b] - x[a]);
      if (delta > HealthLimits::kMaxOverlap * rmin) note_overlap(a, b, delta / rmin);
    }
}

void DemEngine::step() {
  auto T = [&](Stage s) -> double& { return timing_[static_cast<int>(s)]; };
  // a source that changed since the last step's check (the same on every rank)
  if (extra_ && std::isinf(extra_->moved_since_build())) need_rebuild_ = true;
  if (need_rebuild_) {
    Timer tm(T(Stage::kNeighbors));
    rebuild();
  } else {
    Timer tm(T(Stage::kGhosts));
    halo_.update(dd_, p_);
  }
  {
    Timer tm(T(Stage::kContacts));
    std::fill(p_.f.begin(), p_.f.end(), Vec3{});
    std::fill(p_.t.begin(), p_.t.end(), Vec3{});
    compute_pairs();
  }
  if (!first_forces_done_) {  // particles overlapping at the start: stop before moving anything
    first_forces_done_ = true;
    check_health();
  }
  bool free_walls = false;
  {
    Timer tm(T(Stage::kWalls));
    walls_.apply_schedule(step_);  // walls that change their motion at given steps
    walls_.compute(p_, mats_, dt_);
    free_walls = walls_.needs_reduction();  // free and servo walls move with the reduced forces
  }
  if (extra_) {
    Timer tm(T(Stage::kInterface));
    extra_->compute(p_, mats_, dt_);
  }
  if (at_forces_) {  // a measurement at the forces (before the particles move) wants the wall forces
    if (free_walls) {
      Timer tm(T(Stage::kReduce));
      ::fdem::reduce_wall_forces(walls_, dd_.comm);
      free_walls = false;
    }
    const std::function<void()> fn = std::move(at_forces_);
    at_forces_ = nullptr;
    fn();
  }
  {
    Timer tm(T(Stage::kIntegrate));
    integrate_particles(p_, inv_m_.data(), inv_i_.data(), prm_.gravity, dt_, prm_.damping);
  }
  time_ += dt_;
  ++step_;
  // One reduction per step (latency): the walls' forces (the walls move with them), the coupling's
  // values (an FE update's interface totals and surface motion) and the particles' largest
  // displacement since the build. The particles' integration does not need the walls' forces, and
  // the FE update not the walls' motion: both go before the reduction.
  step_sums_.clear();
  std::vector<exact::Int> wall_sums;  // (slots from 0)
  if (free_walls) {
    wall_sums = walls_.local_sums();
    step_sums_.add_sums(wall_sums.data(), wall_sums.size());
  }
  if (extra_) {
    Timer tm(T(Stage::kCoupling));
    extra_->end_step(step_, step_sums_);
  }
  {
    Timer tm(T(Stage::kReduce));
    const std::size_t mp_slot = step_sums_.add_max(max_displacement(p_, x_build_, edge2_, prm_));
    exact::allreduce(step_sums_, dd_.comm);
    if (free_walls) {
      for (std::size_t k = 0; k < wall_sums.size(); ++k) wall_sums[k] = step_sums_.sum(k);
      walls_.set_reduced_sums(wall_sums);
    }
    gmax_ = step_sums_.max(mp_slot);
  }
  {
    Timer tm(T(Stage::kIntegrate));
    walls_.integrate(dt_, prm_.gravity, prm_.damping);
  }
  if (extra_) {
    Timer tm(T(Stage::kCoupling));
    extra_->finish_step(step_sums_);
  }
  const double mw = std::max(walls_.moved_since_build(), extra_ ? extra_->moved_since_build() : 0.0);
  need_rebuild_ = std::max(2 * gmax_, gmax_ + mw) > skin_;
}

void DemEngine::scan_particle_health() {
  const double dt2 = dt_ * dt_, lt2 = HealthLimits::kMaxStepTravel * HealthLimits::kMaxStepTravel,
               lr2 = HealthLimits::kMaxStepRotation * HealthLimits::kMaxStepRotation;
  for (std::size_t i = 0; i < p_.n_owned; ++i) {
    const Vec3 &x = p_.x[i], &v = p_.v[i], &f = p_.f[i], &w = p_.w[i];
    const double s = x.x + x.y + x.z + v.x + v.y + v.z + f.x + f.y + f.z + w.x + w.y + w.z;
    const bool fast = norm2(v) * dt2 > lt2 * p_.r[i] * p_.r[i] || norm2(w) * dt2 > lr2;
    if (std::isfinite(s) && !fast) continue;  // (a sum of finite numbers can overflow: checked below)
    const bool nonfinite = !std::isfinite(x.x) || !std::isfinite(x.y) || !std::isfinite(x.z) || !std::isfinite(v.x) ||
                           !std::isfinite(v.y) || !std::isfinite(v.z) || !std::isfinite(f.x) || !std::isfinite(f.y) ||
                           !std::isfinite(f.z) || !std::isfinite(w.x) || !std::isfinite(w.y) || !std::isfinite(w.z);
    if (!nonfinite && !fast) continue;
    // non-finite before too fast, then the lowest id
    const bool better = bad_.id < 0 || (nonfinite && bad_.fast) || (nonfinite == !bad_.fast && p_.id[i] < bad_.id);
    if (better) bad_ = {p_.id[i], x, v, f, w, p_.r[i], !nonfinite};
  }
}

void DemEngine::note_overlap(std::uint32_t a, std::uint32_t b, double ratio) {
  const std::int64_t ia = std::min(p_.id[a], p_.id[b]), ib = std::max(p_.id[a], p_.id[b]);
  if (ovl_.step >= 0 && (ovl_.step < step_ || (ovl_.step == step_ && (ovl_.a < ia || (ovl_.a == ia && ovl_.b <= ib)))))
    return;  // keep the earliest step, then the lowest ids
  ovl_ = {step_, ia, ib, ratio, std::min(p_.r[a], p_.r[b]), 0.5 * (p_.x[a] + p_.x[b])};
}

void DemEngine::check_health() {
  scan_particle_health();
  std::int64_t loc[2] = {bad_.id >= 0 ? 1 : 0, ovl_.step >= 0 ? 1 : 0}, g[2];
  MPI_Allreduce(loc, g, 2, MPI_INT64_T, MPI_SUM, dd_.comm);
  if (g[0] > 0 || g[1] > 0) diverge(0, total_);
}

void DemEngine::diverge(std::int64_t removed, std::int64_t before) {
  constexpr int kN = 23;
  const double mine[kN] = {static_cast<double>(bad_.id), bad_.x.x, bad_.x.y, bad_.x.z, bad_.v.x, bad_.v.y, bad_.v.z,
                           bad_.f.x, bad_.f.y, bad_.f.z, static_cast<double>(ovl_.step), static_cast<double>(ovl_.a),
                           static_cast<double>(ovl_.b), ovl_.ratio, ovl_.r, ovl_.x.x, ovl_.x.y, ovl_.x.z,
                           bad_.w.x, bad_.w.y, bad_.w.z, bad_.r, bad_.fast ? 1.0 : 0.0};
  std::vector<double> all(static_cast<std::size_t>(kN) * dd_.size);
  MPI_Allgather(mine, kN, MPI_DOUBLE, all.data(), kN, MPI_DOUBLE, dd_.comm);
  const double* bad = nullptr;  // non-finite before too fast, then the lowest id
  const double* ovl = nullptr;  // earliest step, then lowest ids
  for (int q = 0; q < dd_.size; ++q) {
    const double* d = all.data() + static_cast<std::size_t>(kN) * q;
    if (d[0] >= 0 && (!bad || (d[22] < bad[22]) || (d[22] == bad[22] && d[0] < bad[0]))) bad = d;
    if (d[10] >= 0 &&
        (!ovl || d[10] < ovl[10] || (d[10] == ovl[10] && (d[11] < ovl[11] || (d[11] == ovl[11] && d[12] < ovl[12])))))
      ovl = d;
  }
  auto num = [](double v) {
    char b[32];
    std::snprintf(b, sizeof b, "%.6g", v);
    return std::string(b);
  };
  auto vec = [&](const double* d) { return "(" + num(d[0]) + ", " + num(d[1]) + ", " + num(d[2]) + ")"; };
  auto id = [](double v) { return std::to_string(static_cast<long long>(v)); };
  std::string m;
  bool at_start = false;
  if (ovl) {
    const auto st = static_cast<long long>(ovl[10]);
    at_start = st == start_step_;
    m = "step " + std::to_string(st) + ": particles " + id(ovl[11]) + " and " + id(ovl[12]) + " overlap by " +
        num(ovl[13] * ovl[14]) + " m = " + num(ovl[13]) + " of the smaller radius (limit " +
        num(HealthLimits::kMaxOverlap) + ") at " + vec(ovl + 15);
    if (at_start) m += ", in the state the run starts from";
  } else if (bad && bad[22] == 0) {
    m = "step " + std::to_string(step_) + ": particle " + id(bad[0]) + " has a non-finite position, velocity or force: x " +
        vec(bad + 1) + ", v " + vec(bad + 4) + ", F " + vec(bad + 7);
  } else if (bad) {
    const double sv = std::sqrt(bad[4] * bad[4] + bad[5] * bad[5] + bad[6] * bad[6]);
    const double sw = std::sqrt(bad[18] * bad[18] + bad[19] * bad[19] + bad[20] * bad[20]);
    m = "step " + std::to_string(step_) + ": particle " + id(bad[0]) + " moves " + num(sv * dt_ / bad[21]) +
        " of its radius and turns " + num(sw * dt_) + " rad per step (limits " + num(HealthLimits::kMaxStepTravel) +
        " and " + num(HealthLimits::kMaxStepRotation) + "): its kinetic energy grew beyond what the time step "
        "resolves; x " + vec(bad + 1) + ", v " + vec(bad + 4) + " m/s, w " + vec(bad + 18) + " rad/s, F " + vec(bad + 7);
  } else {
    char b[64];
    std::snprintf(b, sizeof b, "%.1f %%", before > 0 ? 100.0 * static_cast<double>(removed) / static_cast<double>(before) : 0.0);
    m = "step " + std::to_string(step_) + ": " + std::to_string(removed) + " of " + std::to_string(before) +
        " particles (" + b + ") left the domain at once (limit " + num(100 * HealthLimits::kMaxLostShare) +
        " % and " + std::to_string(HealthLimits::kMaxLostCount) + " particles per neighbour rebuild)";
  }
  const double ratio = dt_crit_ > 0 ? dt_ / dt_crit_ : 0.0;
  std::string cause;
  if (at_start)
    cause = "particles overlap at the start (check the particle positions and radii: sphere file, inline spheres "
            "or checkpoint)";
  else if (ratio > HealthLimits::kDtRatioSuspect)
    cause = "time step too large: dt = " + num(dt_) + " s, critical " + num(dt_crit_) + " s (dt is " + num(ratio) +
            " x the critical step; use time.safety <= 0.3 or a smaller time.dt)";
  else
    cause = "the loading (a wall velocity, servo or load too large for the particles) or the material values (dt = " +
            num(dt_) + " s is " + num(ratio) + " x the critical step " + num(dt_crit_) + " s)";
  throw RunDiverged("the run diverged at " + m + "; likely cause: " + cause);
}

EngineStats DemEngine::stats() {
  // Kinetic energy, sum |net force|, sum |contact force|, free count: exact sums (the same on
  // any number of ranks, so a stop criterion triggers at the same step).
  exact::ExactSums sums(4);
  std::int64_t cnt[4] = {static_cast<std::int64_t>(p_.n_owned), 0, 0, 0};
  for (std::size_t i = 0; i < p_.n_owned; ++i) {
    sums.add(0, 0.5 * p_.m[i] * norm2(p_.v[i]) + 0.5 * sphere_inertia(p_.m[i], p_.r[i]) * norm2(p_.w[i]));
    if (p_.blocked[i] != kDofAll) { sums.add(1, norm(p_.f[i] + p_.m[i] * prm_.gravity)); sums.add(3, 1.0); }
  }
  // The contact forces of the last force computation (normal magnitude and tangential vector,
  // orthogonal), not recomputed from positions: after the integration the ghosts still hold the
  // old positions, which would make the ratio depend on the number of ranks.
  for (std::size_t k = 0; k < pairs_.size(); ++k) {
    if (!pactive_[k] || pairs_.a[k] >= p_.n_owned) continue;  // counted by the lower id's owner
    sums.add(2, std::sqrt(pfn_[k] * pfn_[k] + norm2(pft_[k])));
    ++cnt[1];
  }
  cnt[2] = static_cast<std::int64_t>(walls_.n_active());
  cnt[3] = extra_ ? static_cast<std::int64_t>(extra_->n_active()) : 0;
  const std::vector<double> g = sums.sums(dd_.comm);
  std::int64_t gc[4];
  MPI_Allreduce(cnt, gc, 4, MPI_INT64_T, MPI_SUM, dd_.comm);
  EngineStats s;
  s.particles = gc[0];
  s.contacts = gc[1];
  s.wall_contacts = gc[2];
  s.interface_contacts = gc[3];
  s.kinetic_energy = g[0];
  const double mean_net = g[3] > 0 ? g[1] / g[3] : 0.0;
  const double mean_contact = gc[1] > 0 ? g[2] / gc[1] : 0.0;
  // No contacts: undefined (NaN), as in YADE.
  s.unbalanced = mean_contact > 0 ? mean_net / mean_contact : std::numeric_limits<double>::quiet_NaN();
  return s;
}

std::vector<ContactRecord> DemEngine::history_records() const {
  std::vector<ContactRecord> out;
  if (!pending_.empty()) {  // not stepped since a restart: hand the restored records back
    std::unordered_set<std::int64_t> owned(p_.id.begin(), p_.id.begin() + p_.n_owned);
    for (const auto& kv : pending_)
      if (owned.count(kv.first.a))  // the owner of the lower id (or of the particle) writes it
        out.push_back({kv.first.a, kv.first.b, kv.first.kind, kv.first.sub, kv.second});
    return out;
  }
  for (std::size_t k = 0; k < pairs_.size(); ++k)
    if (pactive_[k] && pairs_.a[k] < p_.n_owned)
      out.push_back({p_.id[pairs_.a[k]], p_.id[pairs_.b[k]], 0, -1,
                     ContactState{pft_[k], prot_.empty() ? Vec3{} : prot_[k]}});
  walls_.save_history(p_, out);
  if (extra_) extra_->save_history(p_, out);
  return out;
}

std::vector<std::int64_t> DemEngine::take_removed() {
  std::vector<std::int64_t> all = allgather(removed_, dd_.comm);
  removed_.clear();
  std::sort(all.begin(), all.end());
  return all;
}

CommStats DemEngine::comm_stats() const {
  CommStats s;
  s.bytes = halo_.stats.bytes + dist_.stats.bytes;
  s.messages = halo_.stats.messages + dist_.stats.messages;
  return s;
}

}  // namespace fdem
