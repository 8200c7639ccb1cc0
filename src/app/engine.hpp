#pragma once
// DemEngine: the parallel DEM time loop of one communicator (DESIGN.md sections 3 and 4.1).
//
// One step is a pipeline of named, timed stages:
//   neighbours (only when a rebuild is due: remove escaped -> migrate -> ghosts -> pairs -> wall
//   candidates) or ghost update -> particle contacts -> wall contacts -> gravity -> integrate ->
//   rebuild check (global max displacement vs skin/2).
// The physics lives in src/dem (no MPI); the communication in src/partition.
#include <functional>
#include <mpi.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "dem/contact_history.hpp"
#include "dem/contact_source.hpp"
#include "dem/material.hpp"
#include "dem/neighbor.hpp"
#include "dem/particles.hpp"
#include "dem/walls.hpp"
#include "partition/decomposition.hpp"
#include "partition/halo.hpp"
#include "partition/wall_reduce.hpp"

namespace fdem {

struct EngineParams {
  Vec3 domain_min, domain_max;
  Vec3 gravity{0, 0, -9.81};
  double damping = 0.2;
  double dt = 0;          // fixed step; 0: dt_safety * critical step
  double dt_safety = 0.3;
  double skin = 0;        // 0: 0.3 * r_max
  std::array<int, 3> grid{0, 0, 0};  // the process grid (`decomposition.grid`); {0,0,0}: chosen
  /// Where the grid was given (file, line), or the case file (line 0): a grid that does not fit
  /// the domain is an InputError there (the same on every rank: printed once, exit 2).
  std::pair<std::string, int> grid_at;
};

/// Run-health limits (DESIGN.md 4.1; docs/user-guide.md "Runs that diverge"). A run that breaks
/// one stops with RunDiverged (base/errors.hpp): exit code 3, run.json "diverged".
struct HealthLimits {
  /// Largest particle-particle overlap during a run, as a fraction of the smaller radius: the
  /// smaller particle's centre reaches the other's surface. Settled packings sit at ~1e-3 r;
  /// the largest in the test suite is a transient 0.28 r (mpi_measure_servo: a soft bed,
  /// E 5 MPa, met by a servo plate), the shipped cases stay below 0.13 r. A linear contact at
  /// 1 r carries ~E r^2, far beyond any soil stress, and beyond it the centres pass each other:
  /// a blow-up, not physics (with dt 3x critical the overlap passes 1 r a few steps after 0.5 r).
  static constexpr double kMaxOverlap = 1.0;
  /// Largest overlap of the input particles (sphere files, inline, generated), checked before
  /// the run: input has no transients; more than half a radius is a broken file.
  static constexpr double kMaxInputOverlap = 0.5;
  /// Particles leaving the domain in one neighbour rebuild: more than this share of those
  /// present AND more than kMaxLostCount of them is an explosion, not a few escaping grains.
  static constexpr double kMaxLostShare = 0.10;
  static constexpr std::int64_t kMaxLostCount = 10;
  /// Largest travel of a particle in one step, as a fraction of its radius (|v| dt / r), and
  /// largest rotation in one step (|w| dt, radians): the kinetic energy beyond which the time
  /// step no longer resolves a particle's motion (a contact would open and close within a step or
  /// two). A growing instability passes it while its energy is still finite, also where there is
  /// nothing to overlap (a dilute region, a particle spinning on its contacts). Free fall from
  /// 1 m at dt 1e-5 s is 0.02 r per step for 2.5 mm grains; the test suite stays below 0.09.
  static constexpr double kMaxStepTravel = 0.5;
  static constexpr double kMaxStepRotation = 0.5;
  /// dt / critical step above which "time step too large" is given as the likely cause.
  static constexpr double kDtRatioSuspect = 0.5;
};

/// Global statistics (collective to compute).
struct EngineStats {
  std::int64_t particles = 0;
  std::int64_t contacts = 0;       // active particle-particle contacts, each counted once
  std::int64_t wall_contacts = 0;
  std::int64_t interface_contacts = 0;  // particle-FE interface contacts (attached ContactSource)
  double kinetic_energy = 0;       // J (translational + rotational)
  double unbalanced = 0;           // mean |net force| / mean |contact force| (YADE's definition)
};

/// What each rank passes to DemEngine: every particle (the same on every rank) or its share.
enum class ParticleInput { kReplicated, kShare };

enum class Stage { kNeighbors, kGhosts, kContacts, kWalls, kInterface, kIntegrate, kCoupling, kReduce, kCount };
const char* stage_name(Stage s);

class DemEngine {
 public:
  /// `all` holds every particle of the run (identical on every rank, masses set);
  /// this rank keeps those it owns. `history` restores contact histories (checkpoints).
  /// With ParticleInput::kShare, `all` and `history` are this rank's share only (disjoint over
  /// the ranks, any split: a block of a checkpoint's rows); they are sent to their owners
  /// (partition/scatter.hpp) and no rank holds more than its share. The run is the same.
  /// (`all` by value: a driver moves its set-up's particles in, and they are not copied.)
  DemEngine(MPI_Comm comm, const EngineParams& prm, MaterialTable mats, std::vector<Wall> walls,
            ParticleStore all, const std::vector<ContactRecord>& history = {},
            std::int64_t step = 0, double time = 0, ParticleInput input = ParticleInput::kReplicated);

  /// One step. Throws RunDiverged (on every rank) when the run-health check fails: it runs at
  /// every neighbour rebuild (in the reduction that rebuild does anyway) and after the first
  /// force computation (particles overlapping at the start).
  void step();
  /// Collective: the run-health check now (also done at every rebuild); throws RunDiverged.
  /// Drivers call it before writing a checkpoint, so that no checkpoint of a bad state is written.
  void check_health();
  /// The critical step estimate of the initial particles (critical_dt), s.
  double critical_dt_estimate() const { return dt_crit_; }
  void run(std::int64_t nsteps) { for (std::int64_t k = 0; k < nsteps; ++k) step(); }
  /// Plug in another kind of contact (the FE interface, src/coupling); not owned; may be null.
  /// Call before the first step (or right after construction on a restart).
  void attach(ContactSource* src) { extra_ = src; need_rebuild_ = true; }
  ContactSource* attached() const { return extra_; }
  /// Collective: `fn` runs once, inside the next step(), when that step's contact forces (pairs,
  /// walls, attached source) are computed and before anything moves: the current state with its
  /// forces. A step-0 measurement needs it: the first forces are computed in the first step.
  void at_next_forces(std::function<void()> fn) { at_forces_ = std::move(fn); }

  // --- state ---
  const ParticleStore& particles() const { return p_; }
  /// The owned particles moved out of the engine (ghosts dropped), for a caller that builds the
  /// next engine from them without a copy (app/packing.cpp). Afterwards the engine holds no
  /// particles and must not step again; take history_records() first. Forces and torques are
  /// zero in the returned store.
  ParticleStore release_particles() {
    p_.clear_ghosts();
    ParticleStore out = std::move(p_);
    p_ = ParticleStore();
    out.n_owned = out.size();
    // the forces and torques of the last step belong to this engine, not to the state: a new
    // engine starts from zero whatever route the grains take to it (a scatter sends none)
    std::fill(out.f.begin(), out.f.end(), Vec3{});
    std::fill(out.t.begin(), out.t.end(), Vec3{});
    return out;
  }
  ParticleStore& particles() { return p_; }
  WallSet& walls() { return walls_; }
  const WallSet& walls_const() const { return walls_; }
  const Decomposition& decomposition() const { return dd_; }
  const MaterialTable& materials() const { return mats_; }
  double dt() const { return dt_; }
  double time() const { return time_; }
  std::int64_t step_count() const { return step_; }
  double skin() const { return skin_; }
  double cutoff() const { return cutoff_; }
  MPI_Comm comm() const { return dd_.comm; }

  /// Collective: global statistics of the current state.
  EngineStats stats();
  /// Collective: wall forces summed over ranks (exact).
  void reduce_wall_forces() { ::fdem::reduce_wall_forces(walls_, dd_.comm); }
  /// This rank's share of the contact history for a checkpoint: each contact exactly once
  /// over all ranks (particle pairs by the owner of the lower id, wall contacts by the owner).
  std::vector<ContactRecord> history_records() const;
  /// Collective: ids of the particles removed (left the domain) since the last call, all ranks.
  std::vector<std::int64_t> take_removed();
  std::int64_t removed_total() const { return removed_total_; }
  std::int64_t rebuilds() const { return rebuilds_; }
  /// Seconds spent per stage on this rank.
  const std::array<double, static_cast<int>(Stage::kCount)>& timings() const { return timing_; }
  CommStats comm_stats() const;

  // --- contacts, for measurements (src/app/measurements.cpp) ---
  /// One active particle-particle contact of the last step, as seen on this rank. `a`, `b` are
  /// local indices into particles() (either may be a ghost), id[a] < id[b]; n is the unit normal
  /// from A to B and force_b the total contact force on B (A receives -force_b), N. The normal
  /// force is the one of the last step; n and the positions are the current ones.
  struct PairContactView {
    std::uint32_t a, b;
    bool owns_a, owns_b;  // a (b) is owned by this rank
    Vec3 n;
    double fn;            // normal force magnitude of the last step (>= 0), N
    Vec3 force_b;         // fn n + tangential force, on B
  };
  /// Visit the active particle-particle contacts of this rank. A contact whose two particles
  /// are owned by different ranks is visited on both: count the contact itself only where
  /// owns_a (the owner of the lower id, as history_records() does), the side of a particle only
  /// where that particle is owned. Call sync_ghosts() first so that ghost positions are current.
  template <class F> void for_each_pair_contact(F&& fn) const {
    for (std::size_t k = 0; k < pairs_.size(); ++k) {
      if (!pactive_[k]) continue;
      const std::uint32_t a = pairs_.a[k], b = pairs_.b[k];
      const Vec3 d = p_.x[b] - p_.x[a];
      const double dn = norm(d);
      const Vec3 n = dn > 0 ? (1.0 / dn) * d : Vec3{0, 0, 1};
      const Vec3 ft = pft_[k] - dot(pft_[k], n) * n;
      fn(PairContactView{a, b, a < p_.n_owned, b < p_.n_owned, n, pfn_[k], pfn_[k] * n + ft});
    }
  }
  /// Visit the active particle-wall contacts of this rank's owned particles (each once over all
  /// ranks); see WallSet::for_each_active.
  template <class F> void for_each_wall_contact(F&& fn) const { walls_.for_each_active(p_, mats_, fn); }
  /// Collective: refresh the ghosts' positions and velocities from their owners (after step()
  /// the ghosts still hold the positions before the integration). Harmless to the time loop.
  void sync_ghosts() { halo_.update(dd_, p_); }

 private:
  void rebuild();
  void compute_pairs();
  /// Run-health bookkeeping: a non-finite owned particle or one moving faster than the step
  /// resolves (lowest id; non-finite first), and the first overlap beyond the limit (earliest
  /// step, then lowest ids) seen on this rank.
  void scan_particle_health();
  void note_overlap(std::uint32_t a, std::uint32_t b, double ratio);
  /// Collective, once a problem is known on some rank (or `removed` of `before` particles left
  /// the domain in one rebuild): gather the findings, throw RunDiverged with the same message
  /// on every rank.
  [[noreturn]] void diverge(std::int64_t removed, std::int64_t before);
  struct BadParticle { std::int64_t id = -1; Vec3 x, v, f, w; double r = 0; bool fast = false; };
  struct BigOverlap { std::int64_t step = -1, a = -1, b = -1; double ratio = 0, r = 0; Vec3 x; };
  BadParticle bad_;
  BigOverlap ovl_;
  double rmin_here_ = 0, dt_crit_ = 0;  // smallest radius of the local particles (at rebuild)
  std::int64_t start_step_ = 0;
  bool first_forces_done_ = false;
  std::function<void()> at_forces_;  // at_next_forces

  Decomposition dd_;
  EngineParams prm_;
  MaterialTable mats_;
  WallSet walls_;
  ParticleStore p_;
  Halo halo_;
  Distributor dist_;
  PairList pairs_;
  std::vector<Vec3> pft_, prot_;  // contact history: tangential force, rolling rotation
  std::vector<double> pfn_;       // normal force of the last step (measurements, stats)
  std::vector<std::uint8_t> pactive_;
  std::vector<Vec3> x_build_;
  double edge2_ = 0;  // squared smallest distance of an owned particle to the domain's faces at the rebuild
  std::vector<double> inv_m_, inv_i_;  // of the owned particles, set at rebuild
  HistoryMap pending_;  // histories waiting for the first rebuild (restart)
  double dt_ = 0, time_ = 0, skin_ = 0, cutoff_ = 0;
  std::int64_t step_ = 0, total_ = 0, removed_total_ = 0, rebuilds_ = 0;
  bool need_rebuild_ = true;
  ContactSource* extra_ = nullptr;
  exact::StepSums step_sums_;  // the step's one reduction (walls, coupling, rebuild check)
  double gmax_ = 0;            // the particles' largest displacement since the build (global)
  std::vector<std::int64_t> removed_;
  std::array<double, static_cast<int>(Stage::kCount)> timing_{};
};

/// Mass of a solid sphere.
inline double sphere_mass(double density, double r) { return density * 4.0 / 3.0 * M_PI * r * r * r; }

/// Critical time step estimate: min over particles of sqrt(m / (2 E r)) (a particle against a
/// rigid wall of its own stiffness; DESIGN.md 4.1).
double critical_dt(const ParticleStore& all, const MaterialTable& mats);

}  // namespace fdem
