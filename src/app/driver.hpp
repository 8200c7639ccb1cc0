#pragma once
// The case driver: turns a validated CaseConfig into a running DemEngine, runs it with output,
// progress, checkpoints and signal handling. Used by the `fdem` command line (src/app/main.cpp).
#include <mpi.h>

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "app/engine.hpp"
#include "app/measurements.hpp"
#include "app/run_control.hpp"
#include "io/case.hpp"
#include "io/checkpoint.hpp"
#include "io/csv.hpp"
#include "io/run_info.hpp"
#include "io/snapshot.hpp"

namespace fdem {

struct RunOptions {
  bool quiet = false;        // -q: no progress lines
  std::string restart;       // --restart FILE (overrides the case's restart.from)
  std::string specimen;      // --specimen FILE: a packing case's specimen.h5 instead of packing again
  std::string resume_packing;  // a packing's checkpoint given as --restart / restart.from: the packing goes on from it
};

/// Everything needed to start an engine, built identically on every rank -- but the particles
/// and the history of a restart, which each rank holds a share of (`shared`).
struct Setup {
  EngineParams params;
  MaterialTable materials;
  std::vector<Wall> walls;
  ParticleStore particles;              // all particles (every rank), masses set; `shared`: this rank's share
  std::vector<ContactRecord> history;   // from a checkpoint (`shared`: this rank's share)
  bool shared = false;                  // particles and history are shares (DemEngine's ParticleInput::kShare)
  std::vector<Vec3> wall_vel;           // from a checkpoint (else empty)
  std::int64_t step = 0;
  double time = 0;
  bool restarted = false;
  std::int64_t hold = -1, hold_start = -1;  // from a checkpoint of a run with `holds` (-1: none)
  std::vector<Vec3> wall_start;             // and its walls' displacements when the run began
  std::vector<Vec3> wall_check;             // and at the last convergence check (holds.creep)
};

/// The engine input of a set-up: its particles are every particle, or this rank's share.
inline ParticleInput particle_input(const Setup& s) {
  return s.shared ? ParticleInput::kShare : ParticleInput::kReplicated;
}

/// Collective. The particles of a set-up over all ranks (a share is reduced; the sums are exact,
/// so any split of a shared set-up gives the values of the replicated one).
struct ParticleSummary {
  std::int64_t count = 0;
  double rmin = 0, rmax = 0;  // 0 with no particles
  double mass = 0;            // total mass, kg
  double diameter_sum = 0;    // sum of the diameters, m
  double dt_critical = 1e300; // critical_dt of all of them (1e300 with none)
};
ParticleSummary summarize_particles(const Setup& s, MPI_Comm comm);

/// Build the set-up of a case: particles from their sources (or from a checkpoint), constraints,
/// walls. Throws InputError for bad input.
Setup prepare(const CaseConfig& c, const RunOptions& opt, MPI_Comm comm);

/// Print a summary of a validated case on rank 0 (`fdem check`).
void print_check_summary(const CaseConfig& c, const Setup& s, MPI_Comm comm);
/// The effective contact pair table (app/pairs.hpp), for `fdem check` (call on rank 0).
void print_pair_table(const CaseConfig& c);

/// Run the case to the end (or to a signal). Returns the process exit code:
/// 0 finished, 128+signal when stopped by SIGINT/SIGTERM (after writing a checkpoint).
int run_case(const CaseConfig& c, Setup s, const RunOptions& opt, MPI_Comm comm);

/// The outputs and bookkeeping of a DEM run, shared by run_case and the coupled driver
/// (src/app/coupled_driver.cpp): creates the output directory, writes the particle snapshots
/// (XDMF), history.csv, walls.csv, lab.csv, removed.csv, run.json and checkpoints, prints the start-up
/// line and the summary, and polls signals and the progress clock. All methods collective
/// unless noted.
class DemRunOutput {
 public:
  /// `append`: continue the files of a restarted run. Creates c.out_dir.
  DemRunOutput(const CaseConfig& c, DemEngine& e, bool append, std::int64_t n_initial, MPI_Comm comm);
  ~DemRunOutput();
  const std::string& dir() const { return dir_; }
  /// A row of history.csv and walls.csv (and removed.csv for particles that left the domain).
  EngineStats write_history();
  /// A particle snapshot of the current step.
  void snapshot();
  /// The engine's checkpoint as dir/checkpoint.h5; `hold` >= 0: a run with load holds on walls,
  /// at that hold (its first step `hold_start`).
  void checkpoint(std::int64_t hold = -1, std::int64_t hold_start = -1, const std::vector<Vec3>& wall_start = {},
                  const std::vector<Vec3>& wall_check = {});
  /// Update run.json (status "running", "finished", "interrupted" or "diverged", the last with
  /// `message`); `extra`, when set, is called (on every rank: it may be collective) before rank
  /// 0 writes the file.
  void fill_info(const char* status, const std::string& message = "");
  /// run.json with status "failed" and `message`, not collective (an error on some ranks only):
  /// rank 0 writes what it knows; never throws.
  void fail_info(const std::string& message) noexcept;
  std::function<void(RunInfo&)> extra;
  const RunInfo& info() const { return info_; }
  int rank() const { return rank_; }
  /// The start-up line (rank 0), with `extra` appended before the newline.
  void print_start(std::int64_t end_step, const std::string& extra_text = "") const;
  /// The closing lines (rank 0): steps, wall time, rate, time per stage, bytes sent.
  void print_summary() const;

 private:
  const CaseConfig& c_;
  DemEngine& e_;
  MPI_Comm comm_;
  int rank_ = 0, size_ = 1;
  std::string dir_;
  double wall0_ = 0;
  std::int64_t n_initial_ = 0;
  std::unique_ptr<SnapshotWriter> snaps_;
  std::unique_ptr<CsvWriter> history_, walls_csv_, removed_csv_;
  std::unique_ptr<class LabOutput> lab_;  // lab.csv when the case has a `lab` section
  RunInfo info_;
};

/// The engine's full state as a checkpoint (this rank's share; collective writers gather).
Checkpoint engine_checkpoint(const DemEngine& e);
/// The same for writing at once: the particles are not copied (`particles_view` points at the
/// engine's store, valid until the engine next steps).
Checkpoint engine_checkpoint_view(const DemEngine& e);

/// case.yaml in `dir` (rank 0): the case file as run -- its YAML with the --set overrides applied
/// (defaults not filled in) -- so that post-processing reads what ran.
/// case.yaml: the case as run (--set applied, the defaults filled in), with a header naming
/// the case file and the overrides. `fdem check --print-case` prints the same text.
std::string case_yaml_text(const CaseConfig& c);
void write_case_yaml(const CaseConfig& c, const std::string& dir);

/// The step at which a run ends: time.steps, or time.duration in steps of dt.
std::int64_t run_end_step(const CaseConfig& c, double dt);

/// This process's peak resident memory so far (getrusage), MB.
double peak_rss_mb();

// ---- the observers of a run with particles (app/run_control.hpp), shared by run_case and the
// coupled driver ----

/// history.csv and its companions, written by `record` (at most once per step): at the start, on
/// every history row and at the end; with `at_holds_and_signals` also at each hold's end and on
/// a signal.
class HistoryObserver : public Observer {
 public:
  HistoryObserver(std::function<void(const RunState&)> record, bool at_holds_and_signals)
      : record_(std::move(record)), at_holds_and_signals_(at_holds_and_signals) {}
  void on_start(const RunState& st) override { write(st); }
  void on_record(const RunState& st) override { write(st); }
  void on_hold_end(const RunState& st) override { if (at_holds_and_signals_) write(st); }
  void on_signal(const RunState& st, int) override { if (at_holds_and_signals_) write(st); }
  void on_finish(const RunState& st) override { write(st); }

 private:
  void write(const RunState& st);
  std::function<void(const RunState&)> record_;
  bool at_holds_and_signals_;
  std::int64_t written_at_ = -1;
};

/// The measurements (case key `measure`; none when `m` is null): at the start, every
/// `measure.every` steps, at each hold's end and at the last step.
class MeasureObserver : public Observer {
 public:
  explicit MeasureObserver(MeasureRun* m) : m_(m) {}
  void on_start(const RunState&) override;
  void on_step(const RunState& st) override;

 private:
  MeasureRun* m_;
};

/// Snapshots (at most one per step): at the start, every `every` steps, at each hold's end, at
/// the last step, on a signal and at the end.
class SnapshotObserver : public Observer {
 public:
  SnapshotObserver(int every, std::function<void()> write) : every_(every), write_(std::move(write)) {}
  void on_start(const RunState& st) override { write(st); }
  void on_hold_end(const RunState& st) override { write(st); }
  void on_step(const RunState& st) override;
  void on_signal(const RunState& st, int) override { write(st); }
  void on_finish(const RunState& st) override { write(st); }

 private:
  void write(const RunState& st);
  int every_;
  std::function<void()> write_;
  std::int64_t written_at_ = -1;
};

/// Checkpoints: every `every` steps (run.json "running" after each), on a signal and at the end,
/// by `write(state, hold_done)`, which runs the health checks first. With a sub-cycle
/// (`sync_period` > 1) a checkpoint waits for the end of the sub-cycle it falls in (the FE has
/// then received every force summed so far); a run that ends inside a sub-cycle keeps the one
/// written at the start of that sub-cycle, and a restart continues from it bit for bit.
class CheckpointObserver : public Observer {
 public:
  CheckpointObserver(DemRunOutput& out, int every, int sync_period, bool quiet,
                     std::function<void(const RunState&, bool)> write)
      : out_(out), every_(every), sync_period_(sync_period), quiet_(quiet), write_(std::move(write)) {}
  void on_step(const RunState& st) override;
  void on_signal(const RunState& st, int) override { last_checkpoint(st, false); }
  void on_finish(const RunState& st) override { last_checkpoint(st, true); }

 private:
  void last_checkpoint(const RunState& st, bool hold_done);
  DemRunOutput& out_;
  int every_, sync_period_;
  bool quiet_;
  std::function<void(const RunState&, bool)> write_;
  bool due_ = false;
  std::int64_t boundary_ = -1;
};

/// run.json: "interrupted" on a signal, "finished" at the end, "diverged" or "failed" on an error.
class RunJsonObserver : public Observer {
 public:
  explicit RunJsonObserver(DemRunOutput& out) : out_(out) {}
  void on_signal(const RunState&, int) override { out_.fill_info("interrupted"); }
  void on_finish(const RunState&) override { out_.fill_info("finished"); }
  void on_error(const RunState&, bool diverged, const std::string& what) noexcept override;

 private:
  DemRunOutput& out_;
};

}  // namespace fdem
