#include "coupling/interface_forces.hpp"

#include "base/fixed_point.hpp"
#include "dem/contact_law.hpp"

namespace fdem::coupling {
namespace {

/// acc += x in fixed point (exact, order-independent).
inline void add_fixed(F3& acc, const Vec3& x) {
  acc[0] += exact::to_fixed(x.x);
  acc[1] += exact::to_fixed(x.y);
  acc[2] += exact::to_fixed(x.z);
}

}  // namespace

InterfaceForces::InterfaceForces(std::size_t n_vertices, int n_groups)
    : vertex_sum_(n_vertices, F3{}), group_sum_(n_groups, F3{}) {}

void InterfaceForces::apply_law(ParticleStore& p, const MaterialTable& mats, const std::vector<int>& group_material,
                                const InterfaceSurface& s, FacetContacts& c, double dt) {
  const TouchingContacts& tc = c.touching();
  step_particle_ = Vec3{};
  sides_.clear();
  if (force_.size() < tc.geo.size()) force_.resize(tc.geo.size());
  const std::size_t np = tc.particle.size();
  for (std::size_t j = 0; j < np; ++j) {
    const std::uint32_t i = tc.particle[j];
    if (j + 4 < np) {
      const std::uint32_t k = tc.particle[j + 4];
      __builtin_prefetch(&p.v[k]);
      __builtin_prefetch(&p.w[k]);
      __builtin_prefetch(&p.f[k]);
      __builtin_prefetch(&p.t[k]);
    }
    const double r = p.r[i];
    const double ep = mats[p.mat[i]].young;
    int material = -1;  // the pair of the last contact's surface, looked up again only when it changes
    const Material* mi = nullptr;
    const PairParams* pr = nullptr;
    for (std::size_t u = tc.begin[j]; u < tc.begin[j + 1]; ++u) {
      if (!tc.accept[u]) continue;
      if (group_material[s.group(tc.tri[u])] != material) {
        material = group_material[s.group(tc.tri[u])];
        mi = &mats[material];
        pr = &mats.pair(p.mat[i], material);
      }
      const WallGeom& g = tc.geo[u];
      const auto& tv = s.corners(tc.tri[u]);
      const std::array<double, 3>& N = tc.N[u];
      const Vec3 vs = N[0] * s.velocity(tv[0]) + N[1] * s.velocity(tv[1]) + N[2] * s.velocity(tv[2]);
      const Vec3 la = (r - 0.5 * g.delta) * g.n;
      const Vec3 vrel = vs - (p.v[i] + cross(p.w[i], la));
      // The interface is flat: the particle's radius for both springs (linear) and R* = r (Hertz).
      const NormalLaw nl = normal_law(*pr, ep, r, mi->young, r, r, g.delta);
      ContactForce cf = contact_force(g.n, nl, la, Vec3{}, vrel, p.w[i], r, *pr, dt, c.state(tc.cand[u]));
      const double wq = tc.weight[u];
      if (wq != 1.0) { cf.force_b *= wq; cf.torque_a *= wq; }
      p.f[i] -= cf.force_b;
      p.t[i] += cf.torque_a;
      step_particle_ -= cf.force_b;
      sides_.push_back(ContactSource::Side{i, g.n, la, -1.0 * cf.force_b});
      force_[u] = cf.force_b;
    }
  }
}

void InterfaceForces::distribute(const InterfaceSurface& s, const FacetContacts& c) {
  const TouchingContacts& tc = c.touching();
  step_nodal_ = Vec3{};
  for (std::size_t j = 0; j < tc.particle.size(); ++j) {
    const std::size_t b = tc.begin[j], e = tc.begin[j + 1];
    for (std::size_t u = b; u < e; ++u) {
      if (!tc.accept[u]) continue;
      const Vec3& F = force_[u];
      add_fixed(group_sum_[contact_group(s, tc, b, e, u)], F);
      // F_i = N_i F to the corners, each corner's share over its nodes by weight: the share
      // (N_c w) F of each node of corner c is summed per corner (the exchange adds it to each of
      // the corner's nodes) -- the same fixed-point terms as per node.
      const auto& tv = s.corners(tc.tri[u]);
      const std::array<double, 3>& N = tc.N[u];
      for (int cc = 0; cc < 3; ++cc) {
        if (N[cc] == 0.0) continue;
        const std::int32_t v = tv[cc];
        const Vec3 fs = (N[cc] * s.node_weight(v)) * F;
        add_fixed(vertex_sum_[v], fs);
        step_nodal_ += static_cast<double>(s.node_count(v)) * fs;
      }
    }
  }
}

std::int32_t InterfaceForces::contact_group(const InterfaceSurface& s, const TouchingContacts& tc, std::size_t b,
                                            std::size_t e, std::size_t u) const {
  const WallGeom& g = tc.geo[u];
  std::int32_t grp = s.group(tc.tri[u]);
  if (g.region == 0 || s.n_groups() < 2) return grp;
  // A contact on an edge or a corner belongs to the surface the particle pushes on most directly:
  // of its touching triangles, the one whose outward normal is closest to the direction from the
  // contact to the particle (a grain on the top-front edge of a thin rib pushes the rib's front
  // face -- bearing -- when it lies in front of the rib, its top -- friction -- when above it).
  double best = -2;
  for (std::size_t j = b; j < e; ++j) {
    const Vec3& n = s.plane(tc.tri[j]).normal;
    const double c = -(n.x * g.n.x + n.y * g.n.y + n.z * g.n.z);
    if (c > best) { best = c; grp = s.group(tc.tri[j]); }
  }
  return grp;
}

}  // namespace fdem::coupling
