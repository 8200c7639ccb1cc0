// Specimen preparation: multi-layer gravitational packing and radius expansion (packing.hpp).
#include "app/packing.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <optional>
#include <random>
#include <sstream>

#include "app/measurements.hpp"
#include "dem/generate.hpp"
#include "io/checkpoint.hpp"
#include "io/packing_checkpoint.hpp"
#include "base/errors.hpp"
#include "io/run_info.hpp"
#include "base/allgather.hpp"
#include "base/collective_error.hpp"
#include "base/exact_sum.hpp"

namespace fdem {
namespace {

constexpr double kPi = 3.14159265358979323846;

double sphere_volume(double r) { return 4.0 / 3.0 * kPi * r * r * r; }

/// A rank's share of the packing between two engines: the particles it owned when the last
/// engine stopped (any order) and the contact records it was responsible for (each contact on
/// one rank). The next engine takes them as shares (ParticleInput::kShare): it routes them to
/// their owners and orders them by key, so the packing does not depend on the number of ranks,
/// and no rank ever holds more than its share of the specimen.
struct State {
  ParticleStore mine;
  std::vector<ContactRecord> hist;
  std::vector<Wall> walls;
  std::int64_t step = 0;
  double time = 0;
};

/// The state of engine `e`, its particles moved out (the engine must not step again: no second
/// copy of the grains while both exist).
State state_of(DemEngine& e) {
  State s;
  s.hist = e.history_records();
  s.mine = e.release_particles();
  s.walls = e.walls_const().walls;
  for (Wall& w : s.walls) w.force = Vec3{};
  s.step = e.step_count();
  s.time = e.time();
  return s;
}

/// The case's materials with every contact's friction set to `mu` (the min-of-two rule then
/// gives mu for every pair; pair overrides of the friction are set to mu too).
MaterialTable packing_materials(const CaseConfig& c, double mu) {
  if (c.packing.wall_friction_case) {
    // only the packed grains' own contacts take mu; every pair of the packed material with another
    // keeps the case's effective friction (an override, whatever the min-of-two rule would give)
    const MaterialTable full(c.materials, c.interactions, c.contact_model);
    const int g = c.packing.material;
    std::vector<Material> m = c.materials;
    m[static_cast<std::size_t>(g)].friction = mu;
    std::vector<PairOverride> o = c.interactions;
    for (int j = 0; j < static_cast<int>(m.size()); ++j) {
      auto it = std::find_if(o.begin(), o.end(), [&](const PairOverride& q) {
        return (q.a == g && q.b == j) || (q.a == j && q.b == g);
      });
      if (it == o.end() && j == g) continue;  // (the material's own friction: mu)
      if (it == o.end()) {
        o.emplace_back();
        it = o.end() - 1;
        it->a = g;
        it->b = j;
      }
      it->has_friction = true;
      it->friction = j == g ? mu : full.pair(g, j).friction;
    }
    return MaterialTable(m, o, c.contact_model);
  }
  std::vector<Material> m = c.materials;
  for (Material& q : m) q.friction = mu;
  std::vector<PairOverride> o = c.interactions;
  for (PairOverride& q : o)
    if (q.has_friction) q.friction = mu;
  return MaterialTable(m, o, c.contact_model);
}

std::string fmt(double x) {
  std::ostringstream o;
  o << x;
  return o.str();
}

/// Collective. A non-overlapping random cloud of `solid` m^3 of spheres in [lo, hi]
/// (generate.cpp), ids from `next_id` (advanced past the cloud's on every rank), masses set; this
/// rank's share of it is added to `mine`. packing.placement sequential: every rank generates the
/// whole cloud (the same on any number of ranks) and keeps every P-th grain; cells: every rank
/// generates its block of the cloud's generation cells only.
void add_cloud(const CaseConfig& c, const Vec3& lo, const Vec3& hi, double solid, std::uint64_t seed,
               std::int64_t& next_id, ParticleStore& mine, MPI_Comm comm, double grow = 1.0, int material = -1) {
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  const PackingConfig& k = c.packing;
  if (material < 0) material = k.material;
  ParticleSource src;
  src.kind = ParticleSource::kGenerate;
  src.material = material;
  src.source_file = c.file;
  src.line = k.line;
  src.box_min = lo;
  src.box_max = hi;
  const Vec3 L = hi - lo;
  src.porosity = 1.0 - solid / (L.x * L.y * L.z);
  src.size = k.size;
  src.seed = seed;
  src.max_attempts = k.max_attempts;
  src.placement = k.placement;
  CaseConfig tmp;
  tmp.file = c.file;
  tmp.domain_min = c.domain_min;
  tmp.domain_max = c.domain_max;
  tmp.particles.push_back(src);
  const double rho = c.materials[material].density;
  const auto excluded = [&](const SphereRecord& q) {  // packing.exclude: keep-out cylinders (at the grain's full size)
    bool out = false;
    for (const PackingConfig::Cylinder& cy : k.exclude) out = out || cy.axis_distance(q.x) < cy.radius + grow * q.r;
    return out;
  };
  if (k.placement == ParticleSource::kCells) {
    std::vector<SphereRecord> recs;
    std::optional<InputError> bad;
    try {
      recs = build_particle_share(tmp.particles, tmp.domain_min, tmp.domain_max, rank, size).records;
    } catch (const InputError& e) {
      bad = e;
    }
    agree_on_input_error(bad, comm);  // (a cell that cannot be filled is found by its rank only)
    // the cloud's ids are 0 .. n - 1 over all ranks (those kept out leave gaps)
    std::int64_t n = 0;
    mine.make_room(mine.size() + recs.size());
    for (const SphereRecord& q : recs) {
      n = std::max(n, q.id + 1);
      if (!excluded(q)) mine.push_back(q.x, {}, {}, q.r, sphere_mass(rho, q.r), next_id + q.id, material, 0, q.x);
    }
    MPI_Allreduce(MPI_IN_PLACE, &n, 1, MPI_INT64_T, MPI_MAX, comm);
    next_id += n;
  } else {
    const std::vector<SphereRecord> recs = build_particles(tmp);
    mine.make_room(mine.size() + recs.size() / static_cast<std::size_t>(size) + 1);
    for (const SphereRecord& q : recs) {
      if (excluded(q)) continue;
      const std::int64_t id = next_id++;
      if (id % size == rank) mine.push_back(q.x, {}, {}, q.r, sphere_mass(rho, q.r), id, material, 0, q.x);
    }
  }
  mine.n_owned = mine.size();
}

struct LayerInfo {
  int index = 0;
  std::int64_t added = 0, total = 0, steps = 0;
  bool converged = false;
  std::string criterion = "unbalanced", ended_by = "max_steps";
  std::int64_t window = 0;
  double bulk_porosity = std::nan(""), porosity_change = std::nan(""), kinetic_ratio = std::nan("");
  double unbalanced = 0, kinetic = 0, surface = 0, cloud_top = 0, wall_time = 0;
  double porosity_then = std::nan("");  // interior porosity of the specimen so far, right after the layer
  double balance = std::nan("");  // the ranks' owned particles at the layer's end: max / mean (not checkpointed)
};

/// A finished layer's report as a packing checkpoint's row (io/packing_checkpoint.hpp) and back.
std::array<double, kPackingLayerColumns> layer_row(const LayerInfo& l) {
  const double ended = l.ended_by == "unbalanced" ? 0 : l.ended_by == "porosity" ? 1 : 2;
  return {static_cast<double>(l.index), static_cast<double>(l.added), static_cast<double>(l.total),
          static_cast<double>(l.steps), l.converged ? 1.0 : 0.0, l.criterion == "porosity" ? 1.0 : 0.0, ended,
          static_cast<double>(l.window), l.bulk_porosity, l.porosity_change, l.kinetic_ratio, l.unbalanced,
          l.kinetic, l.surface, l.cloud_top, l.wall_time, l.porosity_then};
}

LayerInfo layer_from_row(const std::array<double, kPackingLayerColumns>& r) {
  LayerInfo l;
  l.index = static_cast<int>(r[0]);
  l.added = static_cast<std::int64_t>(r[1]);
  l.total = static_cast<std::int64_t>(r[2]);
  l.steps = static_cast<std::int64_t>(r[3]);
  l.converged = r[4] != 0;
  l.criterion = r[5] != 0 ? "porosity" : "unbalanced";
  l.ended_by = r[6] == 0 ? "unbalanced" : r[6] == 1 ? "porosity" : "max_steps";
  l.window = static_cast<std::int64_t>(r[7]);
  l.bulk_porosity = r[8];
  l.porosity_change = r[9];
  l.kinetic_ratio = r[10];
  l.unbalanced = r[11];
  l.kinetic = r[12];
  l.surface = r[13];
  l.cloud_top = r[14];
  l.wall_time = r[15];
  l.porosity_then = r[16];
  return l;
}

/// Top of the particles of `p`: the highest particle top (m), at least `floor`.
/// The highest top of the first n particles of a store (at least `floor`).
double surface_of(const ParticleStore& p, double floor, std::size_t n) {
  double z = floor;
  for (std::size_t i = 0; i < n; ++i) z = std::max(z, p.x[i].z + p.r[i]);
  return z;
}

/// The final specimen's measurements and grading (Packer::finish).
struct PackReport {
  double top = 0, wall_time = 0;
  MeasureSpec spec;                // the interior box, then each layer's band of it
  MeasureBox in;
  std::vector<int> band_of_layer;  // index in spec.boxes, or -1
  bool empty_interior = false;
  MeasureResult mr;
  EngineStats est;
  std::vector<double> sieves, req_pass;
  GradingStats gr, gg;             // requested, generated
};

class Packer {
 public:
  Packer(const CaseConfig& c, Setup s, const RunOptions& opt, MPI_Comm comm, const PackingStructure* structure)
      : c_(c), k_(c.packing), s_(std::move(s)), opt_(opt), comm_(comm), structure_(structure) {
    MPI_Comm_rank(comm, &rank_);
    MPI_Comm_size(comm, &size_);
    mats_pack_ = packing_materials(c, k_.friction);
    dmax_ = largest_diameter(k_.size);
    margin_ = k_.margin > 0 ? k_.margin : 2 * dmax_;
    top_margin_ = k_.top_margin > 0 ? k_.top_margin : 3 * dmax_;
    // the case's own particles (if any): a share as they are, or every size_-th of a replicated set
    if (s_.shared) {
      st_.mine = std::move(s_.particles);
      st_.hist = std::move(s_.history);
    } else {
      for (std::size_t i = static_cast<std::size_t>(rank_); i < s_.particles.size(); i += static_cast<std::size_t>(size_))
        st_.mine.push_back(s_.particles.x[i], s_.particles.v[i], s_.particles.w[i], s_.particles.r[i], s_.particles.m[i],
                           s_.particles.id[i], s_.particles.mat[i], s_.particles.blocked[i], s_.particles.x0[i],
                           s_.particles.key[i]);
      for (std::size_t i = static_cast<std::size_t>(rank_); i < s_.history.size(); i += static_cast<std::size_t>(size_))
        st_.hist.push_back(s_.history[i]);
    }
    s_.particles = ParticleStore();
    s_.history.clear();
    s_.shared = true;
    st_.mine.n_owned = st_.mine.size();
    st_.walls = s_.walls;
    // while packing, every wall is fixed except the shaking ones (moved here)
    for (Wall& w : st_.walls) { w.motion = Wall::kFixed; w.vel = Vec3{}; w.schedule.clear(); }
    for (std::size_t i = 0; i < st_.mine.size(); ++i) next_id_ = std::max(next_id_, st_.mine.id[i] + 1);
    MPI_Allreduce(MPI_IN_PLACE, &next_id_, 1, MPI_INT64_T, MPI_MAX, comm_);
  }

  Setup run() {
    wall0_ = MPI_Wtime();
    check_fits();
    if (rank_ == 0 && !opt_.quiet) {
      std::printf("fdem packing: %s, box [%g, %g, %g] .. [%g, %g, %g] m, target porosity %g%s\n",
                  k_.method == PackingConfig::kLayers ? (std::to_string(k_.layers) + " layer(s)").c_str()
                                                      : "radius expansion",
                  k_.box_min.x, k_.box_min.y, k_.box_min.z, k_.box_max.x, k_.box_max.y, k_.box_max.z, k_.porosity,
                  k_.friction > 0 ? (", friction " + fmt(k_.friction)).c_str() : ", frictionless");
      std::fflush(stdout);
    }
    if (!opt_.resume_packing.empty()) resume(opt_.resume_packing);
    if (k_.method == PackingConfig::kLayers) layers();
    else expansion();
    return finish();
  }

 private:
  const CaseConfig& c_;
  const PackingConfig& k_;
  Setup s_;
  RunOptions opt_;
  MPI_Comm comm_;
  int rank_ = 0, size_ = 1;
  MaterialTable mats_pack_;
  double dmax_ = 0, margin_ = 0, top_margin_ = 0, wall0_ = 0;
  std::optional<PackReport> settled_;  // the last layer measured as it settled (settled_state)
  State st_;
  std::int64_t next_id_ = 0, steps_total_ = 0;
  std::vector<LayerInfo> info_;
  std::unique_ptr<DemEngine> e_;
  const PackingStructure* structure_ = nullptr;
  std::size_t joined_ = 0;             // structure parts joined so far (the first joined_ of structure_->parts)
  std::int64_t removed_by_structure_ = 0;
  std::int64_t removed_by_level_ = 0;  // packing.level
  double soil_top_ = std::nan("");     // packing.surcharge: the specimen's surface under it
  std::int64_t surcharge_grains_ = 0;
  double surcharge_weight_ = 0;        // N
  int first_layer_ = 1;                // the layer to pack first (a resumed packing: the one after its checkpoint's)
  /// The layer settling now (packing.layers), for the checkpoint a signal writes: where it began,
  /// its grains before the cloud, its cloud's top, its wall-clock start, and the settling's
  /// porosity history while it runs.
  struct InLayer {
    int index = 0;
    std::int64_t before = 0, start_step = 0, shake_steps = 0;
    double cloud_top = 0, t0 = 0;
    const std::vector<std::pair<std::int64_t, double>>* settle_history = nullptr;
  };
  std::optional<InLayer> in_layer_;
  std::optional<PackingProgress> resumed_layer_;  // a checkpoint's layer stopped while settling: go on with it

  std::string checkpoint_path() const { return c_.out_dir + "/checkpoint.h5"; }

  /// The bed after a finished layer (and the structure, if it has just joined) with the
  /// packer's progress: OUT/checkpoint.h5, from which --restart resumes at the next layer.
  void write_layer_checkpoint() {
    Checkpoint ck;
    ck.step = st_.step;
    ck.time = st_.time;
    ck.dt = e_ ? e_->dt() : 0.0;
    ck.particles_view = &st_.mine;  // (each rank its share)
    ck.contacts = st_.hist;
    for (const Wall& w : st_.walls) ck.walls.push_back({w.disp, w.vel});
    write_checkpoint_file(ck, progress_now());
  }

  /// The bed of the layer settling now, stopped by a signal at a settle check: the engine's
  /// state as it is and the layer's progress (in_layer_), from which --restart goes on with the
  /// settling at this step.
  void write_settling_checkpoint() {
    const InLayer& l = *in_layer_;
    const Checkpoint ck = engine_checkpoint_view(*e_);
    PackingProgress p = progress_now();
    p.layer_in_progress = l.index;
    p.layer_start_step = l.start_step;
    p.layer_shake_steps = l.shake_steps;
    p.layer_before = l.before;
    p.layer_cloud_top = l.cloud_top;
    p.layer_elapsed = MPI_Wtime() - l.t0;
    for (const auto& [n, phi] : *l.settle_history) p.settle_history.push_back({static_cast<double>(n), phi});
    write_checkpoint_file(ck, p);
  }

  /// OUT/checkpoint.h5 (the directory made first by rank 0); collective.
  void write_checkpoint_file(const Checkpoint& ck, const PackingProgress& p) {
    if (rank_ == 0) std::filesystem::create_directories(c_.out_dir);
    MPI_Barrier(comm_);
    write_packing_checkpoint(checkpoint_path(), comm_, ck, p);
  }

  /// The packer's progress between layers (for a checkpoint).
  PackingProgress progress_now() const {
    PackingProgress p;
    p.layers_done = static_cast<std::int32_t>(info_.size());
    p.layers = k_.layers;
    p.next_id = next_id_;
    p.steps_total = steps_total_;
    p.removed_by_structure = removed_by_structure_;
    p.structure_wall = first_structure_wall();
    p.structure_parts = static_cast<std::int32_t>(joined_);
    p.case_walls = static_cast<std::int32_t>(c_.walls.size());
    p.elapsed = MPI_Wtime() - wall0_;
    for (const LayerInfo& li : info_) p.layer_rows.push_back(layer_row(li));
    return p;
  }

  /// Continue the packing of checkpoint `path` (write_layer_checkpoint): the bed, the walls'
  /// positions, the structure if it had joined, the layers' reports; the next layer is the one
  /// after the checkpoint's, and the specimen is the one the packing would have given unstopped.
  void resume(const std::string& path) {
    const std::optional<PackingProgress> pr = read_packing_progress(path);
    const PackingProgress& p = *pr;
    const auto bad = [&](const std::string& why) {
      return InputError(path, 0, "cannot resume the packing of case '" + c_.name + "' from this checkpoint: " + why);
    };
    if (k_.method != PackingConfig::kLayers) throw bad("the case packs by radius expansion, the checkpoint by layers");
    if (p.layers != k_.layers)
      throw bad("it is of a packing in " + std::to_string(p.layers) + " layers, the case has packing.layers " +
                std::to_string(k_.layers));
    if (p.case_walls != static_cast<std::int32_t>(c_.walls.size()))
      throw bad("it has " + std::to_string(p.case_walls) + " walls of the case, the case defines " +
                std::to_string(c_.walls.size()));
    const std::size_t parts = structure_ ? structure_->parts.size() : 0;
    // (a checkpoint of fdem before packing.structures: the whole structure joined at once)
    const std::size_t joined = p.structure_parts >= 0 ? static_cast<std::size_t>(p.structure_parts)
                               : p.structure_wall >= 0 ? parts : 0;
    if (joined > 0 && !structure_) throw bad("the structure had joined its packing; the case has none");
    if (joined > parts)
      throw bad(std::to_string(joined) + " parts of the structure had joined its packing; the case's has " +
                std::to_string(parts));
    std::size_t structure_walls = 0;
    for (std::size_t k = 0; k < joined; ++k) structure_walls += structure_->parts[k].facets.tris.empty() ? 0 : 1;
    if (structure_walls > 0 && p.structure_wall != p.case_walls) throw bad("the structure's wall index is wrong (corrupted)");
    // each rank reads its block of the rows: the next engine routes them to their owners
    Checkpoint ck = read_checkpoint(path, comm_, ReadPart::kShare);
    if (ck.walls.size() != static_cast<std::size_t>(p.case_walls) + structure_walls)
      throw bad("it has " + std::to_string(ck.walls.size()) + " walls (corrupted)");
    std::optional<InputError> wrong;
    for (std::size_t i = 0; i < ck.particles.size() && !wrong; ++i)
      if (ck.particles.mat[i] < 0 || ck.particles.mat[i] >= static_cast<std::int32_t>(c_.materials.size()))
        wrong = bad("particle " + std::to_string(ck.particles.id[i]) + " uses material index " +
                    std::to_string(ck.particles.mat[i]) + ", which the case does not define");
    agree_on_input_error(wrong, comm_);  // found in one rank's share: thrown on every rank
    st_.mine = std::move(ck.particles);
    st_.mine.n_owned = st_.mine.size();
    st_.hist = std::move(ck.contacts);
    for (std::size_t k = 0; k < joined; ++k)
      if (!structure_->parts[k].facets.tris.empty()) st_.walls.push_back(structure_->parts[k].facets);
    joined_ = joined;
    for (std::size_t w = 0; w < st_.walls.size(); ++w) {
      st_.walls[w].disp = ck.walls[w].disp;
      st_.walls[w].vel = ck.walls[w].vel;
    }
    st_.step = ck.step;
    st_.time = ck.time;
    next_id_ = p.next_id;
    steps_total_ = p.steps_total;
    removed_by_structure_ = p.removed_by_structure;
    for (const auto& r : p.layer_rows) info_.push_back(layer_from_row(r));
    first_layer_ = p.layers_done + 1;
    wall0_ -= p.elapsed;
    if (p.layer_in_progress > 0) {
      if (p.layer_in_progress > k_.layers) throw bad("its layer in progress is past the last (corrupted)");
      if (ck.step < p.layer_start_step + p.layer_shake_steps)
        throw bad("its layer in progress was stopped before its shaking ended (corrupted)");
      resumed_layer_ = p;
    }
    if (rank_ == 0 && !opt_.quiet) {
      std::printf("fdem packing: resuming from %s: %d of %d layers done, %lld particles, %lld steps", path.c_str(),
                  p.layers_done, p.layers, static_cast<long long>(ck.particles_total), static_cast<long long>(steps_total_));
      if (p.layer_in_progress > 0)
        std::printf("; layer %d goes on settling at its step %lld", p.layer_in_progress,
                    static_cast<long long>(ck.step - p.layer_start_step));
      std::printf("\n");
      std::fflush(stdout);
    }
  }

  Vec3 box_len() const { return k_.box_max - k_.box_min; }

  /// Does grain (x, r) overlap the structure (centre in an element's box, or closer than r to
  /// its surface)?
  bool overlaps_structure(const Vec3& x, double r) const {
    for (std::size_t k = 0; k < joined_; ++k)
      if (overlaps_part(structure_->parts[k], x, r)) return true;
    return false;
  }
  static bool overlaps_part(const PackingStructure::Part& part, const Vec3& x, double r) {
    for (const auto& b : part.solid_boxes)
      if (x.x >= b[0].x && x.x <= b[1].x && x.y >= b[0].y && x.y <= b[1].y && x.z >= b[0].z && x.z <= b[1].z)
        return true;
    const Wall& w = part.facets;
    for (const auto& t : w.tris) {
      const Vec3 &a = w.verts[t[0]], &b = w.verts[t[1]], &c = w.verts[t[2]];
      bool out = false;
      for (int d = 0; d < 3 && !out; ++d)
        out = x[d] < std::min({a[d], b[d], c[d]}) - r || x[d] > std::max({a[d], b[d], c[d]}) + r;
      if (out) continue;
      int region;
      if (norm2(closest_on_triangle(x, a, b, c, region) - x) < r * r) return true;
    }
    return false;
  }

  /// Collective. Remove the grains with id >= first_id that overlap the structure (and their
  /// contact records).
  void remove_overlapping(std::int64_t first_id) {
    if (joined_ == 0) return;
    removed_by_structure_ += remove_grains(
        [&](std::size_t i) { return st_.mine.id[i] >= first_id && overlaps_structure(st_.mine.x[i], st_.mine.r[i]); });
  }

  /// Collective. Remove the grains of this rank's share for which gone_if(index) holds, and
  /// every rank's contact records of them; returns how many went on all ranks.
  template <class Pred>
  std::int64_t remove_grains(Pred gone_if) {
    ParticleStore& p = st_.mine;
    std::vector<std::int64_t> mine;
    std::size_t j = 0;
    for (std::size_t i = 0; i < p.size(); ++i) {
      if (gone_if(i)) { mine.push_back(p.id[i]); continue; }
      if (j != i) p.copy(i, j);
      ++j;
    }
    p.resize(j);
    p.n_owned = j;
    std::vector<std::int64_t> gone = allgather(mine, comm_);  // (a contact's record may be on another rank)
    if (gone.empty()) return 0;
    std::sort(gone.begin(), gone.end());
    const auto went = [&](std::int64_t id) { return std::binary_search(gone.begin(), gone.end(), id); };
    std::vector<ContactRecord>& h = st_.hist;
    h.erase(std::remove_if(h.begin(), h.end(), [&](const ContactRecord& rec) { return went(rec.a) || (rec.kind == 0 && went(rec.b)); }),
            h.end());
    return static_cast<std::int64_t>(gone.size());
  }

  /// Collective: the particles on all ranks.
  std::int64_t count() const {
    std::int64_t n = static_cast<std::int64_t>(st_.mine.size());
    MPI_Allreduce(MPI_IN_PLACE, &n, 1, MPI_INT64_T, MPI_SUM, comm_);
    return n;
  }

  /// Collective: the top of the specimen, the highest particle top over all ranks (m).
  double surface() const { return max_over_ranks(surface_of(st_.mine, k_.box_min.z, st_.mine.size())); }
  double max_over_ranks(double x) const {
    MPI_Allreduce(MPI_IN_PLACE, &x, 1, MPI_DOUBLE, MPI_MAX, comm_);
    return x;
  }

  /// Collective: the solid volume of the specimen (m^3), summed exactly (the same on any
  /// number of ranks, whatever the split).
  double solid_volume() const {
    exact::ExactSums v(1);
    for (std::size_t i = 0; i < st_.mine.size(); ++i) v.add(0, sphere_volume(st_.mine.r[i]));
    return v.sums(comm_)[0];
  }

  /// Index of the first structure wall in st_.walls (they follow the case's walls), -1 while none.
  int first_structure_wall() const {
    return st_.walls.size() > c_.walls.size() ? static_cast<int>(c_.walls.size()) : -1;
  }

  /// The parts of the structure that join after `layer` (0: before the first) join the packing,
  /// each a rigid facet wall; grains overlapping them are removed.
  void insert_structure(int layer) {
    if (!structure_) return;
    while (joined_ < structure_->parts.size() && structure_->parts[joined_].after_layer <= layer) {
      const PackingStructure::Part& part = structure_->parts[joined_];
      if (!part.facets.tris.empty()) st_.walls.push_back(part.facets);
      ++joined_;
      const std::int64_t gone =
          remove_grains([&](std::size_t i) { return overlaps_part(part, st_.mine.x[i], st_.mine.r[i]); });
      removed_by_structure_ += gone;
      if (gone > 0) settled_.reset();  // (the last layer's measurement counted them: finish() measures anew)
      if (rank_ == 0 && !opt_.quiet) {
        std::printf("fdem packing: structure '%s' inserted (%zu interface triangles as a rigid wall); %lld grains "
                    "overlapping it removed\n",
                    part.mesh.c_str(), part.facets.tris.size(), static_cast<long long>(gone));
        std::fflush(stdout);
      }
    }
  }

  /// The lowest of the domain's top and the bottoms of the box walls over the container above
  /// `surf` (their name in `name`).
  double cloud_ceiling(double surf, std::string& name) const {
    double top = c_.domain_max.z;
    name = "the domain's top";
    for (const WallConfig& w : c_.walls)
      if (w.kind == WallConfig::kBox && w.min.z > surf && w.min.z < top && w.min.x < k_.box_max.x &&
          w.max.x > k_.box_min.x && w.min.y < k_.box_max.y && w.max.y > k_.box_min.y) {
        top = w.min.z;
        name = "wall '" + w.name + "'";
      }
    return top;
  }

  /// The clouds must fit below the domain's top: estimate the highest cloud before any work.
  void check_fits() const {
    const Vec3 L = box_len();
    double top;
    if (k_.method == PackingConfig::kLayers) {
      const double h = L.z / k_.layers;
      top = k_.box_min.z + (k_.layers - 1) * h + (1 - k_.porosity) * h / k_.cloud_fraction;
    } else {
      top = k_.box_max.z;
    }
    std::string name;
    const double ceiling = cloud_ceiling(k_.box_min.z, name);
    if (top > ceiling)
      throw InputError(c_.file, k_.line,
                       "packing: the loose clouds (solid fraction cloud_fraction " + fmt(k_.cloud_fraction) +
                           ") reach up to z = " + fmt(top) + " m, above " + name + " at z = " + fmt(ceiling) +
                           " m: raise " + (name == "the domain's top" ? std::string("domain.max z") : name) +
                           " to at least " + fmt(top) + ", use more layers or a larger cloud_fraction");
  }

  /// A new engine from the state's shares (moved in: st_ holds no particles until state_of
  /// refills it).
  void build_engine(const MaterialTable& mats, const Vec3& gravity) {
    e_.reset();
    EngineParams prm = s_.params;
    prm.gravity = gravity;
    e_ = std::make_unique<DemEngine>(comm_, prm, mats, st_.walls, std::move(st_.mine), st_.hist, st_.step, st_.time,
                                     ParticleInput::kShare);
    st_.mine = ParticleStore();
    st_.hist.clear();
    st_.hist.shrink_to_fit();
  }

  /// Runs the engine from its step to step `end` on the run loop (app/run_control.hpp). Polls
  /// for signals every `poll_every` steps (0: where `sched` asks); a signal stops the packing
  /// (PackingInterrupted), a settling layer's bed saved for --restart (write_settling_checkpoint).
  void run_steps(std::int64_t end, Controller* ctl, Schedule* sched, int poll_every) {
    RunControl::Params rp;
    rp.end_step = end;
    rp.hold_start = e_->step_count();
    rp.poll_every = poll_every;
    rp.poll_from_hold_start = true;
    rp.quiet = true;  // no progress lines while packing: one line per layer
    RunControl run(comm_, rp, [this] { e_->step(); }, [this] { return e_->step_count(); });
    if (ctl) run.add(*ctl);
    if (sched) run.set_schedule(*sched);
    const int code = run.run(false);
    if (code > 0) {
      // (a layer of the packing; the surcharge's settling, after levelling, goes back to the last
      // layer's checkpoint: --restart levels and pours the surcharge again)
      if (in_layer_ && in_layer_->settle_history && in_layer_->index <= k_.layers) {
        write_settling_checkpoint();
        if (rank_ == 0) {
          std::printf("fdem packing: signal %d: stopping; %s holds the bed in layer %d of %d, settling at its step "
                      "%lld: go on with --restart %s\n",
                      code - 128, checkpoint_path().c_str(), in_layer_->index, k_.layers,
                      static_cast<long long>(e_->step_count() - in_layer_->start_step), checkpoint_path().c_str());
          std::fflush(stdout);
        }
        throw PackingInterrupted{code - 128};
      }
      if (rank_ == 0 && info_.empty()) {
        std::printf("fdem packing: signal %d: stopping (a partial packing is not saved)\n", code - 128);
        std::fflush(stdout);
      } else if (rank_ == 0) {
        std::printf("fdem packing: signal %d: stopping; %s holds the bed after layer %zu of %d: go on with "
                    "--restart %s\n",
                    code - 128, checkpoint_path().c_str(), info_.size(), k_.layers, checkpoint_path().c_str());
        std::fflush(stdout);
      }
      throw PackingInterrupted{code - 128};
    }
  }

  /// packing.shaking: the shaking walls move at v(t) = a w cos(w t) along the direction for the
  /// shake's steps (t at each step's middle), counted from step s0.
  class ShakeWalls : public Controller {
   public:
    ShakeWalls(const PackingConfig& k, DemEngine& e, std::int64_t s0) : k_(k), e_(e), s0_(s0) {}
    void before_step(const RunState& st) override {
      const double om = 2 * kPi * k_.shake_frequency;
      const double t = (static_cast<double>(st.step - s0_) + 0.5) * e_.dt();
      const Vec3 v = (k_.shake_amplitude * om * std::cos(om * t)) * k_.shake_direction;
      for (int w : k_.shake_walls) { e_.walls().walls[w].motion = Wall::kVelocity; e_.walls().walls[w].vel = v; }
    }

   private:
    const PackingConfig& k_;
    DemEngine& e_;
    std::int64_t s0_;
  };

  /// What ends a layer (packing.settle.criterion, docs/case-format.md#packing): checked every
  /// `check_every` steps after the shaking and at settle.max_steps (counted from the layer's
  /// start). A frictionless deposit creeps: grains keep sliding into the pockets below them
  /// long after the porosity has stopped changing noticeably, and every such event leaves net
  /// forces of order m g on the grains around it, so the unbalanced-force ratio (mean net force /
  /// mean contact force) stays at 0.05-0.5 -- the more so the thinner the deposit, the mean
  /// contact force growing with depth -- for 10^5 steps (docs/verification.md#specimens-and-
  /// packing). There the layer is settled when its bulk porosity has stopped changing and no
  /// grain is still falling.
  class Settle : public Schedule {
   public:
    Settle(const Packer& p, DemEngine& e, std::int64_t s0, std::int64_t s1, LayerInfo& li)
        : p_(p), k_(p.k_), e_(e), s0_(s0), s1_(s1), li_(li) {
      by_porosity = k_.settle_criterion == PackingConfig::kPorosity ||
                    (k_.settle_criterion == PackingConfig::kAuto && k_.friction == 0);
      double mean_mass = 0;
      e_ref_ = p.reference_energy(e, mean_mass);
      // default window: the time a grain takes to fall two diameters from rest, 2 sqrt(d/g)
      const double dt = e.dt();
      const double t_fall =
          2 * std::sqrt(e_ref_ / (mean_mass * std::pow(std::max(norm(p.s_.params.gravity), 1e-300), 2)));
      window = k_.settle_window > 0
                   ? k_.settle_window
                   : k_.check_every * std::max<std::int64_t>(
                                          5, static_cast<std::int64_t>(std::ceil(t_fall / dt / k_.check_every)));
    }
    bool by_porosity = false;
    std::int64_t window = 0;
    /// (steps into the layer, bulk porosity) at each check so far
    const std::vector<std::pair<std::int64_t, double>>& history() const { return hist_; }
    /// Go on from a stopped settling's history (a resumed packing).
    void restore(const std::vector<std::array<double, 2>>& h) {
      for (const auto& r : h) hist_.emplace_back(static_cast<std::int64_t>(r[0]), r[1]);
    }

    void check(RunState& st) override {
      if ((st.step - s1_) % k_.check_every != 0 && !st.last) return;
      st.poll_now = true;
      // current ghost positions first: DemEngine::stats() takes the contact forces of pairs with
      // a ghost from the ghost's position, which step() leaves one step old; without this the
      // ratio (and so the step a layer ends at) would depend on the number of ranks
      e_.sync_ghosts();
      const EngineStats es = e_.stats();
      const std::int64_t now = e_.step_count() - s0_;
      const double ke = es.particles > 0 ? es.kinetic_energy / static_cast<double>(es.particles) : 0;
      li_.kinetic_ratio = ke / e_ref_;
      // nothing still falling, whatever the criterion: grains in flight over a specimen at rest
      // barely move the ratio (their m g against many resting contacts), so without this a layer
      // poured onto an existing specimen would end while it is still in the air
      const bool quiet =
          li_.kinetic_ratio < k_.settle_kinetic_ratio && (k_.settle_kinetic <= 0 || ke < k_.settle_kinetic);
      if (now >= k_.settle_min_steps && es.contacts > 0 && es.unbalanced < k_.settle_unbalanced && quiet) {
        li_.converged = true;
        li_.ended_by = "unbalanced";
        st.stop = true;
        return;
      }
      if (!by_porosity) return;
      const double nb = p_.bulk_porosity(e_);
      hist_.emplace_back(now, nb);
      li_.bulk_porosity = nb;
      // the check at least `window` steps back
      std::size_t j = hist_.size();
      while (j > 0 && now - hist_[j - 1].first < window) --j;
      if (j == 0) return;
      li_.porosity_change = std::fabs(nb - hist_[j - 1].second);
      if (now >= k_.settle_min_steps && es.contacts > 0 && li_.porosity_change < k_.settle_porosity_change && quiet) {
        li_.converged = true;
        li_.ended_by = "porosity";
        st.stop = true;
      }
    }

   private:
    const Packer& p_;
    const PackingConfig& k_;
    DemEngine& e_;
    std::int64_t s0_, s1_;
    LayerInfo& li_;
    double e_ref_ = 0;
    std::vector<std::pair<std::int64_t, double>> hist_;  // (steps done, bulk porosity) at each check
  };

  /// Shake (k_.shake_cycles periods) then settle to equilibrium; returns the layer's statistics.
  /// A resumed layer (resumed_layer_) skips what it had done: its shaking and the settle checks
  /// before its stop.
  LayerInfo shake_and_settle(int layer) {
    DemEngine& e = *e_;
    LayerInfo li;
    li.index = layer;
    const bool resumed = resumed_layer_ && resumed_layer_->layer_in_progress == layer;
    const std::int64_t s0 = resumed ? resumed_layer_->layer_start_step : e.step_count();
    std::int64_t n_shake = resumed ? resumed_layer_->layer_shake_steps : 0;
    if (in_layer_) in_layer_->start_step = s0;
    if (!resumed && k_.shake_cycles > 0 && !k_.shake_walls.empty()) {
      n_shake = static_cast<std::int64_t>(std::llround(k_.shake_cycles / k_.shake_frequency / e.dt()));
      ShakeWalls shake(k_, e, s0);
      run_steps(s0 + n_shake, &shake, nullptr, 0);  // (no polls while shaking)
      for (int w : k_.shake_walls) { e.walls().walls[w].motion = Wall::kFixed; e.walls().walls[w].vel = Vec3{}; }
    }
    Settle settle(*this, e, s0, s0 + n_shake, li);
    if (resumed) settle.restore(resumed_layer_->settle_history);
    resumed_layer_.reset();
    if (in_layer_) {
      in_layer_->shake_steps = n_shake;
      in_layer_->settle_history = &settle.history();
    }
    run_steps(std::max(s0 + k_.settle_max_steps, s0 + n_shake), nullptr, &settle, 0);
    if (in_layer_) in_layer_->settle_history = nullptr;
    li.criterion = settle.by_porosity ? "porosity" : "unbalanced";
    li.window = settle.by_porosity ? settle.window : 0;
    e.sync_ghosts();
    const EngineStats st = e.stats();
    li.steps = e.step_count() - s0;
    li.unbalanced = st.unbalanced;
    li.kinetic = st.kinetic_energy;
    li.total = st.particles;
    steps_total_ += li.steps;
    return li;
  }

  /// Collective. m g d of the mean grain of engine e's particles (J): the scale of
  /// settle.kinetic_ratio; the mean mass in `mean_mass` (kg). Exact sums: the same on any number
  /// of ranks.
  double reference_energy(const DemEngine& e, double& mean_mass) const {
    const ParticleStore& p = e.particles();
    exact::ExactSums s(3);
    for (std::size_t i = 0; i < p.n_owned; ++i) {
      s.add(0, p.m[i]);
      s.add(1, 2 * p.r[i]);
      s.add(2, 1.0);
    }
    const std::vector<double> t = s.sums(comm_);
    const double n = std::max(1.0, t[2]);
    const double g = norm(s_.params.gravity);
    mean_mass = t[0] / n;
    return mean_mass * (g > 0 ? g : 9.81) * (t[1] / n);
  }

  /// Collective. Bulk porosity of the specimen, 1 - V_s / (A h) with A the box's section and
  /// h = 2 (z_s - z_floor), z_s the height of the solid's centroid: exact for a column of
  /// uniform porosity, biased by the loose top (used for its changes). Summed in integers (of
  /// 1e-15 of the box's volume, and of that times its height) so that it is the same on any
  /// number of ranks.
  double bulk_porosity(const DemEngine& e) const {
    const ParticleStore& p = e.particles();
    const Vec3 L = box_len();
    const double vu = 1e-15 * L.x * L.y * L.z, zu = 1e-15 * L.x * L.y * L.z * L.z;
    std::int64_t loc[2] = {0, 0}, tot[2];
    for (std::size_t i = 0; i < p.n_owned; ++i) {
      const double v = sphere_volume(p.r[i]);
      loc[0] += std::llround(v / vu);
      loc[1] += std::llround(v * (p.x[i].z - k_.box_min.z) / zu);
    }
    MPI_Allreduce(loc, tot, 2, MPI_INT64_T, MPI_SUM, comm_);
    if (tot[0] <= 0 || tot[1] <= 0) return std::nan("");
    const double vs = static_cast<double>(tot[0]) * vu, zc = static_cast<double>(tot[1]) * zu / vs;
    return 1 - vs / (L.x * L.y * 2 * zc);
  }

  MeasureBox interior(double top) const {
    MeasureBox b;
    b.lo = k_.box_min + Vec3{margin_, margin_, margin_};
    b.hi = Vec3{k_.box_max.x - margin_, k_.box_max.y - margin_, top - top_margin_};
    return b;
  }

  /// The highest top of the owned particles of an engine's store (at least the box's floor).
  double surface_of_owned(const ParticleStore& p) const { return surface_of(p, k_.box_min.z, p.n_owned); }

  /// The settled bed's state moved out of its engine (`li`: its report, not yet in info_). When
  /// it is the last (`last`) and nothing follows it (no final steps, no surcharge), it is the
  /// specimen: measured here first, on the engine that settled it, whose contact forces are
  /// computed (an engine built from the state has none before its first step); finish() reports
  /// it unless levelling removed grains since. Measuring before the move keeps one copy of the
  /// grains, not two.
  void settled_state(const LayerInfo& li, bool last) {
    settled_.reset();
    if (last && k_.final_steps == 0 && !k_.surcharge.present) {
      info_.push_back(li);  // (measure_specimen's layer bands count this layer)
      settled_ = measure_specimen(*e_);
      info_.pop_back();
    }
    st_ = state_of(*e_);
  }

  double interior_porosity(DemEngine& e) {
    const double top = max_over_ranks(surface_of_owned(e.particles()));
    MeasureSpec spec;
    spec.box_names = {"interior"};
    spec.boxes = {interior(top)};
    if (!(spec.boxes[0].hi.z > spec.boxes[0].lo.z)) return std::nan("");
    return measure(e, spec).boxes[0].porosity;
  }

  /// The ranks' load balance: the largest number of owned particles over the mean (collective).
  double particle_balance(const DemEngine& e) const {
    const double n = static_cast<double>(e.particles().n_owned);
    double mx = 0, sum = 0;
    int size = 1;
    MPI_Comm_size(comm_, &size);
    MPI_Allreduce(&n, &mx, 1, MPI_DOUBLE, MPI_MAX, comm_);
    MPI_Allreduce(&n, &sum, 1, MPI_DOUBLE, MPI_SUM, comm_);
    return sum > 0 ? mx * size / sum : 1.0;
  }

  void progress(const LayerInfo& li, const char* what) const {
    if (rank_ != 0 || opt_.quiet) return;
    std::string end = li.converged ? "ended by " + li.ended_by : "NOT converged: max_steps";
    if (li.criterion == "porosity" && std::isfinite(li.porosity_change)) {
      char b[160];
      std::snprintf(b, sizeof b, "; bulk porosity %.4f, changed %.1e in %lld steps, kinetic %.1e m g d", li.bulk_porosity,
                    li.porosity_change, static_cast<long long>(li.window), li.kinetic_ratio);
      end += b;
    }
    char bal[64] = "";
    if (std::isfinite(li.balance)) std::snprintf(bal, sizeof bal, ", ranks' particles max/mean %.3f", li.balance);
    // a bed still thinner than the interior's margins (bottom and top) has no interior yet
    char por[80] = "interior porosity - (the bed is thinner than the interior's margins)";
    if (std::isfinite(li.porosity_then)) std::snprintf(por, sizeof por, "interior porosity %.4f", li.porosity_then);
    std::printf("fdem packing: %s %d: %lld particles (+%lld), %lld steps, unbalanced %.3e (%s), surface z %.4g m, "
                "%s, %.1f s%s\n",
                what, li.index, static_cast<long long>(li.total), static_cast<long long>(li.added),
                static_cast<long long>(li.steps), li.unbalanced, end.c_str(), li.surface, por, li.wall_time, bal);
    std::fflush(stdout);
  }

  /// Shake and settle the bed with its new cloud (grains from index `before` on) as layer
  /// `index`, gather it, and its report (started at wall-clock t0).
  LayerInfo settle_layer(int index, std::int64_t before, double cloud_top, double t0) {
    build_engine(mats_pack_, s_.params.gravity);
    in_layer_ = InLayer{index, before, 0, 0, cloud_top, t0, nullptr};
    LayerInfo li = shake_and_settle(index);
    in_layer_.reset();
    li.added = li.total - before;
    li.cloud_top = cloud_top;
    li.porosity_then = interior_porosity(*e_);
    li.balance = particle_balance(*e_);
    settled_state(li, index == k_.layers);
    li.surface = surface();
    li.wall_time = MPI_Wtime() - t0;
    return li;
  }

  void layers() {
    insert_structure(first_layer_ - 1);
    for (int layer = first_layer_; layer <= k_.layers; ++layer) {
      double t0 = MPI_Wtime();
      e_.reset();  // the last layer's engine (its state is in st_): freed before the next cloud
      std::int64_t before = 0;
      double cloud_top = 0;
      if (resumed_layer_ && resumed_layer_->layer_in_progress == layer) {
        // a layer stopped while settling: its cloud is in the bed; it goes on settling
        before = resumed_layer_->layer_before;
        cloud_top = resumed_layer_->layer_cloud_top;
        t0 -= resumed_layer_->layer_elapsed;
      } else {
        before = count();
        cloud_top = add_layer_cloud(layer);
      }
      const LayerInfo li = settle_layer(layer, before, cloud_top, t0);
      info_.push_back(li);
      progress(li, "layer");
      insert_structure(layer);
      write_layer_checkpoint();
    }
  }

  /// Collective. The loose cloud of layer `layer` over the surface, sized so that the specimen
  /// up to the layer's nominal top has the target porosity (none if it has already); returns
  /// the cloud's top (the surface without a cloud).
  double add_layer_cloud(int layer) {
    const Vec3 L = box_len();
    const double area = L.x * L.y;
    const double surf = surface();
    const double solid = solid_volume();
    const double z_nominal = k_.box_min.z + layer * L.z / k_.layers;
    const double need = (1 - k_.porosity) * area * (z_nominal - k_.box_min.z) - solid;
    if (!(need > 0)) return surf;
    const std::int64_t first_id = next_id_;
    double h = need / (area * k_.cloud_fraction);
    double cloud_top = surf + h;
    // the clouds stay below the domain's top and below every box wall over the container (a
    // footing or plate waiting above the specimen for place_on_surface): denser than
    // cloud_fraction if the room is short (generate() says if it is too dense)
    std::string ceiling_name;
    const double ceiling = cloud_ceiling(surf, ceiling_name);
    if (cloud_top > ceiling) {
      cloud_top = ceiling;
      h = cloud_top - surf;
      if (!(h > dmax_))
        throw InputError(c_.file, k_.line, "packing: layer " + std::to_string(layer) + ": no room for the cloud between the surface z = " +
                                               fmt(surf) + " m and " + ceiling_name + " at z = " + fmt(ceiling) + " m");
    }
    add_cloud(c_, {k_.box_min.x, k_.box_min.y, surf}, {k_.box_max.x, k_.box_max.y, cloud_top}, need,
              k_.seed + static_cast<std::uint64_t>(layer), next_id_, st_.mine, comm_);
    remove_overlapping(first_id);
    return cloud_top;
  }

  void expansion() {
    const double t0 = MPI_Wtime();
    const Vec3 L = box_len();
    const double vol = L.x * L.y * L.z;
    const std::int64_t before = count();
    const double solid0 = solid_volume();
    const double need = (1 - k_.porosity) * vol - solid0;
    if (before > 0)
      throw InputError(c_.file, k_.line, "packing: method expansion starts from an empty box; the case also has particles");
    if (need <= 0)
      throw InputError(c_.file, k_.line, "packing: the case's particles already fill the box beyond the target porosity");
    // the cloud at cloud_fraction, its sizes scaled down so that it is the target's grains shrunk
    const double shrink = std::cbrt(k_.cloud_fraction / (1 - k_.porosity));
    CaseConfig c2 = c_;
    c2.packing.size.scale *= shrink;
    const double small_need = need * shrink * shrink * shrink;
    const std::int64_t first_new = next_id_;
    // (placement sequential: the whole cloud is generated on every rank for a moment, each keeping its share)
    add_cloud(c2, k_.box_min, k_.box_max, small_need, k_.seed, next_id_, st_.mine, comm_, 1.0 / shrink);
    insert_structure(k_.layers);  // expansion: the structure is there from the start
    // grow the new particles (ids first_new ...) to their full size in `stages` equal factors:
    // at each stage by the ratio of its factor to the last's (a grain's radius goes with it to
    // whichever rank owns it)
    double got = 0;
    {
      exact::ExactSums v(1);
      for (std::size_t i = 0; i < st_.mine.size(); ++i)
        if (st_.mine.id[i] >= first_new) v.add(0, sphere_volume(st_.mine.r[i]));
      got = v.sums(comm_)[0];
    }
    const double total = std::cbrt(need / got);  // = 1/shrink up to the cloud's count rounding
    const double rho = c_.materials[k_.material].density;
    LayerInfo li;
    li.index = 1;
    double f_last = 1;
    for (int stg = 1; stg <= k_.expansion_stages; ++stg) {
      const double f = std::pow(total, static_cast<double>(stg) / k_.expansion_stages);
      for (std::size_t i = 0; i < st_.mine.size(); ++i)
        if (st_.mine.id[i] >= first_new) {
          st_.mine.r[i] *= f / f_last;
          st_.mine.m[i] = sphere_mass(rho, st_.mine.r[i]);
        }
      f_last = f;
      build_engine(mats_pack_, s_.params.gravity);
      run_steps(e_->step_count() + k_.stage_steps, nullptr, nullptr, k_.stage_steps);  // (a poll after each stage)
      steps_total_ += k_.stage_steps;
      if (stg < k_.expansion_stages) st_ = state_of(*e_);  // (after the last stage the engine settles on)
    }
    li = shake_and_settle(1);
    li.steps += static_cast<std::int64_t>(k_.expansion_stages) * k_.stage_steps;
    li.added = li.total - before;
    li.porosity_then = interior_porosity(*e_);
    li.balance = particle_balance(*e_);
    settled_state(li, true);
    li.surface = surface();
    li.cloud_top = k_.box_max.z;
    li.wall_time = MPI_Wtime() - t0;
    info_.push_back(li);
    progress(li, "expansion");
  }

  Setup finish();
  void warn_inside_exclude() const;
  void level();
  void add_surcharge();
  PackReport measure_specimen(DemEngine& e);
  void write_specimen_txt(const std::string& path, double top) const;
  void write_packing_json(const PackReport& r, const std::string& dir) const;
  void print_report(const PackReport& r, const std::string& dir) const;
  Setup handover();
};

// packing.json's numbers: 10 significant digits
std::string json_num(double x) { return json_number(x, 10); }
std::string json_arr(const std::vector<double>& v) { return json_array(v, 10); }

std::string json_box(const MeasureBox& b) {
  return "{\"min\": " + json_arr({b.lo.x, b.lo.y, b.lo.z}) + ", \"max\": " + json_arr({b.hi.x, b.hi.y, b.hi.z}) + "}";
}

std::string json_measure(const BoxMeasure& m) {
  std::ostringstream o;
  o << "\"particles\": " << json_num(m.particles) << ", \"porosity\": " << json_num(m.porosity)
    << ", \"void_ratio\": " << json_num(m.porosity / (1 - m.porosity))
    << ", \"coordination\": " << json_num(m.z) << ", \"coordination_mech\": " << json_num(m.z_mech)
    << ", \"fabric\": " << json_arr({m.fabric, m.fabric + 6})
    << ", \"stress\": " << json_arr({m.stress, m.stress + 6})
    << ", \"k0\": " << json_num(m.stress[2] != 0 ? 0.5 * (m.stress[0] + m.stress[1]) / m.stress[2] : std::nan(""));
  return o.str();
}

/// Mass % passing of the requested curve at size d (sieve curves: linear between sieves,
/// renormalised to the truncation [lo, hi]).
double sieve_passing(const SizeDistribution& s, double d) {
  auto P = [&](double x) {
    x /= s.scale;
    if (x <= s.sieve_d.front()) {
      const double lo = s.dmin > 0 ? s.dmin : s.sieve_d.front();
      if (x <= lo) return 0.0;
      return s.passing.front() * (x - lo) / (s.sieve_d.front() - lo);
    }
    if (x >= s.sieve_d.back()) return 100.0;
    const std::size_t k = std::upper_bound(s.sieve_d.begin(), s.sieve_d.end(), x) - s.sieve_d.begin();
    const double a = s.sieve_d[k - 1], b = s.sieve_d[k];
    return s.passing[k - 1] + (s.passing[k] - s.passing[k - 1]) * (x - a) / (b - a);
  };
  const double lo = (s.dmin > 0 ? s.dmin : 0.0) * s.scale;
  const double hi = (s.dmax > 0 ? std::min(s.dmax, s.sieve_d.back()) : s.sieve_d.back()) * s.scale;
  const double plo = P(lo), phi = P(hi);
  if (d <= lo) return 0;
  if (d >= hi) return 100;
  return 100 * (P(d) - plo) / (phi - plo);
}

/// The final specimen measured (collective): interior box and layer bands, contacts, grading.
PackReport Packer::measure_specimen(DemEngine& e) {
  PackReport r;
  const ParticleStore& p = e.particles();
  r.top = max_over_ranks(surface_of_owned(p));
  // measurement boxes: the interior, and each layer's band of it
  r.spec.box_names.push_back("interior");
  r.in = interior(k_.surcharge.present ? soil_top_ : r.top);  // (below the surcharge)
  r.spec.boxes.push_back(r.in);
  r.band_of_layer.assign(info_.size(), -1);
  for (std::size_t l = 0; l < info_.size() && info_.size() > 1; ++l) {
    MeasureBox b = r.in;
    b.lo.z = std::max(r.in.lo.z, l == 0 ? r.in.lo.z : info_[l - 1].surface);
    b.hi.z = std::min(r.in.hi.z, info_[l].surface);
    if (l + 1 == info_.size()) b.hi.z = r.in.hi.z;
    if (b.hi.z - b.lo.z > dmax_) {
      r.band_of_layer[l] = static_cast<int>(r.spec.boxes.size());
      r.spec.box_names.push_back("layer" + std::to_string(l + 1));
      r.spec.boxes.push_back(b);
    }
  }
  const MeasureBox& in = r.in;
  r.empty_interior = !(in.hi.z > in.lo.z && in.hi.x > in.lo.x && in.hi.y > in.lo.y);
  if (!r.empty_interior) r.mr = measure(e, r.spec);
  r.est = e.stats();
  r.wall_time = MPI_Wtime() - wall0_;

  // size distribution: generated vs requested (20 000 draws of the requested one, or the curve),
  // on rank 0 (which reports it): the diameters are gathered there (8 bytes a grain)
  std::vector<double> dmine;
  for (std::size_t i = 0; i < p.n_owned; ++i)
    if (p.mat[i] == k_.material) dmine.push_back(2 * p.r[i]);
  const std::vector<double> dgen = gather_to(0, dmine, comm_);
  dmine = {};
  if (k_.size.kind == SizeDistribution::kSieve)
    for (double d : k_.size.sieve_d) r.sieves.push_back(d * k_.size.scale);
  std::vector<double> dreq;
  {
    std::mt19937_64 rng(20130101);
    for (int i = 0; i < 20000; ++i) dreq.push_back(sample_diameter(k_.size, rng));
  }
  if (r.sieves.empty()) {
    const GradingStats g = grading(dreq, {});
    r.sieves = {g.d10, g.d30, g.d50, g.d60};
  }
  r.gg = grading(dgen, r.sieves);
  r.gr = grading(dreq, r.sieves);
  r.req_pass = r.gr.passing;
  if (k_.size.kind == SizeDistribution::kSieve)
    for (std::size_t i = 0; i < r.sieves.size(); ++i) r.req_pass[i] = sieve_passing(k_.size, r.sieves[i]);

  return r;
}

/// Collective. The specimen as a sphere text file (the thesis's format) in id order, written by
/// rank 0 in rounds: each round every rank sends it its next grains by id up to the smallest
/// of the ranks' B-th next ids (at most B from each), so rank 0 never holds more than B grains
/// of each rank (B = 2^18 / P, at least 4 096: ~10 MB a round).
void Packer::write_specimen_txt(const std::string& path, double top) const {
  struct Row {
    std::int64_t id;
    double x, y, z, r;
  };
  std::vector<Row> rows(st_.mine.size());
  for (std::size_t i = 0; i < rows.size(); ++i)
    rows[i] = {st_.mine.id[i], st_.mine.x[i].x, st_.mine.x[i].y, st_.mine.x[i].z, st_.mine.r[i]};
  std::sort(rows.begin(), rows.end(), [](const Row& a, const Row& b) { return a.id < b.id; });
  const std::int64_t n = count();
  std::ofstream f;
  int ok = 1;
  if (rank_ == 0) {
    f.open(path);
    ok = f ? 1 : 0;
  }
  MPI_Bcast(&ok, 1, MPI_INT, 0, comm_);
  if (!ok) throw InputError(c_.file, k_.line, "packing.save: cannot write '" + path + "'");
  if (rank_ == 0)
    f << "# fdem specimen of case '" << c_.name << "': " << n << " particles, box [" << k_.box_min.x << ", "
      << k_.box_min.y << ", " << k_.box_min.z << "] .. [" << k_.box_max.x << ", " << k_.box_max.y << ", "
      << k_.box_max.z << "] m, surface z " << top << " m\n# id x y z r (m)\n";
  const std::size_t B = std::max<std::size_t>(4096, (std::size_t{1} << 18) / static_cast<std::size_t>(size_));
  char b[160];
  for (std::size_t pos = 0;;) {
    std::int64_t bound = pos + B < rows.size() ? rows[pos + B - 1].id : std::numeric_limits<std::int64_t>::max();
    MPI_Allreduce(MPI_IN_PLACE, &bound, 1, MPI_INT64_T, MPI_MIN, comm_);
    const std::size_t end = static_cast<std::size_t>(
        std::upper_bound(rows.begin() + static_cast<std::ptrdiff_t>(pos), rows.end(), bound,
                         [](std::int64_t v, const Row& q) { return v < q.id; }) - rows.begin());
    std::vector<Row> got = gather_to(0, std::vector<Row>(rows.begin() + static_cast<std::ptrdiff_t>(pos),
                                                         rows.begin() + static_cast<std::ptrdiff_t>(end)), comm_);
    pos = end;
    std::sort(got.begin(), got.end(), [](const Row& a, const Row& q) { return a.id < q.id; });
    for (const Row& q : got) {
      std::snprintf(b, sizeof b, "%lld %.17g %.17g %.17g %.17g\n", static_cast<long long>(q.id), q.x, q.y, q.z, q.r);
      f << b;
    }
    if (bound == std::numeric_limits<std::int64_t>::max()) break;  // every rank sent all it had left
  }
}

/// packing.json (rank 0).
void Packer::write_packing_json(const PackReport& r, const std::string& dir) const {
  std::ostringstream j;
  j << "{\n  \"case\": " << json_string(c_.name) << ",\n  \"method\": \""
    << (k_.method == PackingConfig::kLayers ? "layers" : "expansion") << "\",\n  \"target_porosity\": "
    << json_num(k_.porosity) << ",\n  \"particles\": " << r.est.particles << ",\n  \"contacts\": " << r.est.contacts
    << ",\n  \"unbalanced\": " << json_num(r.est.unbalanced) << ",\n  \"steps\": " << steps_total_
    << ",\n  \"wall_time\": " << json_num(r.wall_time) << ",\n  \"surface_z\": " << json_num(r.top)
    << ",\n  \"interior_box\": " << json_box(r.in) << ",\n  \"interior\": {";
  if (!r.empty_interior) j << json_measure(r.mr.boxes[0]);
  j << "},\n  \"layers\": [";
  for (std::size_t l = 0; l < info_.size(); ++l) {
    const LayerInfo& li = info_[l];
    j << (l ? "," : "") << "\n    {\"layer\": " << li.index << ", \"added\": " << li.added << ", \"total\": " << li.total
      << ", \"steps\": " << li.steps << ", \"converged\": " << (li.converged ? "true" : "false")
      << ", \"criterion\": \"" << li.criterion << "\", \"ended_by\": \"" << li.ended_by << "\""
      << ", \"bulk_porosity\": " << json_num(li.bulk_porosity) << ", \"porosity_change\": " << json_num(li.porosity_change)
      << ", \"window\": " << li.window << ", \"kinetic_ratio\": " << json_num(li.kinetic_ratio)
      << ", \"unbalanced\": " << json_num(li.unbalanced) << ", \"surface_z\": " << json_num(li.surface)
      << ", \"cloud_top\": " << json_num(li.cloud_top) << ", \"porosity_after_layer\": " << json_num(li.porosity_then)
      << ", \"wall_time\": " << json_num(li.wall_time) << ", \"rank_balance\": " << json_num(li.balance);
    if (r.band_of_layer[l] >= 0 && !r.empty_interior)
      j << ", \"band\": " << json_box(r.spec.boxes[r.band_of_layer[l]]) << ", " << json_measure(r.mr.boxes[r.band_of_layer[l]]);
    j << "}";
  }
  j << "\n  ],\n  \"grading\": {\"sieves\": " << json_arr(r.sieves) << ", \"requested_passing\": " << json_arr(r.req_pass)
    << ", \"generated_passing\": " << json_arr(r.gg.passing) << ",\n    \"requested\": {\"d10\": " << json_num(r.gr.d10)
    << ", \"d30\": " << json_num(r.gr.d30) << ", \"d50\": " << json_num(r.gr.d50) << ", \"d60\": " << json_num(r.gr.d60)
    << ", \"cu\": " << json_num(r.gr.cu) << ", \"cc\": " << json_num(r.gr.cc) << "},\n    \"generated\": {\"d10\": "
    << json_num(r.gg.d10) << ", \"d30\": " << json_num(r.gg.d30) << ", \"d50\": " << json_num(r.gg.d50)
    << ", \"d60\": " << json_num(r.gg.d60) << ", \"cu\": " << json_num(r.gg.cu) << ", \"cc\": " << json_num(r.gg.cc)
    << "}},\n  \"files\": {\"text\": \"specimen.txt\", \"checkpoint\": \"specimen.h5\"";
  if (!k_.save.empty()) j << ", \"save\": " << json_string(k_.save);
  j << "}";
  if (k_.level)
    j << ",\n  \"level\": {\"z\": " << json_num(k_.box_max.z) << ", \"grains_removed\": " << removed_by_level_ << "}";
  if (k_.surcharge.present) {
    const Vec3 L = box_len();
    j << ",\n  \"surcharge\": {\"material\": " << json_string(c_.materials[k_.surcharge.material].name)
      << ", \"thickness\": " << json_num(k_.surcharge.thickness) << ", \"grains\": " << surcharge_grains_
      << ", \"weight\": " << json_num(surcharge_weight_) << ", \"pressure\": " << json_num(surcharge_weight_ / (L.x * L.y))
      << ", \"soil_surface_z\": " << json_num(soil_top_) << "}";
  }
  if (structure_) {
    const std::vector<PackingStructure::Part>& parts = structure_->parts;
    j << ",\n  \"structure\": {\"inserted_after_layer\": " << (parts.empty() ? 0 : parts.front().after_layer)
      << ", \"triangles\": " << structure_->n_triangles() << ", \"grains_removed\": " << removed_by_structure_
      << ", \"parts\": [";
    for (std::size_t k = 0; k < parts.size(); ++k)
      j << (k ? ", " : "") << "{\"mesh\": " << json_string(parts[k].mesh) << ", \"inserted_after_layer\": "
        << parts[k].after_layer << ", \"triangles\": " << parts[k].facets.tris.size() << "}";
    j << "]}";
  }
  j << "\n}\n";
  std::ofstream(dir + "/packing.json") << j.str();
}

/// The closing report on stdout (rank 0).
void Packer::print_report(const PackReport& r, const std::string& dir) const {
  std::printf("fdem packing: done: %lld particles, %lld steps, %.1f s; specimen surface z %.4g m\n",
              static_cast<long long>(r.est.particles), static_cast<long long>(steps_total_), r.wall_time, r.top);
  std::printf("fdem packing: interior box [%.4g, %.4g, %.4g] .. [%.4g, %.4g, %.4g] m (%.3g m from the sides and "
              "bottom, %.3g m below the surface)\n",
              r.in.lo.x, r.in.lo.y, r.in.lo.z, r.in.hi.x, r.in.hi.y, r.in.hi.z, margin_, top_margin_);
  auto line = [&](const char* name, const BoxMeasure& m) {
    std::printf("  %-9s particles %6.0f  porosity %.4f  void ratio %.4f  Z %.3f  fabric (xx yy zz) %.3f %.3f %.3f  "
                "K0 %.3f\n",
                name, m.particles, m.porosity, m.porosity / (1 - m.porosity), m.z, m.fabric[0], m.fabric[1],
                m.fabric[2], 0.5 * (m.stress[0] + m.stress[1]) / m.stress[2]);
  };
  if (!r.empty_interior) {
    if (r.est.contacts == 0)
      std::printf("  (no contact forces in this state, so no coordination, fabric or K0: levelled with no "
                  "packing.final_steps; give it some steps)\n");
    line("interior", r.mr.boxes[0]);
    for (std::size_t l = 0; l < info_.size(); ++l)
      if (r.band_of_layer[l] >= 0) line(("layer " + std::to_string(l + 1)).c_str(), r.mr.boxes[r.band_of_layer[l]]);
  }
  std::printf("  grading   requested D10 %.4g D50 %.4g D60 %.4g Cu %.3f | generated D10 %.4g D50 %.4g D60 %.4g "
              "Cu %.3f (m)\n",
              r.gr.d10, r.gr.d50, r.gr.d60, r.gr.cu, r.gg.d10, r.gg.d50, r.gg.d60, r.gg.cu);
  std::printf("  passing   at");
  for (double d : r.sieves) std::printf(" %.4g", d);
  std::printf(" m: requested");
  for (double p : r.req_pass) std::printf(" %.1f", p);
  std::printf(" %%, generated");
  for (double p : r.gg.passing) std::printf(" %.1f", p);
  std::printf(" %%\nfdem packing: wrote %s/packing.json, %s/specimen.txt, %s/specimen.h5%s%s\n", dir.c_str(),
              dir.c_str(), dir.c_str(), k_.save.empty() ? "" : ", ", k_.save.c_str());
  std::fflush(stdout);
}

/// The set-up to continue with: friction restored, walls back to the case's motions.
Setup Packer::handover() {
  Setup out = std::move(s_);
  out.particles = std::move(st_.mine);  // this rank's share
  out.particles.n_owned = out.particles.size();
  out.shared = true;
  for (std::size_t i = 0; i < out.particles.size(); ++i) out.particles.x0[i] = out.particles.x[i];
  out.history.clear();
  for (const ContactRecord& rec : st_.hist)  // contacts with the structure's wall start afresh on its interface
    if (!(rec.kind == 1 && rec.b >= static_cast<std::int64_t>(c_.walls.size()))) out.history.push_back(rec);
  for (std::size_t w = 0; w < out.walls.size(); ++w) {
    out.walls[w].disp = st_.walls[w].disp;
    out.walls[w].vel = Vec3{};
  }
  out.wall_vel.clear();
  out.step = 0;
  out.time = 0;
  out.restarted = false;
  e_.reset();
  return out;
}

/// packing.level: the grains whose centre lies above the box's top are removed (and their
/// contact records), the surface struck off level as a laboratory specimen's is.
void Packer::level() {
  if (!k_.level) return;
  const double top = k_.box_max.z;
  const double before_top = surface();
  removed_by_level_ = remove_grains([&](std::size_t i) { return st_.mine.x[i].z > top; });
  if (rank_ == 0 && !opt_.quiet) {
    std::printf("fdem packing: levelled at z %.4g m (the box's top): %lld grains above it removed (the surface was at "
                "z %.4g m)%s\n",
                top, static_cast<long long>(removed_by_level_), before_top,
                removed_by_level_ == 0 ? "; the layers did not reach the top: lower packing.porosity to overfill the box" : "");
    std::fflush(stdout);
  }
}

/// packing.exclude keeps the cloud out of its cylinders, not the grains that later roll in (over
/// the top of a structure lower than the layers' overfill, or through a gap): say so, once.
/// Collective.
void Packer::warn_inside_exclude() const {
  for (std::size_t k = 0; k < k_.exclude.size(); ++k) {
    const PackingConfig::Cylinder& cy = k_.exclude[k];
    std::int64_t n = 0;
    for (std::size_t i = 0; i < st_.mine.size(); ++i) n += cy.axis_distance(st_.mine.x[i]) < cy.radius;
    MPI_Allreduce(MPI_IN_PLACE, &n, 1, MPI_INT64_T, MPI_SUM, comm_);
    if (n > 0 && rank_ == 0)
      std::fprintf(stderr,
                   "fdem packing: warning: %lld grain centre(s) inside packing.exclude[%zu] (radius %g m) at the end "
                   "of packing: they entered after placement (over the top of the structure that fills it, or "
                   "through a gap); make it reach above the layers' overfill (%s:%d)\n",
                   static_cast<long long>(n), k, cy.radius, c_.file.c_str(), k_.line);
  }
}

/// packing.surcharge: a layer of the surcharge material rained on the finished specimen and
/// settled like a layer.
void Packer::add_surcharge() {
  const PackingConfig::Surcharge& u = k_.surcharge;
  if (!u.present) return;
  const double t0 = MPI_Wtime();
  if (u.thickness < dmax_)
    throw InputError(c_.file, u.line, "packing.surcharge.thickness: " + fmt(u.thickness) +
                                          " m is less than the largest grain diameter " + fmt(dmax_) + " m");
  const Vec3 L = box_len();
  const double area = L.x * L.y;
  const double surf = surface();
  soil_top_ = surf;
  const double need = (1 - k_.porosity) * area * u.thickness;
  double top = surf + need / (area * k_.cloud_fraction);
  std::string ceiling_name;
  const double ceiling = cloud_ceiling(surf, ceiling_name);
  if (top > ceiling) {
    top = ceiling;
    if (!(top - surf > dmax_))
      throw InputError(c_.file, u.line, "packing.surcharge: no room for its cloud between the surface z = " + fmt(surf) +
                                            " m and " + ceiling_name + " at z = " + fmt(ceiling) + " m");
  }
  const std::int64_t before = count(), first_id = next_id_;
  e_.reset();  // (as between layers)
  add_cloud(c_, {k_.box_min.x, k_.box_min.y, surf}, {k_.box_max.x, k_.box_max.y, top}, need,
            k_.seed + static_cast<std::uint64_t>(k_.layers) + 1, next_id_, st_.mine, comm_, 1.0, u.material);
  remove_overlapping(first_id);
  const LayerInfo li = settle_layer(k_.layers + 1, before, top, t0);
  surcharge_grains_ = 0;
  exact::ExactSums weight(1);
  for (std::size_t i = 0; i < st_.mine.size(); ++i)
    if (st_.mine.id[i] >= first_id) {
      ++surcharge_grains_;
      weight.add(0, st_.mine.m[i] * norm(s_.params.gravity));
    }
  MPI_Allreduce(MPI_IN_PLACE, &surcharge_grains_, 1, MPI_INT64_T, MPI_SUM, comm_);
  surcharge_weight_ = weight.sums(comm_)[0];
  progress(li, "surcharge");
  if (rank_ == 0 && !opt_.quiet) {
    std::printf("fdem packing: surcharge: %lld grains of '%s', %.4g N over %.4g m2: %.4g Pa on the surface at z %.4g m\n",
                static_cast<long long>(surcharge_grains_), c_.materials[u.material].name.c_str(), surcharge_weight_, area,
                surcharge_weight_ / area, soil_top_);
    std::fflush(stdout);
  }
}

Setup Packer::finish() {
  level();
  add_surcharge();
  // Without final steps the specimen is the last layer's settled state: measure it on the engine
  // that settled it, whose contact forces are computed (the engine built next has none before
  // its first step: the report would show no contacts, fabric and stress); unless levelling or a
  // structure joining after the last layer (insert_structure) removed grains since.
  std::optional<PackReport> settled;
  if (removed_by_level_ == 0) settled = std::move(settled_);  // (measured as the last layer settled)
  settled_.reset();
  // friction restored; optional settle with it
  build_engine(MaterialTable(c_.materials, c_.interactions, c_.contact_model), s_.params.gravity);
  if (k_.final_steps > 0) {
    run_steps(e_->step_count() + k_.final_steps, nullptr, nullptr, 0);
    steps_total_ += k_.final_steps;
  }
  DemEngine& e = *e_;
  PackReport r = settled ? std::move(*settled) : measure_specimen(e);
  r.wall_time = MPI_Wtime() - wall0_;

  const std::string dir = c_.out_dir;
  if (rank_ == 0) std::filesystem::create_directories(dir);
  MPI_Barrier(comm_);
  e.check_health();  // (throws RunDiverged: no specimen of a diverged packing)
  write_checkpoint(dir + "/specimen.h5", comm_, engine_checkpoint_view(e));
  st_ = state_of(e);  // (the grains moved out: the engine is done)
  warn_inside_exclude();
  write_specimen_txt(dir + "/specimen.txt", r.top);
  if (!k_.save.empty()) {
    const std::filesystem::path sp(k_.save);
    if (rank_ == 0 && sp.has_parent_path()) std::filesystem::create_directories(sp.parent_path());
    write_specimen_txt(k_.save, r.top);
  }
  if (rank_ == 0) {
    write_case_yaml(c_, dir);
    write_packing_json(r, dir);
    if (!opt_.quiet) print_report(r, dir);
  }
  return handover();
}

}  // namespace

GradingStats grading(std::vector<double> d, const std::vector<double>& sieves) {
  GradingStats g;
  std::sort(d.begin(), d.end());
  std::vector<double> cum(d.size());
  double tot = 0;
  for (std::size_t i = 0; i < d.size(); ++i) { tot += d[i] * d[i] * d[i]; cum[i] = tot; }
  auto dq = [&](double q) {  // the diameter below which a fraction q of the mass lies
    if (d.empty()) return std::nan("");
    const double target = q * tot;
    const std::size_t i = std::lower_bound(cum.begin(), cum.end(), target) - cum.begin();
    return d[std::min(i, d.size() - 1)];
  };
  g.d10 = dq(0.10); g.d30 = dq(0.30); g.d50 = dq(0.50); g.d60 = dq(0.60);
  g.cu = g.d60 / g.d10;
  g.cc = g.d30 * g.d30 / (g.d10 * g.d60);
  for (double s : sieves) {
    const std::size_t i = std::upper_bound(d.begin(), d.end(), s) - d.begin();
    g.passing.push_back(tot > 0 ? 100.0 * (i ? cum[i - 1] : 0.0) / tot : std::nan(""));
  }
  return g;
}

void print_packing_check(const CaseConfig& c, MPI_Comm comm) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  if (rank != 0) return;
  const PackingConfig& k = c.packing;
  const Vec3 L = k.box_max - k.box_min;
  std::mt19937_64 rng(k.seed);
  double v = 0;
  for (int i = 0; i < 2000; ++i) { const double d = sample_diameter(k.size, rng); v += kPi / 6 * d * d * d; }
  const double grains = (1 - k.porosity) * L.x * L.y * L.z / (v / 2000);
  std::printf("%s: ok\n", c.file.c_str());
  std::printf("  case        %s\n", c.name.c_str());
  std::printf("  domain      [%g, %g, %g] .. [%g, %g, %g] m\n", c.domain_min.x, c.domain_min.y, c.domain_min.z,
              c.domain_max.x, c.domain_max.y, c.domain_max.z);
  std::printf("  packing     %s, box [%g, %g, %g] .. [%g, %g, %g] m, target porosity %g, ~%.0f grains\n",
              k.method == PackingConfig::kLayers ? (std::to_string(k.layers) + " layer(s)").c_str() : "radius expansion",
              k.box_min.x, k.box_min.y, k.box_min.z, k.box_max.x, k.box_max.y, k.box_max.z, k.porosity, grains);
  std::printf("  walls       %zu%s\n", c.walls.size(), k.shake_walls.empty() ? "" : " (shaking ones included)");
  std::printf("  then        %s\n", c.steps > 0 || c.duration > 0 ? "the case's steps from the packed specimen" : "ends after packing");
  std::printf("  output      %s\n", c.out_dir.c_str());
  if (!c.coupling.present) print_pair_table(c);  // (a coupled case prints it after its interface)
}

Setup run_packing(const CaseConfig& c, Setup s, const RunOptions& opt, MPI_Comm comm) {
  return run_packing(c, std::move(s), opt, comm, nullptr);
}

Setup run_packing(const CaseConfig& c, Setup s, const RunOptions& opt, MPI_Comm comm,
                  const PackingStructure* structure) {
  Packer p(c, std::move(s), opt, comm, structure);
  return p.run();
}

}  // namespace fdem
