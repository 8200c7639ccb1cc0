#pragma once
// The case driver: turns a validated CaseConfig into a running DemEngine, runs it with output,
// progress, checkpoints and signal handling. Used by the `fdem` command line (src/app/main.cpp).
#include <mpi.h>

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "app/engine.hpp"
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
};

/// Everything needed to start an engine, built identically on every rank.
struct Setup {
  EngineParams params;
  MaterialTable materials;
  std::vector<Wall> walls;
  ParticleStore particles;              // all particles (every rank), masses set
  std::vector<ContactRecord> history;   // from a checkpoint
  std::vector<Vec3> wall_vel;           // from a checkpoint (else empty)
  std::int64_t step = 0;
  double time = 0;
  bool restarted = false;
};

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
  /// The engine's checkpoint as dir/name.
  void checkpoint(const std::string& name = "checkpoint.h5");
  /// Update run.json (status "running", "finished", "interrupted" or "diverged", the last with
  /// `message`); `extra`, when set, is called (on every rank: it may be collective) before rank
  /// 0 writes the file.
  void fill_info(const char* status, const std::string& message = "");
  /// run.json with status "failed" and `message`, not collective (an error on some ranks only):
  /// rank 0 writes what it knows; never throws.
  void fail_info(const std::string& message) noexcept;
  std::function<void(RunInfo&)> extra;
  const RunInfo& info() const { return info_; }
  /// Signal received on any rank (0: none) and whether a progress line is due (rank 0's clock).
  struct Poll { int signal = 0; bool print = false; };
  Poll poll(bool quiet);
  void mark_printed() { last_print_ = MPI_Wtime(); }
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
  double wall0_ = 0, last_print_ = 0;
  std::int64_t n_initial_ = 0;
  std::unique_ptr<SnapshotWriter> snaps_;
  std::unique_ptr<CsvWriter> history_, walls_csv_, removed_csv_;
  std::unique_ptr<class LabOutput> lab_;  // lab.csv when the case has a `lab` section
  RunInfo info_;
};

/// "hh:mm:ss" for an estimated time left ("--:--:--" when unknown).
std::string hms(double seconds);

/// The engine's full state as a checkpoint (this rank's share; collective writers gather).
Checkpoint engine_checkpoint(const DemEngine& e);

/// Install SIGINT/SIGTERM/SIGUSR1 handlers that only set a flag polled by run_case.
void install_signal_handlers();
/// The last signal received (0: none).
int pending_signal();

}  // namespace fdem
