#include "app/run_control.hpp"

#include <csignal>
#include <cstdio>
#include <exception>

#include "base/errors.hpp"

namespace fdem {

namespace {
volatile std::sig_atomic_t g_signal = 0;
extern "C" void on_signal(int sig) { g_signal = sig; }
}  // namespace

int pending_signal() { return static_cast<int>(g_signal); }

void install_signal_handlers() {
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  std::signal(SIGUSR1, on_signal);
}

std::string hms(double s) {
  if (!(s >= 0) || s > 1e8) return "--:--:--";
  const long t = static_cast<long>(s + 0.5);
  char buf[32];
  std::snprintf(buf, sizeof buf, "%02ld:%02ld:%02ld", t / 3600, (t / 60) % 60, t % 60);
  return buf;
}

RunControl::RunControl(MPI_Comm comm, Params p, std::function<void()> advance, std::function<std::int64_t()> step)
    : comm_(comm), p_(std::move(p)), advance_(std::move(advance)), step_(std::move(step)), last_print_(MPI_Wtime()) {
  MPI_Comm_rank(comm, &rank_);
  st_.end_step = p_.end_step;
  st_.holds = p_.holds;
  st_.hold = p_.first_hold;
  st_.hold_start = p_.hold_start;
  st_.step = step_();
}

int RunControl::run(bool fresh) {
  RunState& st = st_;
  int code = 0;
  try {
    if (fresh)
      for (Observer* o : observers_) o->on_start(st);
    st.loop_wall0 = MPI_Wtime();
    st.loop_step0 = step_();
    int pending = 0;
    while (step_() < st.end_step) {
      for (Controller* c : controllers_) c->before_step(st);
      advance_();
      const std::int64_t k = step_();
      st.step = k;
      st.last = k >= st.end_step;
      st.hold_done = st.hold_converged = st.stop = st.poll_now = false;
      for (Controller* c : controllers_) c->after_step(st);
      st.history_row = p_.history_every > 0 && (k % p_.history_every == 0 || st.last);
      if (st.history_row)
        for (Observer* o : observers_) o->on_record(st);
      if (schedule_) schedule_->check(st);
      if (st.hold_done) {
        for (Observer* o : observers_) o->on_hold_end(st);
        if (st.hold + 1 >= st.holds) {
          st.holds_finished = true;
          st.stop = true;
        } else {
          ++st.hold;
          st.hold_start = k;
          if (schedule_) schedule_->begin_hold(st);
        }
      }
      for (Observer* o : observers_) o->on_step(st);
      const std::int64_t since = p_.poll_from_hold_start ? k - st.hold_start : k;
      if (st.poll_now || (p_.poll_every > 0 && (since % p_.poll_every == 0 || st.last))) {
        // one allreduce: a signal on any rank, and rank 0's progress clock
        double flags[2] = {static_cast<double>(g_signal), 0.0}, g[2];
        if (rank_ == 0 && !p_.quiet && MPI_Wtime() - last_print_ >= p_.progress_interval) flags[1] = 1;
        MPI_Allreduce(flags, g, 2, MPI_DOUBLE, MPI_MAX, comm_);
        if (g[1] > 0) {
          for (Observer* o : observers_) o->on_progress(st);
          if (rank_ == 0) last_print_ = MPI_Wtime();
        }
        if (g[0] > 0) pending = static_cast<int>(g[0]);
      }
      if (pending > 0 && !st.holds_finished && (k % p_.sync_period == 0 || st.last)) {
        if (rank_ == 0 && !p_.signal_note.empty())
          std::printf("fdem: signal %d at step %lld: writing %s and stopping\n", pending, static_cast<long long>(k),
                      p_.signal_note.c_str());
        for (Observer* o : observers_) o->on_signal(st, pending);
        code = 128 + pending;
        break;
      }
      if (st.stop) break;
    }
    if (code == 0)
      for (Observer* o : observers_) o->on_finish(st);
  } catch (const RunDiverged& ex) {
    for (Observer* o : observers_) o->on_error(st, true, ex.what());
    throw;
  } catch (const std::exception& ex) {
    for (Observer* o : observers_) o->on_error(st, false, ex.what());
    throw;
  }
  return code;
}

}  // namespace fdem
