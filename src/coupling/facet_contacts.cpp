#include "coupling/facet_contacts.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include "dem/facet_geometry.hpp"
#include "dem/facet_grid.hpp"
#include "dem/facet_select.hpp"

namespace fdem::coupling {

void FacetContacts::build(const ParticleStore& p, const InterfaceSurface& s, const std::vector<std::int32_t>& seen,
                          const Vec3& lo, const Vec3& hi, double margin, const HistoryMap& history) {
  find_candidates(p, s, seen, lo, hi, margin, history);
  group_by_particle(p);
  // Room for every candidate touching at once.
  const std::size_t n = candidates_.size();
  if (touching_.geo.size() < n) {
    touching_.geo.resize(n);
    touching_.N.resize(n);
    touching_.tri.resize(n);
    touching_.cand.resize(n);
    touching_.accept.resize(n);
    touching_.weight.resize(n);
  }
  candidate_vertices_.clear();
  for (const InterfaceCandidate& c : candidates_)
    for (std::int32_t v : c.v) candidate_vertices_.push_back(v);
  std::sort(candidate_vertices_.begin(), candidate_vertices_.end());
  candidate_vertices_.erase(std::unique(candidate_vertices_.begin(), candidate_vertices_.end()),
                            candidate_vertices_.end());
}

void FacetContacts::find_candidates(const ParticleStore& p, const InterfaceSurface& s,
                                    const std::vector<std::int32_t>& seen, const Vec3& lo, const Vec3& hi,
                                    double margin, const HistoryMap& history) {
  // The seen triangles binned in a grid by their box grown by the reach (only the part of the
  // box near this subdomain matters).
  double rmax = 0;
  for (std::size_t i = 0; i < p.n_owned; ++i) rmax = std::max(rmax, p.r[i]);
  const double reach = rmax + margin;
  FacetGrid grid;
  grid.h = std::max(2 * reach, 1e-12);
  grid.origin = lo;
  for (std::int32_t t : seen) {
    const auto& tv = s.corners(t);
    Vec3 bl = s.position(tv[0]), bh = bl;
    for (int c = 1; c < 3; ++c)
      for (int d = 0; d < 3; ++d) {
        bl[d] = std::min(bl[d], s.position(tv[c])[d]);
        bh[d] = std::max(bh[d], s.position(tv[c])[d]);
      }
    std::int64_t a[3], b[3];
    bool skip = false;
    for (int d = 0; d < 3; ++d) {
      const double l = std::max(bl[d] - reach, lo[d] - reach), u = std::min(bh[d] + reach, hi[d] + reach);
      if (l > u) { skip = true; break; }
      a[d] = grid.cell(l, d);
      b[d] = grid.cell(u, d);
    }
    if (!skip) grid.add(a, b, t);
  }
  // A particle's candidates nearest first (then by triangle): scan() stops at the first one that
  // cannot be reached. The particles in the order of their nearest triangle (then by index):
  // consecutive particles then mostly share the surface data (vertices, planes, force sums),
  // which are numbered along the mesh faces -- far fewer cache misses than in particle order.
  // (Each particle's contacts are still summed in a fixed order, so its force does not depend on
  // the order of the particles; the nodal sums are exact.)
  std::vector<std::pair<double, std::int32_t>> near;
  struct Group { std::int32_t key; std::uint32_t i, b, e; };
  std::vector<Group> groups;
  for (std::uint32_t i = 0; i < p.n_owned; ++i) {
    const std::vector<std::int32_t>* in = grid.at(p.x[i]);
    if (!in) continue;
    const std::size_t b0 = near.size();
    for (std::int32_t t : *in) {
      const auto& tv = s.corners(t);
      int region;
      const Vec3 cp = closest_on_triangle(p.x[i], s.position(tv[0]), s.position(tv[1]), s.position(tv[2]), region);
      const double d2 = norm2(cp - p.x[i]);
      if (d2 >= (p.r[i] + margin) * (p.r[i] + margin)) continue;
      near.emplace_back(std::sqrt(d2), t);
    }
    if (near.size() == b0) continue;
    std::sort(near.begin() + b0, near.end());
    groups.push_back({near[b0].second, i, static_cast<std::uint32_t>(b0), static_cast<std::uint32_t>(near.size())});
  }
  std::sort(groups.begin(), groups.end(),
            [](const Group& a, const Group& b) { return a.key != b.key ? a.key < b.key : a.i < b.i; });
  cand_particle_.clear();
  candidates_.clear();
  state_.clear();
  stamp_.clear();
  for (const Group& gr : groups)
    for (std::uint32_t c = gr.b; c < gr.e; ++c) {
      const auto& [d, t] = near[c];
      cand_particle_.push_back(gr.i);
      candidates_.push_back({d, t, s.corners(t), s.opposite(t)});
      auto h = history.find(ContactKey{p.id[gr.i], t, 2, -1});
      state_.push_back(h == history.end() ? ContactState{} : h->second);
      stamp_.push_back(h == history.end() ? 0 : calls_);  // active in the last call
    }
}

void FacetContacts::group_by_particle(const ParticleStore& p) {
  particles_.clear();
  first_.clear();
  pos_at_build_.clear();
  for (std::size_t a = 0, b = 0; a < cand_particle_.size(); a = b) {
    for (b = a + 1; b < cand_particle_.size() && cand_particle_[b] == cand_particle_[a];) ++b;
    particles_.push_back(cand_particle_[a]);
    first_.push_back(static_cast<std::uint32_t>(a));
    pos_at_build_.push_back(p.x[cand_particle_[a]]);
  }
  first_.push_back(static_cast<std::uint32_t>(cand_particle_.size()));
}

void FacetContacts::scan(const ParticleStore& p, const InterfaceSurface& s, double moved_surface, double slack) {
  ++calls_;
  TouchingContacts& tc = touching_;
  tc.particle.clear();
  tc.begin.assign(1, 0);
  touching_group_.clear();
  std::size_t m = 0;  // touching contacts so far
  const std::size_t ng = particles_.size();
  for (std::size_t gr = 0; gr < ng; ++gr) {
    const std::size_t k = first_[gr], e = first_[gr + 1];
    const std::uint32_t i = particles_[gr];
    // Prefetch a few particles ahead: the particle, and the surface data of its nearest candidate.
    if (gr + 4 < ng) {
      const std::uint32_t j = particles_[gr + 4];
      __builtin_prefetch(&p.x[j]);
      __builtin_prefetch(&p.r[j]);
      const std::size_t f = first_[gr + 3];
      for (int c = 0; c < 3; ++c) __builtin_prefetch(&s.position(candidates_[f].v[c]));
      __builtin_prefetch(&s.plane(candidates_[f].t));
    }
    const Vec3 x = p.x[i];
    const double r = p.r[i];
    // Quick rejection (the lists include the skin, and a sphere on a face is a candidate of all
    // the face's triangles near it): (1) the closest-point distance at the build minus how far
    // the particle and the surface moved since cannot be below r -- the candidates are sorted by
    // that distance, so the first such one ends the particle's list; (2) the triangle's plane or
    // bounding circle is out of reach (cannot_touch), tested only when (1) does not already
    // guarantee the triangle within reach (d0 + moved < r: then it cannot say no).
    const double moved = norm(x - pos_at_build_[gr]) + moved_surface;
    const double lim = r + moved;
    const std::size_t m0 = m;
    for (std::size_t q = k; q < e && candidates_[q].d0 < lim; ++q) {
      const InterfaceCandidate& cq = candidates_[q];
      if (cq.d0 + moved < r || !cannot_touch(s.plane(cq.t), x, r + slack)) {
        const auto& tv = cq.v;
        WallGeom& g = tc.geo[m];
        std::array<double, 3> N;
        const Vec3 cp = closest_on_triangle(x, s.position(tv[0]), s.position(tv[1]), s.position(tv[2]), g.region, N);
        const Vec3 dv = cp - x;
        const double dist = norm(dv);
        if (dist < r && dist != 0.0) {
          g.n = (1.0 / dist) * dv;
          g.delta = r - dist;
          tc.N[m] = N;
          tc.tri[m] = cq.t;
          tc.cand[m] = static_cast<std::uint32_t>(q);
          tc.accept[m] = 1;
          ++m;
        }
      }
    }
    if (m == m0) continue;
    tc.particle.push_back(i);
    tc.begin.push_back(static_cast<std::uint32_t>(m));
    touching_group_.push_back(static_cast<std::uint32_t>(gr));
  }
}

void FacetContacts::select(const ParticleStore& p, const InterfaceSurface& s) {
  TouchingContacts& tc = touching_;
  const auto vert = [&](int v) { return s.position(v); };
  for (std::size_t j = 0; j < tc.particle.size(); ++j) {
    const std::size_t gr = touching_group_[j], b = tc.begin[j], e = tc.begin[j + 1], m = e - b;
    const std::uint32_t i = tc.particle[j];
    const Vec3 x = p.x[i];
    const double r = p.r[i];
    order_by_triangle(b, e);
    std::size_t naccept = m;
    if (m > 1) {
      const std::uint32_t* cand = tc.cand.data() + b;
      select_facet_contacts(
          s.all_corners(), s.topology(), vert,
          [&](std::size_t q) -> const std::array<int, 3>& { return candidates_[cand[q]].v; },
          [&](std::size_t q, int k) { return candidates_[cand[q]].nb[k]; }, x, r, tc.tri.data() + b,
          tc.geo.data() + b, tc.accept.data() + b, m, taken_);
      naccept = 0;
      for (std::size_t u = b; u < e; ++u) naccept += tc.accept[u];
    }
    merge_weights(b, e, naccept);
    // A new contact continues the history of one that ended in this call on the same smooth
    // surface (the particle moved on to the next triangle), else starts from zero.
    const std::uint64_t now = calls_;
    for (std::size_t u = b; u < e; ++u)
      if (tc.accept[u] && stamp_[tc.cand[u]] != now - 1) {
        carry_history(s, x, first_[gr], first_[gr + 1], b, e);
        break;
      }
    // The accepted contacts are active now; the others' histories end.
    for (std::size_t u = b; u < e; ++u)
      if (tc.accept[u]) stamp_[tc.cand[u]] = now;
  }
}

void FacetContacts::order_by_triangle(std::size_t b, std::size_t e) {
  // Selection and merging see the touching triangles in triangle order (deterministic).
  TouchingContacts& tc = touching_;
  for (std::size_t a = b + 1; a < e; ++a)
    for (std::size_t c = a; c > b && tc.tri[c - 1] > tc.tri[c]; --c) {
      std::swap(tc.tri[c - 1], tc.tri[c]);
      std::swap(tc.cand[c - 1], tc.cand[c]);
      std::swap(tc.geo[c - 1], tc.geo[c]);
      std::swap(tc.N[c - 1], tc.N[c]);
    }
}

void FacetContacts::merge_weights(std::size_t b, std::size_t e, std::size_t naccept) {
  // Nearly parallel contacts are one contact of a (deformed, locally concave) smooth surface.
  // Contact q is weighted by w_q = delta_q / sum_j s_qj delta_j over the accepted contacts j,
  // with the similarity s_qj = 1 - min(1, (1 - cos a_qj)/(1 - cos theta_c)) of their normals
  // (s_qq = 1): coplanar contacts share one contact's worth of force (weighted by depth),
  // contacts more than theta_c apart (a real concave corner) count fully, and the weights are
  // continuous in the depths and normals and independent of the contacts' order, so the force
  // does not jump when the surface under a particle turns from convex (one vertex or edge
  // contact) to slightly concave (several face contacts). One accepted contact: weight 1.
  TouchingContacts& tc = touching_;
  for (std::size_t u = b; u < e; ++u) {
    double w = 1.0;
    if (!tc.accept[u]) continue;
    if (naccept > 1) {
      double den = 0;
      for (std::size_t v = b; v < e; ++v) {
        if (!tc.accept[v]) continue;
        const double c = v == u ? 1.0 : dot(tc.geo[u].n, tc.geo[v].n);
        den += (1.0 - std::clamp((1.0 - c) / (1.0 - kSmoothSurfaceCos), 0.0, 1.0)) * tc.geo[v].delta;
      }
      w = tc.geo[u].delta / den;
    }
    tc.weight[u] = w;
  }
}

void FacetContacts::carry_history(const InterfaceSurface& s, const Vec3& x, std::size_t k, std::size_t ke,
                                  std::size_t b, std::size_t e) {
  // The particle's contacts that were active in the last call and are not now (its whole
  // candidate range: the scan may have stopped before them), with the normals they have now.
  const TouchingContacts& tc = touching_;
  const std::uint64_t now = calls_;
  ended_.clear();
  ended_n_.clear();
  for (std::size_t q = k; q < ke; ++q) {
    if (stamp_[q] != now - 1) continue;
    bool still = false;
    for (std::size_t u = b; u < e && !still; ++u) still = tc.accept[u] && tc.cand[u] == q;
    if (still) continue;
    const auto& tv = candidates_[q].v;
    Vec3 n;
    if (!facet_normal_now(x, s.position(tv[0]), s.position(tv[1]), s.position(tv[2]), n)) continue;
    ended_.push_back(static_cast<std::uint32_t>(q));
    ended_n_.push_back(n);
  }
  for (std::size_t u = b; u < e; ++u) {
    const std::size_t q = tc.cand[u];
    if (!tc.accept[u] || stamp_[q] == now - 1) continue;
    const int j = continued_contact(tc.geo[u].n, ended_n_.data(), ended_n_.size());
    state_[q] = j < 0 ? ContactState{} : state_[ended_[j]];
  }
}

std::size_t FacetContacts::n_active() const {
  return static_cast<std::size_t>(std::count(stamp_.begin(), stamp_.end(), calls_));
}

void FacetContacts::save_history(const ParticleStore& p, std::vector<ContactRecord>& out) const {
  for (std::size_t k = 0; k < cand_particle_.size(); ++k)
    if (stamp_[k] == calls_) out.push_back({p.id[cand_particle_[k]], candidates_[k].t, 2, -1, state_[k]});
}

}  // namespace fdem::coupling
