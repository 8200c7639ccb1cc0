#include "app/particle_input.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <optional>
#include <stdexcept>
#include <string>
#include <tuple>
#include <vector>

#include "app/engine.hpp"  // HealthLimits
#include "base/alltoall.hpp"
#include "base/collective_error.hpp"
#include "dem/health.hpp"
#include "partition/decomposition.hpp"

namespace fdem {
namespace {

// Where a record came from, in the order of a 1-rank read: its source, and within it the
// sphere file's line, the inline entry's index, or (generated) the id.
struct Origin {
  std::int64_t src = -1, ord = -1;
  bool operator<(const Origin& o) const { return std::tie(src, ord) < std::tie(o.src, o.ord); }
};

std::string origin_name(const CaseConfig& c, const Origin& o) {
  const ParticleSource& s = c.particles[static_cast<std::size_t>(o.src)];
  const std::string P = "particles[" + std::to_string(o.src) + "]";
  if (s.kind == ParticleSource::kFile) return s.path + ":" + std::to_string(o.ord) + " (sphere file of " + P + ")";
  std::string f = s.source_file;
  if (s.line > 0) f += ":" + std::to_string(s.line);
  return f + " (" + P + ".inline.spheres[" + std::to_string(o.ord) + "])";
}

// The file and line an error about a record names.
std::pair<std::string, int> origin_line(const CaseConfig& c, const Origin& o) {
  const ParticleSource& s = c.particles[static_cast<std::size_t>(o.src)];
  if (s.kind == ParticleSource::kFile) return {s.path, static_cast<int>(o.ord)};
  if (s.kind == ParticleSource::kInline) return {s.source_file, s.line};
  return {c.file, 0};
}

// Runs f; an InputError it throws on any rank is thrown on every rank (the lowest rank's).
template <class F>
void agreed(MPI_Comm comm, F&& f) {
  std::optional<InputError> bad;
  try {
    f();
  } catch (const InputError& e) {
    bad = e;
  }
  agree_on_input_error(bad, comm);
}

// Explicit ids unique over every source and rank: each id is checked on rank id mod P. The
// message is the 1-rank one: the first repeat in source order, and where the id was first given.
// Returns the largest explicit id (-1: none).
std::int64_t check_explicit_ids(const CaseConfig& c, const FileShares& fs, MPI_Comm comm) {
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  struct Entry {
    std::int64_t id;
    Origin at;
  };
  std::vector<Entry> mine;
  std::int64_t max_id = -1;
  for (std::size_t i = 0; i < c.particles.size(); ++i) {
    const ParticleSource& s = c.particles[i];
    if (s.kind == ParticleSource::kFile)
      for (std::size_t k = 0; k < fs.records[i].size(); ++k)
        mine.push_back({fs.records[i][k].id, {static_cast<std::int64_t>(i), fs.lines[i][k]}});
    else if (s.kind == ParticleSource::kInline && rank == 0)
      for (std::size_t k = 0; k < s.spheres.size(); ++k)
        if (s.spheres[k].id >= 0) mine.push_back({s.spheres[k].id, {static_cast<std::int64_t>(i), static_cast<std::int64_t>(k)}});
  }
  for (const Entry& e : mine) max_id = std::max(max_id, e.id);
  MPI_Allreduce(MPI_IN_PLACE, &max_id, 1, MPI_INT64_T, MPI_MAX, comm);
  std::vector<int> count;
  std::vector<Entry> send = group_by_rank<Entry>(
      mine.size(), size, [&](std::size_t k) { return static_cast<int>(mine[k].id % size); },
      [&](std::size_t k) { return mine[k]; }, count);
  std::vector<Entry>().swap(mine);
  std::vector<Entry> got = alltoallv(send, count, comm);
  std::vector<Entry>().swap(send);
  std::sort(got.begin(), got.end(), [](const Entry& a, const Entry& b) {
    return std::tie(a.id, a.at.src, a.at.ord) < std::tie(b.id, b.at.src, b.at.ord);
  });
  // this rank's first repeat (by the repeat's origin), and where its id was first given
  struct Repeat {
    std::int64_t id = -1;
    Origin first, again;
  } best;
  for (std::size_t k = 1; k < got.size(); ++k)
    if (got[k].id == got[k - 1].id && (k < 2 || got[k - 2].id != got[k].id)) {
      std::size_t f = k - 1;
      if (best.id < 0 || got[k].at < best.again) best = {got[k].id, got[f].at, got[k].at};
    }
  std::vector<Repeat> all(static_cast<std::size_t>(size));
  MPI_Allgather(&best, sizeof(Repeat), MPI_BYTE, all.data(), sizeof(Repeat), MPI_BYTE, comm);
  const Repeat* r = nullptr;
  for (const Repeat& q : all)
    if (q.id >= 0 && (!r || q.again < r->again)) r = &q;
  if (r) {
    const ParticleSource& s = c.particles[static_cast<std::size_t>(r->again.src)];
    throw InputError(s.source_file, s.line,
                     "duplicate particle id " + std::to_string(r->id) + ": given in " + origin_name(c, r->first) +
                         " and in " + origin_name(c, r->again));
  }
  return max_id;
}

// Input particles overlapping by more than kMaxInputOverlap of the smaller radius, over all
// ranks: the records are sent to the subdomains of the engine's process grid, with a copy to
// every subdomain within 2 r_max (a pair that overlaps is then on the rank of each of its two
// particles).
// The deepest pair (ties: the later origin) is named with the later particle's file and line.
void check_overlaps(const CaseConfig& c, const ParticleShareRecords& sh, MPI_Comm comm) {
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  struct Rec {
    Vec3 x;
    double r;
    std::int64_t id;
    Origin at;
  };
  std::vector<Rec> mine;
  double rmax = 0;
  for (std::size_t i = 0, n = 0; i < sh.count.size(); ++i) {
    const ParticleSource& s = c.particles[i];
    for (std::size_t k = 0; k < sh.count[i]; ++k, ++n) {
      if (sh.everywhere[n] && rank != 0) continue;
      const SphereRecord& q = sh.records[n];
      std::int64_t ord = s.kind == ParticleSource::kFile ? sh.lines[i][k]
                         : s.kind == ParticleSource::kInline ? static_cast<std::int64_t>(k)
                                                             : q.id;
      mine.push_back({q.x, q.r, q.id, {static_cast<std::int64_t>(i), ord}});
      rmax = std::max(rmax, q.r);
    }
  }
  MPI_Allreduce(MPI_IN_PLACE, &rmax, 1, MPI_DOUBLE, MPI_MAX, comm);
  // A process grid whose boxes are at least 4 r_max wide where the domain allows it (else any):
  // each record goes to every rank whose box, widened by 2 r_max, holds its centre, so to at
  // most 2 boxes per direction (8 copies) instead of to every thin slab within reach.
  const double h = 2 * rmax;
  Decomposition dd;
  try {
    dd = Decomposition::create(comm, c.domain_min, c.domain_max, 2 * h);
  } catch (const std::runtime_error&) {
    dd = Decomposition::create(comm, c.domain_min, c.domain_max, 0.0);
  }
  auto for_each_rank = [&](const Vec3& x, auto&& f) {
    int lo[3], hi[3];
    for (int d = 0; d < 3; ++d) {
      lo[d] = dd.slab(d, x[d] - h);
      hi[d] = dd.slab(d, x[d] + h);
    }
    for (int k = lo[2]; k <= hi[2]; ++k)
      for (int j = lo[1]; j <= hi[1]; ++j)
        for (int i = lo[0]; i <= hi[0]; ++i) f(i + dd.dims[0] * (j + dd.dims[1] * k));
  };
  std::vector<int> count(static_cast<std::size_t>(size), 0);
  for (const Rec& q : mine) for_each_rank(q.x, [&](int t) { ++count[static_cast<std::size_t>(t)]; });
  std::vector<std::size_t> at(static_cast<std::size_t>(size), 0);
  for (int k = 1; k < size; ++k) at[k] = at[k - 1] + static_cast<std::size_t>(count[k - 1]);
  std::vector<Rec> send(at.back() + static_cast<std::size_t>(count.back()));
  for (const Rec& q : mine) for_each_rank(q.x, [&](int t) { send[at[static_cast<std::size_t>(t)]++] = q; });
  std::vector<Rec>().swap(mine);
  std::vector<Rec> got = alltoallv(send, count, comm);
  std::vector<Rec>().swap(send);
  // one order on any number of ranks (the received order depends on who read what)
  std::sort(got.begin(), got.end(), [](const Rec& p, const Rec& q) { return p.at < q.at; });
  std::vector<Vec3> x(got.size());
  std::vector<double> r(got.size());
  for (std::size_t k = 0; k < got.size(); ++k) {
    x[k] = got[k].x;
    r[k] = got[k].r;
  }
  const OverlapPair ov = deepest_overlap(x, r, HealthLimits::kMaxInputOverlap);
  struct Found {
    double ratio = 0;
    Rec p, q;  // p before q
  } best;
  if (ov.ratio > 0) best = {ov.ratio, got[ov.i], got[ov.j]};
  std::vector<Found> all(static_cast<std::size_t>(size));
  MPI_Allgather(&best, sizeof(Found), MPI_BYTE, all.data(), sizeof(Found), MPI_BYTE, comm);
  const Found* f = nullptr;
  for (const Found& o : all)
    if (o.ratio > 0 && (!f || o.ratio > f->ratio ||
                        (o.ratio == f->ratio && std::tie(o.q.at, o.p.at) < std::tie(f->q.at, f->p.at))))
      f = &o;
  if (!f) return;
  const Rec &p = f->p, &q = f->q;
  const std::string why = input_overlap_message(p.id, p.x, p.r, q.id, q.x, q.r, f->ratio);
  const auto [file, line] = origin_line(c, q.at);
  throw InputError(file, line, why);
}

}  // namespace

std::string input_overlap_message(std::int64_t id_a, const Vec3& xa, double ra, std::int64_t id_b, const Vec3& xb,
                                  double rb, double ratio) {
  char buf[400];
  std::snprintf(buf, sizeof buf,
                "particles %lld and %lld overlap by %.4g m = %.3g of the smaller radius (limit %g): centres (%g, %g, %g) "
                "and (%g, %g, %g), radii %g and %g; overlapping or coincident input particles blow the run up",
                static_cast<long long>(id_a), static_cast<long long>(id_b), ratio * std::min(ra, rb), ratio,
                HealthLimits::kMaxInputOverlap, xa.x, xa.y, xa.z, xb.x, xb.y, xb.z, ra, rb);
  return buf;
}

bool shared_particle_input(const CaseConfig& c) {
  for (const ParticleSource& s : c.particles)
    if (s.kind == ParticleSource::kFile) return true;
  return has_cell_sources(c.particles);
}

ParticleShareRecords read_particle_share(const CaseConfig& c, MPI_Comm comm) {
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  // 1. each sphere file's part: its byte range, lines numbered after the parts before it
  FileShares fs;
  fs.records.resize(c.particles.size());
  fs.lines.resize(c.particles.size());
  for (std::size_t i = 0; i < c.particles.size(); ++i) {
    const ParticleSource& s = c.particles[i];
    if (s.kind != ParticleSource::kFile) continue;
    FilePart part;
    agreed(comm, [&] {
      std::ifstream probe(s.path);
      if (!probe)
        throw InputError(s.source_file, s.line,
                         "particles[" + std::to_string(i) + "].file: cannot read sphere file '" + s.path + "'");
      part = sphere_file_part(s.path, rank, size);
    });
    std::int64_t before = 0;
    MPI_Exscan(&part.newlines, &before, 1, MPI_INT64_T, MPI_SUM, comm);
    part.first_line = 1 + (rank == 0 ? 0 : before);
    agreed(comm, [&] { fs.records[i] = read_sphere_file(s.path, s.scale, s.offset, s.material, part, &fs.lines[i]); });
    std::int64_t n = static_cast<std::int64_t>(fs.records[i].size());
    MPI_Allreduce(MPI_IN_PLACE, &n, 1, MPI_INT64_T, MPI_SUM, comm);
    if (n == 0) throw InputError(s.path, 0, "the sphere file has no spheres (expected lines 'id x y z r')");
  }
  // 2. explicit ids unique over the ranks, and the first automatic id
  agreed(comm, [&] { fs.max_explicit_id = check_explicit_ids(c, fs, comm); });
  // 3. the records (this rank's cells, its file parts, and every other source)
  ParticleShareRecords sh;
  agreed(comm, [&] { sh = build_particle_share(c.particles, c.domain_min, c.domain_max, rank, size, &fs); });
  // 4. no two input particles overlap
  agreed(comm, [&] { check_overlaps(c, sh, comm); });
  return sh;
}

}  // namespace fdem
