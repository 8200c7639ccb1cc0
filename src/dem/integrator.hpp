#pragma once
// Leapfrog (central-difference) integration of the owned particles with Cundall's local
// damping, as YADE's NewtonIntegrator does (DESIGN.md 4.1). No MPI.
//   v^{n+1/2} = v^{n-1/2} + dt * damp(F^n)/m,   x^{n+1} = x^n + dt * v^{n+1/2}
// Blocked dofs keep their velocity. F (p.f, p.t) is left untouched (undamped, for output).
#include "dem/contact_law.hpp"
#include "dem/particles.hpp"

namespace fdem {

inline void integrate_particles(ParticleStore& p, double dt, double damping) {
  const std::size_t n = p.n_owned;
  Vec3* x = p.x.data();
  Vec3* v = p.v.data();
  Vec3* w = p.w.data();
  const Vec3* f = p.f.data();
  const Vec3* t = p.t.data();
  const double* m = p.m.data();
  const double* r = p.r.data();
  const std::uint8_t* blocked = p.blocked.data();
  for (std::size_t i = 0; i < n; ++i) {
    const double dtm = dt / m[i];
    const double dti = dtm / (0.4 * r[i] * r[i]);  // dt / I, I = 2/5 m r^2
    const std::uint8_t blk = blocked[i];
    if (blk == 0) {
      v[i].x += dtm * local_damping(f[i].x, v[i].x, dtm, damping);
      v[i].y += dtm * local_damping(f[i].y, v[i].y, dtm, damping);
      v[i].z += dtm * local_damping(f[i].z, v[i].z, dtm, damping);
      w[i].x += dti * local_damping(t[i].x, w[i].x, dti, damping);
      w[i].y += dti * local_damping(t[i].y, w[i].y, dti, damping);
      w[i].z += dti * local_damping(t[i].z, w[i].z, dti, damping);
    } else {
      if (!(blk & kDofX)) v[i].x += dtm * local_damping(f[i].x, v[i].x, dtm, damping);
      if (!(blk & kDofY)) v[i].y += dtm * local_damping(f[i].y, v[i].y, dtm, damping);
      if (!(blk & kDofZ)) v[i].z += dtm * local_damping(f[i].z, v[i].z, dtm, damping);
      if (!(blk & kDofRX)) w[i].x += dti * local_damping(t[i].x, w[i].x, dti, damping);
      if (!(blk & kDofRY)) w[i].y += dti * local_damping(t[i].y, w[i].y, dti, damping);
      if (!(blk & kDofRZ)) w[i].z += dti * local_damping(t[i].z, w[i].z, dti, damping);
    }
    x[i].x += dt * v[i].x;
    x[i].y += dt * v[i].y;
    x[i].z += dt * v[i].z;
  }
}

}  // namespace fdem
