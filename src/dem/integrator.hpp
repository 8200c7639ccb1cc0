#pragma once
// Leapfrog (central-difference) integration of the owned particles with Cundall's local
// damping, as YADE's NewtonIntegrator does (DESIGN.md 4.1). No MPI.
//   v^{n+1/2} = v^{n-1/2} + dt * damp(F^n)/m,   x^{n+1} = x^n + dt * v^{n+1/2}
// Blocked dofs keep their velocity. F (p.f, p.t) is left untouched (undamped, for output).
#include "dem/contact_law.hpp"
#include "dem/particles.hpp"

namespace fdem {

inline void integrate_particles(ParticleStore& p, double dt, double damping) {
  for (std::size_t i = 0; i < p.n_owned; ++i) {
    const std::uint8_t blk = p.blocked[i];
    const double dtm = dt / p.m[i];
    const double dti = dt / sphere_inertia(p.m[i], p.r[i]);
    for (int d = 0; d < 3; ++d) {
      if (!(blk & (1u << d))) p.v[i][d] += dtm * local_damping(p.f[i][d], p.v[i][d], dtm, damping);
      if (!(blk & (8u << d))) p.w[i][d] += dti * local_damping(p.t[i][d], p.w[i][d], dti, damping);
    }
    p.x[i] += dt * p.v[i];
  }
}

}  // namespace fdem
