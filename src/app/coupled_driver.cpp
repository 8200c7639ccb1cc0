#include "app/coupled_driver.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "app/fe_driver.hpp"
#include "app/measurements.hpp"
#include "coupling/coupler.hpp"
#include "coupling/interface.hpp"
#include "io/checkpoint.hpp"
#include "io/csv.hpp"
#include "base/errors.hpp"
#include "io/fe_checkpoint.hpp"
#include "io/fe_output.hpp"
#include "base/exact_sum.hpp"

namespace fdem {

namespace fs = std::filesystem;

namespace {

template <class Map>
std::string key_names(const Map& m) {
  std::string s;
  for (const auto& kv : m) s += (s.empty() ? "" : ", ") + kv.first;
  return s.empty() ? "none" : s;
}

/// The message of an InputError thrown without a case-file position ("interface: error: ...").
std::string bare_message(const std::exception& e) {
  const std::string w = e.what();
  const auto pos = w.find(": error: ");
  return pos == std::string::npos ? w : w.substr(pos + 9);
}

}  // namespace

std::vector<coupling::InterfaceTriangle> build_coupling_interface(const CaseConfig& c, const FeMeshes& m) {
  std::vector<coupling::InterfaceTriangle> all;
  // A face belongs to the first surface that names it (so a face set and "the rest of the
  // surface" can be given as two surfaces without counting a face twice).
  std::set<std::array<std::int32_t, 2>> taken;
  for (std::size_t i = 0; i < c.coupling.surfaces.size(); ++i) {
    const CouplingSurfaceConfig& sc = c.coupling.surfaces[i];
    const FeMeshes::Part& part = m.parts[sc.mesh];
    const std::string where = "coupling.surfaces[" + std::to_string(i) + "]";
    if (part.mesh.dim != 3)
      throw InputError(c.file, sc.line, where + ": mesh '" + part.name + "' is 2-D; the interface needs a 3-D mesh");
    std::vector<coupling::InterfaceTriangle> tris;
    try {
      if (!sc.face_set.empty()) {
        if (!part.mesh.face_sets.count(sc.face_set))
          throw InputError(c.file, sc.line, where + ": mesh '" + part.name + "' has no face set '" + sc.face_set +
                                                "' (valid: " + key_names(part.mesh.face_sets) + ")");
        tris = coupling::make_interface(part.mesh, sc.face_set);
      } else if (!sc.element_set.empty()) {
        auto it = part.mesh.element_sets.find(sc.element_set);
        if (it == part.mesh.element_sets.end())
          throw InputError(c.file, sc.line, where + ": mesh '" + part.name + "' has no element set '" +
                                                sc.element_set + "' (valid: " + key_names(part.mesh.element_sets) + ")");
        if (it->second.empty())
          throw InputError(c.file, sc.line, where + ": element set '" + sc.element_set + "' is empty");
        tris = coupling::make_interface(part.mesh, "", it->second);
      } else {
        tris = coupling::make_interface(part.mesh, "");
      }
    } catch (const InputError& e) {
      if (e.file() == c.file) throw;
      throw InputError(c.file, sc.line, where + ": mesh '" + part.name + "': " + bare_message(e));
    }
    if (tris.empty())
      throw InputError(c.file, sc.line, where + ": gives no interface triangles (no surface faces in mesh '" +
                                            part.name + "')");
    std::set<std::array<std::int32_t, 2>> mine;
    std::size_t kept = 0;
    for (auto& t : tris) {
      for (auto& corner : t.nodes)
        for (auto& n : corner)
          if (n >= 0) n += part.node_offset;
      if (t.element >= 0) t.element += part.elem_offset;
      t.group = static_cast<std::int32_t>(i);
      const std::array<std::int32_t, 2> key{t.element, t.face};
      if (taken.count(key)) continue;
      mine.insert(key);
      all.push_back(t);
      ++kept;
    }
    if (kept == 0)
      throw InputError(c.file, sc.line, where + ": all its faces belong to earlier surfaces");
    taken.insert(mine.begin(), mine.end());
  }
  return all;
}

PackingStructure packing_structure(const CaseConfig& c) {
  const FeMeshes m = build_fe_meshes(c);
  const std::vector<coupling::InterfaceTriangle> tris = build_coupling_interface(c, m);
  PackingStructure ps;
  Wall& w = ps.facets;
  w.kind = Wall::kFacets;
  w.name = "structure";
  w.mat = c.coupling.material;
  // Shared corners (a node, or a quad's centre) become shared vertices: the facet selection
  // then treats the surface as one smooth mesh, as the coupler does.
  std::map<std::array<std::int32_t, 4>, int> index;
  for (const coupling::InterfaceTriangle& t : tris) {
    Vec3 x[3];
    coupling::corner_positions(m.merged, {}, t, x);
    std::array<int, 3> tri{};
    for (int k = 0; k < 3; ++k) {
      std::array<std::int32_t, 4> key = t.nodes[k];
      std::sort(key.begin(), key.end());
      auto it = index.find(key);
      if (it == index.end()) {
        it = index.emplace(key, static_cast<int>(w.verts.size())).first;
        w.verts.push_back(x[k]);
      }
      tri[k] = it->second;
    }
    w.tris.push_back(tri);
  }
  for (std::size_t e = 0; e < m.merged.n_elements(); ++e) {
    const fem::ElemType ty = m.merged.elem_type[e];
    if (ty == fem::ElemType::kShell4 || ty == fem::ElemType::kQuad4) continue;  // no volume to be inside
    const std::int32_t* nd;
    const int nn = m.merged.nodes_of(e, nd);
    Vec3 lo{1e300, 1e300, 1e300}, hi{-1e300, -1e300, -1e300};
    for (int k = 0; k < nn; ++k)
      for (int d = 0; d < 3; ++d) {
        const double v = m.merged.coords[3 * static_cast<std::size_t>(nd[k]) + d];
        lo[d] = std::min(lo[d], v);
        hi[d] = std::max(hi[d], v);
      }
    ps.solid_boxes.push_back({lo, hi});
  }
  return ps;
}

namespace {

/// The time steps of a coupled run (DESIGN.md 4.4).
struct CoupledSteps {
  double dt_dem = 0;        // DEM step used
  double dt_dem_wanted = 0; // time.dt or time.safety x DEM critical step
  double dt_fe_critical = 0;  // FE Gershgorin step, interface contact stiffness included
  double dt_fe_alone = 0;   // FE Gershgorin step of the structure alone
  double k_interface = 0;   // largest interface contact stiffness (N/m)
  double k_per_area = 0;    // largest contact stiffness per unit area of a dense grain layer (N/m^3)
  double k_node = 0;        // largest stiffness bound of an interface node (N/m)
  double dt_fe_stable = 0;  // fem.safety x dt_fe_critical
  int subcycle = 1;
  bool clamped = false;     // dt_dem_wanted > dt_fe_stable: dt_dem = dt_fe_stable
};

CoupledSteps choose_steps(const CaseConfig& c, const Setup& s, const fem::Mesh& mesh, fem::FeModel& model,
                          const std::vector<coupling::InterfaceTriangle>& tris) {
  CoupledSteps ts;
  // The FE step must also resolve the particles' contact springs on an interface node (heavy
  // particles on a light node): Gershgorin with a contact stiffness added to every interface
  // node's row. A contact of stiffness k at shape-function values N loads node a's row with
  // k N_a (sum_b N_b = 1), so a node carries up to the sum over the contacts on its triangles of
  // k N_a: at least one whole contact of the stiffest grain (k_n of the contact law against the
  // interface material), and at most a dense layer of grains over the node's share of the
  // surface A_a (the integral of N_a): a hexagonal layer of radius r has one grain per 2 sqrt(3)
  // r^2, i.e. a stiffness k / (2 sqrt(3) r^2) per unit area -- and no more than all the grains
  // there are (sum k_i). Node a: max(k_max, min(s_max A_a, sum k_i)). On a
  // mesh finer than the grains the first term rules (one contact per node); on a coarse one --
  // a footing, a lining, a plate of large elements under fine sand -- the second does, and the
  // single-contact bound would let the FE sub-cycle past its stable step.
  ts.dt_fe_alone = model.critical_dt();
  const int im = c.coupling.material;
  double k_all = 0;  // every particle is on every rank (Setup): the same sum everywhere
  for (std::size_t i = 0; i < s.particles.size(); ++i) {
    const double r = s.particles.r[i];
    const double k = normal_stiffness(s.materials[s.particles.mat[i]].young, r, s.materials[im].young, r);
    ts.k_interface = std::max(ts.k_interface, k);
    ts.k_per_area = std::max(ts.k_per_area, k / (2 * std::sqrt(3.0) * r * r));
    k_all += k;
  }
  const std::vector<std::int32_t> nodes = coupling::interface_nodes(tris);
  const std::vector<double> area = coupling::interface_node_areas(mesh, tris);
  std::vector<double> kn(nodes.size(), 0.0);
  for (std::size_t j = 0; j < nodes.size(); ++j) {
    kn[j] = std::max(ts.k_interface, std::min(ts.k_per_area * area[j], k_all));
    ts.k_node = std::max(ts.k_node, kn[j]);
  }
  ts.dt_fe_critical = ts.k_interface > 0 ? model.critical_dt(nodes, kn) : model.critical_dt();
  ts.dt_fe_stable = c.fem.safety * ts.dt_fe_critical;
  ts.dt_dem_wanted = s.params.dt > 0 ? s.params.dt : s.params.dt_safety * critical_dt(s.particles, s.materials);
  ts.dt_dem = ts.dt_dem_wanted;
  if (ts.dt_dem > ts.dt_fe_stable) {
    ts.dt_dem = ts.dt_fe_stable;
    ts.clamped = true;
  }
  if (c.coupling.subcycle > 0) {
    ts.subcycle = c.coupling.subcycle;
    if (ts.subcycle * ts.dt_dem > ts.dt_fe_stable * (1 + 1e-9)) {
      const int nmax = coupling::Coupler::auto_subcycle(ts.dt_fe_stable, ts.dt_dem);
      char buf[400];
      std::snprintf(buf, sizeof buf,
                    "coupling.subcycle: %d DEM steps of %.4g s make an FE step of %.4g s, above the FE stable step "
                    "%.4g s (fem.safety x %.4g s, the structure with the interface contact stiffness); use subcycle <= %d, "
                    "0 (automatic) or a smaller time.dt",
                    ts.subcycle, ts.dt_dem, ts.subcycle * ts.dt_dem, ts.dt_fe_stable, ts.dt_fe_critical, nmax);
      throw InputError(c.file, c.coupling.line, buf);
    }
  } else {
    ts.subcycle = coupling::Coupler::auto_subcycle(ts.dt_fe_stable, ts.dt_dem);
  }
  return ts;
}

/// The DEM unbalanced-force ratio of the convergence check: EngineStats::unbalanced (mean net
/// force / mean particle-particle contact force); when it is undefined (no particle-particle
/// contact, e.g. a few particles resting on a structure), mean |net force| / mean |m g| over
/// the free particles. Collective.
double dem_unbalanced(DemEngine& e, const EngineStats& st, const Vec3& gravity, MPI_Comm comm) {
  if (std::isfinite(st.unbalanced)) return st.unbalanced;
  const ParticleStore& p = e.particles();
  exact::ExactSums sums(2);  // rank-independent
  for (std::size_t i = 0; i < p.n_owned; ++i) {
    if (p.blocked[i] == kDofAll) continue;
    sums.add(0, norm(p.f[i] + p.m[i] * gravity));  // p.f: contact forces (as in DemEngine::stats)
    sums.add(1, p.m[i] * norm(gravity));
  }
  const std::vector<double> g = sums.sums(comm);
  return g[1] > 0 ? g[0] / g[1] : std::numeric_limits<double>::quiet_NaN();
}

}  // namespace

namespace {
/// The file holding the FE state for a coupled restart from `restart`: the checkpoint itself
/// (its group /fe: one file with the DEM state, written by one rename), or for a checkpoint
/// without it (fdem before format version 2 wrote two files) fe_checkpoint.h5 next to it.
std::string coupled_fe_state_file(const std::string& restart) {
  if (has_fe_state(restart)) return restart;
  return (fs::path(restart).parent_path() / "fe_checkpoint.h5").string();
}
}  // namespace

void check_coupled_options(const CaseConfig& c, const RunOptions& opt) {
  const std::string restart = !opt.restart.empty() ? opt.restart : c.restart_from;
  if (restart.empty()) return;
  const std::string fe = coupled_fe_state_file(restart);
  if (!fs::exists(fe)) {
    (void)read_checkpoint(restart, MPI_COMM_WORLD);  // an unreadable checkpoint: say what is wrong with it
    throw InputError(restart, 0, "restarting a coupled run needs the FE state: the checkpoint has no group /fe "
                                 "(not written by a coupled run) and the FE checkpoint next to the DEM checkpoint, " +
                                     fe + ", does not exist");
  }
}

void check_coupled_case(const CaseConfig& c, Setup s, MPI_Comm comm) {
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  const std::unique_ptr<FeSetup> fe = make_fe_setup(c, comm);
  const std::vector<coupling::InterfaceTriangle> tris = build_coupling_interface(c, fe->meshes);
  const CoupledSteps ts = choose_steps(c, s, fe->mesh(), *fe->model, tris);
  s.params.dt = ts.dt_dem;
  // Also check that the decomposition works for this number of ranks.
  DemEngine probe(comm, s.params, s.materials, s.walls, s.particles, {}, 0, 0);
  print_check_summary(c, s, comm);
  if (rank != 0) return;
  for (const auto& p : fe->meshes.parts)
    std::printf("  mesh        %s: %zu nodes, %zu elements\n", p.name.c_str(), p.mesh.n_nodes(), p.mesh.n_elements());
  std::printf("  interface   %zu triangles from %zu surface(s), material '%s'\n", tris.size(), c.coupling.surfaces.size(),
              c.materials[c.coupling.material].name.c_str());
  std::printf("  coupling    dt_DEM %.3e s%s, FE every %d DEM steps (dt_FE %.3e s, FE stable %.3e s)\n", ts.dt_dem,
              ts.clamped ? " (clamped to the FE stable step)" : "", ts.subcycle, ts.subcycle * ts.dt_dem,
              ts.dt_fe_stable);
  std::printf("  FE step     critical %.3e s alone, %.3e s with the interface contact stiffness %.3e N/m per "
              "contact, up to %.3e N/m on a node (a dense grain layer on its share of the surface); x fem.safety %.2f\n",
              ts.dt_fe_alone, ts.dt_fe_critical, ts.k_interface, ts.k_node, c.fem.safety);
  const std::size_t holds = fe_hold_count(c);
  const bool holds_mode = !c.fem.load_steps.empty() || !c.fem.displacement_steps.empty();
  std::printf("  holds       %s, rigid for %lld steps, tolerance %g\n",
              holds_mode ? (std::to_string(holds) + " hold(s)").c_str() : "none (time.steps / duration)",
              static_cast<long long>(c.coupling.rigid_steps),
              c.coupling.tolerance > 0 ? c.coupling.tolerance : c.fem.tolerance);
  print_pair_table(c);
}

int run_coupled_case(const CaseConfig& c, Setup s, const RunOptions& opt, MPI_Comm comm) {
  check_coupled_options(c, opt);
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);

  // ---- set-up: FE side, interface, time steps, engine, coupler ----
  const std::unique_ptr<FeSetup> fe = make_fe_setup(c, comm);
  fem::FeModel& model = *fe->model;
  std::vector<coupling::InterfaceTriangle> tris = build_coupling_interface(c, fe->meshes);
  const std::size_t n_tris = tris.size();
  const CoupledSteps ts = choose_steps(c, s, fe->mesh(), model, tris);
  s.params.dt = ts.dt_dem;
  // Restart: the FE state and hold from the checkpoint's group /fe (or, for a checkpoint of an
  // older fdem, fe_checkpoint.h5 next to it), written at the same step at the end of a sub-cycle
  // (nothing of a sub-cycle is lost).
  const bool restarted = s.restarted;
  std::size_t hold = 0;
  std::int64_t ck_hold_start = -1;
  if (restarted) {
    const std::string path = coupled_fe_state_file(!opt.restart.empty() ? opt.restart : c.restart_from);
    const FeCheckpoint ck = read_fe_checkpoint_for(path, model, fe->mesh());
    if (ck.step != s.step)
      throw InputError(path, 0, "FE checkpoint is of step " + std::to_string(ck.step) + ", the DEM checkpoint of step " +
                                    std::to_string(s.step) + ": they are not of the same coupled run");
    model.restore(ck.state);
    hold = static_cast<std::size_t>(ck.hold);
    ck_hold_start = ck.hold_start;
  }
  const std::int64_t n_initial = static_cast<std::int64_t>(s.particles.size());
  DemEngine e(comm, s.params, s.materials, s.walls, s.particles, s.history, s.step, s.time);
  s.particles = ParticleStore{};
  coupling::CouplerParams cp;
  cp.material = c.coupling.material;
  cp.subcycle = ts.subcycle;
  cp.rigid = c.coupling.rigid_steps > s.step;
  coupling::Coupler coupler(comm, fe->mesh(), model, std::move(tris), cp, e.dt());
  e.attach(&coupler);
  const std::int64_t end_step = c.steps > 0 ? c.steps : static_cast<std::int64_t>(std::ceil(c.duration / e.dt() - 1e-9));
  const bool holds_mode = !c.fem.load_steps.empty() || !c.fem.displacement_steps.empty();
  const std::size_t holds = fe_hold_count(c);
  const double tol = c.coupling.tolerance > 0 ? c.coupling.tolerance : c.fem.tolerance;
  const double threshold = holds_mode ? tol : c.stop_unbalanced;

  // ---- output: the DEM run's files, then the FE and coupling files in the same directory ----
  DemRunOutput out(c, e, restarted, n_initial, comm);
  const std::string& dir = out.dir();
  FeSnapshotWriter fe_snaps(dir, "fe", comm);
  if (restarted) fe_snaps.adopt_existing(e.step_count());  // as the particle snapshots (DemRunOutput)
  // On a restart the rows after the checkpoint's step are dropped (reactions.csv: its second
  // column is the step).
  CsvWriter reac(dir + "/reactions.csv", fe_reaction_columns(*fe), comm, restarted,
                 restarted ? static_cast<double>(s.step) : std::numeric_limits<double>::infinity(), 1);
  // With several surfaces, the force on each (e.g. a geogrid's top and bottom faces vs its
  // transverse ribs' front faces) follows the totals.
  std::vector<std::string> iface_cols{"step",          "time",          "hold",           "fx", "fy", "fz",
                                      "interface_contacts", "fe_unbalanced", "dem_unbalanced", "max_fe_displacement",
                                      "fe_resultant", "servo_misfit"};
  const bool per_surface = c.coupling.surfaces.size() > 1;
  if (per_surface)
    for (const CouplingSurfaceConfig& sc : c.coupling.surfaces)
      for (const char* d : {"_fx", "_fy", "_fz"}) iface_cols.push_back(sc.name + d);
  CsvWriter iface(dir + "/interface.csv", iface_cols, comm, restarted,
                  restarted ? static_cast<double>(s.step) : std::numeric_limits<double>::infinity());
  out.extra = [&](RunInfo& info) {
    const coupling::CouplerTimings& t = coupler.timings();
    double loc[4] = {t.contacts, t.reduce, t.fe, t.scatter}, mx[4];
    MPI_Allreduce(loc, mx, 4, MPI_DOUBLE, MPI_MAX, comm);
    info.timings.push_back({"coupling_contacts", mx[0]});
    info.timings.push_back({"coupling_reduce", mx[1]});
    info.timings.push_back({"coupling_fe", mx[2]});
    info.timings.push_back({"coupling_scatter", mx[3]});
    info.element_updates_per_second =
        mx[2] > 0 ? static_cast<double>(coupler.fe_steps()) * static_cast<double>(model.n_elements_global()) / mx[2] : 0;
    info.coupling = {{"subcycle", static_cast<double>(ts.subcycle)},
                     {"dt_dem", ts.dt_dem},
                     {"dt_fe", coupler.dt_fe()},
                     {"dt_fe_stable", ts.dt_fe_stable},
                     {"dt_fe_critical_alone", ts.dt_fe_alone},
                     {"k_interface", ts.k_interface},
                     {"k_interface_node", ts.k_node},
                     {"dt_dem_clamped", ts.clamped ? 1.0 : 0.0},
                     {"fe_steps", static_cast<double>(coupler.fe_steps())},
                     {"interface_triangles", static_cast<double>(n_tris)},
                     {"rigid_steps", static_cast<double>(c.coupling.rigid_steps)}};
  };

  std::int64_t recorded_at = -1, snap_at = -1;
  // fe: the larger of the FE unbalanced-force ratio (norm) and its resultant ratio (global
  // equilibrium of the structure: clamp force = interface force).
  // servo: the largest |sigma - sigma_0| / sigma_0 of the servo walls (a hold is not over while a
  // servo plate is still finding its stress).
  struct Ratios { double dem = 0, fe = 0, fe_norm = 0, fe_res = 0, servo = 0; std::int64_t contacts = 0; };
  auto servo_misfit = [&]() {
    double m = 0;
    for (const Wall& w : e.walls().walls)
      if (w.motion == Wall::kServo && w.servo.stress > 0) m = std::max(m, std::fabs(w.stress - w.servo.stress) / w.servo.stress);
    return m;
  };
  Ratios last{};
  // A row of history.csv / walls.csv, interface.csv and reactions.csv (collective).
  auto record = [&]() -> Ratios {
    const std::int64_t k = e.step_count();
    if (recorded_at == k) return last;
    const EngineStats st = out.write_history();
    Ratios r;
    r.dem = dem_unbalanced(e, st, c.gravity, comm);
    const std::array<double, 2> fu = model.unbalanced_measures();
    fe_check_health(*fe, "hold " + std::to_string(hold + 1) + ", step " + std::to_string(k), fu[0]);
    r.fe_norm = fu[0];
    r.fe_res = fu[1];
    r.fe = std::max(fu[0], fu[1]);
    r.servo = servo_misfit();
    r.contacts = st.contacts + st.interface_contacts;
    const Vec3 F = coupler.last_update_force();
    std::vector<double> row{static_cast<double>(k), e.time(), static_cast<double>(hold), F.x, F.y, F.z,
                            static_cast<double>(st.interface_contacts), r.fe_norm, r.dem, fe_max_displacement(model, comm),
                            r.fe_res, r.servo};
    if (per_surface)
      for (const Vec3& g : coupler.last_group_forces()) row.insert(row.end(), {g.x, g.y, g.z});
    iface.row(row);
    reac.row(fe_reaction_row(*fe, static_cast<double>(hold), static_cast<double>(k)));
    recorded_at = k;
    last = r;
    return r;
  };
  // The convergence measures without writing a row (collective).
  auto ratios = [&]() -> Ratios {
    if (recorded_at == e.step_count()) return last;
    const EngineStats st = e.stats();
    const std::array<double, 2> fu = model.unbalanced_measures();
    return {dem_unbalanced(e, st, c.gravity, comm), std::max(fu[0], fu[1]), fu[0], fu[1], servo_misfit(),
            st.contacts + st.interface_contacts};
  };
  auto snapshot = [&]() {
    if (snap_at == e.step_count()) return;
    out.snapshot();
    fe_snaps.write(e.step_count(), e.time(), fe_snapshot_data(*fe, comm));
    snap_at = e.step_count();
  };
  // A hold begins when the structure is released (or at the start); restarts continue it.
  std::int64_t hold_start =
      ck_hold_start >= 0 ? ck_hold_start : std::max<std::int64_t>(e.step_count(), c.coupling.rigid_steps);
  // coupling.ramp_steps: the load and displacement factors move smoothly from the last hold's
  // (0 before the first) to this hold's over that many DEM steps (a clamp pulled at a constant
  // rate, then held), instead of jumping at the hold's first FE step.
  auto apply_ramp = [&]() {
    if (c.coupling.ramp_steps <= 0) return;
    const std::int64_t j = e.step_count() - hold_start;  // steps done in this hold
    if (j < 0 || j >= c.coupling.ramp_steps) return;
    // smooth (1 - cos) ramp: the clamp starts and stops without a jump in velocity (a jump would
    // hit the structure's -- possibly scaled -- mass with an impulse)
    const double t = 0.5 * (1 - std::cos(M_PI * static_cast<double>(j + 1) / static_cast<double>(c.coupling.ramp_steps)));
    const double lf0 = hold > 0 ? fe_load_factor(c, hold - 1) : 0.0, df0 = hold > 0 ? fe_disp_factor(c, hold - 1) : 0.0;
    model.set_load_factor(lf0 + (fe_load_factor(c, hold) - lf0) * t);
    model.set_disp_factor(df0 + (fe_disp_factor(c, hold) - df0) * t);
  };
  // The DEM and FE states in one file, checkpoint.h5 (FE in its group /fe), written to a
  // temporary name and renamed: a kill at any moment leaves the previous pair or the new one.
  auto checkpoint = [&](bool hold_done) {
    // no checkpoint of a bad state: the run-health checks first (they throw RunDiverged)
    e.check_health();
    fe_check_health(*fe, "hold " + std::to_string(hold + 1) + ", step " + std::to_string(e.step_count()), 0.0);
    FeCheckpoint ck;
    ck.hold = static_cast<std::int64_t>(hold);
    ck.hold_done = hold_done ? 1 : 0;
    ck.step = e.step_count();
    ck.hold_start = hold_start;
    ck.dim = model.node_dofs();
    ck.state = model.state();
    write_coupled_checkpoint(dir + "/checkpoint.h5", comm, engine_checkpoint(e), ck);
  };
  // A checkpoint inside a sub-cycle would lose the interface forces summed since its start, so a
  // run that ends inside one (time.steps not a multiple of the sub-cycle) checkpoints at the
  // start of that last sub-cycle and keeps that one at the end: a restart continues from there
  // bit for bit (steps are redone, not lost).
  std::int64_t boundary_ck = -1;
  auto final_checkpoint = [&](bool hold_done) {
    const std::int64_t k = e.step_count(), n = coupler.subcycle();
    if (k % n != 0 && boundary_ck == k - k % n) {
      if (rank == 0 && !opt.quiet)
        std::printf("fdem: step %lld ends inside a sub-cycle of %lld steps: the checkpoint is the one of step %lld "
                    "(the sub-cycle's start)\n", static_cast<long long>(k), static_cast<long long>(n),
                    static_cast<long long>(boundary_ck));
      return;
    }
    checkpoint(hold_done);
  };

  begin_fe_hold(c, *fe, hold);
  if (!opt.quiet) {
    char buf[400];
    std::snprintf(buf, sizeof buf, "\nfdem: coupled: %zu FE nodes, %zu elements, %zu interface triangles; FE every %d DEM "
                  "steps (dt_FE %.3e s, FE stable %.3e s incl. interface contact stiffness)%s",
                  fe->mesh().n_nodes(), fe->mesh().n_elements(), n_tris, ts.subcycle, coupler.dt_fe(), ts.dt_fe_stable,
                  holds_mode ? (", " + std::to_string(holds) + " hold(s)").c_str() : "");
    std::string extra = buf;
    if (ts.clamped) {
      std::snprintf(buf, sizeof buf, "\nfdem: dt clamped to the FE stable step %.3e s (the DEM alone would take %.3e s)",
                    ts.dt_fe_stable, ts.dt_dem_wanted);
      extra += buf;
    }
    if (c.coupling.rigid_steps > e.step_count())
      extra += "\nfdem: structure held rigid for the first " + std::to_string(c.coupling.rigid_steps) + " steps";
    if (restarted)
      extra += "\nfdem: restarting at step " + std::to_string(e.step_count()) + ", hold " + std::to_string(hold + 1);
    out.print_start(end_step, extra);
  }
  out.fill_info("running");
  int exit_code = 0;
  // A run that diverges or fails ends with run.json saying so (see driver.cpp run_case).
  try {
  // Micro-mechanics measurements (case key `measure`; the same files as a particle run; the
  // interface contacts count like wall contacts).
  std::unique_ptr<MeasureRun> measure_run;
  if (c.measure.present) measure_run = std::make_unique<MeasureRun>(c.measure, e, dir, restarted, comm);
  if (!restarted) {
    record();
    if (measure_run) measure_run->at_step(true);
    snapshot();
  }

  const int kPoll = 20;
  const double t_loop0 = MPI_Wtime();
  const std::int64_t loop_step0 = e.step_count();
  bool rigid = c.coupling.rigid_steps > e.step_count();
  // Checkpoints (periodic, or for a signal) are written at the end of a sub-cycle, when the FE
  // has received all the forces summed so far: at most n - 1 steps later than due.
  const int n_sub = coupler.subcycle();
  bool checkpoint_due = false;
  int pending_signal = 0;
  bool finished_holds = false;
  while (e.step_count() < end_step) {
    apply_ramp();
    e.step();
    const std::int64_t k = e.step_count();
    if (rigid && k >= c.coupling.rigid_steps) {
      coupler.set_rigid(false);
      rigid = false;
      if (rank == 0 && !opt.quiet) {
        std::printf("fdem: step %lld: structure released (coupling.rigid_steps)\n", static_cast<long long>(k));
        std::fflush(stdout);
      }
    }
    const bool last = k >= end_step;
    bool stop_now = false, hold_done = false;
    if (c.history_every > 0 && (k % c.history_every == 0 || last)) record();
    const bool ramping = holds_mode && k - hold_start < c.coupling.ramp_steps;
    if (!rigid && !ramping && threshold > 0 && k % c.fem.check_every == 0) {
      const Ratios r = ratios();
      if (r.dem < threshold && r.fe < threshold && r.servo < threshold && r.contacts > 0) {
        if (holds_mode) hold_done = true;
        else {
          if (rank == 0 && !opt.quiet)
            std::printf("fdem: unbalanced-force ratios DEM %.3e and FE %.3e below %.3e at step %lld: stopping\n", r.dem,
                        r.fe, threshold, static_cast<long long>(k));
          stop_now = true;
        }
      }
    }
    if (holds_mode && !hold_done && k - hold_start >= c.fem.max_steps) {
      const Ratios r = ratios();
      if (rank == 0)
        std::printf("fdem: hold %zu did not converge in %lld steps (unbalanced DEM %.3e, FE %.3e, servo misfit %.3e; "
                  "tolerance %.1e); continuing\n",
                    hold + 1, static_cast<long long>(k - hold_start), r.dem, r.fe, r.servo, tol);
      hold_done = true;
    }
    if (hold_done) {
      const Ratios r = record();
      snapshot();
      if (rank == 0 && !opt.quiet) {
        const Vec3 F = coupler.last_update_force();
        std::printf("hold %zu/%zu: load factor %g, displacement factor %g, unbalanced DEM %.3e FE %.3e, interface "
                    "force (%.4g, %.4g, %.4g) N, step %lld\n",
                    hold + 1, holds, fe_load_factor(c, hold), fe_disp_factor(c, hold), r.dem, r.fe, F.x, F.y, F.z,
                    static_cast<long long>(k));
        std::fflush(stdout);
      }
      if (hold + 1 >= holds) {
        finished_holds = true;
        stop_now = true;
      } else {
        ++hold;
        if (begin_fe_hold(c, *fe, hold) && coupler.dt_fe() > c.fem.safety * model.critical_dt() && rank == 0)
          std::printf("fdem: warning: after the element removal of hold %zu the FE step %.3e s exceeds the FE stable "
                      "step %.3e s\n", hold + 1, coupler.dt_fe(), c.fem.safety * model.critical_dt());
        hold_start = k;
      }
    }
    // (measurements also at the end of every hold: the states a load-step analysis reports)
    if (measure_run) measure_run->at_step(last || stop_now || hold_done);
    if ((c.snapshot_every > 0 && k % c.snapshot_every == 0) || last || stop_now) snapshot();
    if (c.checkpoint_every > 0 && k % c.checkpoint_every == 0 && !last) checkpoint_due = true;
    // (and at the start of a last sub-cycle that time.steps cuts short: see final_checkpoint)
    const bool last_cycle = end_step % n_sub != 0 && end_step - k < n_sub;
    if ((checkpoint_due || last_cycle) && k % n_sub == 0 && !last) {
      checkpoint(false);
      out.fill_info("running");
      checkpoint_due = false;
      if (last_cycle) boundary_ck = k;
    }
    if (k % kPoll == 0 || last) {
      const DemRunOutput::Poll pl = out.poll(opt.quiet);
      if (pl.print) {
        const Ratios r = ratios();
        const Vec3 F = coupler.last_update_force();
        if (rank == 0) {
          const double el = MPI_Wtime() - t_loop0;
          const double eta = k > loop_step0 ? el / (k - loop_step0) * (end_step - k) : -1;
          std::printf("step %lld/%lld  t %.4e s  hold %zu/%zu  interface F (%.3e, %.3e, %.3e) N  unbalanced DEM %.3e "
                      "FE %.3e  left %s\n",
                      static_cast<long long>(k), static_cast<long long>(end_step), e.time(), hold + 1, holds, F.x, F.y,
                      F.z, r.dem, r.fe, hms(eta).c_str());
          std::fflush(stdout);
          out.mark_printed();
        }
      }
      if (pl.signal > 0) pending_signal = pl.signal;
    }
    if (pending_signal > 0 && (k % n_sub == 0 || last)) {
      if (rank == 0)
        std::printf("fdem: signal %d at step %lld: writing %s/checkpoint.h5 (DEM and FE state) and stopping\n",
                    pending_signal, static_cast<long long>(k), dir.c_str());
      record();
      snapshot();
      final_checkpoint(false);
      out.fill_info("interrupted");
      exit_code = 128 + pending_signal;
      break;
    }
    if (stop_now) break;
  }
  if (exit_code == 0) {
    if (holds_mode && !finished_holds && rank == 0)
      std::printf("fdem: time.steps / duration reached in hold %zu of %zu before the holds converged\n", hold + 1, holds);
    record();
    snapshot();
    final_checkpoint(true);
    out.fill_info("finished");
    if (!opt.quiet) {
      out.print_summary();
      const Vec3 F = coupler.last_update_force();
      if (rank == 0)
        std::printf("fdem: %lld FE steps (every %d DEM steps); interface force (%.6g, %.6g, %.6g) N\n",
                    static_cast<long long>(coupler.fe_steps()), ts.subcycle, F.x, F.y, F.z);
    }
  }
  } catch (const RunDiverged& ex) {
    out.fill_info("diverged", ex.what());
    throw;
  } catch (const std::exception& ex) {
    out.fail_info(ex.what());
    throw;
  }
  return exit_code;
}

}  // namespace fdem
