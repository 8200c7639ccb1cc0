// Initial particle set: inline spheres, generated clouds (random sequential addition with a
// uniform grid hash) and the thesis's sphere text format. See docs/case-format.md.
//
// Determinism: all randomness comes from one std::mt19937_64 per generate entry, seeded from the
// entry's seed, and is turned into numbers by our own functions (not std::*_distribution, whose
// algorithms are implementation-defined), so every rank -- and every build -- gets the same cloud.
#include "dem/generate.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>
#include <tuple>

#include "base/files.hpp"
#include "base/errors.hpp"

namespace fdem {
namespace {

constexpr double kPi = 3.14159265358979323846;

/// Uniform in [0, 1) with 53 random bits.
double uniform01(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

/// Standard normal (Box-Muller, one value per call).
double std_normal(std::mt19937_64& rng) {
  double u1;
  do { u1 = uniform01(rng); } while (u1 <= 0);
  const double u2 = uniform01(rng);
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * kPi * u2);
}

/// Size classes of a sieve curve after truncation: [a_k, b_k] with NUMBER weights (cumulative).
struct SieveClasses {
  std::vector<double> a, b, cum;  // cum: cumulative number probability, last = 1
};

/// Mean of d^3 for d uniform in [a, b].
double mean_d3(double a, double b) { return (a + b) * (a * a + b * b) / 4.0; }

SieveClasses sieve_classes(const SizeDistribution& s) {
  SieveClasses c;
  const std::size_t n = s.sieve_d.size();
  const double lo = s.dmin > 0 ? s.dmin : 0, hi = s.dmax > 0 ? s.dmax : std::numeric_limits<double>::infinity();
  std::vector<double> w;
  for (std::size_t k = 0; k < n; ++k) {
    double a, b, frac;
    if (k == 0) {
      if (!(s.passing[0] > 0) || !(s.dmin > 0)) continue;  // nothing below the smallest sieve
      a = s.dmin; b = s.sieve_d[0]; frac = s.passing[0];
    } else {
      a = s.sieve_d[k - 1]; b = s.sieve_d[k]; frac = s.passing[k] - s.passing[k - 1];
    }
    if (!(frac > 0) || !(b > a)) continue;
    // truncation: the passing curve is linear between sieves, so a clipped class keeps the
    // mass share of the part that remains
    const double aa = std::max(a, lo), bb = std::min(b, hi);
    if (!(bb > aa)) continue;
    const double mass = frac * (bb - aa) / (b - a);
    c.a.push_back(aa);
    c.b.push_back(bb);
    w.push_back(mass / mean_d3(aa, bb));  // number weight: mass share / mean particle volume
  }
  double tot = 0;
  for (double x : w) tot += x;
  double run = 0;
  for (double x : w) { run += x; c.cum.push_back(run / tot); }
  if (!c.cum.empty()) c.cum.back() = 1.0;
  return c;
}

double sample_sieve(const SizeDistribution& s, std::mt19937_64& rng) {
  // the classes depend only on `s`; cache the last one (sample_diameter is called in loops)
  thread_local const SizeDistribution* last = nullptr;
  thread_local std::vector<double> last_d, last_p;
  thread_local double last_lo = -1, last_hi = -1;
  thread_local SieveClasses cls;
  if (last != &s || last_d != s.sieve_d || last_p != s.passing || last_lo != s.dmin || last_hi != s.dmax) {
    cls = sieve_classes(s);
    last = &s; last_d = s.sieve_d; last_p = s.passing; last_lo = s.dmin; last_hi = s.dmax;
  }
  if (cls.cum.empty()) throw InputError("", 0, "sieve curve has no mass within [min, max]");
  const double u = uniform01(rng);
  std::size_t k = std::upper_bound(cls.cum.begin(), cls.cum.end(), u) - cls.cum.begin();
  if (k >= cls.cum.size()) k = cls.cum.size() - 1;
  return cls.a[k] + (cls.b[k] - cls.a[k]) * uniform01(rng);
}

std::string fmt(double x) {
  std::ostringstream o;
  o << x;
  return o.str();
}

std::string where(const ParticleSource&, std::size_t index) {
  return "particles[" + std::to_string(index) + "]";
}

/// Random sequential addition of non-overlapping spheres with the given diameters (sorted
/// descending) in the box [lo, hi]. Overlap checks use a uniform grid in which every placed
/// sphere is entered in all cells its bounding box touches, so a query looks only at the cells
/// of the new sphere's bounding box, whatever the size ratio.
std::vector<Vec3> place(const ParticleSource& src, std::size_t index, const std::vector<double>& diam,
                        std::mt19937_64& rng) {
  const Vec3 lo = src.box_min, hi = src.box_max, L = hi - lo;
  const std::size_t n = diam.size();
  std::vector<Vec3> x(n);
  if (n == 0) return x;
  // cell: about the median diameter, enlarged so the grid has at most ~8 cells per sphere
  std::vector<double> sorted = diam;
  std::nth_element(sorted.begin(), sorted.begin() + n / 2, sorted.end());
  double cell = sorted[n / 2];
  const double vol = L.x * L.y * L.z;
  cell = std::max(cell, std::cbrt(vol / (8.0 * static_cast<double>(n) + 64.0)));
  int nc[3];
  for (int k = 0; k < 3; ++k) nc[k] = std::max(1, static_cast<int>(std::ceil(L[k] / cell)));
  std::vector<std::vector<std::uint32_t>> grid(static_cast<std::size_t>(nc[0]) * nc[1] * nc[2]);
  auto cidx = [&](double v, int k) {
    int i = static_cast<int>(std::floor((v - lo[k]) / cell));
    return std::min(std::max(i, 0), nc[k] - 1);
  };
  double solid = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const double r = 0.5 * diam[i];
    for (int k = 0; k < 3; ++k)
      if (!(2 * r <= L[k]))
        throw InputError(src.source_file, src.line,
                         where(src, index) + ".generate: a particle of diameter " + fmt(diam[i]) +
                             " m does not fit in the box (" + std::string(1, "xyz"[k]) + " size " + fmt(L[k]) + " m)");
    bool placed = false;
    Vec3 c;
    for (int att = 0; att < src.max_attempts && !placed; ++att) {
      for (int k = 0; k < 3; ++k) c[k] = lo[k] + r + (L[k] - 2 * r) * uniform01(rng);
      int a0[3], a1[3];
      for (int k = 0; k < 3; ++k) { a0[k] = cidx(c[k] - r, k); a1[k] = cidx(c[k] + r, k); }
      bool overlap = false;
      for (int iz = a0[2]; iz <= a1[2] && !overlap; ++iz)
        for (int iy = a0[1]; iy <= a1[1] && !overlap; ++iy)
          for (int ix = a0[0]; ix <= a1[0] && !overlap; ++ix)
            for (std::uint32_t j : grid[(static_cast<std::size_t>(iz) * nc[1] + iy) * nc[0] + ix]) {
              const double rr = r + 0.5 * diam[j];
              if (norm2(c - x[j]) < rr * rr) { overlap = true; break; }
            }
      placed = !overlap;
    }
    if (!placed) {
      std::string what = src.count > 0 ? "count " + std::to_string(src.count) : "porosity " + fmt(src.porosity);
      throw InputError(src.source_file, src.line,
                       where(src, index) + ".generate: could not place particle " + std::to_string(i + 1) + " of " +
                           std::to_string(n) + " (d = " + fmt(diam[i]) + " m) in " + std::to_string(src.max_attempts) +
                           " attempts; solid fraction reached " + fmt(solid / vol) +
                           "; the box is too dense for the requested " + what +
                           " (random placement stops near a solid fraction of 0.2-0.25 with 100 attempts, 0.3 "
                           "with 1000): use a larger box, fewer particles, a higher porosity or more max_attempts");
    }
    x[i] = c;
    solid += kPi / 6 * diam[i] * diam[i] * diam[i];
    int a0[3], a1[3];
    for (int k = 0; k < 3; ++k) { a0[k] = cidx(c[k] - r, k); a1[k] = cidx(c[k] + r, k); }
    for (int iz = a0[2]; iz <= a1[2]; ++iz)
      for (int iy = a0[1]; iy <= a1[1]; ++iy)
        for (int ix = a0[0]; ix <= a1[0]; ++ix)
          grid[(static_cast<std::size_t>(iz) * nc[1] + iy) * nc[0] + ix].push_back(static_cast<std::uint32_t>(i));
  }
  return x;
}

/// The diameters of a cloud in a box of volume `vol`: `count` draws, or (count 0) draws until the
/// solid volume is closest to (1 - porosity) vol (at least one), from `rng`.
std::vector<double> draw_diameters(const ParticleSource& src, std::size_t index, std::int64_t count, double vol,
                                   std::mt19937_64& rng) {
  std::vector<double> d;
  if (src.count > 0) {
    if (src.count > 50000000)
      throw InputError(src.source_file, src.line, where(src, index) + ".generate: count above 5e7 is not supported");
    d.reserve(static_cast<std::size_t>(count));
    for (std::int64_t i = 0; i < count; ++i) d.push_back(sample_diameter(src.size, rng));
  } else {
    const double target = (1.0 - src.porosity) * vol;
    double solid = 0;
    while (solid < target) {
      const double di = sample_diameter(src.size, rng);
      const double vi = kPi / 6 * di * di * di;
      // stop at the count closest to the target
      if (solid + vi > target && (solid + vi - target) > (target - solid) && !d.empty()) break;
      d.push_back(di);
      solid += vi;
      if (d.size() > 50000000)
        throw InputError(src.source_file, src.line,
                         where(src, index) + ".generate: porosity " + fmt(src.porosity) +
                             " needs more than 5e7 particles in this box");
    }
  }
  return d;
}

/// Placed spheres (diameters d, centres x) in spatial order for memory locality (cells of size
/// d_max from `origin`, z then y then x).
std::vector<SphereRecord> spatially_ordered(const ParticleSource& src, const std::vector<double>& d,
                                            const std::vector<Vec3>& x, const Vec3& origin) {
  double dmax = 0;
  for (double v : d) dmax = std::max(dmax, v);
  if (!(dmax > 0)) dmax = 1.0;
  std::vector<std::tuple<long, long, long, std::size_t>> key(d.size());
  for (std::size_t i = 0; i < d.size(); ++i) {
    const Vec3 q = x[i] - origin;
    key[i] = {static_cast<long>(std::floor(q.z / dmax)), static_cast<long>(std::floor(q.y / dmax)),
              static_cast<long>(std::floor(q.x / dmax)), i};
  }
  std::sort(key.begin(), key.end());
  std::vector<SphereRecord> out(d.size());
  for (std::size_t i = 0; i < d.size(); ++i) {
    const std::size_t j = std::get<3>(key[i]);
    out[i].x = x[j];
    out[i].r = 0.5 * d[j];
    out[i].v = src.velocity;
    out[i].mat = src.material;
  }
  return out;
}

/// A generated cloud (placement: sequential), spatially ordered.
std::vector<SphereRecord> generate(const ParticleSource& src, std::size_t index) {
  std::mt19937_64 rng(src.seed);
  const Vec3 L = src.box_max - src.box_min;
  std::vector<double> d = draw_diameters(src, index, src.count, L.x * L.y * L.z, rng);
  std::stable_sort(d.begin(), d.end(), std::greater<double>());
  const std::vector<Vec3> x = place(src, index, d, rng);
  return spatially_ordered(src, d, x, src.box_min);
}

// ---- placement: cells ----

/// splitmix64's finaliser: a well-mixed 64-bit value from a counter.
std::uint64_t mix64(std::uint64_t z) {
  z += 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

/// The random stream of cell c (independent of the other cells and of who builds it).
std::mt19937_64 cell_stream(const ParticleSource& src, std::int64_t c) {
  return std::mt19937_64(mix64(mix64(src.seed) ^ static_cast<std::uint64_t>(c)));
}

/// Cell c's box.
void cell_box(const GenerationCells& g, std::int64_t c, Vec3& lo, Vec3& hi) {
  const std::int64_t ix = c % g.n[0], iy = (c / g.n[0]) % g.n[1], iz = c / (static_cast<std::int64_t>(g.n[0]) * g.n[1]);
  const std::int64_t i[3] = {ix, iy, iz};
  for (int k = 0; k < 3; ++k) {
    lo[k] = g.lo[k] + static_cast<double>(i[k]) * g.edge[k];
    hi[k] = i[k] + 1 == g.n[k] ? g.lo[k] + g.n[k] * g.edge[k] : g.lo[k] + static_cast<double>(i[k] + 1) * g.edge[k];
  }
}

/// Number of grains of every cell: `count` split evenly (the first count mod C cells one more),
/// or, with a porosity, each cell's draws replayed (cheap: no placement).
std::vector<std::int64_t> cell_counts(const ParticleSource& src, std::size_t index, const GenerationCells& g) {
  const std::int64_t C = g.count();
  std::vector<std::int64_t> n(static_cast<std::size_t>(C));
  if (src.count > 0) {
    for (std::int64_t c = 0; c < C; ++c) n[c] = src.count / C + (c < src.count % C ? 1 : 0);
    return n;
  }
  for (std::int64_t c = 0; c < C; ++c) {
    Vec3 lo, hi;
    cell_box(g, c, lo, hi);
    const Vec3 L = hi - lo;
    std::mt19937_64 rng = cell_stream(src, c);
    n[c] = static_cast<std::int64_t>(draw_diameters(src, index, 0, L.x * L.y * L.z, rng).size());
  }
  return n;
}

/// The grains of cells [c0, c1) (ids unset), cell by cell, each cell's spatially ordered.
std::vector<SphereRecord> generate_cells(const ParticleSource& src, std::size_t index, const GenerationCells& g,
                                         const std::vector<std::int64_t>& counts, std::int64_t c0, std::int64_t c1) {
  std::vector<SphereRecord> out;
  for (std::int64_t c = c0; c < c1; ++c) {
    ParticleSource cell = src;
    cell_box(g, c, cell.box_min, cell.box_max);
    const Vec3 L = cell.box_max - cell.box_min;
    std::mt19937_64 rng = cell_stream(src, c);
    std::vector<double> d = draw_diameters(src, index, counts[c], L.x * L.y * L.z, rng);
    std::stable_sort(d.begin(), d.end(), std::greater<double>());
    std::vector<Vec3> x;
    try {
      x = place(cell, index, d, rng);
    } catch (const InputError& e) {
      std::ostringstream m;
      m << where(src, index) << ".generate (placement: cells): in generation cell " << c << " of " << g.count()
        << " ([" << cell.box_min.x << ", " << cell.box_max.x << "] x [" << cell.box_min.y << ", " << cell.box_max.y
        << "] x [" << cell.box_min.z << ", " << cell.box_max.z << "] m): "
        << std::string(e.what()).substr(InputError::format(src.source_file, src.line, "").size() +
                                        (where(src, index) + ".generate: ").size());
      throw InputError(src.source_file, src.line, m.str());
    }
    const std::vector<SphereRecord> part = spatially_ordered(src, d, x, cell.box_min);
    out.insert(out.end(), part.begin(), part.end());
  }
  return out;
}

/// Two cells sources must not share volume: each fills its box alone.
void check_cell_boxes(const std::vector<ParticleSource>& sources) {
  for (std::size_t j = 0; j < sources.size(); ++j)
    for (std::size_t i = 0; i < j; ++i) {
      const ParticleSource &a = sources[i], &b = sources[j];
      if (a.kind != ParticleSource::kGenerate || b.kind != ParticleSource::kGenerate) continue;
      if (a.placement != ParticleSource::kCells || b.placement != ParticleSource::kCells) continue;
      bool apart = false;
      for (int k = 0; k < 3; ++k) apart = apart || a.box_max[k] <= b.box_min[k] || b.box_max[k] <= a.box_min[k];
      if (!apart)
        throw InputError(b.source_file, b.line,
                         where(b, j) + ".generate: its box overlaps the box of " + where(a, i) +
                             ".generate; two `placement: cells` clouds fill their boxes independently, so their "
                             "boxes must not overlap");
    }
}

std::string origin_text(const std::string& file, int line, const std::string& what) {
  std::string s = file;
  if (line > 0) s += ":" + std::to_string(line);
  return s + " (" + what + ")";
}

}  // namespace

double largest_diameter(const SizeDistribution& s) {
  double d = 0;
  switch (s.kind) {
    case SizeDistribution::kConstant: d = s.d; break;
    case SizeDistribution::kUniform: d = s.dmax; break;
    case SizeDistribution::kNormal: d = s.dmax > 0 ? s.dmax : s.mean + 5 * s.sd; break;
    case SizeDistribution::kSieve:
      d = s.sieve_d.empty() ? 0 : s.sieve_d.back();
      if (s.dmax > 0) d = std::min(d, s.dmax);
      break;
  }
  return d * s.scale;
}

GenerationCells generation_cells(const ParticleSource& src) {
  GenerationCells g;
  g.lo = src.box_min;
  const Vec3 L = src.box_max - src.box_min;
  // 20 largest diameters: a centre keeps its radius from the cell's faces, which leaves
  // (1 - d/edge)^3 = 0.86-0.95 of the cell to the centres (random addition jams earlier than in
  // one box) and makes cells of a few thousand grains
  const double target = 20 * largest_diameter(src.size);
  for (int k = 0; k < 3; ++k) {
    g.n[k] = target > 0 ? static_cast<int>(std::min(1e4, std::max(1.0, std::floor(L[k] / target)))) : 1;
    g.edge[k] = L[k] / g.n[k];
  }
  return g;
}

double sample_diameter(const SizeDistribution& s, std::mt19937_64& rng) {
  double d = 0;
  switch (s.kind) {
    case SizeDistribution::kConstant:
      d = s.d;
      break;
    case SizeDistribution::kUniform:
      d = s.dmin + (s.dmax - s.dmin) * uniform01(rng);
      break;
    case SizeDistribution::kNormal: {
      const double lo = s.dmin > 0 ? s.dmin : 0.0;
      const double hi = s.dmax > 0 ? s.dmax : std::numeric_limits<double>::infinity();
      int tries = 0;
      do {
        d = s.mean + s.sd * std_normal(rng);
        if (++tries > 1000000)
          throw InputError("", 0, "normal size distribution: cannot draw a diameter in [" + fmt(lo) + ", " +
                                      fmt(hi) + "] (mean " + fmt(s.mean) + ", sd " + fmt(s.sd) + ")");
      } while (!(d > 0) || d < lo || d > hi);
      break;
    }
    case SizeDistribution::kSieve:
      d = sample_sieve(s, rng);
      break;
  }
  return d * s.scale;
}

namespace {

// The file's size, or an InputError for a path that is not a readable regular file.
std::uint64_t sphere_file_size(const std::string& path) {
  // stat first: a directory, FIFO (would block) or device is refused before opening
  const std::string problem = input_file_problem(path);
  if (!problem.empty() && problem.rfind("cannot read", 0) != 0)
    throw InputError(path, 0, "sphere file '" + path + "' " + problem);
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) throw InputError(path, 0, "cannot read sphere file '" + path + "'");
  return static_cast<std::uint64_t>(static_cast<std::streamoff>(in.tellg()));
}

// The first line start at or after byte b (b itself when b is 0 or follows a newline).
std::uint64_t line_start_at(std::ifstream& in, std::uint64_t b, std::uint64_t size) {
  if (b == 0 || b >= size) return std::min(b, size);
  in.clear();
  in.seekg(static_cast<std::streamoff>(b - 1));
  std::vector<char> buf(1 << 16);
  std::uint64_t at = b - 1;
  while (at < size) {
    in.read(buf.data(), static_cast<std::streamsize>(buf.size()));
    const std::size_t got = static_cast<std::size_t>(in.gcount());
    if (got == 0) break;
    if (const void* nl = std::memchr(buf.data(), '\n', got))
      return at + static_cast<std::uint64_t>(static_cast<const char*>(nl) - buf.data()) + 1;
    at += got;
  }
  return size;
}

}  // namespace

FilePart sphere_file_part(const std::string& path, int part, int parts) {
  const std::uint64_t size = sphere_file_size(path);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, 0, "cannot read sphere file '" + path + "'");
  FilePart f;
  // byte offsets of the even cut (size * k / parts without overflow for files under 2^63 / parts)
  auto cut = [&](int k) {
    return static_cast<std::uint64_t>((static_cast<unsigned __int128>(size) * static_cast<unsigned>(k)) /
                                      static_cast<unsigned>(parts));
  };
  f.begin = line_start_at(in, cut(part), size);
  f.end = part + 1 >= parts ? size : line_start_at(in, cut(part + 1), size);
  if (f.end < f.begin) f.end = f.begin;
  in.clear();
  in.seekg(static_cast<std::streamoff>(f.begin));
  std::vector<char> buf(1 << 20);
  for (std::uint64_t at = f.begin; at < f.end;) {
    const std::size_t want = static_cast<std::size_t>(std::min<std::uint64_t>(buf.size(), f.end - at));
    in.read(buf.data(), static_cast<std::streamsize>(want));
    const std::size_t got = static_cast<std::size_t>(in.gcount());
    if (got == 0) break;
    f.newlines += std::count(buf.data(), buf.data() + got, '\n');
    at += got;
  }
  if (in.bad()) throw InputError(path, 0, "read error");
  return f;
}

std::vector<SphereRecord> read_sphere_file(const std::string& path, double scale, const Vec3& offset, int material,
                                           const FilePart& part, std::vector<std::int64_t>* lines) {
  sphere_file_size(path);  // a directory, FIFO or unreadable path: refused before opening
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, 0, "cannot read sphere file '" + path + "'");
  in.seekg(static_cast<std::streamoff>(part.begin));
  std::vector<SphereRecord> out;
  std::string line;
  std::int64_t ln = part.first_line - 1;
  std::uint64_t at = part.begin;
  const char* ws = " \t\r\v\f";
  while (at < part.end && std::getline(in, line)) {
    ++ln;
    at += line.size() + 1;
    const auto hash = line.find('#');
    if (hash != std::string::npos) line.erase(hash);
    std::string tok[6];
    std::size_t nt = 0;
    for (std::size_t b = line.find_first_not_of(ws); b != std::string::npos && nt < 6;) {
      const std::size_t e = std::min(line.find_first_of(ws, b), line.size());
      tok[nt++] = line.substr(b, e - b);
      b = line.find_first_not_of(ws, e);
    }
    if (nt == 0) continue;
    const int L = static_cast<int>(ln);
    if (nt != 5) {
      std::size_t all = 0;  // the count of a line with more than 6 values
      for (std::size_t b = line.find_first_not_of(ws); b != std::string::npos; ++all)
        b = line.find_first_not_of(ws, std::min(line.find_first_of(ws, b), line.size()));
      throw InputError(path, L, "expected 5 values 'id x y z r', got " + std::to_string(all));
    }
    SphereRecord s;
    char* end = nullptr;
    errno = 0;
    const long long id = std::strtoll(tok[0].c_str(), &end, 10);
    if (end != tok[0].c_str() + tok[0].size() || errno != 0 || id < 0)
      throw InputError(path, L, "the id must be a non-negative integer, got '" + tok[0] + "'");
    double v[4];
    for (int k = 0; k < 4; ++k) {
      v[k] = std::strtod(tok[k + 1].c_str(), &end);
      if (end != tok[k + 1].c_str() + tok[k + 1].size() || !std::isfinite(v[k]))
        throw InputError(path, L, std::string("column ") + std::to_string(k + 2) + " (" + "xyzr"[k] +
                                      "): expected a number, got '" + tok[k + 1] + "'");
    }
    if (!(v[3] > 0)) throw InputError(path, L, "radius must be positive, got " + tok[4]);
    // the ranges of the case file (docs/case-format.md#ranges): radius 1e-6 .. 10 m, |x| <= 1e5 m
    if (v[3] * scale < 1e-6 || v[3] * scale > 10)
      throw InputError(path, L, "radius " + tok[4] + " (times scale) is out of range; allowed: [1e-06, 10] m");
    for (int k = 0; k < 3; ++k)
      if (std::fabs(v[k] * scale + offset[k]) > 1e5)
        throw InputError(path, L, std::string("column ") + std::to_string(k + 2) + " (" + "xyz"[k] + "): " +
                                      tok[k + 1] + " is out of range; allowed: [-1e+05, 1e+05] m");
    s.id = id;
    s.x = Vec3{v[0], v[1], v[2]} * scale + offset;
    s.r = v[3] * scale;
    s.mat = material;
    out.push_back(s);
    if (lines) lines->push_back(ln);
  }
  if (in.bad()) throw InputError(path, static_cast<int>(ln), "read error");
  return out;
}

std::vector<SphereRecord> read_sphere_file(const std::string& path, double scale, const Vec3& offset,
                                           int material) {
  std::vector<SphereRecord> out = read_sphere_file(path, scale, offset, material, FilePart{}, nullptr);
  if (out.empty()) throw InputError(path, 0, "the sphere file has no spheres (expected lines 'id x y z r')");
  return out;
}

namespace {

// Where sphere k of source i came from, for messages: "file:line (what)".
std::string sphere_origin(const ParticleSource& s, std::size_t i, std::size_t k, const std::vector<std::int64_t>& lines) {
  const std::string P = "particles[" + std::to_string(i) + "]";
  if (s.kind == ParticleSource::kFile)
    return origin_text(s.path, k < lines.size() ? static_cast<int>(lines[k]) : 0, "sphere file of " + P);
  return origin_text(s.source_file, s.line, P + ".inline.spheres[" + std::to_string(k) + "]");
}

// Every source's spheres, and a file source's lines (for messages). Of a cells source, the block
// of cells of `rank` of `size` (all of them for 0 of 1); of a file source, `files`' part when
// given (else the whole file). `first[i]`/`total[i]`: the number of source i's auto-numbered
// particles before this rank's block and in all (for ids).
void collect_spheres(const std::vector<ParticleSource>& sources, std::vector<std::vector<SphereRecord>>& per,
                     std::vector<std::vector<std::int64_t>>& lines, int rank, int size, FileShares* files,
                     std::vector<std::int64_t>& first, std::vector<std::int64_t>& total) {
  first.assign(sources.size(), 0);
  total.assign(sources.size(), 0);
  for (std::size_t i = 0; i < sources.size(); ++i) {
    const ParticleSource& s = sources[i];
    const std::string P = "particles[" + std::to_string(i) + "]";
    switch (s.kind) {
      case ParticleSource::kInline:
        for (std::size_t k = 0; k < s.spheres.size(); ++k) {
          const auto& q = s.spheres[k];
          if (!(q.r > 0))
            throw InputError(s.source_file, s.line, P + ".inline.spheres[" + std::to_string(k) + "]: radius must be positive");
          per[i].push_back({q.id, q.x, q.r, q.v, s.material});
        }
        break;
      case ParticleSource::kGenerate:
        if (s.placement == ParticleSource::kCells) {
          const GenerationCells g = generation_cells(s);
          const std::vector<std::int64_t> n = cell_counts(s, i, g);
          const std::int64_t C = g.count(), c0 = C * rank / size, c1 = C * (rank + 1) / size;
          for (std::int64_t c = 0; c < C; ++c) (c < c0 ? first[i] : total[i]) += n[c];
          total[i] += first[i];
          per[i] = generate_cells(s, i, g, n, c0, c1);
          continue;
        }
        per[i] = generate(s, i);
        break;
      case ParticleSource::kFile:
        if (files) {
          per[i] = std::move(files->records[i]);
          lines[i] = std::move(files->lines[i]);
        } else {
          {
            std::ifstream probe(s.path);
            if (!probe) throw InputError(s.source_file, s.line, P + ".file: cannot read sphere file '" + s.path + "'");
          }
          per[i] = read_sphere_file(s.path, s.scale, s.offset, s.material, FilePart{}, &lines[i]);
          if (per[i].empty())
            throw InputError(s.path, 0, "the sphere file has no spheres (expected lines 'id x y z r')");
        }
        for (SphereRecord& q : per[i]) q.v = s.velocity;
        break;
    }
    total[i] = static_cast<std::int64_t>(per[i].size());
  }
}

// Ids: explicit ones kept (unique), then auto ids in source order after the largest one (source
// i's block of `per[i]` numbered from its `first[i]`-th particle; `total[i]` in all). With
// `files`, the caller has checked the explicit ids over every rank and gives their maximum. The
// records are moved out of `per` (left empty).
std::vector<SphereRecord> assign_ids(const std::vector<ParticleSource>& sources,
                                     std::vector<std::vector<SphereRecord>>& per,
                                     const std::vector<std::vector<std::int64_t>>& lines, const FileShares* files,
                                     const std::vector<std::int64_t>& first, const std::vector<std::int64_t>& total) {
  std::int64_t max_id = -1;
  if (files) {
    max_id = files->max_explicit_id;
  } else {
    std::map<std::int64_t, std::pair<std::size_t, std::size_t>> seen;  // id -> (source, index)
    for (std::size_t i = 0; i < per.size(); ++i)
      for (std::size_t k = 0; k < per[i].size(); ++k) {
        const auto& q = per[i][k];
        if (q.id < 0) continue;
        auto [it, fresh] = seen.emplace(q.id, std::make_pair(i, k));
        if (!fresh) {
          const auto [i0, k0] = it->second;
          throw InputError(sources[i].source_file, sources[i].line,
                           "duplicate particle id " + std::to_string(q.id) + ": given in " +
                               sphere_origin(sources[i0], i0, k0, lines[i0]) + " and in " +
                               sphere_origin(sources[i], i, k, lines[i]));
        }
        max_id = std::max(max_id, q.id);
      }
  }
  std::int64_t next = max_id + 1;
  std::vector<SphereRecord> out;
  if (per.size() == 1) {  // one source: numbered where it is, not copied
    std::int64_t auto_id = next + first[0];
    for (auto& q : per[0])
      if (q.id < 0) q.id = auto_id++;
    return std::move(per[0]);
  }
  std::size_t n_all = 0;
  for (const auto& v : per) n_all += v.size();
  out.reserve(n_all);
  for (std::size_t i = 0; i < per.size(); ++i) {
    std::int64_t auto_id = next + first[i];
    for (auto& q : per[i]) {
      if (q.id < 0) q.id = auto_id++;
      out.push_back(q);
    }
    const std::int64_t here = static_cast<std::int64_t>(per[i].size());
    std::vector<SphereRecord>().swap(per[i]);  // moved into out: not held twice
    // a source's explicit ids are not counted: only inline and file sources have them, and
    // there the auto ids of the source are numbered consecutively as before
    next = auto_id + (total[i] - first[i] - here);
  }
  return out;
}

// Every sphere inside the domain (by centre).
void check_inside_domain(const std::vector<ParticleSource>& sources, const std::vector<std::size_t>& sizes,
                         const std::vector<std::vector<std::int64_t>>& lines, const std::vector<SphereRecord>& out,
                         const Vec3& domain_min, const Vec3& domain_max) {
  for (std::size_t i = 0, n = 0; i < sizes.size(); ++i)
    for (std::size_t k = 0; k < sizes[i]; ++k, ++n) {
      const SphereRecord& q = out[n];
      const bool in = q.x.x >= domain_min.x && q.x.x <= domain_max.x && q.x.y >= domain_min.y &&
                      q.x.y <= domain_max.y && q.x.z >= domain_min.z && q.x.z <= domain_max.z;
      if (!in) {
        const ParticleSource& s = sources[i];
        std::string file = s.source_file;
        int line = s.line;
        if (s.kind == ParticleSource::kFile) {  // point at the sphere's own line
          file = s.path;
          line = k < lines[i].size() ? static_cast<int>(lines[i][k]) : 0;
        }
        std::ostringstream m;
        m << "particle id " << q.id << " (particles[" << i << "]) at (" << q.x.x << ", " << q.x.y << ", " << q.x.z
          << ") lies outside the domain [" << domain_min.x << ", " << domain_max.x << "] x [" << domain_min.y
          << ", " << domain_max.y << "] x [" << domain_min.z << ", " << domain_max.z << "]";
        throw InputError(file, line, m.str());
      }
    }
}

}  // namespace

ParticleShareRecords build_particle_share(const std::vector<ParticleSource>& sources, const Vec3& domain_min,
                                          const Vec3& domain_max, int rank, int size, FileShares* files) {
  check_cell_boxes(sources);
  // 1. every source's spheres (of a cells source, this rank's block of cells)
  std::vector<std::vector<SphereRecord>> per(sources.size());
  ParticleShareRecords out;
  out.lines.assign(sources.size(), {});
  std::vector<std::int64_t> first, total;
  collect_spheres(sources, per, out.lines, rank, size, files, first, total);
  // 2. ids: explicit ones kept (unique), then auto ids in source order after the largest one
  out.count.resize(per.size());
  for (std::size_t i = 0; i < per.size(); ++i) out.count[i] = per[i].size();
  out.records = assign_ids(sources, per, out.lines, files, first, total);
  // 3. inside the domain (by centre)
  check_inside_domain(sources, out.count, out.lines, out.records, domain_min, domain_max);
  for (std::size_t i = 0; i < sources.size(); ++i) {
    const bool cells = sources[i].kind == ParticleSource::kGenerate && sources[i].placement == ParticleSource::kCells;
    const bool part = files && sources[i].kind == ParticleSource::kFile;
    out.everywhere.insert(out.everywhere.end(), out.count[i], cells || part ? 0 : 1);
  }
  return out;
}

std::vector<SphereRecord> build_particles(const std::vector<ParticleSource>& sources, const Vec3& domain_min,
                                          const Vec3& domain_max) {
  return build_particle_share(sources, domain_min, domain_max, 0, 1).records;
}

bool has_cell_sources(const std::vector<ParticleSource>& sources) {
  for (const ParticleSource& s : sources)
    if (s.kind == ParticleSource::kGenerate && s.placement == ParticleSource::kCells) return true;
  return false;
}

}  // namespace fdem
