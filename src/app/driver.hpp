#pragma once
// The case driver: turns a validated CaseConfig into a running DemEngine, runs it with output,
// progress, checkpoints and signal handling. Used by the `fdem` command line (src/app/main.cpp).
#include <mpi.h>

#include <memory>
#include <string>
#include <vector>

#include "app/engine.hpp"
#include "io/case.hpp"
#include "io/checkpoint.hpp"

namespace fdem {

struct RunOptions {
  bool quiet = false;        // -q: no progress lines
  std::string restart;       // --restart FILE (overrides the case's restart.from)
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

/// Run the case to the end (or to a signal). Returns the process exit code:
/// 0 finished, 128+signal when stopped by SIGINT/SIGTERM (after writing a checkpoint).
int run_case(const CaseConfig& c, Setup s, const RunOptions& opt, MPI_Comm comm);

/// The engine's full state as a checkpoint (this rank's share; collective writers gather).
Checkpoint engine_checkpoint(const DemEngine& e);

/// Install SIGINT/SIGTERM/SIGUSR1 handlers that only set a flag polled by run_case.
void install_signal_handlers();
/// The last signal received (0: none).
int pending_signal();

}  // namespace fdem
