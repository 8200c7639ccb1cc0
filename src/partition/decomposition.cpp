#include "partition/decomposition.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace fdem {

std::array<int, 3> choose_grid(int P, const Vec3& L, double min_width, int uncut_axis) {
  for (int pass = uncut_axis >= 0 ? 0 : 1; pass < 2; ++pass) {
    std::array<int, 3> best{0, 0, 0};
    double best_area = std::numeric_limits<double>::infinity();
    for (int px = 1; px <= P; ++px) {
      if (P % px) continue;
      for (int py = 1; py <= P / px; ++py) {
        if ((P / px) % py) continue;
        const std::array<int, 3> g{px, py, P / px / py};
        if (pass == 0 && g[uncut_axis] > 1) continue;
        if (L.x / g[0] < min_width && g[0] > 1) continue;
        if (L.y / g[1] < min_width && g[1] > 1) continue;
        if (L.z / g[2] < min_width && g[2] > 1) continue;
        const double area = (g[0] - 1) * L.y * L.z + (g[1] - 1) * L.x * L.z + (g[2] - 1) * L.x * L.y;
        if (area < best_area * (1 - 1e-12)) {
          best_area = area;
          best = g;
        }
      }
    }
    if (best[0] > 0) return best;
  }
  return {0, 0, 0};
}

int gravity_axis(const Vec3& g) {
  int a = -1;
  double m = 0;
  for (int d = 0; d < 3; ++d)
    if (std::fabs(g[d]) > m) {
      m = std::fabs(g[d]);
      a = d;
    }
  return a;
}

Decomposition Decomposition::create(MPI_Comm comm, const Vec3& dmin, const Vec3& dmax,
                                    double min_width, const GridRequest& request) {
  Decomposition d;
  d.comm = comm;
  MPI_Comm_rank(comm, &d.rank);
  MPI_Comm_size(comm, &d.size);
  d.domain_min = dmin;
  d.domain_max = dmax;
  const Vec3 L = dmax - dmin;
  if (request.dims[0] > 0) {
    const std::array<int, 3>& g = request.dims;
    std::ostringstream s;
    if (static_cast<long long>(g[0]) * g[1] * g[2] != d.size) {
      s << "decomposition.grid [" << g[0] << ", " << g[1] << ", " << g[2] << "] has " << g[0] * g[1] * g[2]
        << " subdomains but the run has " << d.size << " ranks";
      throw std::runtime_error(s.str());
    }
    for (int a = 0; a < 3; ++a)
      if (g[a] > 1 && L[a] / g[a] < min_width) {
        s << "decomposition.grid [" << g[0] << ", " << g[1] << ", " << g[2] << "] makes subdomains "
          << L[a] / g[a] << " m wide along " << "xyz"[a] << ", less than the ghost-layer width "
          << min_width << " m (2*r_max + skin); split that direction into fewer parts";
        throw std::runtime_error(s.str());
      }
    d.dims = g;
  } else {
    d.dims = choose_grid(d.size, L, min_width, request.uncut_axis);
  }
  if (d.dims[0] == 0) {
    std::ostringstream s;
    s << "the domain " << L.x << " x " << L.y << " x " << L.z << " m cannot be split over "
      << d.size << " ranks with subdomains at least " << min_width
      << " m wide (the ghost-layer width, 2*r_max + skin); use fewer ranks or a larger domain";
    throw std::runtime_error(s.str());
  }
  // Rank order: x fastest.
  int r = d.rank;
  d.coords[0] = r % d.dims[0];
  r /= d.dims[0];
  d.coords[1] = r % d.dims[1];
  d.coords[2] = r / d.dims[1];
  auto rank_of = [&](int i, int j, int k) { return i + d.dims[0] * (j + d.dims[1] * k); };
  for (int a = 0; a < 3; ++a) {
    std::array<int, 3> c = d.coords;
    if (c[a] > 0) { c[a] -= 1; d.lo_neighbor[a] = rank_of(c[0], c[1], c[2]); }
    c = d.coords;
    if (c[a] < d.dims[a] - 1) { c[a] += 1; d.hi_neighbor[a] = rank_of(c[0], c[1], c[2]); }
    d.cuts[a].resize(d.dims[a] + 1);
    for (int k = 0; k <= d.dims[a]; ++k)
      d.cuts[a][k] = k == d.dims[a] ? dmax[a] : dmin[a] + (dmax[a] - dmin[a]) * k / d.dims[a];
  }
  d.min_width = min_width;
  d.set_bounds();
  return d;
}

void Decomposition::set_bounds() {
  for (int a = 0; a < 3; ++a) {
    lo[a] = cuts[a][coords[a]];
    hi[a] = cuts[a][coords[a] + 1];
  }
}

double Decomposition::ghost_share(double w) const {
  double inner = 1, outer = 1;
  for (int d = 0; d < 3; ++d) {
    const double width = hi[d] - lo[d];
    inner *= width;
    outer *= width + w * ((lo_neighbor[d] >= 0) + (hi_neighbor[d] >= 0));
  }
  return inner > 0 ? outer / inner - 1 : 0.0;
}

double Decomposition::imbalance(MPI_Comm comm, double load) {
  double loc[2] = {load, -load}, g[2];
  double sum = 0, mine = load;
  int size = 1;
  MPI_Comm_size(comm, &size);
  MPI_Allreduce(loc, g, 1, MPI_DOUBLE, MPI_MAX, comm);
  MPI_Allreduce(&mine, &sum, 1, MPI_DOUBLE, MPI_SUM, comm);
  return sum > 0 ? g[0] / (sum / size) : 1.0;
}

bool Decomposition::rebalance(const std::vector<Vec3>& x, std::size_t n, const double* weight) {
  constexpr int kBins = 2048;
  bool moved = false;
  for (int a = 0; a < 3; ++a) {
    if (dims[a] == 1) continue;
    const double lo_d = domain_min[a], len = domain_max[a] - domain_min[a];
    std::vector<double> h(kBins, 0.0), g(kBins);
    for (std::size_t i = 0; i < n; ++i) {
      int b = static_cast<int>((x[i][a] - lo_d) / len * kBins);
      h[std::clamp(b, 0, kBins - 1)] += weight ? weight[i] : 1.0;
    }
    MPI_Allreduce(h.data(), g.data(), kBins, MPI_DOUBLE, MPI_SUM, comm);
    double total = 0;
    for (double c : g) total += c;
    if (total == 0) continue;
    std::vector<double> nc(dims[a] + 1);
    nc[0] = domain_min[a];
    nc[dims[a]] = domain_max[a];
    double acc = 0;
    int b = 0;
    for (int k = 1; k < dims[a]; ++k) {
      const double target = total * k / dims[a];
      while (b < kBins && acc + g[b] < target) acc += g[b++];
      const double frac = (b < kBins && g[b] > 0) ? (target - acc) / g[b] : 0.0;
      nc[k] = lo_d + len * (b + frac) / kBins;
    }
    // Keep every slab at least min_width wide (forward, then backward pass).
    for (int k = 1; k < dims[a]; ++k) nc[k] = std::max(nc[k], nc[k - 1] + min_width);
    for (int k = dims[a] - 1; k >= 1; --k) nc[k] = std::min(nc[k], nc[k + 1] - min_width);
    for (int k = 1; k < dims[a]; ++k)
      if (nc[k] != cuts[a][k]) moved = true;
    cuts[a] = nc;
  }
  set_bounds();
  return moved;
}

int Decomposition::slab(int d, double c) const {
  // Consistent with cut(): the slab k with cut(k) <= c < cut(k+1). Most points asked about are
  // in this rank's own slab.
  if (c >= lo[d] && c < hi[d]) return coords[d];
  int k = static_cast<int>(std::floor((c - domain_min[d]) / (domain_max[d] - domain_min[d]) * dims[d]));
  if (k < 0) k = 0;
  if (k > dims[d] - 1) k = dims[d] - 1;
  while (k > 0 && c < cut(d, k)) --k;
  while (k < dims[d] - 1 && c >= cut(d, k + 1)) ++k;
  return k;
}

int Decomposition::owner_of(const Vec3& x) const {
  const int i = slab(0, x.x), j = slab(1, x.y), k = slab(2, x.z);
  return i + dims[0] * (j + dims[1] * k);
}

}  // namespace fdem
