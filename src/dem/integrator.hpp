#pragma once
// Leapfrog (central-difference) integration of the owned particles with Cundall's local
// damping, as YADE's NewtonIntegrator does (DESIGN.md 4.1). No MPI.
//   v^{n+1/2} = v^{n-1/2} + dt * damp(F^n)/m,   x^{n+1} = x^n + dt * v^{n+1/2}
// Blocked dofs keep their velocity. F (p.f, p.t) is left untouched (undamped, for output).
#include "dem/contact_law.hpp"
#include "dem/particles.hpp"

namespace fdem {

/// inv_m, inv_i: 1/m and 1/I of the owned particles; the force is f + m g (p.f holds the
/// contact forces only and is not modified).
inline void integrate_particles(ParticleStore& p, const double* inv_m, const double* inv_i,
                                const Vec3& g, double dt, double damping) {
  const std::size_t n = p.n_owned;
  Vec3* x = p.x.data();
  Vec3* v = p.v.data();
  Vec3* w = p.w.data();
  const Vec3* f = p.f.data();
  const Vec3* t = p.t.data();
  const double* m = p.m.data();
  const std::uint8_t* blocked = p.blocked.data();
  for (std::size_t i = 0; i < n; ++i) {
    const double fx = f[i].x + m[i] * g.x, fy = f[i].y + m[i] * g.y, fz = f[i].z + m[i] * g.z;
    const double dtm = dt * inv_m[i];
    const double dti = dt * inv_i[i];
    const std::uint8_t blk = blocked[i];
    if (blk == 0) {
      v[i].x += dtm * local_damping(fx, v[i].x, dtm, damping);
      v[i].y += dtm * local_damping(fy, v[i].y, dtm, damping);
      v[i].z += dtm * local_damping(fz, v[i].z, dtm, damping);
      w[i].x += dti * local_damping(t[i].x, w[i].x, dti, damping);
      w[i].y += dti * local_damping(t[i].y, w[i].y, dti, damping);
      w[i].z += dti * local_damping(t[i].z, w[i].z, dti, damping);
    } else {
      if (!(blk & kDofX)) v[i].x += dtm * local_damping(fx, v[i].x, dtm, damping);
      if (!(blk & kDofY)) v[i].y += dtm * local_damping(fy, v[i].y, dtm, damping);
      if (!(blk & kDofZ)) v[i].z += dtm * local_damping(fz, v[i].z, dtm, damping);
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
