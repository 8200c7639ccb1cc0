// Load holds on walls (wall_holds.hpp).
#include "app/wall_holds.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace fdem {

namespace {
std::string fmt_m(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.3g", v);
  return b;
}

std::vector<std::string> holds_columns(const CaseConfig& c, const std::vector<std::string>& extra) {
  std::vector<std::string> cols{"hold", "step", "time", "converged", "unbalanced"};
  for (const HoldsConfig::Wall& w : c.holds.walls) {
    const std::string& n = c.walls[static_cast<std::size_t>(w.wall)].name;
    if (w.moved())
      for (const char* q : {"_target", "_force", "_displacement"}) cols.push_back(n + q);
    else
      for (const char* q : {"_target", "_stress", "_settlement"}) cols.push_back(n + q);
  }
  cols.insert(cols.end(), extra.begin(), extra.end());
  cols.push_back("held_by");
  return cols;
}

/// A displacement-held wall counts as arrived within this distance of its target (m).
constexpr double kArrived = 1e-12;
}  // namespace

WallHolds::WallHolds(const CaseConfig& c, DemEngine& e, const std::string& dir, bool restarted,
                     const std::vector<Vec3>& start, const std::vector<Vec3>& check, bool quiet, MPI_Comm comm,
                     const std::vector<std::string>& extra_columns)
    : c_(c), h_(c.holds), e_(e), quiet_(quiet), start_(start), check_(check), extra_(extra_columns.size(), 0.0) {
  MPI_Comm_rank(comm, &rank_);
  if (start_.size() != e.walls().walls.size()) {
    start_.clear();
    for (const Wall& w : e.walls().walls) start_.push_back(w.disp);
  }
  if (check_.size() != e.walls().walls.size()) {
    check_.clear();
    for (const Wall& w : e.walls().walls) check_.push_back(w.disp);
  }
  // the step is column 1: on a restart the rows after the checkpoint's step are dropped
  csv_ = std::make_unique<CsvWriter>(dir + "/holds.csv", holds_columns(c, extra_columns), comm, restarted,
                                     static_cast<double>(e.step_count()), 1);
}

void WallHolds::apply(std::size_t h) {
  hold_ = h;
  for (const HoldsConfig::Wall& w : h_.walls)
    if (!w.moved()) e_.walls().walls[static_cast<std::size_t>(w.wall)].servo.stress = w.stress[h];
}

void WallHolds::before_step(const RunState& st) {
  hold_ = std::min(st.hold, h_.count - 1);
  const double dt = e_.dt();
  for (const HoldsConfig::Wall& w : h_.walls) {
    if (!w.moved()) continue;
    Wall& wall = e_.walls().walls[static_cast<std::size_t>(w.wall)];
    const double rest = w.displacement[hold_] - displacement(w);
    if (std::fabs(rest) <= kArrived) {
      wall.motion = Wall::kFixed;
      wall.vel = Vec3{};
      continue;
    }
    const double cap = w.velocity * dt;  // the last step lands on the target
    wall.motion = Wall::kVelocity;
    wall.vel = (std::clamp(rest, -cap, cap) / dt) * w.axis;
  }
}

bool WallHolds::arrived() const {
  for (const HoldsConfig::Wall& w : h_.walls)
    if (w.moved() && std::fabs(w.displacement[hold_] - displacement(w)) > kArrived) return false;
  return true;
}

double WallHolds::displacement(const HoldsConfig::Wall& w) const {
  const Wall& wall = e_.walls().walls[static_cast<std::size_t>(w.wall)];
  return dot(wall.disp - start_[static_cast<std::size_t>(w.wall)], w.moved() ? w.axis : wall.servo.axis);
}

void WallHolds::begin(std::size_t h) {
  apply(h);
  for (std::size_t i = 0; i < check_.size(); ++i) check_[i] = e_.walls().walls[i].disp;
}

bool WallHolds::creeping() {
  moved_ = 0;
  creeping_.clear();
  for (const HoldsConfig::Wall& w : h_.walls) {
    if (w.moved()) continue;  // (it moves by prescription)
    const Wall& wall = e_.walls().walls[static_cast<std::size_t>(w.wall)];
    const double m = std::fabs(dot(wall.disp - check_[static_cast<std::size_t>(w.wall)], wall.servo.axis));
    moved_ = std::max(moved_, m);
    if (h_.creep > 0 && m >= h_.creep) creeping_.push_back(wall.name);
  }
  for (std::size_t i = 0; i < check_.size(); ++i) check_[i] = e_.walls().walls[i].disp;
  return h_.creep > 0 && moved_ >= h_.creep;
}

std::string WallHolds::open_walls() const {
  std::string s;
  auto add = [&](const std::string& w) { s += (s.empty() ? "" : "+") + w; };
  for (const std::string& n : creeping_) add("creep:" + n);
  for (const HoldsConfig::Wall& w : h_.walls)
    if (w.moved() && std::fabs(w.displacement[hold_] - displacement(w)) > kArrived)
      add("arrive:" + e_.walls().walls[static_cast<std::size_t>(w.wall)].name);
  return s;
}

double WallHolds::settlement(int wall) const {
  const Wall& w = e_.walls().walls[static_cast<std::size_t>(wall)];
  return dot(w.disp - start_[static_cast<std::size_t>(wall)], w.servo.axis);
}

bool WallHolds::stop_reached(RunState& st) {
  if (h_.stop_wall >= 0 && settlement(h_.stop_wall) >= h_.stop_displacement) {
    if (rank_ == 0 && !quiet_)
      std::printf("fdem: wall '%s' has moved %.4g m along its axis (holds.stop: %.4g m) in hold %zu at step %lld: "
                  "stopping\n",
                  c_.walls[static_cast<std::size_t>(h_.stop_wall)].name.c_str(), settlement(h_.stop_wall),
                  h_.stop_displacement, st.hold + 1, static_cast<long long>(st.step));
    e_.sync_ghosts();
    unbalanced_ = e_.stats().unbalanced;
    held_by_ = "stop";
    row(st, 0);
    st.stop = true;
    return true;
  }
  return false;
}

void WallHolds::check(RunState& st) {
  const std::int64_t done = st.step - st.hold_start;
  if (stop_reached(st)) return;
  if (done < h_.min_steps || done % h_.check_every != 0) return;
  st.poll_now = true;
  // current ghost positions first (as the packing's checks): the ratio, and so the step a hold
  // ends at, is then the same on any number of ranks
  e_.sync_ghosts();
  const EngineStats es = e_.stats();
  unbalanced_ = es.unbalanced;
  double misfit = 0;
  for (const HoldsConfig::Wall& w : h_.walls) {
    if (w.moved()) continue;
    const Wall& wall = e_.walls().walls[static_cast<std::size_t>(w.wall)];
    misfit = std::max(misfit, std::fabs(wall.stress - wall.servo.stress) / wall.servo.stress);
  }
  const bool creep = creeping();
  {  // the parts above their tolerance (holds.csv's held_by)
    std::string open = es.contacts > 0 && es.unbalanced < h_.tolerance ? "" : "dem";
    if (!(misfit < h_.tolerance)) open += std::string(open.empty() ? "" : "+") + "servo";
    const std::string walls = open_walls();
    if (!walls.empty()) open += (open.empty() ? "" : "+") + walls;
    held_by_ = open;
  }
  if (es.contacts > 0 && es.unbalanced < h_.tolerance && misfit < h_.tolerance && !creep && arrived()) {
    st.hold_converged = true;
    st.hold_done = true;
  } else if (done >= h_.max_steps) {
    if (rank_ == 0)
      std::printf("fdem: hold %zu did not converge in %lld steps (unbalanced %.3e, servo misfit %.3e; tolerance "
                  "%.1e%s); continuing\n",
                  st.hold + 1, static_cast<long long>(done), es.unbalanced, misfit, h_.tolerance,
                  h_.creep > 0 ? (", moved " + fmt_m(moved_) + " m in the last check interval, creep " + fmt_m(h_.creep)).c_str() : "");
    st.hold_done = true;
  }
}

void WallHolds::row(const RunState& st, int converged) {
  std::vector<double> r{static_cast<double>(st.hold + 1), static_cast<double>(st.step), e_.time(),
                        static_cast<double>(converged), unbalanced_};
  for (const HoldsConfig::Wall& w : h_.walls) {
    const Wall& wall = e_.walls().walls[static_cast<std::size_t>(w.wall)];
    if (w.moved()) r.insert(r.end(), {w.displacement[st.hold], dot(wall.force, w.axis), displacement(w)});
    else r.insert(r.end(), {wall.servo.stress, wall.stress, settlement(w.wall)});
  }
  r.insert(r.end(), extra_.begin(), extra_.end());
  // held_by: what kept a hold open at its last check ("none" for a converged hold; "stop" when
  // holds.stop ended the run)
  csv_->row(r, converged ? std::string("none") : (held_by_.empty() ? std::string("none") : held_by_));
  if (rank_ != 0 || quiet_ || h_.walls.empty()) return;
  const HoldsConfig::Wall& w0 = h_.walls.front();
  const Wall& wall = e_.walls().walls[static_cast<std::size_t>(w0.wall)];
  if (w0.moved()) {
    std::printf("hold %zu/%zu %s at step %lld: wall '%s' at %.6g m along its axis (target %.6g), force along it %.6g N, "
                "unbalanced %.3e\n",
                st.hold + 1, h_.count, converged ? "converged" : "ended", static_cast<long long>(st.step),
                wall.name.c_str(), displacement(w0), w0.displacement[st.hold], dot(wall.force, w0.axis), unbalanced_);
    std::fflush(stdout);
    return;
  }
  std::printf("hold %zu/%zu %s at step %lld: wall '%s' stress %.6g Pa (target %.6g), settlement %.6g m, unbalanced "
              "%.3e\n",
              st.hold + 1, h_.count, converged ? "converged" : "ended", static_cast<long long>(st.step),
              wall.name.c_str(), wall.stress, wall.servo.stress, settlement(w0.wall), unbalanced_);
  std::fflush(stdout);
}

}  // namespace fdem
