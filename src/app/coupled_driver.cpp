#include "app/coupled_driver.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <fstream>
#include <limits>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "app/fe_driver.hpp"
#include "app/wall_holds.hpp"
#include "app/measurements.hpp"
#include "coupling/coupler.hpp"
#include "coupling/interface.hpp"
#include "io/checkpoint.hpp"
#include "io/csv.hpp"
#include "base/errors.hpp"
#include "io/fe_checkpoint.hpp"
#include "io/fe_output.hpp"
#include "base/exact_sum.hpp"
#include "base/sorted_index.hpp"
#include "base/bytes.hpp"

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

std::vector<std::uint8_t> active_at_hold(const std::vector<coupling::HoldRange>& holds, std::size_t hold) {
  std::vector<std::uint8_t> a(holds.size());
  for (std::size_t t = 0; t < holds.size(); ++t) a[t] = holds[t].at(static_cast<std::int32_t>(hold)) ? 1 : 0;
  return a;
}

std::vector<coupling::InterfaceTriangle> build_coupling_interface(const CaseConfig& c, const FeMeshes& m,
                                                                 std::vector<coupling::HoldRange>* holds) {
  std::vector<coupling::InterfaceTriangle> all;
  std::vector<coupling::HoldRange> all_holds;
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
    std::vector<coupling::HoldRange> th;
    // the hold at whose start each element of this mesh goes (fem.remove; -1: never)
    std::vector<std::int32_t> removed_at;
    for (const FeRemovalConfig& rm : c.fem.removals) {
      if (rm.mesh != sc.mesh) continue;
      const auto set = part.mesh.element_sets.find(rm.element_set);
      if (set == part.mesh.element_sets.end()) continue;  // (fe_driver reports it)
      if (removed_at.empty()) removed_at.assign(part.mesh.n_elements(), -1);
      for (std::int32_t e : set->second)
        if (removed_at[e] < 0 || rm.at_hold < removed_at[e]) removed_at[e] = rm.at_hold;
    }
    try {
      if (!sc.face_set.empty()) {
        if (!part.mesh.face_sets.count(sc.face_set))
          throw InputError(c.file, sc.line, where + ": mesh '" + part.name + "' has no face set '" + sc.face_set +
                                                "' (valid: " + key_names(part.mesh.face_sets) + ")");
        tris = coupling::make_interface(part.mesh, sc.face_set, {}, removed_at, th);
      } else if (!sc.element_set.empty()) {
        auto it = part.mesh.element_sets.find(sc.element_set);
        if (it == part.mesh.element_sets.end())
          throw InputError(c.file, sc.line, where + ": mesh '" + part.name + "' has no element set '" +
                                                sc.element_set + "' (valid: " + key_names(part.mesh.element_sets) + ")");
        if (it->second.empty())
          throw InputError(c.file, sc.line, where + ": element set '" + sc.element_set + "' is empty");
        tris = coupling::make_interface(part.mesh, "", it->second, removed_at, th);
      } else {
        tris = coupling::make_interface(part.mesh, "", {}, removed_at, th);
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
    for (std::size_t q = 0; q < tris.size(); ++q) {
      coupling::InterfaceTriangle& t = tris[q];
      for (auto& corner : t.nodes)
        for (auto& n : corner)
          if (n >= 0) n = m.node(part, n);
      if (t.element >= 0) t.element += part.elem_offset;
      t.group = static_cast<std::int32_t>(i);
      const std::array<std::int32_t, 2> key{t.element, t.face};
      if (taken.count(key)) continue;
      mine.insert(key);
      all.push_back(t);
      all_holds.push_back(th[q]);
      ++kept;
    }
    if (kept == 0)
      throw InputError(c.file, sc.line, where + ": all its faces belong to earlier surfaces");
    taken.insert(mine.begin(), mine.end());
  }
  if (holds) *holds = std::move(all_holds);
  return all;
}

PackingStructure packing_structure(const CaseConfig& c) {
  const FeMeshes m = build_fe_meshes(c);
  std::vector<coupling::HoldRange> holds;
  std::vector<coupling::InterfaceTriangle> tris = build_coupling_interface(c, m, &holds);
  {  // the surface of the first hold (faces that element removals expose later are inside the solid)
    std::size_t k = 0;
    for (std::size_t t = 0; t < tris.size(); ++t)
      if (holds[t].at(0)) tris[k++] = tris[t];
    tris.resize(k);
  }
  // the mesh an element of the merged mesh belongs to
  const auto mesh_of = [&](std::int32_t e) {
    std::size_t k = 0;
    while (k + 1 < m.parts.size() && e >= m.parts[k + 1].elem_offset) ++k;
    return k;
  };
  std::vector<PackingStructure::Part> parts(m.parts.size());
  std::vector<std::map<std::array<std::int32_t, 4>, int>> index(m.parts.size());
  for (std::size_t k = 0; k < m.parts.size(); ++k) {
    parts[k].mesh = m.parts[k].name;
    parts[k].after_layer = c.packing.join_layer(static_cast<int>(k));
    Wall& w = parts[k].facets;
    w.kind = Wall::kFacets;
    w.name = "structure " + m.parts[k].name;
    w.mat = c.coupling.material;  // (the first surface on this mesh with its own material: that one)
    for (std::size_t i = 0; i < c.coupling.surfaces.size(); ++i)
      if (c.coupling.surfaces[i].mesh == static_cast<int>(k)) {
        w.mat = c.coupling.surface_material(i);
        break;
      }
  }
  // Shared corners (a node, or a quad's centre) become shared vertices: the facet selection
  // then treats each mesh's surface as one smooth mesh, as the coupler does.
  for (const coupling::InterfaceTriangle& t : tris) {
    const std::size_t k = mesh_of(t.element);
    Wall& w = parts[k].facets;
    Vec3 x[3];
    coupling::corner_positions(m.merged, {}, t, x);
    std::array<int, 3> tri{};
    for (int q = 0; q < 3; ++q) {
      std::array<std::int32_t, 4> key = t.nodes[q];
      std::sort(key.begin(), key.end());
      auto it = index[k].find(key);
      if (it == index[k].end()) {
        it = index[k].emplace(key, static_cast<int>(w.verts.size())).first;
        w.verts.push_back(x[q]);
      }
      tri[q] = it->second;
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
    parts[mesh_of(static_cast<std::int32_t>(e))].solid_boxes.push_back({lo, hi});
  }
  PackingStructure ps;
  for (PackingStructure::Part& p : parts)
    if (!p.facets.tris.empty() || !p.solid_boxes.empty()) ps.parts.push_back(std::move(p));
  std::stable_sort(ps.parts.begin(), ps.parts.end(),
                   [](const PackingStructure::Part& a, const PackingStructure::Part& b) { return a.after_layer < b.after_layer; });
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
  double mass_scaling = 1;  // the FE densities' scaling (fem.mass_scaling, or the one `auto` chose)
  bool mass_scaling_auto = false;
};

/// Collective when `s` is shared (its particles are reduced over `comm`).
/// The FE side of a coupled case and its interface (collective). With fem.distribute rank 0 makes
/// the triangles from the whole meshes before it sends the parts, and every rank gets them over a
/// mesh of the interface's nodes alone -- in the merged mesh's order, so that every order the
/// coupler keeps is the replicated run's -- with each node's global FE number and its index in
/// this rank's part (-1: not there).
struct CoupledFe {
  std::unique_ptr<FeSetup> fe;
  std::vector<coupling::InterfaceTriangle> tris;
  std::vector<coupling::HoldRange> holds;  // when each triangle is on the surface (fem.remove)
  fem::Mesh surface;                       // fem.distribute: the interface's nodes
  std::vector<PetscInt> global;            // fem.distribute: their global FE node numbers
  std::vector<std::int32_t> model_node;    // fem.distribute: their index in the model's part (-1)
  /// The mesh the triangles index.
  const fem::Mesh& mesh() const { return fe->distributed ? surface : fe->mesh(); }
  /// The model's mesh index of node n of mesh() (-1: not in this rank's part).
  std::int32_t to_model(std::int32_t n) const { return fe->distributed ? model_node[n] : n; }
};

CoupledFe make_coupled_fe(const CaseConfig& c, MPI_Comm comm) {
  CoupledFe cf;
  std::vector<std::int64_t> whole;  // fem.distribute: the merged index of each surface node
  cf.fe = make_fe_setup(c, comm, [&](const FeMeshes& m) {
    cf.tris = build_coupling_interface(c, m, &cf.holds);
    if (!c.fem.distribute) return;
    const std::vector<std::int32_t> nodes = coupling::interface_nodes(cf.tris);  // (ascending)
    cf.surface.dim = 3;
    for (std::int32_t n : nodes) {
      whole.push_back(n);
      cf.surface.node_id.push_back(m.merged.node_id[static_cast<std::size_t>(n)]);
      cf.surface.coords.insert(cf.surface.coords.end(), m.merged.coords.begin() + 3 * static_cast<std::ptrdiff_t>(n),
                               m.merged.coords.begin() + 3 * static_cast<std::ptrdiff_t>(n) + 3);
    }
    for (auto& t : cf.tris)
      for (auto& corner : t.nodes)
        for (auto& n : corner)
          if (n >= 0) n = static_cast<std::int32_t>(std::lower_bound(nodes.begin(), nodes.end(), n) - nodes.begin());
  });
  if (!cf.fe->distributed) return cf;
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  Bytes b;
  if (rank == 0) {
    b.put(cf.tris);
    b.put(cf.holds);
    b.put(cf.surface.coords);
    b.put(cf.surface.node_id);
    b.put(whole);
  }
  bcast_bytes(b.data(), 0, comm);
  if (rank != 0) {
    b.get(cf.tris);
    b.get(cf.holds);
    b.get(cf.surface.coords);
    b.get(cf.surface.node_id);
    b.get(whole);
    cf.surface.dim = 3;
  }
  // Each node's global number from the rank that holds it (every rank of a node's elements
  // knows it: the largest over the ranks, -1 elsewhere).
  const FeSetup& fe = *cf.fe;
  cf.model_node.resize(whole.size());
  cf.global.resize(whole.size());
  for (std::size_t i = 0; i < whole.size(); ++i) {
    cf.model_node[i] = find_sorted(fe.part.node_index, whole[i]);
    cf.global[i] = cf.model_node[i] >= 0 ? fe.model->global_node(cf.model_node[i]) : -1;
  }
  MPI_Allreduce(MPI_IN_PLACE, cf.global.data(), static_cast<int>(cf.global.size()), MPIU_INT, MPI_MAX, comm);
  return cf;
}

CoupledSteps choose_steps(const CaseConfig& c, const Setup& s, const CoupledFe& cf, MPI_Comm comm) {
  const fem::Mesh& mesh = cf.mesh();
  fem::FeModel& model = *cf.fe->model;
  const std::vector<coupling::InterfaceTriangle>& tris = cf.tris;
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
  const std::vector<int> ims = c.coupling.interface_materials();
  // A shared set-up holds a share on each rank: the maxima and the (exact) sum over all ranks.
  exact::ExactSums k_sum(1);
  for (std::size_t i = 0; i < s.particles.size(); ++i) {
    const double r = s.particles.r[i];
    // The contact's normal stiffness (the model table; flat interface: R* = r). A Hertz pair
    // stiffens with the overlap: take its tangent stiffness at the largest overlap a run allows
    // (HealthLimits::kMaxOverlap r), an upper bound. A linear pair's is K_N at any overlap. With
    // several interface materials, the stiffest.
    double k = 0;
    for (int im : ims)
      k = std::max(k, normal_law(s.materials.pair(s.particles.mat[i], im), s.materials[s.particles.mat[i]].young, r,
                                 s.materials[im].young, r, r, HealthLimits::kMaxOverlap * r).k);
    ts.k_interface = std::max(ts.k_interface, k);
    ts.k_per_area = std::max(ts.k_per_area, k / (2 * std::sqrt(3.0) * r * r));
    k_sum.add(0, k);
  }
  const double k_all = k_sum.sums(s.shared ? comm : MPI_COMM_SELF)[0];
  double dt_particles = critical_dt(s.particles, s.materials);
  if (s.shared) {
    MPI_Allreduce(MPI_IN_PLACE, &ts.k_interface, 1, MPI_DOUBLE, MPI_MAX, comm);
    MPI_Allreduce(MPI_IN_PLACE, &ts.k_per_area, 1, MPI_DOUBLE, MPI_MAX, comm);
    MPI_Allreduce(MPI_IN_PLACE, &dt_particles, 1, MPI_DOUBLE, MPI_MIN, comm);
  }
  const std::vector<std::int32_t> nodes = coupling::interface_nodes(tris);
  const std::vector<double> area = coupling::interface_node_areas(mesh, tris);
  std::vector<double> kn;
  std::vector<std::int32_t> in_model;  // (the interface nodes in the model's mesh, kn of each)
  for (std::size_t j = 0; j < nodes.size(); ++j) {
    const double k = std::max(ts.k_interface, std::min(ts.k_per_area * area[j], k_all));
    ts.k_node = std::max(ts.k_node, k);
    if (const std::int32_t m = cf.to_model(nodes[j]); m >= 0) {
      in_model.push_back(m);
      kn.push_back(k);
    }
  }
  ts.dt_fe_critical = ts.k_interface > 0 ? model.critical_dt(in_model, kn) : model.critical_dt();
  ts.dt_fe_stable = c.fem.safety * ts.dt_fe_critical;
  ts.dt_dem_wanted = s.params.dt > 0 ? s.params.dt : s.params.dt_safety * dt_particles;
  ts.mass_scaling = c.fem.mass_scaling;
  if (c.fem.mass_scaling_auto) {
    // The smallest scaling (>= 1) whose stable FE step is the DEM's own: the step goes with
    // sqrt(mass), so s = (dt_DEM / dt_FE,stable(1))^2 (a hair more: not clamped by round-off).
    const double r = ts.dt_dem_wanted / ts.dt_fe_stable;
    ts.mass_scaling = std::max(1.0, r * r * (1 + 1e-9));
    ts.mass_scaling_auto = true;
    model.set_density_scale(ts.mass_scaling);
    ts.dt_fe_alone = model.critical_dt();
    ts.dt_fe_critical = ts.k_interface > 0 ? model.critical_dt(in_model, kn) : model.critical_dt();
    ts.dt_fe_stable = c.fem.safety * ts.dt_fe_critical;
  }
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

/// The grains' resultant ratio |sum_i (f_i + m_i g)| / sum_i m_i |g| over the free grains (f_i:
/// their contact, wall and interface forces): the acceleration of their centre of mass in g,
/// zero when the fill is balanced as a whole. A column ringing after a release has a resultant
/// while each grain's own force is nearly balanced (the mean ratio dem_unbalanced small).
/// Exact sums: the same bits on any number of ranks. Collective.
double grain_resultant(DemEngine& e, const Vec3& gravity, MPI_Comm comm) {
  const ParticleStore& p = e.particles();
  exact::ExactSums sums(4);
  for (std::size_t i = 0; i < p.n_owned; ++i) {
    if (p.blocked[i] == kDofAll) continue;
    const Vec3 f = p.f[i] + p.m[i] * gravity;
    sums.add(0, f.x);
    sums.add(1, f.y);
    sums.add(2, f.z);
    sums.add(3, p.m[i] * norm(gravity));
  }
  const std::vector<double> g = sums.sums(comm);
  return g[3] > 0 ? norm(Vec3{g[0], g[1], g[2]}) / g[3] : std::numeric_limits<double>::quiet_NaN();
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
  const CoupledFe cf = make_coupled_fe(c, comm);
  const std::unique_ptr<FeSetup>& fe = cf.fe;
  const std::vector<coupling::InterfaceTriangle>& tris = cf.tris;
  const CoupledSteps ts = choose_steps(c, s, cf, comm);
  s.params.dt = ts.dt_dem;
  // Also check that the decomposition works for this number of ranks.
  DemEngine probe(comm, s.params, s.materials, s.walls, s.particles, {}, 0, 0, particle_input(s));
  print_check_summary(c, s, comm);
  if (rank != 0) return;
  for (const auto& p : fe->meshes.parts)
    std::printf("  mesh        %s: %zu nodes, %zu elements\n", p.name.c_str(), p.mesh.n_nodes(), p.mesh.n_elements());
  if (!c.fem.ties.empty()) std::printf("  ties        %s\n", ties_text(c, fe->meshes).c_str());
  std::printf("  interface   %zu triangles from %zu surface(s), material %s\n", tris.size(), c.coupling.surfaces.size(),
              c.coupling.material_names(c.materials).c_str());
  std::printf("  coupling    dt_DEM %.3e s%s, FE every %d DEM steps (dt_FE %.3e s, FE stable %.3e s)\n", ts.dt_dem,
              ts.clamped ? " (clamped to the FE stable step)" : "", ts.subcycle, ts.subcycle * ts.dt_dem,
              ts.dt_fe_stable);
  std::printf("  FE step     critical %.3e s alone, %.3e s with the interface contact stiffness %.3e N/m per "
              "contact, up to %.3e N/m on a node (a dense grain layer on its share of the surface); x fem.safety %.2f\n",
              ts.dt_fe_alone, ts.dt_fe_critical, ts.k_interface, ts.k_node, c.fem.safety);
  std::printf("  FE mass     densities x %.4g (fem.mass_scaling%s)\n", ts.mass_scaling,
              ts.mass_scaling_auto ? " auto: the FE stable step is the DEM's own" : "");
  const std::size_t holds = fe_hold_count(c);
  const bool holds_mode = fe_holds_mode(c);
  std::printf("  holds       %s, rigid for %lld steps, tolerance %g\n",
              holds_mode ? (std::to_string(holds) + " hold(s)").c_str() : "none (time.steps / duration)",
              static_cast<long long>(c.coupling.rigid_steps),
              c.coupling.tolerance > 0 ? c.coupling.tolerance : c.fem.tolerance);
  print_pair_table(c);
}

namespace {

/// The convergence measures of a coupled run: DEM and FE unbalanced ratios, the servo misfit.
/// fe: the larger of the FE unbalanced-force ratio (norm) and its resultant ratio (global
/// equilibrium of the structure: clamp force = interface force). servo: the largest
/// |sigma - sigma_0| / sigma_0 of the servo walls (a hold is not over while a servo plate is
/// still finding its stress).
struct Ratios {
  double dem = 0, fe = 0, fe_norm = 0, fe_res = 0, servo = 0;
  double kinetic = 0;  // J per grain
  double resultant = 0;  // the grains' resultant ratio (grain_resultant)
  std::int64_t contacts = 0;
  std::vector<fem::FeModel::PartBalance> parts;  // per FE part (case mesh)
};

/// The FE parts' names: the case meshes' when the ratios are taken per mesh, else the one
/// mesh's name (or "fe" for several meshes measured as one).
std::vector<std::string> fe_part_names(const FeSetup& fe) {
  std::vector<std::string> names;
  if (fe.model->node_groups() > 1 || fe.meshes.parts.size() == 1)
    for (const auto& p : fe.meshes.parts) names.push_back(p.name);
  if (names.size() != static_cast<std::size_t>(fe.model->node_groups())) names.assign(1, "fe");
  return names;
}

/// The largest of the parts' RMS speeds (m/s).
double max_speed(const std::vector<fem::FeModel::PartBalance>& parts) {
  double v = 0;
  for (const fem::FeModel::PartBalance& p : parts) v = std::max(v, p.speed);
  return v;
}



/// The rows of history.csv / walls.csv (DemRunOutput), interface.csv and reactions.csv, at most
/// one per step, and the convergence measures (computed once per step). Collective.
class CoupledRecorder {
 public:
  /// `restarted`: continue the files, dropping the rows after the checkpoint's step.
  CoupledRecorder(const CaseConfig& c, DemEngine& e, FeSetup& fe, coupling::Coupler& coupler, DemRunOutput& out,
                  bool restarted, MPI_Comm comm)
      : c_(c), e_(e), fe_(fe), coupler_(coupler), out_(out), comm_(comm) {
    const std::string& dir = out.dir();
    const double keep = restarted ? static_cast<double>(e.step_count()) : std::numeric_limits<double>::infinity();
    // reactions.csv: its second column is the step
    reac_ = std::make_unique<CsvWriter>(dir + "/reactions.csv", fe_reaction_columns(fe), comm, restarted, keep, 1);
    // With several surfaces, the force on each (e.g. a geogrid's top and bottom faces vs its
    // transverse ribs' front faces) follows the totals.
    std::vector<std::string> cols{"step",          "time",          "hold",           "fx", "fy", "fz",
                                  "interface_contacts", "fe_unbalanced", "dem_unbalanced", "max_fe_displacement",
                                  "fe_resultant", "servo_misfit", "fe_speed", "fe_damping"};
    if (c.coupling.surfaces.size() > 1)
      for (const CouplingSurfaceConfig& sc : c.coupling.surfaces)
        for (const char* d : {"_fx", "_fy", "_fz"}) cols.push_back(sc.name + d);
    iface_ = std::make_unique<CsvWriter>(dir + "/interface.csv", cols, comm, restarted, keep);
  }

  Ratios record(const RunState& st) {
    const std::int64_t k = e_.step_count();
    if (recorded_at_ == k) return last_;
    fem::FeModel& model = *fe_.model;
    const EngineStats es = out_.write_history();
    const Ratios r = measure(es);
    fe_check_health(fe_, "hold " + std::to_string(st.hold + 1) + ", step " + std::to_string(k), r.fe_norm);
    const Vec3 F = coupler_.last_update_force();
    std::vector<double> row{static_cast<double>(k), e_.time(), static_cast<double>(st.hold), F.x, F.y, F.z,
                            static_cast<double>(es.interface_contacts), r.fe_norm, r.dem,
                            fe_max_displacement(model, comm_), r.fe_res, r.servo, max_speed(r.parts),
                            model.damping_used()};
    if (c_.coupling.surfaces.size() > 1)
      for (const Vec3& g : coupler_.last_group_forces()) row.insert(row.end(), {g.x, g.y, g.z});
    iface_->row(row);
    reac_->row(fe_reaction_row(fe_, static_cast<double>(st.hold), static_cast<double>(k)));
    recorded_at_ = k;
    last_ = r;
    return r;
  }

  /// The measures without writing a row.
  Ratios ratios() {
    if (recorded_at_ == e_.step_count()) return last_;
    return measure(e_.stats());
  }
  const Ratios& last() const { return last_; }

 private:
  /// The convergence measures from the engine's statistics `es`; collective.
  Ratios measure(const EngineStats& es) {
    Ratios r;
    r.dem = dem_unbalanced(e_, es, c_.gravity, comm_);
    r.parts = fe_.model->part_balance();
    const std::array<double, 2> fu = fem::FeModel::worst(r.parts);
    r.fe_norm = fu[0];
    r.fe_res = fu[1];
    r.fe = std::max(fu[0], fu[1]);
    r.servo = servo_misfit();
    r.kinetic = es.kinetic_energy / std::max<double>(1.0, static_cast<double>(es.particles));
    r.resultant = grain_resultant(e_, c_.gravity, comm_);
    r.contacts = es.contacts + es.interface_contacts;
    return r;
  }
  double servo_misfit() {
    double m = 0;
    for (const Wall& w : e_.walls().walls)
      if (w.motion == Wall::kServo && w.servo.stress > 0) m = std::max(m, std::fabs(w.stress - w.servo.stress) / w.servo.stress);
    return m;
  }
  const CaseConfig& c_;
  DemEngine& e_;
  FeSetup& fe_;
  coupling::Coupler& coupler_;
  DemRunOutput& out_;
  MPI_Comm comm_;
  std::unique_ptr<CsvWriter> reac_, iface_;
  std::int64_t recorded_at_ = -1;
  Ratios last_{};
};

/// coupling.ramp_steps: the load and displacement factors move smoothly from the last hold's
/// (0 before the first) to this hold's over that many DEM steps (a clamp pulled at a constant
/// rate, then held), instead of jumping at the hold's first FE step.
class LoadRamp : public Controller {
 public:
  LoadRamp(const CaseConfig& c, fem::FeModel& model, DemEngine& e) : c_(c), model_(model), e_(e) {}
  void before_step(const RunState& st) override {
    if (c_.coupling.ramp_steps <= 0) return;
    const std::int64_t j = e_.step_count() - st.hold_start;  // steps done in this hold
    if (j < 0 || j >= c_.coupling.ramp_steps) return;
    // smooth (1 - cos) ramp: the clamp starts and stops without a jump in velocity (a jump would
    // hit the structure's -- possibly scaled -- mass with an impulse)
    const double t =
        0.5 * (1 - std::cos(M_PI * static_cast<double>(j + 1) / static_cast<double>(c_.coupling.ramp_steps)));
    const std::size_t h = st.hold;
    const double lf0 = h > 0 ? fe_load_factor(c_, h - 1) : 0.0, df0 = h > 0 ? fe_disp_factor(c_, h - 1) : 0.0;
    model_.set_load_factor(lf0 + (fe_load_factor(c_, h) - lf0) * t);
    model_.set_disp_factor(df0 + (fe_disp_factor(c_, h) - df0) * t);
  }

 private:
  const CaseConfig& c_;
  fem::FeModel& model_;
  DemEngine& e_;
};

/// coupling.rigid_steps: the structure is a rigid wall until that step, then released.
class RigidRelease : public Controller {
 public:
  RigidRelease(const CaseConfig& c, coupling::Coupler& coupler, std::int64_t step, bool quiet, int rank)
      : c_(c), coupler_(coupler), rigid_(c.coupling.rigid_steps > step), quiet_(quiet), rank_(rank) {}
  bool rigid() const { return rigid_; }
  void after_step(const RunState& st) override {
    if (!rigid_ || st.step < c_.coupling.rigid_steps) return;
    coupler_.set_rigid(false);
    rigid_ = false;
    if (rank_ == 0 && !quiet_) {
      std::printf("fdem: step %lld: structure released (coupling.rigid_steps)\n", static_cast<long long>(st.step));
      std::fflush(stdout);
    }
  }

 private:
  const CaseConfig& c_;
  coupling::Coupler& coupler_;
  bool rigid_, quiet_;
  int rank_;
};

/// A coupled run's holds (fem.load_steps / displacement_steps): a hold ends when the DEM, the FE
/// and the servo walls are all below the tolerance (checked every fem.check_every steps, not
/// while the structure is rigid or the load ramps), or after fem.max_steps. Without holds the
/// same test against time.stop_unbalanced ends the run. With load holds on walls (`holds`,
/// `walls`: app/wall_holds.hpp) each hold also sets the held walls' targets, `holds.stop` can end
/// the run, and the tolerance, check interval and step limits are the `holds` section's.
class CoupledHolds : public Schedule {
 public:
  CoupledHolds(const CaseConfig& c, FeSetup& fe, coupling::Coupler& coupler, CoupledRecorder& rec,
               const RigidRelease& rigid, WallHolds* walls, const std::vector<coupling::HoldRange>& surface_holds,
               double grain_mgd, double dt, bool quiet, int rank)
      : c_(c), fe_(fe), coupler_(coupler), rec_(rec), rigid_(rigid), walls_(walls), surface_holds_(surface_holds),
        grain_mgd_(grain_mgd), dt_(dt), quiet_(quiet), rank_(rank), parts_(fe_part_names(fe)) {}
  /// holds.csv's columns after the walls' (then `held_by`): the servo misfit, the kinetic energy
  /// per grain over m g d, the grains' resultant ratio, and per FE part its unbalanced and resultant ratios, RMS speed and
  /// drift since the previous check.
  std::vector<std::string> columns() const { return hold_columns(parts_); }
  static std::vector<std::string> hold_columns(const std::vector<std::string>& parts) {
    std::vector<std::string> cols{"servo_misfit", "kinetic_ratio", "grain_resultant"};
    for (const std::string& p : parts)
      for (const char* q : {"_unbalanced", "_resultant", "_speed", "_drift"}) cols.push_back(p + q);
    return cols;
  }
  /// The values of columns() at the last check.
  std::vector<double> values(const Ratios& r) const {
    std::vector<double> v{r.servo, grain_mgd_ > 0 ? r.kinetic / grain_mgd_ : 0.0, r.resultant};
    for (const fem::FeModel::PartBalance& p : r.parts) v.insert(v.end(), {p.norm, p.resultant, p.speed, p.drift});
    v.resize(3 + 4 * parts_.size(), std::numeric_limits<double>::quiet_NaN());
    return v;
  }
  /// The measures of the last check and the parts above their tolerance then (holds.csv).
  const Ratios& last_check() const { return last_; }
  const std::string& held_by() const { return held_by_; }
  bool holds_mode() const { return fe_holds_mode(c_); }
  double tolerance() const {
    if (c_.holds.present) return c_.holds.tolerance;
    return c_.coupling.tolerance > 0 ? c_.coupling.tolerance : c_.fem.tolerance;
  }
  std::int64_t check_every() const { return c_.holds.present ? c_.holds.check_every : c_.fem.check_every; }
  std::int64_t max_steps() const { return c_.holds.present ? c_.holds.max_steps : c_.fem.max_steps; }

  /// Nothing still falling: the kinetic energy per grain below coupling.kinetic_ratio x m g d
  /// (without holds, where time.stop_unbalanced ends the run: time.stop_kinetic_ratio when coupling
  /// gives none). Not checked without gravity (m g d = 0).
  bool is_still(const Ratios& r, bool holds) const {
    double k = c_.coupling.kinetic_ratio;
    if (!holds && !(k > 0)) k = c_.stop_kinetic_ratio;
    return !(k > 0) || !(grain_mgd_ > 0) || r.kinetic < k * grain_mgd_;
  }
  void check(RunState& st) override {
    if (walls_ && walls_->stop_reached(st)) return;
    const bool holds = holds_mode();
    const double threshold = holds ? tolerance() : c_.stop_unbalanced;
    const std::int64_t k = st.step;
    const bool ramping = holds && k - st.hold_start < c_.coupling.ramp_steps;
    const bool early = c_.holds.present && k - st.hold_start < c_.holds.min_steps;
    if (!rigid_.rigid() && !ramping && !early && threshold > 0 && k % check_every() == 0) {
      const Ratios r = rec_.ratios();
      const bool creeping = walls_ && walls_->creeping();  // (every check: it moves the window)
      const bool arrived = !walls_ || walls_->arrived();  // walls held by displacement
      // coupling.kinetic_ratio: nothing still falling (the ratios above are means over all grains)
      const bool still = is_still(r, holds);
      const std::string open = open_parts(r, threshold, still);
      const std::string walls = walls_ ? walls_->open_walls() : std::string();  // creep:<wall>, arrive:<wall>
      note(k, r, open + (open.empty() || walls.empty() ? "" : "+") + walls);
      fe_.model->mark_check();  // (the next check's drift is from here)
      if (c_.coupling.creep_damping > 0) set_creep_damping(r);
      if (open.empty() && !creeping && arrived) {
        if (holds) {
          st.hold_done = true;
          st.hold_converged = true;
        } else {
          if (rank_ == 0 && !quiet_)
            std::printf("fdem: unbalanced-force ratios DEM %.3e and FE %.3e below %.3e at step %lld: stopping\n", r.dem,
                        r.fe, threshold, static_cast<long long>(k));
          st.stop = true;
        }
      }
    }
    if (holds && !st.hold_done && k - st.hold_start >= max_steps()) {
      if (last_step_ != k) {  // (not checked at this step: the measures now)
        const Ratios r = rec_.ratios();
        const bool still = is_still(r, true);
        note(k, r, open_parts(r, tolerance(), still));
      }
      const Ratios& r = last_;
      if (rank_ == 0)
        std::printf("fdem: hold %zu did not converge in %lld steps (unbalanced DEM %.3e, FE %.3e, servo misfit %.3e; "
                    "tolerance %.1e; held open by %s); continuing\n",
                    st.hold + 1, static_cast<long long>(k - st.hold_start), r.dem, r.fe, r.servo, tolerance(),
                    held_by_.empty() ? "none" : held_by_.c_str());
      st.hold_done = true;
    }
  }

  /// The parts above their tolerance, joined by '+' (empty: none): `dem` (the DEM unbalanced
  /// ratio, or no contact at all), `kinetic` (coupling.kinetic_ratio), `resultant` (the grains'
  /// resultant ratio above coupling.grain_resultant), `servo` (a servo wall's
  /// misfit), `fe:<part>` for each FE part whose resultant ratio is above it, or whose unbalanced
  /// ratio (norm) is while it is not at rest by coupling.creep (its drift since the previous check,
  /// the mass-weighted RMS displacement of its nodes, below it): a part balanced as a whole whose
  /// residual is a few nodes' chatter about their places counts as held.
  std::string open_parts(const Ratios& r, double tol, bool still) const {
    std::string s;
    auto add = [&](const std::string& w) { s += (s.empty() ? "" : "+") + w; };
    if (!(r.dem < tol && r.contacts > 0)) add("dem");
    if (!still) add("kinetic");
    if (c_.coupling.grain_resultant > 0 && !(r.resultant < c_.coupling.grain_resultant)) add("resultant");
    if (!(r.servo < tol)) add("servo");
    for (std::size_t i = 0; i < r.parts.size() && i < parts_.size(); ++i) {
      const fem::FeModel::PartBalance& p = r.parts[i];
      const bool at_rest = c_.coupling.creep > 0 && p.drift < c_.coupling.creep;  // (NaN: no reference yet)
      if (!(p.resultant < tol && (p.norm < tol || at_rest))) add("fe:" + parts_[i]);
    }
    return s;
  }

  /// coupling.creep_damping: the FE damping becomes that fraction of the least over the moving
  /// parts of tolerance x load / (mass x v_c), v_c = coupling.creep / the check interval, at most
  /// fem.damping (a part with no load yet leaves it there).
  void set_creep_damping(const Ratios& r) {
    const double vc = c_.coupling.creep / (static_cast<double>(check_every()) * dt_);
    double c = c_.fem.damping;
    for (const fem::FeModel::PartBalance& p : r.parts)
      if (p.mass > 0 && p.load > 0) c = std::min(c, c_.coupling.creep_damping * tolerance() * p.load / (p.mass * vc));
    fe_.model->set_damping(c);
  }

  void begin_hold(const RunState& st) override {
    if (walls_) walls_->begin(st.hold);
    fem::FeModel& model = *fe_.model;
    model.mark_check();  // a hold's first check: the drift since its start
    const bool removed = begin_fe_hold(c_, fe_, st.hold);
    if (removed && coupler_.dt_fe() > c_.fem.safety * model.critical_dt() && rank_ == 0)
      std::printf("fdem: warning: after the element removal of hold %zu the FE step %.3e s exceeds the FE stable "
                  "step %.3e s\n", st.hold + 1, coupler_.dt_fe(), c_.fem.safety * model.critical_dt());
    if (removed) {  // the interface of the remaining elements (a void's walls exposed)
      const std::size_t before = coupler_.n_active_triangles();
      coupler_.set_active_triangles(active_at_hold(surface_holds_, st.hold));
      if (rank_ == 0 && !quiet_)
        std::printf("fdem: hold %zu: elements removed; interface triangles %zu -> %zu\n", st.hold + 1, before,
                    coupler_.n_active_triangles());
    }
  }

 private:
  const CaseConfig& c_;
  FeSetup& fe_;
  coupling::Coupler& coupler_;
  CoupledRecorder& rec_;
  const RigidRelease& rigid_;
  WallHolds* walls_;
  const std::vector<coupling::HoldRange>& surface_holds_;
  double grain_mgd_;  // mean grain mass x |g| x mean diameter at the start (J): coupling.kinetic_ratio's unit
  double dt_;         // the DEM step (s): check_every x dt_ is the check interval (coupling.creep_damping)
  bool quiet_;
  int rank_;
  std::vector<std::string> parts_;  // the FE parts' names
  Ratios last_{};                   // the measures of the last check
  std::string held_by_;             // the parts above their tolerance then
  std::int64_t last_step_ = -1;     // its step
  void note(std::int64_t step, const Ratios& r, std::string open) {
    last_ = r;
    held_by_ = std::move(open);
    last_step_ = step;
    if (walls_) walls_->note_check(r.dem, values(r), held_by_);
  }
};

/// holds.csv of a coupled run without load holds on walls (without a `holds` section): one row
/// per hold's end -- hold, step, time, converged, the DEM unbalanced ratio, CoupledHolds' columns,
/// held_by. (With a `holds` section WallHolds writes it, with the walls' columns.)
class CoupledHoldLog : public Observer {
 public:
  CoupledHoldLog(const CoupledHolds& holds, DemEngine& e, const std::string& dir, bool restarted, MPI_Comm comm)
      : holds_(holds), e_(e) {
    std::vector<std::string> cols{"hold", "step", "time", "converged", "unbalanced"};
    const std::vector<std::string> more = holds.columns();
    cols.insert(cols.end(), more.begin(), more.end());
    cols.push_back("held_by");
    // the step is column 1: on a restart the rows after the checkpoint's step are dropped
    csv_ = std::make_unique<CsvWriter>(dir + "/holds.csv", cols, comm, restarted, static_cast<double>(e.step_count()), 1);
  }
  void on_hold_end(const RunState& st) override {
    const Ratios& r = holds_.last_check();
    std::vector<double> row{static_cast<double>(st.hold + 1), static_cast<double>(st.step), e_.time(),
                            st.hold_converged ? 1.0 : 0.0, r.dem};
    const std::vector<double> v = holds_.values(r);
    row.insert(row.end(), v.begin(), v.end());
    csv_->row(row, st.hold_converged || holds_.held_by().empty() ? std::string("none") : holds_.held_by());
  }

 private:
  const CoupledHolds& holds_;
  DemEngine& e_;
  std::unique_ptr<CsvWriter> csv_;
};

/// The coupled run's lines: a hold's end, the progress line, the closing lines.
class CoupledReport : public Observer {
 public:
  CoupledReport(const CaseConfig& c, DemEngine& e, coupling::Coupler& coupler, CoupledRecorder& rec,
                DemRunOutput& out, int subcycle, bool quiet, int rank)
      : c_(c), e_(e), coupler_(coupler), rec_(rec), out_(out), subcycle_(subcycle), quiet_(quiet), rank_(rank) {}
  void on_hold_end(const RunState& st) override {
    if (rank_ != 0 || quiet_) return;
    const Ratios& r = rec_.last();
    const Vec3 F = coupler_.last_update_force();
    std::printf("hold %zu/%zu: load factor %g, displacement factor %g, unbalanced DEM %.3e FE %.3e, interface "
                "force (%.4g, %.4g, %.4g) N, step %lld\n",
                st.hold + 1, st.holds, fe_load_factor(c_, st.hold), fe_disp_factor(c_, st.hold), r.dem, r.fe, F.x, F.y,
                F.z, static_cast<long long>(st.step));
    std::fflush(stdout);
  }
  void on_progress(const RunState& st) override {
    const Ratios r = rec_.ratios();
    const Vec3 F = coupler_.last_update_force();
    if (rank_ != 0) return;
    const std::int64_t k = st.step;
    const double el = MPI_Wtime() - st.loop_wall0;
    const double eta = k > st.loop_step0 ? el / (k - st.loop_step0) * (st.end_step - k) : -1;
    std::printf("step %lld/%lld  t %.4e s  hold %zu/%zu  interface F (%.3e, %.3e, %.3e) N  unbalanced DEM %.3e "
                "FE %.3e  left %s\n",
                static_cast<long long>(k), static_cast<long long>(st.end_step), e_.time(), st.hold + 1, st.holds, F.x,
                F.y, F.z, r.dem, r.fe, hms(eta).c_str());
    std::fflush(stdout);
  }
  void on_finish(const RunState& st) override {
    if (fe_holds_mode(c_) && !st.holds_finished && rank_ == 0)
      std::printf("fdem: time.steps / duration reached in hold %zu of %zu before the holds converged\n", st.hold + 1,
                  st.holds);
    if (quiet_) return;
    out_.print_summary();
    const Vec3 F = coupler_.last_update_force();
    if (rank_ == 0)
      std::printf("fdem: %lld FE steps (every %d DEM steps); interface force (%.6g, %.6g, %.6g) N\n",
                  static_cast<long long>(coupler_.fe_steps()), subcycle_, F.x, F.y, F.z);
  }

 private:
  const CaseConfig& c_;
  DemEngine& e_;
  coupling::Coupler& coupler_;
  CoupledRecorder& rec_;
  DemRunOutput& out_;
  int subcycle_;
  bool quiet_;
  int rank_;
};

/// run.json of a coupled run: the coupling's timings (slowest rank), element updates/s and the
/// coupling block (collective).
void add_coupling_info(RunInfo& info, const coupling::Coupler& coupler, const fem::FeModel& model,
                       const CoupledSteps& ts, std::size_t n_tris, const CaseConfig& c, MPI_Comm comm) {
  gather_fe_ranks(model, comm, info);
  const auto stages = coupler.timings().stages();
  std::vector<double> loc, mx(stages.size());
  for (const auto& st : stages) loc.push_back(st.second);
  MPI_Allreduce(loc.data(), mx.data(), static_cast<int>(loc.size()), MPI_DOUBLE, MPI_MAX, comm);
  double fe = 0;
  for (std::size_t k = 0; k < stages.size(); ++k) {
    info.timings.push_back({stages[k].first, mx[k]});
    if (std::string(stages[k].first) == "coupling_fe") fe = mx[k];
  }
  info.element_updates_per_second =
      fe > 0 ? static_cast<double>(coupler.fe_steps()) * static_cast<double>(model.n_elements_global()) / fe : 0;
  info.coupling = {{"subcycle", static_cast<double>(ts.subcycle)},
                   {"dt_dem", ts.dt_dem},
                   {"dt_fe", coupler.dt_fe()},
                   {"dt_fe_stable", ts.dt_fe_stable},
                   {"dt_fe_critical_alone", ts.dt_fe_alone},
                   {"k_interface", ts.k_interface},
                   {"k_interface_node", ts.k_node},
                   {"dt_dem_clamped", ts.clamped ? 1.0 : 0.0},
                   {"mass_scaling", ts.mass_scaling},
                   {"fe_steps", static_cast<double>(coupler.fe_steps())},
                   {"interface_triangles", static_cast<double>(n_tris)},
                   {"rigid_steps", static_cast<double>(c.coupling.rigid_steps)}};
}

/// The start-up line's coupled part.
std::string coupled_start_text(const CaseConfig& c, const FeSetup& fe, const coupling::Coupler& coupler,
                               const CoupledSteps& ts, std::size_t n_tris, std::int64_t step, bool restarted,
                               std::size_t hold) {
  char buf[400];
  std::snprintf(buf, sizeof buf, "\nfdem: coupled: %zu FE nodes, %zu elements, %zu interface triangles; FE every %d DEM "
                "steps (dt_FE %.3e s, FE stable %.3e s incl. interface contact stiffness)%s",
                static_cast<std::size_t>(fe.n_nodes), static_cast<std::size_t>(fe.n_elements), n_tris, ts.subcycle, coupler.dt_fe(), ts.dt_fe_stable,
                fe_holds_mode(c) ? (", " + std::to_string(fe_hold_count(c)) + " hold(s)").c_str() : "");
  std::string text = buf;
  if (!c.fem.ties.empty()) text += "\nfdem: tied " + ties_text(c, fe.meshes);
  if (ts.clamped) {
    const double r = ts.dt_dem_wanted / ts.dt_fe_stable;
    std::snprintf(buf, sizeof buf, "\nfdem: dt clamped to the FE stable step %.3e s (the DEM alone would take %.3e s; "
                  "fem.mass_scaling %.4g, or auto, would let it)", ts.dt_fe_stable, ts.dt_dem_wanted,
                  ts.mass_scaling * r * r);
    text += buf;
  }
  if (ts.mass_scaling_auto) {
    std::snprintf(buf, sizeof buf, "\nfdem: fem.mass_scaling auto: the FE densities x %.6g (the FE stable step = the "
                  "DEM's %.3e s)", ts.mass_scaling, ts.dt_dem_wanted);
    text += buf;
  }
  if (c.coupling.rigid_steps > step)
    text += "\nfdem: structure held rigid for the first " + std::to_string(c.coupling.rigid_steps) + " steps";
  if (restarted) text += "\nfdem: restarting at step " + std::to_string(step) + ", hold " + std::to_string(hold + 1);
  return text;
}

/// The FE state and hold of a restarted run (Setup::restarted): from the checkpoint's group /fe
/// (or, for a checkpoint of an older fdem, fe_checkpoint.h5 next to it), written at the same step
/// at the end of a sub-cycle (nothing of a sub-cycle is lost). hold_start -1: not restarted.
struct FeRestart {
  std::size_t hold = 0;
  std::int64_t hold_start = -1;
  int subcycle = 0;  // the checkpoint's sub-cycle (0: not recorded, or not a restart)
  double mass_scaling = 0;  // the scaling fem.mass_scaling auto chose then (0: not recorded)
};
FeRestart restore_fe_state(const CaseConfig& c, const Setup& s, const RunOptions& opt, FeSetup& fe) {
  FeRestart r;
  if (!s.restarted) return r;
  const std::string path = coupled_fe_state_file(!opt.restart.empty() ? opt.restart : c.restart_from);
  const FeCheckpoint ck = read_fe_checkpoint_for(path, *fe.model, fe.n_nodes, fe.n_elements, fe.comm);
  if (ck.step != s.step)
    throw InputError(path, 0, "FE checkpoint is of step " + std::to_string(ck.step) + ", the DEM checkpoint of step " +
                                  std::to_string(s.step) + ": they are not of the same coupled run");
  // fem.mass_scaling auto: the masses the run had (chosen from the grains at its start), not
  // those the grains now would give
  if (c.fem.mass_scaling_auto && ck.mass_scaling > 0) fe.model->set_density_scale(ck.mass_scaling);
  fe.model->restore(ck.state);
  // coupling.creep_damping: the damping the holds had set (the checkpoint's, in effect then)
  if (c.coupling.creep_damping > 0) fe.model->set_damping(fe.model->damping_used());
  r.mass_scaling = ck.mass_scaling;
  r.hold = static_cast<std::size_t>(ck.hold);
  r.hold_start = ck.hold_start;
  r.subcycle = ck.subcycle;
  return r;
}

/// The DEM and FE states in one file, dir/checkpoint.h5 (FE in its group /fe), after the
/// run-health checks (no checkpoint of a bad state: they throw RunDiverged). Collective.
void write_checkpoint(DemEngine& e, FeSetup& fe, int subcycle, double auto_mass_scaling, const std::string& dir,
                      const RunState& st, bool hold_done, const WallHolds* walls, MPI_Comm comm) {
  e.check_health();
  fe_check_health(fe, "hold " + std::to_string(st.hold + 1) + ", step " + std::to_string(e.step_count()), 0.0);
  fem::FeModel& model = *fe.model;
  FeCheckpoint ck;
  ck.hold = static_cast<std::int64_t>(st.hold);
  ck.hold_done = hold_done ? 1 : 0;
  ck.step = e.step_count();
  ck.hold_start = st.hold_start;
  ck.dim = model.node_dofs();
  ck.subcycle = subcycle;
  ck.mass_scaling = auto_mass_scaling;  // (0 unless fem.mass_scaling is auto)
  ck.state = model.state();
  Checkpoint dem = engine_checkpoint_view(e);
  if (walls) {  // load holds on walls: the settlements' origin (the hold is the FE state's)
    dem.hold = ck.hold;
    dem.hold_start = ck.hold_start;
    dem.wall_start = walls->start();
    dem.wall_check = walls->check_disp();
  }
  write_coupled_checkpoint(dir + "/checkpoint.h5", comm, dem, ck);
}

/// The run loop's parameters of a coupled run: signals are acted on at the end of a sub-cycle.
RunControl::Params coupled_run_params(const CaseConfig& c, std::int64_t end_step, std::size_t holds, std::size_t hold,
                                      std::int64_t hold_start, int subcycle, bool quiet, const std::string& dir) {
  RunControl::Params rp;
  rp.end_step = end_step;
  rp.holds = holds;
  rp.first_hold = hold;
  rp.hold_start = hold_start;
  rp.history_every = c.history_every;
  rp.sync_period = subcycle;
  rp.quiet = quiet;
  rp.progress_interval = c.progress_interval;
  rp.signal_note = dir + "/checkpoint.h5 (DEM and FE state)";
  return rp;
}

}  // namespace

int run_coupled_case(const CaseConfig& c, Setup s, const RunOptions& opt, MPI_Comm comm) {
  check_coupled_options(c, opt);
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);

  // ---- set-up: FE side, interface, time steps, engine, coupler ----
  CoupledFe cf = make_coupled_fe(c, comm);
  const std::unique_ptr<FeSetup>& fe = cf.fe;
  fem::FeModel& model = *fe->model;
  const std::vector<coupling::HoldRange>& surface_holds = cf.holds;  // when each triangle is on the surface (fem.remove)
  const std::size_t n_tris = cf.tris.size();
  CoupledSteps ts = choose_steps(c, s, cf, comm);
  // A restart continues with the checkpoint's DEM step and sub-cycle: choose_steps' bound comes
  // from the particles there are now (fewer after some left the domain, or settled elsewhere),
  // and an automatic sub-cycle chosen from them would change dt_FE and the steps the FE updates
  // at -- the run would leave its trajectory. (Older checkpoints do not record it: chosen again.)
  const bool restarted = s.restarted;
  const double dt_checkpoint = s.params.dt;
  const FeRestart fr = restore_fe_state(c, s, opt, *fe);
  if (c.fem.mass_scaling_auto && fr.mass_scaling > 0) ts.mass_scaling = fr.mass_scaling;
  if (fr.subcycle > 0) {
    ts.subcycle = fr.subcycle;
    ts.dt_dem = dt_checkpoint;
    ts.clamped = false;
  }
  s.params.dt = ts.dt_dem;
  const std::size_t hold = fr.hold;
  const std::int64_t ck_hold_start = fr.hold_start;
  const ParticleSummary ps = summarize_particles(s, comm);
  const std::int64_t n_initial = ps.count;
  const double np_ = std::max<double>(1.0, static_cast<double>(ps.count));
  const double grain_mgd = (ps.mass / np_) * norm(s.params.gravity) * (ps.diameter_sum / np_);
  DemEngine e(comm, s.params, s.materials, s.walls, std::move(s.particles), s.history, s.step, s.time, particle_input(s));
  s.particles = ParticleStore{};
  s.history = {};
  coupling::CouplerParams cp;
  cp.material = c.coupling.material;
  for (std::size_t i = 0; i < c.coupling.surfaces.size(); ++i) cp.group_material.push_back(c.coupling.surface_material(i));
  cp.subcycle = ts.subcycle;
  cp.rigid = c.coupling.rigid_steps > s.step;
  coupling::Coupler coupler(comm, cf.mesh(), model, std::move(cf.tris), cp, e.dt(), std::move(cf.global));
  coupler.set_active_triangles(active_at_hold(surface_holds, hold));
  e.attach(&coupler);
  const std::int64_t end_step = run_end_step(c, e.dt());
  const std::size_t holds = fe_hold_count(c);

  // ---- output: the DEM run's files, then the FE and coupling files in the same directory ----
  DemRunOutput out(c, e, restarted, n_initial, comm);
  const std::string& dir = out.dir();
  if (rank == 0) std::ofstream(dir + "/structures.json") << fe->structures;
  FeSnapshotWriter fe_snaps(dir, "fe", comm);
  if (restarted) fe_snaps.adopt_existing(e.step_count());  // as the particle snapshots (DemRunOutput)
  out.extra = [&](RunInfo& info) { add_coupling_info(info, coupler, model, ts, n_tris, c, comm); };
  CoupledRecorder recorder(c, e, *fe, coupler, out, restarted, comm);
  // A hold begins when the structure is released (or at the start); restarts continue it.
  const std::int64_t hold_start =
      ck_hold_start >= 0 ? ck_hold_start : std::max<std::int64_t>(e.step_count(), c.coupling.rigid_steps);

  begin_fe_hold(c, *fe, hold);
  if (!opt.quiet) out.print_start(end_step, coupled_start_text(c, *fe, coupler, ts, n_tris, e.step_count(), restarted, hold));
  out.fill_info("running");

  const RunControl::Params rp =
      coupled_run_params(c, end_step, holds, hold, hold_start, coupler.subcycle(), opt.quiet, dir);
  RunControl run(comm, rp, [&] { e.step(); }, [&] { return e.step_count(); });
  LoadRamp ramp(c, model, e);
  RigidRelease release(c, coupler, e.step_count(), opt.quiet, rank);
  std::unique_ptr<WallHolds> wall_holds;  // load holds on walls (`holds`)
  if (c.holds.present) {
    wall_holds = std::make_unique<WallHolds>(c, e, dir, restarted, s.wall_start, s.wall_check, opt.quiet, comm,
                                             CoupledHolds::hold_columns(fe_part_names(*fe)));
    wall_holds->apply(hold);
  }
  CoupledHolds schedule(c, *fe, coupler, recorder, release, wall_holds.get(), surface_holds, grain_mgd, e.dt(),
                        opt.quiet, rank);
  std::unique_ptr<CoupledHoldLog> hold_log;  // holds.csv without a `holds` section
  if (!wall_holds && schedule.holds_mode()) hold_log = std::make_unique<CoupledHoldLog>(schedule, e, dir, restarted, comm);
  HistoryObserver history([&](const RunState& st) { recorder.record(st); }, true);
  // micro-mechanics measurements (case key `measure`; the same files as a particle run; the
  // interface contacts count like wall contacts), also at the end of every hold: the states a
  // load-step analysis reports
  std::unique_ptr<MeasureRun> measure_run;
  if (c.measure.present) measure_run = std::make_unique<MeasureRun>(c.measure, e, dir, restarted, comm);
  MeasureObserver measure(measure_run.get());
  SnapshotObserver snapshots(c.snapshot_every, [&] {
    out.snapshot();
    fe_snaps.write(e.step_count(), e.time(), fe_snapshot_data(*fe));
  });
  // The DEM and FE states in one file, checkpoint.h5 (FE in its group /fe), written to a
  // temporary name and renamed: a kill at any moment leaves the previous pair or the new one.
  CheckpointObserver checkpoints(out, c.checkpoint_every, coupler.subcycle(), opt.quiet,
                                 [&](const RunState& st, bool hold_done) {
    write_checkpoint(e, *fe, coupler.subcycle(), ts.mass_scaling_auto ? ts.mass_scaling : 0.0, dir, st, hold_done,
                     wall_holds.get(), comm);
  });
  RunJsonObserver run_json(out);
  CoupledReport report(c, e, coupler, recorder, out, ts.subcycle, opt.quiet, rank);
  run.add(ramp);
  run.add(release);
  run.set_schedule(schedule);
  run.add(history);
  if (wall_holds) {
    run.add(static_cast<Observer&>(*wall_holds));  // (holds.csv at each hold's end)
    run.add(static_cast<Controller&>(*wall_holds));  // (walls held by displacement)
  }
  if (hold_log) run.add(*hold_log);
  for (Observer* o : std::initializer_list<Observer*>{&measure, &snapshots, &checkpoints, &run_json, &report})
    run.add(*o);
  return run.run(!restarted);
}

}  // namespace fdem
