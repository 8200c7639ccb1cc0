#include "app/measurements.hpp"

#include <algorithm>

#include "io/measure_output.hpp"

namespace fdem {

MeasureSpec measure_spec(const MeasureConfig& c) {
  MeasureSpec s;
  for (const MeasureBoxConfig& b : c.boxes) {
    s.box_names.push_back(b.name);
    s.boxes.push_back(MeasureBox{b.min, b.max});
  }
  s.has_grid = c.has_grid;
  if (c.has_grid) s.grid = MeasureGrid{c.grid_min, c.grid_max, c.grid_divisions};
  for (const MeasureRoseConfig& r : c.roses) s.roses.push_back({r.axes[0], r.axes[1], r.bins, r.plane});
  s.force_network = c.force_network;
  s.particle_displacements = c.particle_displacements;
  return s;
}

void reset_displacement_reference(DemEngine& e) {
  ParticleStore& p = e.particles();
  for (std::size_t i = 0; i < p.n_owned; ++i) p.x0[i] = p.x[i];
}

namespace {

// Particle-particle contacts of every owned particle (its owner sees them all).
std::vector<int> owned_contact_counts(const DemEngine& e, std::size_t nown) {
  std::vector<int> count(nown, 0);
  e.for_each_pair_contact([&](const DemEngine::PairContactView& c) {
    if (c.owns_a) ++count[c.a];
    if (c.owns_b) ++count[c.b];
  });
  return count;
}

// The owned particles: counts and displacements in the box or cell of their centre, solid
// volume in every box and cell they overlap.
void add_particles(const ParticleStore& p, const MeasureSpec& spec, std::size_t nb, std::size_t nc,
                   const std::vector<int>& count, std::vector<MeasureSums>& sums, MeasureResult& res) {
  const MeasureGrid& G = spec.grid;
  for (std::size_t i = 0; i < p.n_owned; ++i) {
    const Vec3& x = p.x[i];
    const double r = p.r[i];
    const Vec3 d = x - p.x0[i];
    for (std::size_t b = 0; b < nb; ++b) {
      const MeasureBox& B = spec.boxes[b];
      if (B.contains(x)) add_particle(sums[b], count[i], d);
      sums[b].solid += sphere_box_volume(x, r, B.lo, B.hi);
    }
    if (nc) {
      const long cell = G.cell_of(x);
      if (cell >= 0) add_particle(sums[nb + cell], count[i], d);
      const auto rx = G.range(0, x.x - r, x.x + r), ry = G.range(1, x.y - r, x.y + r),
                 rz = G.range(2, x.z - r, x.z + r);
      for (int k = rz[0]; k <= rz[1]; ++k)
        for (int j = ry[0]; j <= ry[1]; ++j)
          for (int ii = rx[0]; ii <= rx[1]; ++ii) {
            const std::size_t cc = (static_cast<std::size_t>(k) * G.n[1] + j) * G.n[0] + ii;
            const MeasureBox B = G.cell(cc);
            sums[nb + cc].solid += sphere_box_volume(x, r, B.lo, B.hi);
          }
    }
    if (spec.particle_displacements) {
      res.particle_id.push_back(p.id[i]);
      res.particle_x.push_back(x);
      res.particle_disp.push_back(d);
    }
  }
}

// One particle's side of a contact, to the boxes and the cell holding the particle's centre.
struct ContactSide {
  const ParticleStore& p;
  const MeasureSpec& spec;
  std::size_t nb, nc;
  std::vector<MeasureSums>& sums;
  void operator()(std::uint32_t i, const Vec3& lever, const Vec3& f, const Vec3& n, bool pp) const {
    const Vec3& x = p.x[i];
    for (std::size_t b = 0; b < nb; ++b)
      if (spec.boxes[b].contains(x)) add_contact_side(sums[b], lever, f, n, pp);
    if (nc) {
      const long cell = spec.grid.cell_of(x);
      if (cell >= 0) add_contact_side(sums[nb + cell], lever, f, n, pp);
    }
  }
};

// Every contact of the owned particles (particles, walls, an attached contact source) into the
// sums; the particle contacts also into the roses (per rose: bins counts then bins sums of fn,
// from rose_off) and the force network.
void add_contacts(const DemEngine& e, const MeasureSpec& spec, const ContactSide& side, std::vector<double>& roses,
                  const std::vector<std::size_t>& rose_off, MeasureResult& res) {
  const ParticleStore& p = e.particles();
  const std::size_t nr = spec.roses.size();
  e.for_each_pair_contact([&](const DemEngine::PairContactView& c) {
    const double dist = norm(p.x[c.b] - p.x[c.a]);
    const double delta = p.r[c.a] + p.r[c.b] - dist;
    const Vec3 la = (p.r[c.a] - 0.5 * delta) * c.n, lb = -(p.r[c.b] - 0.5 * delta) * c.n;
    if (c.owns_a) side(c.a, la, -c.force_b, c.n, true);
    if (c.owns_b) side(c.b, lb, c.force_b, c.n, true);
    if (!c.owns_a) return;  // the contact itself: by the owner of the lower id
    for (std::size_t k = 0; k < nr; ++k) {
      const MeasureSpec::Rose& R = spec.roses[k];
      const int bin = rose_bin(c.n, R.a0, R.a1, R.bins);
      if (bin < 0) continue;
      roses[rose_off[k] + bin] += 1;
      roses[rose_off[k] + R.bins + bin] += c.fn;
    }
    if (spec.force_network)
      res.network.push_back({p.id[c.a], p.id[c.b], p.x[c.a], p.x[c.b], c.fn, c.force_b});
  });
  e.for_each_wall_contact([&](const WallSet::ContactView& w) {
    const Vec3 la = (p.r[w.particle] - 0.5 * w.delta) * w.n;
    side(w.particle, la, -w.force_wall, w.n, false);
  });
  // Contacts with an attached contact source (the FE interface of a coupled run): like walls.
  if (const ContactSource* src = e.attached())
    for (const ContactSource::Side& sd : src->sides()) side(sd.particle, sd.lever, sd.force, sd.n, false);
}

// Sum over ranks: boxes and cells, then the roses; the results from the sums.
void reduce_and_finish(MPI_Comm comm, const MeasureSpec& spec, std::size_t nb, std::size_t nc,
                       std::vector<MeasureSums>& sums, const std::vector<double>& roses,
                       const std::vector<std::size_t>& rose_off, MeasureResult& res) {
  std::vector<double> all(sums.size() * MeasureSums::kDoubles + roses.size());
  for (std::size_t k = 0; k < sums.size(); ++k)
    std::copy(sums[k].data(), sums[k].data() + MeasureSums::kDoubles, all.begin() + k * MeasureSums::kDoubles);
  std::copy(roses.begin(), roses.end(), all.begin() + sums.size() * MeasureSums::kDoubles);
  if (!all.empty())
    MPI_Allreduce(MPI_IN_PLACE, all.data(), static_cast<int>(all.size()), MPI_DOUBLE, MPI_SUM, comm);
  for (std::size_t k = 0; k < sums.size(); ++k)
    std::copy(all.begin() + k * MeasureSums::kDoubles, all.begin() + (k + 1) * MeasureSums::kDoubles, sums[k].data());
  const double* rs = all.data() + sums.size() * MeasureSums::kDoubles;
  for (std::size_t b = 0; b < nb; ++b) res.boxes.push_back(finish(sums[b], spec.boxes[b].volume()));
  for (std::size_t c = 0; c < nc; ++c) res.cells.push_back(finish(sums[nb + c], spec.grid.cell(c).volume()));
  for (std::size_t k = 0; k < spec.roses.size(); ++k) {
    const int bins = spec.roses[k].bins;
    res.rose_count.emplace_back(rs + rose_off[k], rs + rose_off[k] + bins);
    res.rose_fn.emplace_back(rs + rose_off[k] + bins, rs + rose_off[k] + 2 * bins);
  }
}

}  // namespace

MeasureResult measure(DemEngine& e, const MeasureSpec& spec) {
  e.sync_ghosts();
  const ParticleStore& p = e.particles();
  const std::size_t nb = spec.boxes.size(), nc = spec.has_grid ? spec.grid.cells() : 0;
  MeasureResult res;
  res.step = e.step_count();
  res.time = e.time();
  const std::vector<int> count = owned_contact_counts(e, p.n_owned);
  std::vector<MeasureSums> sums(nb + nc);
  add_particles(p, spec, nb, nc, count, sums, res);
  const std::size_t nr = spec.roses.size();
  std::vector<double> roses;  // per rose: bins counts then bins sums of fn
  std::vector<std::size_t> rose_off(nr + 1, 0);
  for (std::size_t k = 0; k < nr; ++k) rose_off[k + 1] = rose_off[k] + 2 * spec.roses[k].bins;
  roses.assign(rose_off[nr], 0.0);
  add_contacts(e, spec, ContactSide{p, spec, nb, nc, sums}, roses, rose_off, res);
  reduce_and_finish(e.comm(), spec, nb, nc, sums, roses, rose_off, res);
  return res;
}

MeasureRun::MeasureRun(const MeasureConfig& c, DemEngine& e, const std::string& dir, bool append, MPI_Comm comm)
    : c_(c), e_(e), spec_(measure_spec(c)) {
  out_ = std::make_unique<MeasureWriter>(dir, spec_, comm, append, static_cast<double>(e.step_count()));
}

MeasureRun::~MeasureRun() { e_.at_next_forces(nullptr); }

void MeasureRun::at_start() {
  // at step 0 no contact force is computed yet: measure inside the first step, once they are
  last_ = e_.step_count();
  if (c_.displacement_from >= 0 && last_ == c_.displacement_from) reset_displacement_reference(e_);
  e_.at_next_forces([this] { out_->write(measure(e_, spec_)); });
}

void MeasureRun::at_step(bool force) {
  const std::int64_t k = e_.step_count();
  if (c_.displacement_from >= 0 && k == c_.displacement_from) reset_displacement_reference(e_);
  if (k == last_) return;
  if (!force && k % c_.every != 0) return;
  last_ = k;
  out_->write(measure(e_, spec_));
}

}  // namespace fdem
