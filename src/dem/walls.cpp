#include "dem/walls.hpp"

#include "base/fixed_point.hpp"

#include "dem/facet_select.hpp"

#include <algorithm>
#include <cmath>
#include <set>

namespace fdem {

WallGeom wall_geometry(const Wall& w, int sub, const Vec3& x, double r) {
  WallGeom g{{0, 0, 0}, -1.0, 0};
  switch (w.kind) {
    case Wall::kPlane: {
      const double d = dot(x - (w.point + w.disp), w.normal);
      g.n = -w.normal;
      g.delta = r - d;
      break;
    }
    case Wall::kBox: {
      const Vec3 lo = w.bmin + w.disp, hi = w.bmax + w.disp;
      Vec3 cp;
      bool inside = true;
      for (int d = 0; d < 3; ++d) {
        cp[d] = std::clamp(x[d], lo[d], hi[d]);
        if (x[d] <= lo[d] || x[d] >= hi[d]) inside = false;
      }
      if (!inside) {
        const Vec3 dv = cp - x;
        const double dist = norm(dv);
        if (dist >= r || dist == 0.0) break;
        g.n = (1.0 / dist) * dv;
        g.delta = r - dist;
      } else {
        // Centre inside the solid box: push out through the nearest face.
        double best = 1e300;
        for (int d = 0; d < 3; ++d) {
          const double dl = x[d] - lo[d], dh = hi[d] - x[d];
          if (dl < best) { best = dl; g.n = Vec3{}; g.n[d] = 1.0; }
          if (dh < best) { best = dh; g.n = Vec3{}; g.n[d] = -1.0; }
        }
        g.delta = r + best;
      }
      break;
    }
    case Wall::kFacets: {
      const auto& t = w.tris[sub];
      const Vec3 a = w.verts[t[0]] + w.disp, b = w.verts[t[1]] + w.disp, c = w.verts[t[2]] + w.disp;
      const Vec3 cp = closest_on_triangle(x, a, b, c, g.region);
      const Vec3 dv = cp - x;
      const double dist = norm(dv);
      if (dist >= r || dist == 0.0) break;
      g.n = (1.0 / dist) * dv;
      g.delta = r - dist;
      break;
    }
  }
  return g;
}

void WallSet::build(const ParticleStore& p, double margin, const HistoryMap& history) {
  if (topo_.size() != walls.size()) {
    topo_.clear();
    for (const Wall& w : walls) topo_.push_back(w.kind == Wall::kFacets ? FacetTopology::build(w) : FacetTopology{});
  }
  pi_.clear(); wi_.clear(); sub_.clear(); state_.clear(); active_.clear();
  // Facet walls with many triangles get a hash grid (else every particle would test every
  // triangle at every rebuild: O(particles x triangles)).
  double rmax = 0;
  for (std::size_t i = 0; i < p.n_owned; ++i) rmax = std::max(rmax, p.r[i]);
  const double reach = rmax + margin;
  grids_.resize(walls.size());
  constexpr std::size_t kGridFrom = 64;
  for (std::size_t w = 0; w < walls.size(); ++w) {
    const Wall& wall = walls[w];
    WallGrid& g = grids_[w];
    if (wall.kind != Wall::kFacets || wall.tris.size() < kGridFrom) { g = WallGrid{}; continue; }
    const double h = 2 * reach;
    if (g.grid.h >= h && g.grid.h <= 2 * h) continue;  // still fine: cells hold everything within h / 2 >= reach
    g = WallGrid{};
    g.grid.h = h;
    for (std::size_t t = 0; t < wall.tris.size(); ++t) {
      Vec3 lo = wall.verts[wall.tris[t][0]], hi = lo;
      for (int c = 1; c < 3; ++c)
        for (int d = 0; d < 3; ++d) {
          lo[d] = std::min(lo[d], wall.verts[wall.tris[t][c]][d]);
          hi[d] = std::max(hi[d], wall.verts[wall.tris[t][c]][d]);
        }
      std::int64_t a[3], b[3], n = 1;
      for (int d = 0; d < 3; ++d) {
        a[d] = g.grid.cell(lo[d] - 0.5 * h, d);
        b[d] = g.grid.cell(hi[d] + 0.5 * h, d);
        n *= b[d] - a[d] + 1;
      }
      if (n > 512) { g.large.push_back(static_cast<std::int32_t>(t)); continue; }
      g.grid.add(a, b, static_cast<std::int32_t>(t));
    }
  }
  for (std::uint32_t i = 0; i < p.n_owned; ++i) {
    for (std::size_t w = 0; w < walls.size(); ++w) {
      const Wall& wall = walls[w];
      auto consider = [&](int sub) {
        const WallGeom g = wall_geometry(wall, sub < 0 ? 0 : sub, p.x[i], p.r[i] + margin);
        if (g.delta <= 0) return;
        pi_.push_back(i);
        wi_.push_back(static_cast<std::uint16_t>(w));
        sub_.push_back(sub);
        auto h = history.find(ContactKey{p.id[i], static_cast<std::int64_t>(w), 1, sub});
        state_.push_back(h == history.end() ? ContactState{} : h->second);
        active_.push_back(h != history.end());
      };
      if (wall.kind != Wall::kFacets) { consider(-1); continue; }
      const WallGrid& g = grids_[w];
      if (g.grid.h == 0) {
        for (int s = 0; s < static_cast<int>(wall.tris.size()); ++s) consider(s);
        continue;
      }
      // Candidates from the particle's cell (reference frame: the wall moves by disp), in
      // triangle order (the same order as without the grid).
      cand_.assign(g.large.begin(), g.large.end());
      if (const std::vector<std::int32_t>* in = g.grid.at(p.x[i] - wall.disp))
        cand_.insert(cand_.end(), in->begin(), in->end());
      std::sort(cand_.begin(), cand_.end());
      for (std::int32_t s : cand_) consider(s);
    }
  }
  disp_at_build_.resize(walls.size());
  for (std::size_t w = 0; w < walls.size(); ++w) disp_at_build_[w] = walls[w].disp;
}

namespace {

using exact::from_fixed;
using exact::to_fixed;

}  // namespace

void WallSet::select_facet_contacts(std::size_t w, const Vec3& x, double r, std::size_t k,
                                    std::size_t e, const std::vector<WallGeom>& geo,
                                    std::vector<std::uint8_t>& accept) const {
  const Wall& wall = walls[w];
  fdem::select_facet_contacts(wall.tris, topo_[w], [&](int v) { return wall.verts[v] + wall.disp; }, x, r,
                              sub_.data() + k, geo.data(), accept.data(), e - k, taken_);
}

FacetTopology FacetTopology::build(const Wall& w) { return build(w.tris); }

FacetTopology FacetTopology::build(const std::vector<std::array<int, 3>>& tris) {
  FacetTopology t;
  // Every triangle edge as (sorted vertex pair, slot 3 t + k); equal pairs form a group.
  struct E { std::int32_t lo, hi, slot; };
  std::vector<E> e;
  e.reserve(3 * tris.size());
  int nv = 0;
  for (std::size_t i = 0; i < tris.size(); ++i)
    for (int k = 0; k < 3; ++k) {
      const int a = tris[i][k], b = tris[i][(k + 1) % 3];
      e.push_back({std::min(a, b), std::max(a, b), static_cast<std::int32_t>(3 * i + k)});
      nv = std::max(nv, std::max(a, b) + 1);
    }
  std::sort(e.begin(), e.end(), [](const E& x, const E& y) {
    return x.lo != y.lo ? x.lo < y.lo : (x.hi != y.hi ? x.hi < y.hi : x.slot < y.slot);
  });
  t.edge_group.assign(e.size(), -1);
  std::vector<std::int32_t> deg(nv + 1, 0);
  std::vector<std::array<std::int32_t, 2>> unique_edges;
  for (std::size_t k = 0; k < e.size();) {
    std::size_t m = k;
    const auto g = static_cast<std::int32_t>(t.group_off.size() - 1);
    while (m < e.size() && e[m].lo == e[k].lo && e[m].hi == e[k].hi) {
      t.edge_group[e[m].slot] = g;
      t.group_tris.push_back(e[m].slot / 3);
      ++m;
    }
    t.group_off.push_back(static_cast<std::int32_t>(t.group_tris.size()));
    unique_edges.push_back({e[k].lo, e[k].hi});
    ++deg[e[k].lo];
    ++deg[e[k].hi];
    k = m;
  }
  t.vert_off.assign(nv + 1, 0);
  for (int v = 0; v < nv; ++v) t.vert_off[v + 1] = t.vert_off[v] + deg[v];
  t.vert_nbrs.resize(t.vert_off[nv]);
  std::vector<std::int32_t> fill(t.vert_off.begin(), t.vert_off.end() - 1);
  for (const auto& ue : unique_edges) {
    t.vert_nbrs[fill[ue[0]]++] = ue[1];
    t.vert_nbrs[fill[ue[1]]++] = ue[0];
  }
  return t;
}

void WallSet::carry_history(const Wall& wall, const Vec3& x, std::size_t k, std::size_t e,
                            const std::vector<WallGeom>& geo, const std::vector<std::uint8_t>& accept) {
  // A particle moving on from one triangle of a smooth surface to the next: the new contact
  // continues the ended one's history (fdem::continued_contact).
  bool fresh = false;
  ended_.clear();
  ended_n_.clear();
  for (std::size_t q = k; q < e; ++q) {
    if (accept[q - k] && !active_[q]) fresh = true;
    if (accept[q - k] || !active_[q]) continue;
    // The normal it would have now (also when it no longer touches).
    const auto& t = wall.tris[sub_[q]];
    Vec3 n;
    const Vec3 a = wall.verts[t[0]] + wall.disp, b = wall.verts[t[1]] + wall.disp, c = wall.verts[t[2]] + wall.disp;
    if (!facet_normal_now(x, a, b, c, n)) continue;
    ended_.push_back(q);
    ended_n_.push_back(n);
  }
  if (!fresh || ended_.empty()) return;
  for (std::size_t q = k; q < e; ++q) {
    if (!accept[q - k] || active_[q]) continue;
    const int j = continued_contact(geo[q - k].n, ended_n_.data(), ended_n_.size());
    if (j >= 0) state_[q] = state_[ended_[j]];
  }
}

int band_of(const std::vector<double>& edges, double s) {
  if (edges.size() < 2 || !(s >= edges.front()) || !(s < edges.back())) return -1;
  return static_cast<int>(std::upper_bound(edges.begin(), edges.end(), s) - edges.begin()) - 1;
}

void WallSet::size_bands() {
  band_off_.assign(walls.size() + 1, 0);
  for (std::size_t w = 0; w < walls.size(); ++w)
    band_off_[w + 1] = band_off_[w] + (walls[w].band_edges.empty() ? 0 : walls[w].band_edges.size() - 1);
  local_band_.assign(band_off_.back(), {0, 0, 0});
}

void WallSet::compute(ParticleStore& p, const MaterialTable& mats, double dt) {
  local_force_.assign(walls.size(), {0, 0, 0});
  local_k_.assign(walls.size(), 0);
  size_bands();

  std::vector<std::uint8_t> accept;
  const std::size_t n = pi_.size();
  std::size_t k = 0;
  while (k < n) {
    // A group: one particle against one wall.
    std::size_t e = k + 1;
    while (e < n && pi_[e] == pi_[k] && wi_[e] == wi_[k]) ++e;
    const std::uint32_t i = pi_[k];
    const Wall& wall = walls[wi_[k]];
    accept.assign(e - k, 0);
    std::vector<WallGeom>& geo = geo_;
    geo.resize(e - k);
    for (std::size_t q = k; q < e; ++q) {
      geo[q - k] = wall_geometry(wall, sub_[q] < 0 ? 0 : sub_[q], p.x[i], p.r[i]);
      accept[q - k] = geo[q - k].delta > 0;
    }
    if (wall.kind == Wall::kFacets && e - k > 1) {
      select_facet_contacts(wi_[k], p.x[i], p.r[i], k, e, geo, accept);
      carry_history(wall, p.x[i], k, e, geo, accept);
    }
    for (std::size_t q = k; q < e; ++q) {
      if (!accept[q - k]) { state_[q] = ContactState{}; active_[q] = 0; continue; }
      const WallGeom& g = geo[q - k];
      const Material& mp = mats[p.mat[i]];
      const Material& mw = mats[wall.mat];
      const PairParams& pp = mats.pair(p.mat[i], wall.mat);
      // A wall is flat: the particle's radius for both springs (linear) and R* = r (Hertz).
      const NormalLaw nl = normal_law(pp, mp.young, p.r[i], mw.young, p.r[i], p.r[i], g.delta);
      const Vec3 la = (p.r[i] - 0.5 * g.delta) * g.n;
      const Vec3 vrel = wall.vel - (p.v[i] + cross(p.w[i], la));
      const ContactForce cf = contact_force(g.n, nl, la, Vec3{}, vrel, p.w[i], p.r[i], pp, dt, state_[q]);
      active_[q] = 1;
      p.f[i] -= cf.force_b;
      p.t[i] += cf.torque_a;
      auto& lf = local_force_[wi_[q]];
      lf[0] += to_fixed(cf.force_b.x);
      lf[1] += to_fixed(cf.force_b.y);
      lf[2] += to_fixed(cf.force_b.z);
      if (wall.motion == Wall::kServo) {
        const double c = dot(g.n, wall.servo.axis);
        local_k_[wi_[q]] += to_fixed(nl.k * c * c);  // the normal tangent stiffness
      }
      if (!wall.band_edges.empty()) {
        const int b = band_of(wall.band_edges, dot(p.x[i], wall.band_axis));
        if (b >= 0) {
          auto& lb = local_band_[band_off_[wi_[q]] + static_cast<std::size_t>(b)];
          lb[0] += to_fixed(cf.force_b.x);
          lb[1] += to_fixed(cf.force_b.y);
          lb[2] += to_fixed(cf.force_b.z);
        }
      }
    }
    k = e;
  }
}

std::vector<exact::Int> WallSet::local_sums() {
  local_force_.resize(walls.size(), {0, 0, 0});
  local_k_.resize(walls.size(), 0);
  // Per wall: the three force components and the servo stiffness K, all as exact integer sums.
  if (band_off_.size() != walls.size() + 1) size_bands();  // (no compute yet: zero bands)
  const std::size_t nw = 4 * walls.size();
  std::vector<exact::Int> in(nw + 3 * local_band_.size());
  for (std::size_t w = 0; w < walls.size(); ++w) {
    for (int d = 0; d < 3; ++d) in[4 * w + d] = local_force_[w][d];
    in[4 * w + 3] = local_k_[w];
  }
  for (std::size_t b = 0; b < local_band_.size(); ++b)
    for (int d = 0; d < 3; ++d) in[nw + 3 * b + d] = local_band_[b][d];
  return in;
}

void WallSet::set_reduced_sums(const std::vector<exact::Int>& out) {
  const std::size_t nw = 4 * walls.size();
  for (std::size_t w = 0; w < walls.size(); ++w) {
    Wall& wall = walls[w];
    wall.force = {from_fixed(out[4 * w]), from_fixed(out[4 * w + 1]), from_fixed(out[4 * w + 2])};
    wall.stiffness = from_fixed(out[4 * w + 3]);
    wall.band_force.resize(band_off_[w + 1] - band_off_[w]);
    for (std::size_t b = band_off_[w]; b < band_off_[w + 1]; ++b)
      wall.band_force[b - band_off_[w]] = {from_fixed(out[nw + 3 * b]), from_fixed(out[nw + 3 * b + 1]),
                                           from_fixed(out[nw + 3 * b + 2])};
  }
}

double plane_gap(const Wall& a, const Wall& b) {
  return dot((b.point + b.disp) - (a.point + a.disp), a.normal);
}

double projected_area(const Wall& w, const Vec3& axis) {
  if (w.kind == Wall::kBox) {
    // The box face across the axis (axis-aligned boxes: the extents of the other two directions).
    const Vec3 e = w.bmax - w.bmin;
    return std::fabs(axis.x) * e.y * e.z + std::fabs(axis.y) * e.x * e.z + std::fabs(axis.z) * e.x * e.y;
  }
  if (w.kind == Wall::kFacets) {
    double a = 0;
    for (const auto& t : w.tris)
      a += 0.5 * std::fabs(dot(cross(w.verts[t[1]] - w.verts[t[0]], w.verts[t[2]] - w.verts[t[0]]), axis));
    return a;
  }
  return 0;  // a plane has no area of its own
}

double servo_step(const ServoParams& s, double force_along_axis, double stiffness, double area, double dt) {
  const double cap = s.max_velocity * dt;
  // The particles push the wall against the axis: the compressive force is -F . axis.
  const double missing = s.stress * area + force_along_axis;  // F0 - F (N)
  double dz;
  if (stiffness > 0) dz = s.gain * missing / stiffness;
  else dz = s.stress > 0 ? cap : 0.0;  // no contact: approach at the velocity cap
  return std::clamp(dz, -cap, cap);
}

void WallSet::apply_schedule(std::int64_t step) {
  for (Wall& w : walls) {
    if (w.schedule.empty()) continue;
    // The last phase that has started (phases sorted by from_step).
    const WallPhase* ph = nullptr;
    for (const WallPhase& q : w.schedule)
      if (q.from_step <= step) ph = &q;
    if (!ph) { w.motion = Wall::kFixed; w.vel = Vec3{}; continue; }
    const auto m = static_cast<Wall::Motion>(ph->motion);
    w.motion = m;
    w.servo = ph->servo;
    w.mass = ph->mass;
    w.free_dofs = ph->free_dofs;
    w.gravity = ph->gravity;
    if (m == Wall::kVelocity) w.vel = ph->velocity;
    else if (m == Wall::kFixed) w.vel = Vec3{};
    else if (m == Wall::kFree && ph->from_step == step) w.vel = ph->velocity;
  }
}

bool WallSet::needs_reduction() const {
  for (const Wall& w : walls)
    if (w.motion == Wall::kFree || w.motion == Wall::kServo) return true;
  return false;
}

void WallSet::integrate(double dt, const Vec3& gravity, double damping) {
  for (Wall& w : walls) {
    if (w.motion == Wall::kFree) {
      for (int d = 0; d < 3; ++d) {
        if (!(w.free_dofs & (1u << d))) { w.vel[d] = 0; continue; }
        double f = w.force[d] + (w.gravity ? w.mass * gravity[d] : 0.0);
        f = local_damping(f, w.vel[d], dt / w.mass, damping);
        w.vel[d] += dt * f / w.mass;
      }
    } else if (w.motion == Wall::kServo) {
      const ServoParams& s = w.servo;
      double area = s.area;
      if (s.area_walls[0] >= 0)
        area = std::fabs(plane_gap(walls[s.area_walls[0]], walls[s.area_walls[1]])) *
               std::fabs(plane_gap(walls[s.area_walls[2]], walls[s.area_walls[3]]));
      const double fa = dot(w.force, s.axis);
      w.area_now = area;
      w.stress = area > 0 ? -fa / area : 0.0;
      const double k = s.stiffness > 0 && w.stiffness > 0 ? s.stiffness : w.stiffness;
      const double dz = servo_step(s, fa, k, area, dt);
      w.vel = s.velocity - dot(s.velocity, s.axis) * s.axis + (dz / dt) * s.axis;
    }
  }
  // Move after every velocity is known: a servo's area may depend on other walls' positions.
  for (Wall& w : walls)
    if (w.motion != Wall::kFixed) w.disp += dt * w.vel;
}

double WallSet::moved_since_build() const {
  double m = 0;
  for (std::size_t w = 0; w < walls.size() && w < disp_at_build_.size(); ++w)
    m = std::max(m, norm(walls[w].disp - disp_at_build_[w]));
  return m;
}

void WallSet::save_history(const ParticleStore& p, std::vector<ContactRecord>& out) const {
  for (std::size_t k = 0; k < pi_.size(); ++k)
    if (active_[k]) out.push_back({p.id[pi_[k]], wi_[k], 1, sub_[k], state_[k]});
}

std::size_t WallSet::n_active() const {
  return static_cast<std::size_t>(std::count(active_.begin(), active_.end(), 1));
}

}  // namespace fdem
