#pragma once
// Helpers shared by the DEM tests: building particle sets and gathering results by id.
#include <mpi.h>

#include <algorithm>
#include <cstdint>
#include <map>
#include <random>
#include <vector>

#include "app/engine.hpp"
#include "base/allgather.hpp"

namespace fdem::testing {

inline Material make_material(const std::string& name, double E, double rho, double mu,
                              double kt_kn = 0.25, double beta_r = 0, double eta_r = 0) {
  Material m;
  m.name = name; m.young = E; m.density = rho; m.friction = mu; m.kt_kn = kt_kn;
  m.rolling_stiffness = beta_r; m.rolling_limit = eta_r;
  return m;
}

inline void add_sphere(ParticleStore& p, std::int64_t id, const Vec3& x, double r, double rho,
                       int mat = 0, const Vec3& v = {}, std::uint8_t blocked = 0) {
  p.push_back(x, v, {}, r, sphere_mass(rho, r), id, mat, blocked, x);
  p.n_owned = p.size();
}

inline Wall make_plane(const std::string& name, const Vec3& point, const Vec3& normal, int mat) {
  Wall w;
  w.kind = Wall::kPlane; w.name = name; w.point = point; w.mat = mat;
  w.normal = (1.0 / norm(normal)) * normal;
  return w;
}

/// Engine parameters of a test: domain, gravity, local damping, fixed step (0: automatic).
inline EngineParams params(const Vec3& lo, const Vec3& hi, const Vec3& g, double damping, double dt = 0) {
  EngineParams e;
  e.domain_min = lo; e.domain_max = hi; e.gravity = g; e.damping = damping; e.dt = dt;
  return e;
}

struct Gathered {
  std::vector<std::int64_t> id;
  std::vector<Vec3> x, v, w;
};

/// All owned particles of all ranks of the engine's communicator, sorted by id, on every rank.
inline Gathered gather(const DemEngine& e) {
  const ParticleStore& p = e.particles();
  MPI_Comm comm = e.comm();
  std::vector<double> loc;
  for (std::size_t i = 0; i < p.n_owned; ++i) {
    loc.push_back(static_cast<double>(p.id[i]));
    for (const Vec3* a : {&p.x[i], &p.v[i], &p.w[i]}) { loc.push_back(a->x); loc.push_back(a->y); loc.push_back(a->z); }
  }
  const std::vector<double> all = allgather(loc, comm);
  const int total = static_cast<int>(all.size());
  std::map<std::int64_t, std::size_t> order;
  for (int k = 0; k < total; k += 10) order[static_cast<std::int64_t>(all[k])] = k;
  Gathered g;
  for (const auto& kv : order) {
    const double* a = &all[kv.second];
    g.id.push_back(kv.first);
    g.x.push_back({a[1], a[2], a[3]});
    g.v.push_back({a[4], a[5], a[6]});
    g.w.push_back({a[7], a[8], a[9]});
  }
  return g;
}

/// Particles (same ids, same order) whose position or spin differs in any bit.
inline std::size_t count_differing(const Gathered& a, const Gathered& b) {
  std::size_t differ = 0;
  for (std::size_t i = 0; i < a.id.size(); ++i)
    if (a.x[i].x != b.x[i].x || a.x[i].y != b.x[i].y || a.x[i].z != b.x[i].z || a.w[i].x != b.w[i].x) ++differ;
  return differ;
}

/// A dense, polydisperse block of spheres on a jittered lattice (deterministic).
inline ParticleStore lattice_block(const Vec3& lo, int nx, int ny, int nz, double rmax,
                                   double rho, std::uint64_t seed, double rmin_frac = 0.8,
                                   double spacing = 2.05) {
  ParticleStore p;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double a = spacing * rmax;
  std::int64_t id = 0;
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        const double r = rmax * (rmin_frac + (1 - rmin_frac) * u(rng));
        const double slack = a - 2 * r;
        Vec3 x{lo.x + a * (i + 0.5) + 0.5 * slack * (u(rng) - 0.5),
               lo.y + a * (j + 0.5) + 0.5 * slack * (u(rng) - 0.5),
               lo.z + a * (k + 0.5) + 0.5 * slack * (u(rng) - 0.5)};
        add_sphere(p, id++, x, r, rho);
      }
  return p;
}

}  // namespace fdem::testing
