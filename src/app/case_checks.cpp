#include "app/case_checks.hpp"

#include <algorithm>
#include <cstdio>
#include <limits>
#include <optional>

#include "base/errors.hpp"

namespace fdem {

namespace {

std::string g6(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%g", v);
  return b;
}

std::string vec_text(const Vec3& v) { return "[" + g6(v.x) + ", " + g6(v.y) + ", " + g6(v.z) + "]"; }

std::string at(const std::string& file, int line) { return line > 0 ? file + ":" + std::to_string(line) : file; }

/// The signed distances of the domain's eight corners from a plane (normal n through p): the
/// least and the largest.
std::pair<double, double> corner_range(const CaseConfig& c, const Vec3& p, const Vec3& n) {
  double lo = 1e300, hi = -1e300;
  for (int k = 0; k < 8; ++k) {
    const Vec3 q{k & 1 ? c.domain_max.x : c.domain_min.x, k & 2 ? c.domain_max.y : c.domain_min.y,
                 k & 4 ? c.domain_max.z : c.domain_min.z};
    const double d = dot(q - p, n);
    lo = std::min(lo, d);
    hi = std::max(hi, d);
  }
  return {lo, hi};
}

}  // namespace

std::vector<std::string> case_warnings(const CaseConfig& c) {
  std::vector<std::string> out = c.warnings;  // (the reader's: --set by position)
  for (std::size_t m = 0; m < c.materials.size(); ++m) {
    const Material& mat = c.materials[m];
    const std::string where = m < c.material_at.size() ? at(c.material_at[m].first, c.material_at[m].second) : c.file;
    const std::string head = where + ": warning: material '" + mat.name + "': ";
    if (mat.density < 100)
      out.push_back(head + "density " + g6(mat.density) + " kg/m^3 is lighter than any grain: g/cm^3? (quartz sand " +
                    "is 2650 kg/m^3)");
    if (mat.friction > 2)
      out.push_back(head + "friction " + g6(mat.friction) + " is steeper than 63 deg: degrees? friction is the " +
                    "coefficient tan(phi) (30 deg is 0.577)");
    if (mat.young < 1e4)
      out.push_back(head + "young " + g6(mat.young) + " Pa is softer than a sponge: MPa? young is in Pa (" +
                    "100 MPa is 1e8)");
  }
  if (c.fem.present)
    for (const FeMaterialConfig& m : c.fem.materials) {
      const std::string head = at(c.file, m.line) + ": warning: fem material '" + m.name + "': ";
      if (m.young > 0 && m.young < 1e4)
        out.push_back(head + "young " + g6(m.young) + " Pa is softer than a sponge: MPa? young is in Pa");
      if (m.density > 0 && m.density < 100)
        out.push_back(head + "density " + g6(m.density) + " kg/m^3: g/cm^3? (steel is 7850 kg/m^3)");
    }
  for (const WallConfig& w : c.walls) {
    bool outside = false;
    if (w.kind == WallConfig::kPlane) {
      outside = corner_range(c, w.point, w.normal).first > 0;  // the whole domain in front of it, off it
    } else if (w.kind == WallConfig::kBox) {
      for (int d = 0; d < 3; ++d) outside = outside || w.max[d] < c.domain_min[d] || w.min[d] > c.domain_max[d];
    } else {
      Vec3 lo{1e300, 1e300, 1e300}, hi{-1e300, -1e300, -1e300};
      for (const Vec3& v : w.vertices)
        for (int d = 0; d < 3; ++d) {
          lo[d] = std::min(lo[d], v[d]);
          hi[d] = std::max(hi[d], v[d]);
        }
      for (int d = 0; d < 3; ++d) outside = outside || hi[d] < c.domain_min[d] || lo[d] > c.domain_max[d];
    }
    // (a moving wall may come into the domain later)
    if (outside && w.motion.kind == WallMotion::kFixed && w.schedule.empty())
      out.push_back(at(c.file, w.line) + ": warning: wall '" + w.name + "' lies wholly outside the domain " +
                    vec_text(c.domain_min) + " .. " + vec_text(c.domain_max) +
                    ": no grain reaches it (grains leaving the domain are removed); move it or widen the domain");
  }
  return out;
}

WallTally tally_grains_in_walls(const CaseConfig& c, std::size_t n, const Vec3* x, const std::int64_t* id) {
  const std::size_t nw = c.walls.size();
  WallTally t;
  t.count.assign(nw, 0);
  t.first.assign(nw, -1);
  t.where.assign(nw, Vec3{});
  t.total = static_cast<long long>(n);
  for (std::size_t w = 0; w < nw; ++w) {
    const WallConfig& wall = c.walls[w];
    if (wall.kind == WallConfig::kFacets) continue;
    for (std::size_t i = 0; i < n; ++i) {
      bool in = true;
      if (wall.kind == WallConfig::kPlane) {
        in = dot(x[i] - wall.point, wall.normal) < 0;
      } else {
        for (int d = 0; d < 3; ++d) in = in && x[i][d] > wall.min[d] && x[i][d] < wall.max[d];
      }
      if (!in) continue;
      ++t.count[w];
      if (t.first[w] < 0 || id[i] < t.first[w]) {
        t.first[w] = id[i];
        t.where[w] = x[i];
      }
    }
  }
  return t;
}

std::optional<InputError> grains_in_walls_error(const CaseConfig& c, const WallTally& t) {
  for (std::size_t w = 0; w < t.count.size(); ++w) {
    if (t.count[w] == 0) continue;
    const WallConfig& wall = c.walls[w];
    const std::string n = std::to_string(t.count[w]) + " of the " + std::to_string(t.total) + " grains";
    const std::string one = " (e.g. id " + std::to_string(t.first[w]) + " at " + vec_text(t.where[w]) + ")";
    std::string msg;
    if (wall.kind == WallConfig::kBox) {
      msg = "wall '" + wall.name + "': " + n + " start inside it" + one +
            ". A `type: box` wall is solid (a footing, a plate): grains touch it from outside. For the container the " +
            "grains fill, use `type: container` (the same min and max, `open: [zmax]` for an open top) or six planes";
    } else {
      msg = "wall '" + wall.name + "': " + n + " start behind it" + one + ": a plane is solid on the far side of its " +
            "normal " + vec_text(wall.normal) + ", which must point to the grains' side";
      if (2 * t.count[w] > t.total) msg += ". Most grains are behind it: flip the normal to " + vec_text(Vec3{} - wall.normal) + "?";
      else msg += ". Move the plane, or the grains, so that every grain is in front of it";
    }
    return InputError(c.file, wall.line, msg);
  }
  return std::nullopt;
}

void check_grains_in_walls(const CaseConfig& c, const Setup& s, MPI_Comm comm) {
  const ParticleStore& p = s.particles;
  WallTally t = tally_grains_in_walls(c, p.n_owned, p.x.data(), p.id.data());
  if (s.shared) {  // each rank holds a share: sum the counts; the lowest id over ranks and its centre
    const int nw = static_cast<int>(t.count.size());
    MPI_Allreduce(MPI_IN_PLACE, t.count.data(), nw, MPI_LONG_LONG, MPI_SUM, comm);
    MPI_Allreduce(MPI_IN_PLACE, &t.total, 1, MPI_LONG_LONG, MPI_SUM, comm);
    std::vector<long long> mine(t.first.size()), lowest(t.first.size());
    for (std::size_t w = 0; w < mine.size(); ++w)
      mine[w] = t.first[w] < 0 ? std::numeric_limits<long long>::max() : t.first[w];
    MPI_Allreduce(mine.data(), lowest.data(), nw, MPI_LONG_LONG, MPI_MIN, comm);
    for (std::size_t w = 0; w < mine.size(); ++w) {
      double x[3] = {0, 0, 0};
      if (t.first[w] >= 0 && t.first[w] == lowest[w])
        for (int d = 0; d < 3; ++d) x[d] = t.where[w][d];
      MPI_Allreduce(MPI_IN_PLACE, x, 3, MPI_DOUBLE, MPI_SUM, comm);
      t.where[w] = Vec3{x[0], x[1], x[2]};
      t.first[w] = t.count[w] > 0 ? lowest[w] : -1;
    }
  }
  const std::optional<InputError> bad = grains_in_walls_error(c, t);
  if (bad) throw *bad;  // (every rank alike: the counts are global)
}

}  // namespace fdem
