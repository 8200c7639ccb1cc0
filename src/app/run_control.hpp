#pragma once
// The run loop (docs/dev/run-loop-plan.md): one loop over a run's steps and holds, with the
// parts that change the state around a step (controllers: load ramps, rigid release) kept apart
// from the parts that only record it (observers: history, measurements, snapshots, checkpoints,
// run.json, progress lines). What ends a hold or a run is a Schedule. The particle run and the
// coupled run are built from these parts (app/driver.cpp, app/coupled_driver.cpp); a new
// protocol (e.g. load holds on walls) is a new Schedule or Controller, not a new loop.
//
// Per step, the order is fixed: controllers' before_step -> advance -> controllers' after_step
// -> on_record (a history row is due) -> Schedule::check -> on_hold_end and the next hold's
// begin -> on_step -> every `poll_every` steps the progress clock and the signal flags (one
// allreduce) -> on a signal, at a step that is a multiple of `sync_period`: on_signal, stop.
// Observers are called in the order they were added; the order is part of the results (a
// measurement refreshes the ghosts, a history row reduces the wall forces).
#include <mpi.h>

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace fdem {

/// Where a run stands, as the loop hands it to its parts.
struct RunState {
  std::int64_t step = 0;        ///< steps done
  std::int64_t end_step = 0;    ///< the step at which the run ends (time.steps / duration)
  std::int64_t hold_start = 0;  ///< the step at which the current hold began
  std::size_t hold = 0;         ///< the current hold (0-based)
  std::size_t holds = 1;        ///< holds of the run (1: no holds)
  bool last = false;            ///< step == end_step
  bool history_row = false;     ///< a history row is written at this step
  bool hold_done = false;       ///< the hold ended at this step (it was `hold` before on_hold_end)
  bool hold_converged = false;  ///< ... because it converged (not because it ran out of steps)
  bool stop = false;            ///< the run ends at this step (converged, or its last hold done)
  bool holds_finished = false;  ///< the last hold has ended
  bool poll_now = false;        ///< the schedule asks for a poll at this step (its checks)
  double loop_wall0 = 0;        ///< MPI_Wtime() when the loop started (for rates and ETAs)
  std::int64_t loop_step0 = 0;  ///< the step at which the loop started
};

/// Changes the state around a step: load and displacement ramps, releasing a rigid structure.
class Controller {
 public:
  virtual ~Controller() = default;
  virtual void before_step(const RunState&) {}
  virtual void after_step(const RunState&) {}
};

/// Records the state. Collective calls must be made on every rank in the same order.
class Observer {
 public:
  virtual ~Observer() = default;
  virtual void on_start(const RunState&) {}   ///< a fresh run (not a restart): the step-0 output
  virtual void on_record(const RunState&) {}  ///< a history row is due (`history_every`, the last step)
  virtual void on_hold_end(const RunState&) {}
  virtual void on_step(const RunState&) {}    ///< every step, after the hold/stop decision
  virtual void on_progress(const RunState&) {}  ///< a progress line is due (collective; rank 0 prints)
  virtual void on_signal(const RunState&, int /*sig*/) {}
  virtual void on_finish(const RunState&) {}  ///< the run reached its end (not on a signal)
  /// The run threw: `diverged` for RunDiverged (the run-health checks), else any other error
  /// (possibly on some ranks only: no collective calls). Must not throw.
  virtual void on_error(const RunState&, bool /*diverged*/, const std::string& /*what*/) noexcept {}
};

/// What ends holds and runs.
class Schedule {
 public:
  virtual ~Schedule() = default;
  /// After the step's history row: set st.hold_done (the hold converged or ran out of steps) or
  /// st.stop (a run without holds converged). Collective.
  virtual void check(RunState& st) = 0;
  /// Hold st.hold begins at st.hold_start (called for every hold after the first).
  virtual void begin_hold(const RunState&) {}
};

/// One loop for a run. `advance` takes one step, `step` says how many are done.
class RunControl {
 public:
  struct Params {
    std::int64_t end_step = 0;
    std::size_t holds = 1, first_hold = 0;
    std::int64_t hold_start = 0;
    int history_every = 0;       ///< 0: history rows only where observers write them
    int poll_every = 20;         ///< steps between polls of the signals and the progress clock (and at
                                 ///< the last step); 0: only where the schedule asks (RunState::poll_now)
    bool poll_from_hold_start = false;  ///< count them from the hold's start (polls at a hold's checks)
    int sync_period = 1;         ///< a signal is acted on at a step that is a multiple of it (or the last)
    bool quiet = false;
    double progress_interval = 10;  ///< seconds between progress lines
    std::string signal_note;        ///< "writing <signal_note> and stopping" (empty: the observers say it)
  };
  RunControl(MPI_Comm comm, Params p, std::function<void()> advance, std::function<std::int64_t()> step);
  void add(Controller& c) { controllers_.push_back(&c); }
  void add(Observer& o) { observers_.push_back(&o); }
  void set_schedule(Schedule& s) { schedule_ = &s; }
  const RunState& state() const { return st_; }
  /// Runs to the end, the last hold, convergence or a signal. `fresh`: call on_start first.
  /// A signal that arrives at the step where the last hold ends does not interrupt the run: it
  /// finishes (on_finish). Returns 0, or 128 + the signal. Rethrows what the steps or the observers throw, after
  /// on_error.
  int run(bool fresh);

 private:
  MPI_Comm comm_;
  int rank_ = 0;
  Params p_;
  std::function<void()> advance_;
  std::function<std::int64_t()> step_;
  std::vector<Controller*> controllers_;
  std::vector<Observer*> observers_;
  Schedule* schedule_ = nullptr;
  RunState st_;
  double last_print_ = 0;
};

/// Install SIGINT/SIGTERM/SIGUSR1 handlers that only set a flag polled by the run loops.
void install_signal_handlers();
/// The last signal received (0: none).
int pending_signal();

/// "hh:mm:ss" for an estimated time left ("--:--:--" when unknown).
std::string hms(double seconds);

}  // namespace fdem
