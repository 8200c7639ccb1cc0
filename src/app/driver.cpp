#include "app/driver.hpp"

#include "app/case_checks.hpp"
#include "app/particle_input.hpp"

#include <sys/resource.h>
#include "app/wall_holds.hpp"
#include "app/pairs.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <sys/resource.h>

#include "app/lab_output.hpp"
#include "dem/generate.hpp"
#include "dem/health.hpp"
#include "io/checkpoint.hpp"
#include "io/csv.hpp"
#include "base/collective_error.hpp"
#include "base/errors.hpp"
#include "base/exact_sum.hpp"
#include "io/run_info.hpp"
#include "io/snapshot.hpp"

namespace fdem {

namespace {

/// The servo law's parameters of wall `w` (its geometry already set): axis from the plane's
/// normal unless given; area given, between two pairs of planes, or the projected area.
ServoParams make_servo(const ServoConfig& sc, const Wall& w) {
  ServoParams s;
  s.axis = sc.has_axis ? sc.axis : w.normal;
  s.stress = sc.stress;
  s.area_walls = sc.area_wall_index;
  s.area = sc.area > 0 ? sc.area : (s.area_walls[0] >= 0 ? 0.0 : projected_area(w, s.axis));
  s.gain = sc.gain;
  s.stiffness = sc.stiffness;
  s.max_velocity = sc.max_velocity;
  s.velocity = sc.velocity;
  return s;
}

WallPhase make_phase(const WallMotion& m, const Wall& w) {
  WallPhase ph;
  ph.from_step = m.from_step;
  if (m.after) {
    ph.from_step = kPhasePending;
    ph.after.on = true;
    ph.after.unbalanced = m.after_unbalanced;
    ph.after.kinetic = m.after_unbalanced > 0 ? m.after_kinetic : 0.0;  // (the guard of the ratio)
    ph.after.servo = m.after_servo;
    ph.after.time = m.after_time;
    ph.after.steps = m.after_steps;
  }
  switch (m.kind) {
    case WallMotion::kFixed: ph.motion = Wall::kFixed; break;
    case WallMotion::kVelocity: ph.motion = Wall::kVelocity; break;
    case WallMotion::kFree: ph.motion = Wall::kFree; break;
    case WallMotion::kServo: ph.motion = Wall::kServo; break;
  }
  ph.velocity = m.velocity;
  ph.mass = m.mass;
  ph.free_dofs = m.free_dofs;
  ph.gravity = m.gravity;
  if (m.kind == WallMotion::kServo) ph.servo = make_servo(m.servo, w);
  return ph;
}

Wall make_wall(const WallConfig& wc) {
  Wall w;
  w.name = wc.name;
  w.mat = wc.material;
  switch (wc.kind) {
    case WallConfig::kPlane: w.kind = Wall::kPlane; break;
    case WallConfig::kBox: w.kind = Wall::kBox; break;
    case WallConfig::kFacets: w.kind = Wall::kFacets; break;
  }
  w.point = wc.point;
  const double nn = norm(wc.normal);
  w.normal = nn > 0 ? (1.0 / nn) * wc.normal : wc.normal;
  w.bmin = wc.min;
  w.bmax = wc.max;
  w.verts = wc.vertices;
  w.tris = wc.triangles;
  w.band_axis = wc.band_axis;
  w.band_edges = wc.band_edges;
  if (!w.band_edges.empty()) w.band_force.assign(w.band_edges.size() - 1, Vec3{});
  switch (wc.motion.kind) {
    case WallMotion::kFixed: w.motion = Wall::kFixed; break;
    case WallMotion::kVelocity: w.motion = Wall::kVelocity; break;
    case WallMotion::kFree: w.motion = Wall::kFree; break;
    case WallMotion::kServo: w.motion = Wall::kServo; break;
  }
  w.vel = wc.motion.velocity;
  w.mass = wc.motion.mass;
  w.free_dofs = wc.motion.free_dofs;
  w.gravity = wc.motion.gravity;
  if (wc.motion.kind == WallMotion::kServo) w.servo = make_servo(wc.motion.servo, w);
  for (const WallMotion& m : wc.schedule) w.schedule.push_back(make_phase(m, w));
  if (!w.schedule.empty() && w.schedule.front().from_step > 0) { w.motion = Wall::kFixed; w.vel = Vec3{}; }
  return w;
}

/// Walls that are servo-controlled at some point of the run get a `<name>_stress` column.
bool servo_wall(const Wall& w) {
  if (w.motion == Wall::kServo) return true;
  for (const WallPhase& ph : w.schedule)
    if (ph.motion == Wall::kServo) return true;
  return false;
}

/// The servo's measured stress for walls.csv: -F . axis / A with the current force (reduced)
/// and area; 0 while the wall is not servo-controlled.
double servo_stress(const Wall& w) {
  if (w.motion != Wall::kServo) return 0.0;
  double area = w.servo.area;
  if (w.servo.area_walls[0] >= 0) area = w.area_now;
  return area > 0 ? -dot(w.force, w.servo.axis) / area : 0.0;
}

/// Input particles overlapping beyond the run-health limit (coincident ones included) would
/// blow the run up at its first step: an input error naming the two ids and, where the source
/// is known, the case file's particles entry of the second one (replicated sources only).
void check_input_overlaps(const CaseConfig& c, const std::vector<SphereRecord>& recs) {
  std::vector<Vec3> x;
  std::vector<double> r;
  for (const SphereRecord& q : recs) { x.push_back(q.x); r.push_back(q.r); }
  const OverlapPair ov = deepest_overlap(x, r, HealthLimits::kMaxInputOverlap);
  if (!(ov.ratio > 0)) return;
  // The source of record j: build_particles keeps the sources' order (inline sources have known
  // counts; after a generated source the position is unknown). Sphere files are read shared
  // (app/particle_input.cpp checks them).
  std::string file = c.file;
  int line = 0;
  std::size_t first = 0;
  for (const ParticleSource& s : c.particles) {
    if (s.kind != ParticleSource::kInline) break;
    if (ov.j < first + s.spheres.size()) {
      file = s.source_file;
      line = s.line;
      break;
    }
    first += s.spheres.size();
  }
  const SphereRecord &a = recs[ov.i], &b = recs[ov.j];
  throw InputError(file, line, input_overlap_message(a.id, a.x, a.r, b.id, b.x, b.r, ov.ratio));
}

}  // namespace

Checkpoint engine_checkpoint_view(const DemEngine& e) {
  Checkpoint ck;
  ck.step = e.step_count();
  ck.time = e.time();
  ck.dt = e.dt();
  ck.particles_view = &e.particles();
  ck.contacts = e.history_records();
  for (const Wall& w : e.walls_const().walls) {
    ck.walls.push_back({w.disp, w.vel});
    for (const WallPhase& ph : w.schedule) ck.phase_from.push_back(ph.from_step);
  }
  return ck;
}

Checkpoint engine_checkpoint(const DemEngine& e) {
  Checkpoint ck = engine_checkpoint_view(e);
  const ParticleStore& p = e.particles();
  for (std::size_t i = 0; i < p.n_owned; ++i)
    ck.particles.push_back(p.x[i], p.v[i], p.w[i], p.r[i], p.m[i], p.id[i], p.mat[i], p.blocked[i], p.x0[i],
                            p.key[i]);
  ck.particles.n_owned = ck.particles.size();
  ck.particles_view = nullptr;
  return ck;
}

namespace {
/// `after: {stage: name}`: the wall and phase of that name (the reader checked it exists).
void link_phase_stages(const CaseConfig& c, std::vector<Wall>& walls) {
  for (std::size_t w = 0; w < c.walls.size(); ++w)
    for (std::size_t k = 0; k < c.walls[w].schedule.size(); ++k) {
      const std::string& st = c.walls[w].schedule[k].after_stage;
      if (st.empty()) continue;
      for (std::size_t j = 0; j < c.walls.size(); ++j)
        for (std::size_t l = 0; l < c.walls[j].schedule.size(); ++l)
          if (c.walls[j].schedule[l].name == st && (j != w || l != k)) {
            walls[w].schedule[k].after.stage_wall = static_cast<int>(j);
            walls[w].schedule[k].after.stage_phase = static_cast<int>(l);
          }
    }
}

/// The schedules' phase starts of a checkpoint (Checkpoint::phase_from): the steps at which
/// phases that start `after:` a condition began. A checkpoint without them (written before
/// conditions existed) keeps the case's steps.
void restore_phase_starts(const std::vector<std::int64_t>& from, std::vector<Wall>& walls, const std::string& file) {
  if (from.empty()) return;
  std::size_t n = 0;
  for (const Wall& w : walls) n += w.schedule.size();
  if (from.size() != n)
    throw InputError(file, 0, "the checkpoint's walls have " + std::to_string(from.size()) +
                                  " motion phases but the case's have " + std::to_string(n));
  std::size_t k = 0;
  for (Wall& w : walls)
    for (WallPhase& ph : w.schedule) {
      const std::int64_t f = from[k++];
      if (ph.after.on) ph.from_step = f;  // (a from_step phase keeps the case's: a --set may move it)
    }
}
}  // namespace

Setup prepare(const CaseConfig& c, const RunOptions& opt, MPI_Comm comm) {
  if (c.grid[0] > 0) {
    int size = 1;
    MPI_Comm_size(comm, &size);
    const long long n = static_cast<long long>(c.grid[0]) * c.grid[1] * c.grid[2];
    if (n != size)
      throw InputError(c.grid_at.first, c.grid_at.second,
                       "decomposition.grid [" + std::to_string(c.grid[0]) + ", " + std::to_string(c.grid[1]) + ", " +
                           std::to_string(c.grid[2]) + "] has " + std::to_string(n) + " subdomains but the run has " +
                           std::to_string(size) + " rank(s): their product must be the rank count (or 'auto')");
  }
  Setup s;
  s.params.domain_min = c.domain_min;
  s.params.domain_max = c.domain_max;
  s.params.gravity = c.gravity;
  s.params.damping = c.damping;
  s.params.dt = c.dt;
  s.params.dt_safety = c.dt_safety;
  s.params.skin = c.skin;
  s.params.grid = c.grid;
  s.params.grid_at = c.grid[0] > 0 ? c.grid_at : std::make_pair(c.file, 0);
  s.materials = MaterialTable(c.materials, c.interactions, c.contact_model);
  for (const WallConfig& wc : c.walls) s.walls.push_back(make_wall(wc));
  link_phase_stages(c, s.walls);

  const std::string restart = !opt.restart.empty() ? opt.restart : c.restart_from;
  if (!restart.empty()) {
    // Each rank reads its share of the particles and contacts (the engine sends them to their
    // owners): no rank holds them all.
    Checkpoint ck = read_checkpoint(restart, comm, ReadPart::kShare);
    if (ck.walls.size() != s.walls.size())
      throw InputError(restart, 0, "checkpoint has " + std::to_string(ck.walls.size()) +
                                       " walls but the case defines " + std::to_string(s.walls.size()));
    std::optional<InputError> bad;
    for (std::size_t i = 0; i < ck.particles.size() && !bad; ++i)
      if (ck.particles.mat[i] < 0 || ck.particles.mat[i] >= s.materials.size())
        bad = InputError(restart, 0, "particle " + std::to_string(ck.particles.id[i]) +
                                         " uses material index " + std::to_string(ck.particles.mat[i]) +
                                         " which the case does not define");
    agree_on_input_error(bad, comm);  // found in one rank's share: thrown on every rank
    for (std::size_t w = 0; w < s.walls.size(); ++w) {
      s.walls[w].disp = ck.walls[w].disp;
      s.walls[w].vel = ck.walls[w].vel;
    }
    restore_phase_starts(ck.phase_from, s.walls, restart);
    s.particles = std::move(ck.particles);
    s.particles.n_owned = s.particles.size();
    s.shared = true;
    s.history = std::move(ck.contacts);
    s.step = ck.step;
    s.time = ck.time;
    s.params.dt = ck.dt;  // the same step continues the same trajectory
    s.hold = ck.hold;
    s.hold_start = ck.hold_start;
    s.wall_start = ck.wall_start;
    s.wall_check = ck.wall_check;
    s.restarted = true;
    return s;
  }

  // With `placement: cells` clouds or sphere files each rank builds its block of the cells and
  // reads its byte range of the files (the other sources are kept by rank 0 only): a shared
  // set-up, no rank holds every particle (app/particle_input.hpp).
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  // (a packing case starts from them too: the packing holds shares, app/packing.cpp)
  s.shared = shared_particle_input(c);
  ParticleShareRecords sh;
  if (s.shared) {
    sh = read_particle_share(c, comm);
  } else {
    sh.records = build_particles(c);
    check_input_overlaps(c, sh.records);
    sh.everywhere.assign(sh.records.size(), 0);
  }
  ParticleStore& p = s.particles;
  bool by_id = false;  // the id -> index map only when a constraint names ids
  for (const ConstraintConfig& cc : c.constraints) by_id = by_id || !cc.ids.empty();
  std::map<std::int64_t, std::size_t> index;
  {  // the store at its size: grown by doubling it would hold up to twice the particles' memory
    std::size_t keep = 0;
    for (std::size_t k = 0; k < sh.records.size(); ++k) keep += !(s.shared && sh.everywhere[k] && rank != 0);
    p.reserve(keep);
  }
  for (std::size_t k = 0; k < sh.records.size(); ++k) {
    if (s.shared && sh.everywhere[k] && rank != 0) continue;
    const SphereRecord& r = sh.records[k];
    const double m = sphere_mass(c.materials[r.mat].density, r.r);
    if (by_id) index[r.id] = p.size();
    p.push_back(r.x, r.v, {}, r.r, m, r.id, r.mat, 0, r.x);
  }
  sh = ParticleShareRecords{};
  p.n_owned = p.size();
  for (const ConstraintConfig& cc : c.constraints) {
    std::vector<std::size_t> sel;
    std::vector<int> found(cc.ids.size(), 0);
    for (std::size_t k = 0; k < cc.ids.size(); ++k) {
      auto it = index.find(cc.ids[k]);
      if (it == index.end()) continue;
      found[k] = 1;
      sel.push_back(it->second);
    }
    if (s.shared && !found.empty())  // each id is on one rank
      MPI_Allreduce(MPI_IN_PLACE, found.data(), static_cast<int>(found.size()), MPI_INT, MPI_MAX, comm);
    for (std::size_t k = 0; k < cc.ids.size(); ++k)
      if (!found[k])
        throw InputError(c.file, cc.line, "constraint names particle id " + std::to_string(cc.ids[k]) +
                                              " which does not exist");
    if (cc.has_region)
      for (std::size_t i = 0; i < p.size(); ++i) {
        bool in = true;
        for (int d = 0; d < 3; ++d) in = in && p.x[i][d] >= cc.region_min[d] && p.x[i][d] <= cc.region_max[d];
        if (in) sel.push_back(i);
      }
    for (std::size_t i : sel) {
      p.blocked[i] |= cc.blocked;
      for (int d = 0; d < 3; ++d) {
        if (cc.blocked & (1u << d)) p.v[i][d] = cc.has_velocity ? cc.velocity[d] : 0.0;
        if (cc.blocked & (8u << d)) p.w[i][d] = 0.0;
      }
    }
  }
  // (a packing's walls meet its grains only once they have settled: its own checks)
  if (!c.packing.present) check_grains_in_walls(c, s, comm);
  return s;
}

ParticleSummary summarize_particles(const Setup& s, MPI_Comm comm) {
  const ParticleStore& p = s.particles;
  ParticleSummary o;
  double lo = 1e300, hi = 0;
  exact::ExactSums sums(2);
  for (std::size_t i = 0; i < p.size(); ++i) {
    lo = std::min(lo, p.r[i]);
    hi = std::max(hi, p.r[i]);
    sums.add(0, p.m[i]);
    sums.add(1, 2 * p.r[i]);
  }
  o.count = static_cast<std::int64_t>(p.size());
  o.dt_critical = critical_dt(p, s.materials);
  const MPI_Comm over = s.shared ? comm : MPI_COMM_SELF;  // replicated: every rank has them all
  if (s.shared) {
    MPI_Allreduce(MPI_IN_PLACE, &o.count, 1, MPI_INT64_T, MPI_SUM, comm);
    MPI_Allreduce(MPI_IN_PLACE, &lo, 1, MPI_DOUBLE, MPI_MIN, comm);
    MPI_Allreduce(MPI_IN_PLACE, &hi, 1, MPI_DOUBLE, MPI_MAX, comm);
    MPI_Allreduce(MPI_IN_PLACE, &o.dt_critical, 1, MPI_DOUBLE, MPI_MIN, comm);
  }
  const std::vector<double> g = sums.sums(over);
  o.rmin = o.count > 0 ? lo : 0.0;
  o.rmax = hi;
  o.mass = g[0];
  o.diameter_sum = g[1];
  return o;
}

void print_check_summary(const CaseConfig& c, const Setup& s, MPI_Comm comm) {
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  const ParticleSummary ps = summarize_particles(s, comm);  // collective
  if (rank != 0) return;
  const double rmin = ps.rmin, rmax = ps.rmax, mass = ps.mass;
  const double dt = s.params.dt > 0 ? s.params.dt : s.params.dt_safety * ps.dt_critical;
  const std::int64_t steps = c.steps > 0 ? c.steps : static_cast<std::int64_t>(std::ceil(c.duration / dt));
  std::printf("%s: ok\n", c.file.c_str());
  std::printf("  case        %s\n", c.name.c_str());
  std::printf("  domain      [%g, %g, %g] .. [%g, %g, %g] m\n", c.domain_min.x, c.domain_min.y,
              c.domain_min.z, c.domain_max.x, c.domain_max.y, c.domain_max.z);
  std::printf("  particles   %lld (r %g .. %g m, total mass %g kg)%s\n", static_cast<long long>(ps.count), rmin, rmax,
              mass, s.restarted ? " from checkpoint" : "");
  std::printf("  materials   %d, walls %zu\n", s.materials.size(), s.walls.size());
  std::printf("  time step   %g s (%s), %lld steps, %g s simulated\n", dt,
              s.params.dt > 0 ? "fixed" : "auto", static_cast<long long>(steps), steps * dt);
  if (c.holds.present) {
    std::printf("  holds       %zu on", c.holds.count);
    for (const HoldsConfig::Wall& w : c.holds.walls) {
      std::printf(" %s (", c.walls[static_cast<std::size_t>(w.wall)].name.c_str());
      const std::vector<double>& t = w.moved() ? w.displacement : w.stress;
      for (std::size_t k = 0; k < t.size(); ++k) std::printf("%s%g", k ? ", " : "", t[k]);
      std::printf(w.moved() ? " m)" : " Pa)");
    }
    std::printf("; tolerance %g, checked every %lld steps, at most %lld per hold\n", c.holds.tolerance,
                static_cast<long long>(c.holds.check_every), static_cast<long long>(c.holds.max_steps));
  }
  std::printf("  output      %s\n", c.out_dir.c_str());
  if (!(c.fem.present && c.has_particles())) print_pair_table(c);  // (a coupled case: after its interface)
}

void print_pair_table(const CaseConfig& c) {
  std::printf("  contact pairs (* set in interactions; otherwise friction the smaller of the two, the rest the mean; beta_r, eta_r of total pairs the larger):\n");
  for (const std::string& l : pair_table_lines(c)) std::printf("    %s\n", l.c_str());
}

DemRunOutput::DemRunOutput(const CaseConfig& c, DemEngine& e, bool append, std::int64_t n_initial, MPI_Comm comm)
    : c_(c), e_(e), comm_(comm), dir_(c.out_dir), wall0_(MPI_Wtime()),
      n_initial_(n_initial) {
  namespace fs = std::filesystem;
  MPI_Comm_rank(comm, &rank_);
  MPI_Comm_size(comm, &size_);
  // Output directory: created only now, after every input check passed.
  if (rank_ == 0) {
    fs::create_directories(dir_);
    write_case_yaml(c, dir_);
  }
  MPI_Barrier(comm);
  snaps_ = std::make_unique<SnapshotWriter>(dir_, comm);
  if (append) snaps_->adopt_existing(e.step_count());
  const double keep = static_cast<double>(e.step_count());
  std::vector<std::string> hcols{"step", "time", "particles", "kinetic_energy", "unbalanced", "contacts"};
  history_ = std::make_unique<CsvWriter>(dir_ + "/history.csv", hcols, comm, append, keep);
  std::vector<std::string> wcols{"step", "time"};
  for (const Wall& w : e.walls().walls) {
    for (const char* k : {"_fx", "_fy", "_fz", "_ux", "_uy", "_uz"}) wcols.push_back(w.name + k);
    if (servo_wall(w)) wcols.push_back(w.name + "_stress");
    for (std::size_t b = 0; b < w.band_force.size(); ++b)
      for (const char* k : {"_fx", "_fy", "_fz"}) wcols.push_back(w.name + "_b" + std::to_string(b + 1) + k);
  }
  walls_csv_ = std::make_unique<CsvWriter>(dir_ + "/walls.csv", wcols, comm, append, keep);
  if (c.lab.kind != LabConfig::kNone)
    lab_ = std::make_unique<LabOutput>(c.lab, e.walls().walls, dir_, comm, append, keep);
  removed_csv_ = std::make_unique<CsvWriter>(dir_ + "/removed.csv", std::vector<std::string>{"step", "time", "id"},
                                             comm, append, keep);
  info_.version = FDEM_VERSION;
  info_.case_name = c.name;
  info_.case_file = c.file;
  info_.overrides = c.overrides;
  info_.specimen = c.specimen_from;
  info_.ranks = size_;
  info_.dt = e.dt();
  info_.start_step = e.step_count();
  info_.particles_initial = n_initial;
  info_.pairs = pair_records(c);
}

DemRunOutput::~DemRunOutput() = default;

void DemRunOutput::fail_info(const std::string& message) noexcept {
  if (rank_ != 0) return;
  try {
    info_.status = "failed";
    info_.message = message;
    info_.wall_time = MPI_Wtime() - wall0_;
    write_run_json(dir_ + "/run.json", info_);
  } catch (...) {
  }
}

double peak_rss_mb() {
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  return static_cast<double>(ru.ru_maxrss) / 1024.0;  // Linux: kB
}

namespace {
// Collective: each rank's particles, ghosts and traffic, gathered on rank 0 (run.json's
// "decomposition").
void gather_ranks(const DemEngine& e, RunInfo& info) {
  const Decomposition& dd = e.decomposition();
  const CommStats cs = e.comm_stats();
  const std::int64_t mine[4] = {static_cast<std::int64_t>(e.particles().n_owned),
                                static_cast<std::int64_t>(e.particles().n_ghost()),
                                static_cast<std::int64_t>(cs.bytes), static_cast<std::int64_t>(cs.messages)};
  std::vector<std::int64_t> all(4 * static_cast<std::size_t>(dd.size));
  MPI_Gather(mine, 4, MPI_INT64_T, all.data(), 4, MPI_INT64_T, 0, dd.comm);
  const double rss = peak_rss_mb();
  std::vector<double> rss_all(static_cast<std::size_t>(dd.size));
  MPI_Gather(&rss, 1, MPI_DOUBLE, rss_all.data(), 1, MPI_DOUBLE, 0, dd.comm);
  info.grid = dd.dims;
  info.ranks_detail.assign(static_cast<std::size_t>(dd.size), RankRecord{});
  for (std::size_t r = 0; r < info.ranks_detail.size(); ++r) {
    RankRecord& q = info.ranks_detail[r];
    q.owned = all[4 * r];
    q.ghosts = all[4 * r + 1];
    q.bytes = static_cast<std::uint64_t>(all[4 * r + 2]);
    q.messages = static_cast<std::uint64_t>(all[4 * r + 3]);
    q.peak_rss_mb = rss_all[r];
  }
}
}  // namespace

void DemRunOutput::fill_info(const char* status, const std::string& message) {
  DemEngine& e = e_;
  RunInfo& info = info_;
  info.status = status;
  info.message = message;
  info.steps = e.step_count();
  info.simulated_time = e.time();
  info.wall_time = MPI_Wtime() - wall0_;
  info.particles_final = e.stats().particles;
  info.particles_removed = e.removed_total();
  const double pst = static_cast<double>(info.steps - info.start_step) *
                     0.5 * static_cast<double>(info.particles_initial + info.particles_final);
  info.particle_steps_per_second = info.wall_time > 0 ? pst / info.wall_time : 0;
  info.rebuilds = e.rebuilds();
  long long bytes = static_cast<long long>(e.comm_stats().bytes), maxb = 0;
  MPI_Allreduce(&bytes, &maxb, 1, MPI_LONG_LONG, MPI_MAX, comm_);
  info.comm_bytes = maxb;
  gather_ranks(e, info);
  info.timings.clear();
  std::vector<double> loc(e.timings().begin(), e.timings().end()), mx(loc.size());
  MPI_Allreduce(loc.data(), mx.data(), static_cast<int>(loc.size()), MPI_DOUBLE, MPI_MAX, comm_);
  for (std::size_t k = 0; k < mx.size(); ++k) info.timings.push_back({stage_name(static_cast<Stage>(k)), mx[k]});
  if (extra) extra(info);
  if (rank_ == 0) write_run_json(dir_ + "/run.json", info);
}

void DemRunOutput::checkpoint(std::int64_t hold, std::int64_t hold_start, const std::vector<Vec3>& wall_start,
                              const std::vector<Vec3>& wall_check) {
  Checkpoint ck = engine_checkpoint_view(e_);
  ck.hold = hold;
  ck.hold_start = hold_start;
  ck.wall_start = wall_start;
  ck.wall_check = wall_check;
  write_checkpoint(dir_ + "/checkpoint.h5", comm_, ck);
}

void DemRunOutput::snapshot() { snaps_->write(e_.step_count(), e_.time(), e_.particles()); }

EngineStats DemRunOutput::write_history() {
  DemEngine& e = e_;
  EngineStats st = e.stats();
  history_->row({static_cast<double>(e.step_count()), e.time(), static_cast<double>(st.particles),
                 st.kinetic_energy, st.unbalanced, static_cast<double>(st.contacts)});
  e.reduce_wall_forces();
  std::vector<double> row{static_cast<double>(e.step_count()), e.time()};
  for (const Wall& w : e.walls().walls) {
    row.insert(row.end(), {w.force.x, w.force.y, w.force.z, w.disp.x, w.disp.y, w.disp.z});
    if (servo_wall(w)) row.push_back(servo_stress(w));
    for (const Vec3& f : w.band_force) row.insert(row.end(), {f.x, f.y, f.z});
  }
  walls_csv_->row(row);
  if (lab_) lab_->row(static_cast<double>(e.step_count()), e.time(), e.walls().walls);
  const std::vector<std::int64_t> gone = e.take_removed();
  for (std::int64_t id : gone) removed_csv_->row({static_cast<double>(e.step_count()), e.time(), static_cast<double>(id)});
  if (!gone.empty() && rank_ == 0) {
    std::ostringstream ids;
    for (std::size_t k = 0; k < gone.size() && k < 20; ++k) ids << (k ? ", " : "") << gone[k];
    if (gone.size() > 20) ids << ", ...";
    std::printf("fdem: step %lld: %zu particle(s) left the domain and were removed (ids %s; all in removed.csv)\n",
                static_cast<long long>(e.step_count()), gone.size(), ids.str().c_str());
    std::fflush(stdout);
  }
  return st;
}

void DemRunOutput::print_start(std::int64_t end_step, const std::string& extra_text) const {
  if (rank_ != 0) return;
  const DemEngine& e = e_;
  std::printf("fdem %s: case '%s' on %d rank(s), grid %dx%dx%d, %lld particles, dt %.3e s, steps %lld..%lld%s\n",
              FDEM_VERSION, c_.name.c_str(), size_, e.decomposition().dims[0], e.decomposition().dims[1],
              e.decomposition().dims[2], static_cast<long long>(n_initial_), e.dt(),
              static_cast<long long>(e.step_count()), static_cast<long long>(end_step), extra_text.c_str());
  std::fflush(stdout);
}

void DemRunOutput::print_summary() const {
  if (rank_ != 0) return;
  const RunInfo& info = info_;
  const CommStats cs = e_.comm_stats();
  std::printf("fdem: finished %lld steps in %.2f s (%.3e particle-steps/s); results in %s\n",
              static_cast<long long>(info.steps - info.start_step), info.wall_time,
              info.particle_steps_per_second, dir_.c_str());
  std::printf("fdem: time per stage (s, slowest rank):");
  for (const auto& t : info.timings) std::printf(" %s %.2f", t.first.c_str(), t.second);
  std::printf("\nfdem: rank 0 sent %.2f MB in %llu messages\n", cs.bytes / 1e6,
              static_cast<unsigned long long>(cs.messages));
}


// ---- the observers of a run with particles (the particle run and the coupled run) ----

void HistoryObserver::write(const RunState& st) {
  if (written_at_ == st.step) return;
  record_(st);
  written_at_ = st.step;
}

void MeasureObserver::on_start(const RunState&) {
  if (m_) m_->at_start();
}
void MeasureObserver::on_step(const RunState& st) {
  if (m_) m_->at_step(st.last || st.stop || st.hold_done);
}

void SnapshotObserver::write(const RunState& st) {
  if (written_at_ == st.step) return;
  write_();
  written_at_ = st.step;
}
void SnapshotObserver::on_step(const RunState& st) {
  if ((every_ > 0 && st.step % every_ == 0) || st.last || st.stop) write(st);
}

void CheckpointObserver::on_step(const RunState& st) {
  const std::int64_t k = st.step, n = sync_period_;
  if (every_ > 0 && k % every_ == 0 && !st.last) due_ = true;
  // (and at the start of a last sub-cycle that time.steps cuts short: see last_checkpoint)
  const bool last_cycle = st.end_step % n != 0 && st.end_step - k < n;
  if ((due_ || last_cycle) && k % n == 0 && !st.last) {
    write_(st, false);
    out_.fill_info("running");
    due_ = false;
    if (last_cycle) boundary_ = k;
  }
}

void CheckpointObserver::last_checkpoint(const RunState& st, bool hold_done) {
  const std::int64_t k = st.step, n = sync_period_;
  if (k % n != 0 && boundary_ == k - k % n) {
    if (!quiet_ && out_.rank() == 0)
      std::printf("fdem: step %lld ends inside a sub-cycle of %lld steps: the checkpoint is the one of step %lld "
                  "(the sub-cycle's start)\n", static_cast<long long>(k), static_cast<long long>(n),
                  static_cast<long long>(boundary_));
    return;
  }
  write_(st, hold_done);
}

void RunJsonObserver::on_error(const RunState&, bool diverged, const std::string& what) noexcept {
  if (diverged) {
    // collective: every rank's run-health check throws RunDiverged at the same step
    try {
      out_.fill_info("diverged", what);
    } catch (...) {
    }
  } else {
    out_.fail_info(what);
  }
}

namespace {

/// The particle run's schedule: no holds; `time.stop_unbalanced` ends the run on a history row,
/// when the kinetic energy per grain is also below time.stop_kinetic_ratio x m g d (`grain_mgd`,
/// J; 0 without gravity: not checked): a cloud in free fall has few contacts, each balanced.
class StopUnbalanced : public Schedule {
 public:
  StopUnbalanced(const CaseConfig& c, const EngineStats& last, double grain_mgd, bool quiet, int rank)
      : c_(c), last_(last), grain_mgd_(grain_mgd), quiet_(quiet), rank_(rank) {}
  void check(RunState& st) override {
    if (!st.history_row || !(c_.stop_unbalanced > 0)) return;
    if (!(last_.unbalanced < c_.stop_unbalanced && last_.contacts > 0)) return;
    const double ke = last_.particles > 0 ? last_.kinetic_energy / static_cast<double>(last_.particles) : 0.0;
    const bool guard = c_.stop_kinetic_ratio > 0 && grain_mgd_ > 0;
    if (guard && !(ke < c_.stop_kinetic_ratio * grain_mgd_)) return;  // still moving
    if (rank_ == 0 && !quiet_) {
      std::printf("fdem: unbalanced-force ratio %.3e below %.3e", last_.unbalanced, c_.stop_unbalanced);
      if (guard) std::printf(", kinetic energy %.3e m g d below %.3e", ke / grain_mgd_, c_.stop_kinetic_ratio);
      std::printf(" at step %lld: stopping\n", static_cast<long long>(st.step));
    }
    st.stop = true;
  }

 private:
  const CaseConfig& c_;
  const EngineStats& last_;
  double grain_mgd_;
  bool quiet_;
  int rank_;
};

/// Motion phases that start `after:` a condition (walls.motion.after): at each history row the
/// first waiting phase of each wall starts at this step when every condition it gives holds,
/// counted from the previous phase's start. The measures are global (history.csv's exact sums,
/// the reduced wall forces): every rank decides alike, on any number of ranks.
class PhaseStarts : public Observer {
 public:
  PhaseStarts(DemEngine& e, const EngineStats& last, double grain_mgd, bool quiet, int rank)
      : e_(e), last_(last), grain_mgd_(grain_mgd), quiet_(quiet), rank_(rank) {}
  void on_record(const RunState& st) override {
    // the conditions first, then the phases that start with a named one (`stage`), until none
    // changes: a chain of stages all starts at this step
    std::vector<Wall>& walls = e_.walls().walls;
    for (bool linked : {false, true})
      for (bool changed = true; changed;) {
        changed = false;
        for (Wall& w : walls)
          for (std::size_t k = 0; k < w.schedule.size(); ++k) {
            WallPhase& ph = w.schedule[k];
            if (ph.from_step != kPhasePending) continue;
            const std::int64_t prev = k > 0 ? w.schedule[k - 1].from_step : 0;
            const bool staged = ph.after.stage_wall >= 0;
            std::string why;
            if (prev <= st.step && staged == linked && (staged ? with_stage(ph.after, st.step, why) :
                                                                   met(ph.after, st.step - prev, why))) {
              ph.from_step = st.step;  // (the next step applies it)
              changed = linked;
              if (rank_ == 0 && !quiet_)
                std::printf("fdem: wall '%s': motion phase %zu starts at step %lld (%s)\n", w.name.c_str(), k + 1,
                            static_cast<long long>(st.step), why.c_str());
            }
            break;  // (one waiting phase per wall at a time)
          }
      }
  }

 private:
  /// `stage`: the named phase has started (at this row, when it starts on a condition: the same step).
  bool with_stage(const PhaseCondition& a, std::int64_t step, std::string& why) const {
    const Wall& w = e_.walls_const().walls[static_cast<std::size_t>(a.stage_wall)];
    const std::int64_t from = w.schedule[static_cast<std::size_t>(a.stage_phase)].from_step;
    if (from == kPhasePending || from > step) return false;
    why = "with phase " + std::to_string(a.stage_phase + 1) + " of wall '" + w.name + "'";
    return true;
  }
  bool met(const PhaseCondition& a, std::int64_t since, std::string& why) const {
    char b[160];
    if (a.unbalanced > 0) {
      if (!(last_.contacts > 0 && last_.unbalanced < a.unbalanced)) return false;
      std::snprintf(b, sizeof b, "unbalanced %.3e < %.3e", last_.unbalanced, a.unbalanced);
      why += b;
      if (a.kinetic > 0 && grain_mgd_ > 0) {
        const double ke = last_.particles > 0 ? last_.kinetic_energy / static_cast<double>(last_.particles) : 0.0;
        if (!(ke < a.kinetic * grain_mgd_)) return false;
        std::snprintf(b, sizeof b, ", kinetic %.3e m g d < %.3e", ke / grain_mgd_, a.kinetic);
        why += b;
      }
    }
    if (a.servo > 0) {
      double worst = 0;
      for (const Wall& w : e_.walls_const().walls)
        if (w.motion == Wall::kServo && w.servo.stress > 0)
          worst = std::max(worst, std::fabs(w.stress - w.servo.stress) / w.servo.stress);
      if (!(worst < a.servo)) return false;
      std::snprintf(b, sizeof b, "%sservo misfit %.3e < %.3e", why.empty() ? "" : ", ", worst, a.servo);
      why += b;
    }
    if (a.time > 0) {
      if (!(static_cast<double>(since) * e_.dt() >= a.time)) return false;
      std::snprintf(b, sizeof b, "%s%.4g s after the previous phase", why.empty() ? "" : ", ", static_cast<double>(since) * e_.dt());
      why += b;
    }
    if (a.steps > 0) {
      if (since < a.steps) return false;
      std::snprintf(b, sizeof b, "%s%lld steps after the previous phase", why.empty() ? "" : ", ", static_cast<long long>(since));
      why += b;
    }
    return true;
  }
  DemEngine& e_;
  const EngineStats& last_;
  double grain_mgd_;
  bool quiet_;
  int rank_;
};

/// The particle run's progress line and closing lines.
class DemReport : public Observer {
 public:
  DemReport(DemEngine& e, DemRunOutput& out, bool quiet, int rank) : e_(e), out_(out), quiet_(quiet), rank_(rank) {}
  void on_progress(const RunState& st) override {
    const EngineStats s = e_.stats();
    if (rank_ != 0) return;
    const std::int64_t k = st.step;
    const double el = MPI_Wtime() - st.loop_wall0;
    const double rate = el > 0 ? static_cast<double>(k - st.loop_step0) * s.particles / el : 0;
    const double eta = k > st.loop_step0 ? el / (k - st.loop_step0) * (st.end_step - k) : -1;
    std::printf("step %lld/%lld  t %.4e s  particles %lld  unbalanced %.3e  %.3e particle-steps/s  left %s\n",
                static_cast<long long>(k), static_cast<long long>(st.end_step), e_.time(),
                static_cast<long long>(s.particles), s.unbalanced, rate, hms(eta).c_str());
    std::fflush(stdout);
  }
  void on_finish(const RunState&) override {
    if (!quiet_) out_.print_summary();
  }

 private:
  DemEngine& e_;
  DemRunOutput& out_;
  bool quiet_;
  int rank_;
};

}  // namespace

std::string case_yaml_text(const CaseConfig& c) {
  std::ostringstream f;
  f << "# The case as run by fdem " << FDEM_VERSION << ": " << c.file;
  if (!c.overrides.empty()) {
    f << ", with";
    for (const std::string& o : c.overrides) f << " --set " << o;
  }
  if (!c.specimen_from.empty()) f << ", from the specimen " << c.specimen_from;
  f << "\n# The keys the case left out carry their defaults (docs/case-format.md); relative paths are\n"
    << "# relative to the case file's folder, " << std::filesystem::absolute(c.file).parent_path().string() << "\n"
    << c.resolved_yaml << "\n";
  return f.str();
}

void write_case_yaml(const CaseConfig& c, const std::string& dir) {
  std::ofstream f(dir + "/case.yaml");
  f << case_yaml_text(c);
}

std::int64_t run_end_step(const CaseConfig& c, double dt) {
  return c.steps > 0 ? c.steps : static_cast<std::int64_t>(std::ceil(c.duration / dt - 1e-9));
}

namespace {
/// Where a run with load holds on walls starts: hold 0 at its first step, or the checkpoint's hold.
std::pair<std::size_t, std::int64_t> first_hold(const CaseConfig& c, const Setup& s, const RunOptions& opt) {
  if (!c.holds.present || !s.restarted || s.hold < 0) return {0, s.step};
  const std::string ck = !opt.restart.empty() ? opt.restart : c.restart_from;
  if (static_cast<std::size_t>(s.hold) >= c.holds.count)
    throw InputError(ck, 0, "the run of this checkpoint has finished its " + std::to_string(c.holds.count) +
                                " holds: nothing to continue (give more holds.walls stresses to go on loading)");
  return {static_cast<std::size_t>(s.hold), s.hold_start};
}
}  // namespace

int run_case(const CaseConfig& c, Setup s, const RunOptions& opt, MPI_Comm comm) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  const ParticleSummary ps = summarize_particles(s, comm);
  const std::int64_t n_initial = ps.count;
  const double np = std::max<double>(1.0, static_cast<double>(ps.count));
  const double grain_mgd = (ps.mass / np) * norm(s.params.gravity) * (ps.diameter_sum / np);  // stop_kinetic_ratio's unit
  const auto [hold0, hold_start] = first_hold(c, s, opt);
  DemEngine e(comm, s.params, s.materials, s.walls, std::move(s.particles), s.history, s.step, s.time, particle_input(s));
  s.particles = ParticleStore{};  // the engine keeps what this rank owns
  s.history = {};
  const std::int64_t end_step = run_end_step(c, e.dt());

  const bool append = s.restarted;
  DemRunOutput out(c, e, append, n_initial, comm);
  if (!opt.quiet) out.print_start(end_step);
  out.fill_info("running");

  RunControl::Params rp;
  rp.end_step = end_step;
  rp.history_every = c.history_every;
  rp.quiet = opt.quiet;
  rp.progress_interval = c.progress_interval;
  rp.signal_note = "checkpoint " + out.dir() + "/checkpoint.h5";
  if (c.holds.present) {
    rp.holds = c.holds.count;
    rp.first_hold = hold0;
    rp.hold_start = hold_start;
  }
  RunControl run(comm, rp, [&] { e.step(); }, [&] { return e.step_count(); });
  std::unique_ptr<WallHolds> holds;
  if (c.holds.present) {
    holds = std::make_unique<WallHolds>(c, e, out.dir(), append, s.wall_start, s.wall_check, opt.quiet, comm);
    holds->apply(hold0);
  }

  EngineStats last_stats;
  HistoryObserver history([&](const RunState&) { last_stats = out.write_history(); }, false);
  // micro-mechanics measurements (case key `measure`)
  std::unique_ptr<MeasureRun> measure_run;
  if (c.measure.present) measure_run = std::make_unique<MeasureRun>(c.measure, e, out.dir(), append, comm);
  MeasureObserver measure(measure_run.get());
  SnapshotObserver snapshots(c.snapshot_every, [&] { out.snapshot(); });
  // checkpoints only after a passed run-health check: the last good one is kept
  CheckpointObserver checkpoints(out, c.checkpoint_every, 1, opt.quiet, [&](const RunState& st, bool) {
    e.check_health();
    if (!holds) out.checkpoint();
    else
      out.checkpoint(static_cast<std::int64_t>(st.holds_finished ? st.holds : st.hold), st.hold_start, holds->start(),
                     holds->check_disp());
  });
  RunJsonObserver run_json(out);
  DemReport report(e, out, opt.quiet, rank);
  StopUnbalanced stop(c, last_stats, grain_mgd, opt.quiet, rank);
  PhaseStarts phase_starts(e, last_stats, grain_mgd, opt.quiet, rank);
  run.add(history);
  run.add(phase_starts);  // (after the history row: its measures)
  if (holds) {
    run.add(static_cast<Observer&>(*holds));  // (holds.csv at each hold's end)
    run.add(static_cast<Controller&>(*holds));  // (walls held by displacement)
  }
  for (Observer* o : std::initializer_list<Observer*>{&measure, &snapshots, &checkpoints, &run_json, &report})
    run.add(*o);
  if (holds) run.set_schedule(*holds);
  else run.set_schedule(stop);
  return run.run(!append);
}

}  // namespace fdem
