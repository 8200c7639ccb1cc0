#pragma once
// Load holds on walls (the case's `holds`, docs/case-format.md#holds): a footing's pressure raised
// in increments, each held until the particles and the servo have converged -- the protocol of
// thesis ch. 5 as a Schedule of the run loop (app/run_control.hpp), usable by any particle case.
//
// Hold h sets every held servo wall's target to its h-th stress. Every `check_every` steps from
// the hold's start (and after `min_steps`) the hold has converged when the unbalanced-force ratio
// and every held wall's misfit |sigma - target| / target are below `tolerance` (the ratio from
// DemEngine::stats() after a ghost refresh: the same on any number of ranks); after `max_steps`
// it ends unconverged. `stop` ends the run once a servo wall has moved a given distance along its
// axis (failure). Each hold's end (and a stop) is a row of holds.csv.
//
// A wall held by displacement (a fixed wall with `displacement` instead of `stress`: a shaft's
// segments or a retaining wall moved in steps, thesis ch. 3) is driven before every step towards
// its hold's displacement along its axis at its velocity (the last step lands on it exactly);
// its hold converges only once it has arrived (and the unbalanced-force ratio is below the
// tolerance). The walls move identically on every rank: the drive depends only on the step.
#include <mpi.h>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "app/engine.hpp"
#include "app/run_control.hpp"
#include "io/case.hpp"
#include "io/csv.hpp"

namespace fdem {

class WallHolds : public Schedule, public Observer, public Controller {
 public:
  /// `restarted`: continue holds.csv, dropping its rows after the checkpoint's step. `start`: the
  /// walls' displacements when the run began (a restart's checkpoint; empty: now).
  /// `check`: their displacements at the last convergence check (holds.creep; a restart's
  /// checkpoint; empty: now).
  /// `extra_columns`: a coupled run's measures (note_check), between the walls' columns and
  /// `held_by`.
  WallHolds(const CaseConfig& c, DemEngine& e, const std::string& dir, bool restarted, const std::vector<Vec3>& start,
            const std::vector<Vec3>& check, bool quiet, MPI_Comm comm,
            const std::vector<std::string>& extra_columns = {});
  /// The walls' displacements when the run began (the settlements' reference; checkpointed).
  const std::vector<Vec3>& start() const { return start_; }
  /// The walls' displacements at the last check (checkpointed when holds.creep is set; else empty).
  std::vector<Vec3> check_disp() const { return h_.creep > 0 ? check_ : std::vector<Vec3>{}; }
  /// Set the held walls' targets to those of hold `h` (called for the first hold by the owner).
  void apply(std::size_t h);
  /// A hold begins: its targets, and the creep window starts here.
  void begin(std::size_t h);
  /// Before every step: drive the displacement-held walls towards hold st.hold's displacements.
  void before_step(const RunState& st) override;
  /// Have the displacement-held walls reached the current hold's displacements? (true without any)
  bool arrived() const;
  /// holds.creep: has a held wall moved `creep` or more along its axis since the last check?
  /// (false when creep is 0). Moves the window to now; called at every convergence check.
  bool creeping();
  /// The particle run's schedule: the stop, then the convergence checks.
  void check(RunState& st) override;
  void begin_hold(const RunState& st) override { begin(st.hold); }
  void on_hold_end(const RunState& st) override { row(st, st.hold_converged ? 1 : 0); }
  /// holds.stop: has the wall moved its distance? Then a row, a line, and st.stop (collective;
  /// a coupled run's schedule calls it before its own checks).
  bool stop_reached(RunState& st);
  /// What a coupled run's schedule measured at its last check (holds.csv's columns): the DEM
  /// unbalanced-force ratio, the extra columns' values, the parts above their tolerance.
  void note_check(double u, std::vector<double> extra, std::string held_by) {
    unbalanced_ = u;
    extra_ = std::move(extra);
    held_by_ = std::move(held_by);
  }
  /// The held walls that kept the hold open at the last check: `creep:<wall>` (moved `creep` or
  /// more), `arrive:<wall>` (a displacement hold not at its target), joined by '+'; empty: none.
  std::string open_walls() const;
  /// A wall's settlement: its displacement along its servo axis since the run began (m; after a
  /// packing's packing.place_on_surface, from where it was placed).
  double settlement(int wall) const;
  /// A held wall's displacement along its axis (its servo axis, or a displacement hold's axis)
  /// since the run began (m).
  double displacement(const HoldsConfig::Wall& w) const;

 private:
  void row(const RunState& st, int converged);
  const CaseConfig& c_;
  const HoldsConfig& h_;
  DemEngine& e_;
  bool quiet_;
  int rank_ = 0;
  std::unique_ptr<CsvWriter> csv_;
  std::vector<Vec3> start_;
  std::vector<Vec3> check_;  // the walls' displacements at the last check (holds.creep)
  double unbalanced_ = 0;  // at the last check
  double moved_ = 0;       // the largest held wall's movement in the last check window (m)
  std::vector<std::string> creeping_;  // the walls that moved `creep` or more in it
  std::vector<double> extra_;          // a coupled run's measures at the last check
  std::string held_by_;                // the parts above their tolerance at the last check
  std::size_t hold_ = 0;   // the hold whose displacements the moved walls are driven to
};

}  // namespace fdem
