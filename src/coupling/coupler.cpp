#include "coupling/coupler.hpp"

#include "base/exact_sum.hpp"
#include "base/petsc_check.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>
#include <string>
#include <unordered_map>

#include "dem/contact_law.hpp"
#include "dem/facet_select.hpp"
#include "dem/walls.hpp"
#include "base/scoped_timer.hpp"

namespace fdem::coupling {
namespace {

/// acc += x in fixed point (exact, order-independent).
inline void add_fixed(std::array<__int128, 3>& acc, const Vec3& x) {
  acc[0] += exact::to_fixed(x.x);
  acc[1] += exact::to_fixed(x.y);
  acc[2] += exact::to_fixed(x.z);
}


// True when triangle t (plane, centroid and bounding radius in pl) cannot touch the sphere
// (x, r): its plane is at least r away, or the circle the sphere cuts from the plane lies outside
// the triangle's bounding circle. Never true for a degenerate (NaN) plane.
inline bool cannot_touch(const std::array<double, 8>& pl, const Vec3& x, double r) {
  const double h = pl[0] * x.x + pl[1] * x.y + pl[2] * x.z - pl[3];
  if (std::abs(h) >= r) return true;
  const double px = x.x - h * pl[0] - pl[4], py = x.y - h * pl[1] - pl[5], pz = x.z - h * pl[2] - pl[6];
  const double rho = std::sqrt(r * r - h * h) + pl[7];
  return px * px + py * py + pz * pz >= rho * rho;
}

using Timer = ScopedTimer;

// The closest point of closest_on_triangle (dem/walls.cpp: the same arithmetic, the same point
// and region) and its barycentric coordinates N (as coupling::barycentric: on an edge the
// opposite N is exactly 0, at a vertex that vertex's N is exactly 1), from the same sub-results.
inline Vec3 closest_with_weights(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c, int& region,
                                 std::array<double, 3>& N) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) { region = 4; N = {1.0, 0.0, 0.0}; return a; }
  const Vec3 bp = p - b;
  const double d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) { region = 5; N = {0.0, 1.0, 0.0}; return b; }
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    region = 1;
    const double s = d1 / (d1 - d3);
    N = {1.0 - s, s, 0.0};
    return a + s * ab;
  }
  const Vec3 cp = p - c;
  const double d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) { region = 6; N = {0.0, 0.0, 1.0}; return c; }
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    region = 3;
    const double s = d2 / (d2 - d6);
    N = {1.0 - s, 0.0, s};
    return a + s * ac;
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    region = 2;
    const double s = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    N = {0.0, 1.0 - s, s};
    return b + s * (c - b);
  }
  region = 0;
  const double denom = 1.0 / (va + vb + vc);
  const Vec3 q = a + (vb * denom) * ab + (vc * denom) * ac;
  N = {1.0 - vb * denom - vc * denom, vb * denom, vc * denom};
  if (!(va + vb + vc > 0)) N = barycentric(a, b, c, q);  // degenerate: as coupling::barycentric
  return q;
}

// select_facet_contacts (dem/facet_select.hpp) for the interface: the same rules, the same
// arithmetic and so the same choice, but an edge shared by exactly two triangles is checked with
// nb[q][k], the vertex opposite edge k in the other triangle (-1: the edge has no other
// triangle; -2: not such a simple edge, the general adjacency is used), read with the candidate
// instead of through the edge groups. tri[q]: the triangle, cand[q]: its candidate, whose
// triangle's corners are cands[cand[q]].v and opposite vertices cands[cand[q]].nb.
template <class VertFn>
void select_interface(const std::vector<std::array<int, 3>>& tris, const FacetTopology& topo, VertFn&& vert,
                      const Vec3& x, double r, const std::int32_t* tri, const std::uint32_t* cand,
                      const InterfaceCandidate* cands,
                      const WallGeom* geo, std::uint8_t* accept, std::size_t count, std::vector<Vec3>& taken) {
  const double tol = 1e-9 * r;
  taken.clear();
  for (std::size_t q = 0; q < count; ++q) {
    if (!accept[q]) continue;
    const WallGeom& g = geo[q];
    const auto& t = cands[cand[q]].v;  // = tris[tri[q]]
    bool valid = true;
    if (g.region >= 1 && g.region <= 3) {
      const int k = g.region - 1;
      const int a = t[k], b = t[g.region % 3];
      const Vec3 pa = vert(a), ed = vert(b) - pa;
      const double ed2 = norm2(ed);
      // Inside the plane of the triangle with third corner o, perpendicular to the edge, inwards.
      auto beyond = [&](int o) {
        Vec3 in = vert(o) - pa;
        in -= (dot(in, ed) / ed2) * ed;
        const double len = norm(in);
        return !(len > 0 && dot(x - pa, in) / len > tol);
      };
      const std::int32_t o2 = cands[cand[q]].nb[k];
      if (o2 != -2) {
        valid = beyond(t[(k + 2) % 3]) && (o2 < 0 || beyond(o2));
      } else {
        const std::int32_t grp = topo.edge_group[3 * static_cast<std::size_t>(tri[q]) + k];
        for (std::int32_t it = topo.group_off[grp]; it < topo.group_off[grp + 1] && valid; ++it) {
          const auto& tf = tris[topo.group_tris[it]];
          const int o = tf[0] != a && tf[0] != b ? tf[0] : (tf[1] != a && tf[1] != b ? tf[1] : tf[2]);
          valid = beyond(o);
        }
      }
    } else if (g.region >= 4) {
      valid = facet_vertex_contact_counts(topo, vert, x, t[g.region - 4], tol);
    }
    if (!facet_contact_is_new(valid, x, r, g, tol, taken)) accept[q] = 0;
  }
}

}  // namespace

struct Coupler::Topo {
  std::vector<std::array<int, 3>> tris;  // vertex triples
  FacetTopology adj;
};

int Coupler::auto_subcycle(double dt_fe_stable, double dt_dem) {
  if (!(dt_dem > 0)) throw std::invalid_argument("auto_subcycle: the DEM step must be positive");
  const double q = dt_fe_stable / dt_dem;
  if (!(q >= 1)) return 1;
  return static_cast<int>(std::min(q * (1 + 1e-12), 1e9));
}

Coupler::Coupler(MPI_Comm comm, const fem::Mesh& mesh, fem::FeModel& model, std::vector<InterfaceTriangle> tris,
                 const CouplerParams& prm, double dt_dem)
    : comm_(comm), mesh_(mesh), model_(model), tris_(std::move(tris)), prm_(prm), dt_dem_(dt_dem),
      n_(prm.subcycle), rigid_(prm.rigid) {
  if (n_ < 1) throw std::invalid_argument("Coupler: subcycle must be at least 1, got " + std::to_string(n_));
  if (!(dt_dem > 0)) throw std::invalid_argument("Coupler: the DEM step must be positive");
  if (mesh.dim != 3) throw std::invalid_argument("Coupler: the FE mesh must be 3-D");
  // Vertices: unique corners, keyed by their sorted node list (a node, or a quad's 4 corners).
  std::map<std::array<std::int32_t, 4>, std::int32_t> index;
  topo_ = new Topo;
  tv_.resize(tris_.size());
  topo_->tris.resize(tris_.size());
  ref_box_.resize(tris_.size());
  for (std::size_t t = 0; t < tris_.size(); ++t) {
    for (int c = 0; c < 3; ++c) {
      Vertex v{tris_[t].nodes[c], tris_[t].weights[c]};
      std::array<std::int32_t, 4> key = v.nodes;
      std::sort(key.begin(), key.end());
      auto it = index.find(key);
      if (it == index.end()) {
        it = index.emplace(key, static_cast<std::int32_t>(verts_.size())).first;
        verts_.push_back(v);
      }
      tv_[t][c] = it->second;
      topo_->tris[t][c] = it->second;
    }
  }
  topo_->adj = FacetTopology::build(topo_->tris);
  vw_.assign(verts_.size(), 0.0);
  vnn_.assign(verts_.size(), 0);
  vsum_.assign(verts_.size(), F3{});
  for (std::size_t v = 0; v < verts_.size(); ++v)
    for (int k = 0; k < 4; ++k) {
      if (verts_[v].nodes[k] < 0) continue;
      if (vnn_[v] > 0 && verts_[v].w[k] != vw_[v])
        throw std::invalid_argument("Coupler: the nodes of an interface corner must have equal weights");
      vw_[v] = verts_[v].w[k];
      ++vnn_[v];
    }
  // Per triangle edge: the vertex opposite it in the one other triangle sharing it (see
  // select_interface).
  tnb_.resize(tris_.size());
  for (std::size_t t = 0; t < tris_.size(); ++t) {
    const auto& tt = topo_->tris[t];
    const bool distinct = tt[0] != tt[1] && tt[1] != tt[2] && tt[2] != tt[0];
    for (int k = 0; k < 3; ++k) {
      const std::int32_t grp = topo_->adj.edge_group[3 * t + k];
      const std::int32_t b = topo_->adj.group_off[grp], e = topo_->adj.group_off[grp + 1];
      std::int32_t o = -2;
      if (distinct && e - b == 1) {
        o = -1;
      } else if (distinct && e - b == 2) {
        const std::int32_t other = topo_->adj.group_tris[b] == static_cast<std::int32_t>(t) ? topo_->adj.group_tris[b + 1]
                                                                                            : topo_->adj.group_tris[b];
        const auto& tf = topo_->tris[other];
        const int a0 = tt[k], a1 = tt[(k + 1) % 3];
        const bool ok = other != static_cast<std::int32_t>(t) && tf[0] != tf[1] && tf[1] != tf[2] && tf[2] != tf[0];
        if (ok) o = tf[0] != a0 && tf[0] != a1 ? tf[0] : (tf[1] != a0 && tf[1] != a1 ? tf[1] : tf[2]);
      }
      tnb_[t][k] = o;
    }
  }
  int groups = 1;
  for (const InterfaceTriangle& t : tris_) {
    if (t.group < 0) throw std::invalid_argument("Coupler: negative surface group");
    groups = std::max(groups, t.group + 1);
  }
  tgroup_.resize(tris_.size());
  for (std::size_t t = 0; t < tris_.size(); ++t) tgroup_[t] = tris_[t].group;
  group_sum_.assign(groups, F3{});
  last_group_force_.assign(groups, Vec3{});
  // Reference positions and boxes.
  vx_.assign(verts_.size(), Vec3{});
  vv_.assign(verts_.size(), Vec3{});
  vx_fe_.assign(verts_.size(), Vec3{});
  for (std::size_t v = 0; v < verts_.size(); ++v)
    for (int k = 0; k < 4; ++k) {
      const std::int32_t n = verts_[v].nodes[k];
      if (n < 0) continue;
      const double* X = &mesh.coords[3 * static_cast<std::size_t>(n)];
      vx_[v] += verts_[v].w[k] * Vec3{X[0], X[1], X[2]};
    }
  for (std::size_t t = 0; t < tris_.size(); ++t) {
    Vec3 lo = vx_[tv_[t][0]], hi = lo;
    for (int c = 1; c < 3; ++c)
      for (int d = 0; d < 3; ++d) {
        lo[d] = std::min(lo[d], vx_[tv_[t][c]][d]);
        hi[d] = std::max(hi[d], vx_[tv_[t][c]][d]);
      }
    ref_box_[t] = {lo, hi};
  }
  node_slot_.assign(mesh.n_nodes(), -1);
  plane_.resize(tris_.size());
  // The largest displacement so far (a restarted model may be deformed already).
  const std::vector<double> u = model_.owned_displacements();
  const int dim = model_.dim();
  double m = 0;
  for (std::size_t i = 0; i + dim <= u.size(); i += dim) m = std::max(m, u[i] * u[i] + u[i + 1] * u[i + 1] + u[i + 2] * u[i + 2]);
  m = std::sqrt(m);
  MPI_Allreduce(&m, &max_u_, 1, MPI_DOUBLE, MPI_MAX, comm_);
}

Coupler::~Coupler() {
  if (vel_) VecDestroy(&vel_);
  if (scatter_) VecScatterDestroy(&scatter_);
  if (local_) VecDestroy(&local_);
  delete topo_;
}

void Coupler::choose_seen(const Vec3& lo, const Vec3& hi, double reach) {
  const double g = reach + max_u_;
  seen_.clear();
  for (std::size_t t = 0; t < tris_.size(); ++t) {
    const auto& b = ref_box_[t];
    bool overlap = true;
    for (int d = 0; d < 3; ++d)
      if (b[0][d] - g > hi[d] || b[1][d] + g < lo[d]) overlap = false;
    if (overlap) seen_.push_back(static_cast<std::int32_t>(t));
  }
}

void Coupler::build_scatter() {
  // Nodes of the seen triangles, ascending; remap the per-node data kept across rebuilds.
  std::vector<std::int32_t> nodes;
  for (std::int32_t t : seen_)
    for (int c = 0; c < 3; ++c)
      for (std::int32_t n : verts_[tv_[t][c]].nodes)
        if (n >= 0) nodes.push_back(n);
  std::sort(nodes.begin(), nodes.end());
  nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
  seen_verts_.clear();
  for (std::int32_t t : seen_)
    for (int c = 0; c < 3; ++c) seen_verts_.push_back(tv_[t][c]);
  std::sort(seen_verts_.begin(), seen_verts_.end());
  seen_verts_.erase(std::unique(seen_verts_.begin(), seen_verts_.end()), seen_verts_.end());
  std::vector<Vec3> nu(nodes.size()), nu_prev(nodes.size());
  std::vector<F3> fsum(nodes.size(), F3{});
  for (std::size_t s = 0; s < nodes.size(); ++s) {
    const std::int32_t old = node_slot_[nodes[s]];
    if (old >= 0) { nu[s] = nu_[old]; nu_prev[s] = nu_prev_[old]; fsum[s] = fsum_[old]; }
  }
  // Forces summed this sub-cycle on nodes no longer seen are handed over at the next update.
  for (std::size_t s = 0; s < need_nodes_.size(); ++s) {
    if (fsum_[s] == F3{}) continue;
    if (!std::binary_search(nodes.begin(), nodes.end(), need_nodes_[s])) {
      carry_nodes_.push_back(model_.global_node(need_nodes_[s]));
      carry_forces_.push_back(fsum_[s]);
    }
  }
  for (std::int32_t n : need_nodes_) node_slot_[n] = -1;
  need_nodes_.swap(nodes);
  for (std::size_t s = 0; s < need_nodes_.size(); ++s) node_slot_[need_nodes_[s]] = static_cast<std::int32_t>(s);
  nu_.swap(nu);
  nu_prev_.swap(nu_prev);
  fsum_.swap(fsum);
  gnode_.resize(need_nodes_.size());
  for (std::size_t s = 0; s < need_nodes_.size(); ++s) gnode_[s] = model_.global_node(need_nodes_[s]);

  if (scatter_) VecScatterDestroy(&scatter_);
  if (local_) VecDestroy(&local_);
  const PetscInt nf = model_.node_dofs();
  std::vector<PetscInt> idx(3 * need_nodes_.size());
  for (std::size_t s = 0; s < need_nodes_.size(); ++s)
    for (int d = 0; d < 3; ++d) idx[3 * s + d] = gnode_[s] * nf + d;
  IS is;
  petsc_check(ISCreateGeneral(PETSC_COMM_SELF, static_cast<PetscInt>(idx.size()), idx.data(), PETSC_COPY_VALUES, &is),
        "ISCreateGeneral");
  petsc_check(VecCreateSeq(PETSC_COMM_SELF, static_cast<PetscInt>(idx.size()), &local_), "VecCreateSeq");
  petsc_check(VecScatterCreate(model_.displacement_vec(), is, local_, nullptr, &scatter_), "VecScatterCreate");
  petsc_check(ISDestroy(&is), "ISDestroy");
}

void Coupler::scatter_positions() {
  Timer tm(timing_.scatter);
  petsc_check(VecScatterBegin(scatter_, model_.displacement_vec(), local_, INSERT_VALUES, SCATTER_FORWARD), "VecScatterBegin");
  petsc_check(VecScatterEnd(scatter_, model_.displacement_vec(), local_, INSERT_VALUES, SCATTER_FORWARD), "VecScatterEnd");
  const PetscScalar* a;
  petsc_check(VecGetArrayRead(local_, &a), "VecGetArrayRead");
  for (std::size_t s = 0; s < need_nodes_.size(); ++s) nu_[s] = Vec3{a[3 * s], a[3 * s + 1], a[3 * s + 2]};
  petsc_check(VecRestoreArrayRead(local_, &a), "VecRestoreArrayRead");
  // Vertex positions of the seen triangles.
  for (std::int32_t t : seen_)
    for (int c = 0; c < 3; ++c) {
      const std::int32_t v = tv_[t][c];
      Vec3 x;
      for (int k = 0; k < 4; ++k) {
        const std::int32_t n = verts_[v].nodes[k];
        if (n < 0) continue;
        const double* X = &mesh_.coords[3 * static_cast<std::size_t>(n)];
        x += verts_[v].w[k] * (Vec3{X[0], X[1], X[2]} + nu_[node_slot_[n]]);
      }
      vx_[v] = x;
    }
  // Positions at this FE update (the sub-steps extrapolate from them) and the seen vertices.
  for (std::int32_t v : seen_verts_) vx_fe_[v] = vx_[v];
  update_planes(seen_);
}

void Coupler::update_planes(const std::vector<std::int32_t>& tris) {
  for (std::int32_t t : tris) {
    const Vec3 a = vx_[tv_[t][0]], b = vx_[tv_[t][1]], c = vx_[tv_[t][2]];
    const Vec3 nn = cross(b - a, c - a);
    const double l = norm(nn);
    // A degenerate triangle gets a NaN plane: the quick rejection never skips it.
    const Vec3 u = l > 0 ? (1.0 / l) * nn : Vec3{NAN, NAN, NAN};
    const Vec3 m = (1.0 / 3.0) * (a + b + c);
    const double R = std::sqrt(std::max({norm2(a - m), norm2(b - m), norm2(c - m)}));
    plane_[t] = {u.x, u.y, u.z, dot(u, a), m.x, m.y, m.z, R};
  }
}

void Coupler::scatter_velocities(bool reduce_vmax) {
  Timer tm(timing_.scatter);
  if (!vel_) petsc_check(VecDuplicate(model_.displacement_vec(), &vel_), "VecDuplicate");
  const std::vector<double> v = model_.owned_velocities();
  const int dim = model_.dim(), nf = model_.node_dofs();
  PetscScalar* a;
  petsc_check(VecGetArray(vel_, &a), "VecGetArray");
  for (std::size_t i = 0; i < model_.n_owned(); ++i)
    for (int d = 0; d < nf; ++d) a[i * nf + d] = d < dim ? v[i * dim + d] : 0.0;
  petsc_check(VecRestoreArray(vel_, &a), "VecRestoreArray");
  petsc_check(VecScatterBegin(scatter_, vel_, local_, INSERT_VALUES, SCATTER_FORWARD), "VecScatterBegin");
  petsc_check(VecScatterEnd(scatter_, vel_, local_, INSERT_VALUES, SCATTER_FORWARD), "VecScatterEnd");
  const PetscScalar* b;
  petsc_check(VecGetArrayRead(local_, &b), "VecGetArrayRead");
  double loc = 0, g = 0;
  for (std::size_t s = 0; s < need_nodes_.size(); ++s) {
    nu_prev_[s] = rigid_ ? Vec3{} : Vec3{b[3 * s], b[3 * s + 1], b[3 * s + 2]};
    loc = std::max(loc, norm2(nu_prev_[s]));
  }
  petsc_check(VecRestoreArrayRead(local_, &b), "VecRestoreArrayRead");
  // Vertex velocities of the seen triangles (always the FE's own velocity: a finite difference
  // of positions would differ from it in the last bits, and on a rank whose scatter was just
  // rebuilt the two would mix -- results would then depend on the number of ranks).
  for (std::int32_t t : seen_)
    for (int c = 0; c < 3; ++c) {
      const std::int32_t v = tv_[t][c];
      Vec3 w;
      for (int k = 0; k < 4; ++k)
        if (verts_[v].nodes[k] >= 0) w += verts_[v].w[k] * nu_prev_[node_slot_[verts_[v].nodes[k]]];
      vv_[v] = w;
    }
  if (!reduce_vmax) return;  // the caller reduces it with other maxima
  loc = std::sqrt(loc);
  MPI_Allreduce(&loc, &g, 1, MPI_DOUBLE, MPI_MAX, comm_);
  vmax_ = g;
}

void Coupler::refresh_positions() {
  // Collective: every rank rebuilds (its seen set is unchanged) and reads the FE state.
  if (!scatter_) return;
  scatter_positions();
  moved_ = std::numeric_limits<double>::infinity();  // unknown motion: no quick rejection, rebuild
}

void Coupler::flush_vertex_sums() {
  for (std::int32_t v : cand_verts_) {
    F3& a = vsum_[v];
    if (a == F3{}) continue;
    for (int k = 0; k < 4; ++k) {
      const std::int32_t n = verts_[v].nodes[k];
      if (n < 0) continue;
      F3& f = fsum_[node_slot_[n]];
      for (int d = 0; d < 3; ++d) f[d] += a[d];
    }
    a = F3{};
  }
}

void Coupler::build(const ParticleStore& p, const Vec3& lo, const Vec3& hi, double margin, const HistoryMap& history) {
  flush_vertex_sums();  // the candidates' vertices change below
  double rmax = 0;
  for (std::size_t i = 0; i < p.n_owned; ++i) rmax = std::max(rmax, p.r[i]);
  const std::vector<std::int32_t> old_seen = seen_;
  choose_seen(lo, hi, rmax + margin);
  int changed = (seen_ != old_seen || !scatter_) ? 1 : 0, any = 0;
  MPI_Allreduce(&changed, &any, 1, MPI_INT, MPI_LOR, comm_);
  if (any) {
    {
      Timer tm(timing_.scatter);
      build_scatter();
    }
    // Positions, then the nodal velocities of the last FE step: the FE's own velocity, which is
    // exactly its last displacement increment / dt_FE (also for prescribed dofs), so newly seen
    // nodes and a restarted run get the same surface velocity as an uninterrupted run.
    scatter_positions();
    scatter_velocities();
  }
  nu_at_build_ = nu_;
  // Between FE updates the surface is extrapolated (see compute()): it may move dt_FE v_max
  // within one sub-cycle without any FE update.
  moved_ = extrapolating() ? dt_fe() * vmax_ : 0.0;

  // The whole seen surface where it is now (extrapolated within the sub-cycle; compute() then
  // moves only the candidates' triangles).
  if (extrapolating()) {
    const double s = substeps_ * dt_dem_;
    for (std::int32_t v : seen_verts_) vx_[v] = vx_fe_[v] + s * vv_[v];
  }
  // Candidates: seen triangles binned in a hash grid by their box grown by the reach.
  Timer tm(timing_.contacts);
  const double reach = rmax + margin;
  const double h = std::max(2 * reach, 1e-12);
  auto cell = [&](double c, double o) { return static_cast<std::int64_t>(std::floor((c - o) / h)); };
  const Vec3 o = lo;
  auto key = [](std::int64_t i, std::int64_t j, std::int64_t k) {
    return static_cast<std::uint64_t>((i & 0x1FFFFF) | ((j & 0x1FFFFF) << 21) | ((k & 0x1FFFFF) << 42));
  };
  std::unordered_map<std::uint64_t, std::vector<std::int32_t>> grid;
  for (std::int32_t t : seen_) {
    Vec3 bl = vx_[tv_[t][0]], bh = bl;
    for (int c = 1; c < 3; ++c)
      for (int d = 0; d < 3; ++d) {
        bl[d] = std::min(bl[d], vx_[tv_[t][c]][d]);
        bh[d] = std::max(bh[d], vx_[tv_[t][c]][d]);
      }
    std::int64_t a[3], b[3];
    bool skip = false;
    for (int d = 0; d < 3; ++d) {
      // Only the part of the box near this subdomain matters.
      const double l = std::max(bl[d] - reach, lo[d] - reach), u = std::min(bh[d] + reach, hi[d] + reach);
      if (l > u) { skip = true; break; }
      a[d] = cell(l, o[d]);
      b[d] = cell(u, o[d]);
    }
    if (skip) continue;
    for (std::int64_t i = a[0]; i <= b[0]; ++i)
      for (std::int64_t j = a[1]; j <= b[1]; ++j)
        for (std::int64_t k = a[2]; k <= b[2]; ++k) grid[key(i, j, k)].push_back(t);
  }
  pi_.clear();
  cand_.clear();
  state_.clear();
  stamp_.clear();
  // A particle's candidates nearest first (then by triangle): compute() stops at the first one
  // that cannot be reached. The particles in the order of their nearest triangle (then by
  // index): consecutive particles then mostly share the surface data (vertices, planes, force
  // sums), which are numbered along the mesh faces -- far fewer cache misses than in particle
  // order. (Each particle's contacts are still summed in a fixed order, so its force does not
  // depend on the order of the particles; the nodal sums are exact.)
  std::vector<std::pair<double, std::int32_t>> near;
  struct Group { std::int32_t key; std::uint32_t i, b, e; };
  std::vector<Group> groups;
  for (std::uint32_t i = 0; i < p.n_owned; ++i) {
    auto it = grid.find(key(cell(p.x[i].x, o.x), cell(p.x[i].y, o.y), cell(p.x[i].z, o.z)));
    if (it == grid.end()) continue;
    const std::size_t b0 = near.size();
    for (std::int32_t t : it->second) {
      int region;
      const Vec3 cp = closest_on_triangle(p.x[i], vx_[tv_[t][0]], vx_[tv_[t][1]], vx_[tv_[t][2]], region);
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
  for (const Group& gr : groups)
    for (std::uint32_t c = gr.b; c < gr.e; ++c) {
      const auto& [d, t] = near[c];
      pi_.push_back(gr.i);
      cand_.push_back({d, t, tv_[t], tnb_[t]});
      auto h = history.find(ContactKey{p.id[gr.i], t, 2, -1});
      state_.push_back(h == history.end() ? ContactState{} : h->second);
      stamp_.push_back(h == history.end() ? 0 : ncompute_);  // active in the last compute()
    }
  // The particles with candidates (their candidate ranges and positions at the build), and the
  // scratch of compute() for the largest number of candidates of one particle.
  std::size_t most = 0;
  gi_.clear();
  gbeg_.clear();
  gxb_.clear();
  for (std::size_t a = 0, b = 0; a < pi_.size(); a = b) {
    for (b = a + 1; b < pi_.size() && pi_[b] == pi_[a];) ++b;
    most = std::max(most, b - a);
    gi_.push_back(pi_[a]);
    gbeg_.push_back(static_cast<std::uint32_t>(a));
    gxb_.push_back(p.x[pi_[a]]);
  }
  gbeg_.push_back(static_cast<std::uint32_t>(pi_.size()));
  if (geo_.size() < most) {
    accept_.resize(most);
    geo_.resize(most);
    bary_.resize(most);
    tsel_.resize(most);
    qsel_.resize(most);
    weight_.resize(most);
  }
  rmax_build_ = rmax;
  cand_verts_.clear();
  for (const InterfaceCandidate& c : cand_)
    for (std::int32_t v : c.v) cand_verts_.push_back(v);
  std::sort(cand_verts_.begin(), cand_verts_.end());
  cand_verts_.erase(std::unique(cand_verts_.begin(), cand_verts_.end()), cand_verts_.end());
}

bool Coupler::extrapolating() const { return !rigid_ && n_ > 1 && vmax_ > 0; }

void Coupler::compute(ParticleStore& p, const MaterialTable& mats, double dt) {
  Timer tm(timing_.contacts);
  // Sub-step k of a sub-cycle sees the surface where the last FE velocity carries it,
  // x = x_FE + k dt_DE v_FE, instead of frozen for n steps and then jumping by dt_FE v_FE:
  // the jump at the next FE update is then only O(dt_FE^2 a).
  if (extrapolating()) {
    const double s = substeps_ * dt_dem_;
    for (std::int32_t v : cand_verts_) vx_[v] = vx_fe_[v] + s * vv_[v];
  }
  // The quick rejection uses the planes of the FE positions: the extrapolated triangle is
  // within s v_max of them.
  const double slack = extrapolating() ? substeps_ * dt_dem_ * vmax_ : 0.0;
  step_nodal_ = Vec3{};
  step_particle_ = Vec3{};
  sides_.clear();
  const Material& mi = mats[prm_.material];
  const std::uint64_t now = ++ncompute_;
  const std::size_t ng = gi_.size();
  for (std::size_t gr = 0; gr < ng; ++gr) {
    const std::size_t k = gbeg_[gr], e = gbeg_[gr + 1];
    const std::uint32_t i = gi_[gr];
    // Prefetch a few particles ahead: the particle, and the surface data of its nearest candidate.
    if (gr + 4 < ng) {
      const std::uint32_t j = gi_[gr + 4];
      __builtin_prefetch(&p.x[j]);
      __builtin_prefetch(&p.r[j]);
      __builtin_prefetch(&p.v[j]);
      __builtin_prefetch(&p.w[j]);
      __builtin_prefetch(&p.f[j]);
      __builtin_prefetch(&p.t[j]);
      const std::size_t f = gbeg_[gr + 3];
      for (int c = 0; c < 3; ++c) {
        __builtin_prefetch(&vx_[cand_[f].v[c]]);
        __builtin_prefetch(&vv_[cand_[f].v[c]]);
      }
      __builtin_prefetch(&plane_[cand_[f].t]);
      __builtin_prefetch(&state_[f]);
      __builtin_prefetch(&stamp_[f]);
    }
    const Vec3 x = p.x[i];
    const double r = p.r[i];
    // Quick rejection (the lists include the skin, and a sphere on a face is a candidate of all
    // the face's triangles near it): (1) the closest-point distance at the build minus how far
    // the particle and the surface moved since cannot be below r -- the candidates are sorted by
    // that distance, so the first such one ends the particle's list; (2) the triangle's plane or
    // bounding circle is out of reach (cannot_touch), tested only when (1) does not already
    // guarantee the triangle within reach (d0 + moved < r: then it cannot say no).
    const double moved = norm(x - gxb_[gr]) + moved_;
    const double lim = r + moved;
    std::size_t m = 0;  // touching candidates of this particle
    for (std::size_t q = k; q < e && cand_[q].d0 < lim; ++q) {
      const InterfaceCandidate& cq = cand_[q];
      if (cq.d0 + moved < r || !cannot_touch(plane_[cq.t], x, r + slack)) {
        const auto& tv = cq.v;
        WallGeom& g = geo_[m];
        std::array<double, 3> N;
        const Vec3 cp = closest_with_weights(x, vx_[tv[0]], vx_[tv[1]], vx_[tv[2]], g.region, N);
        const Vec3 dv = cp - x;
        const double dist = norm(dv);
        if (dist < r && dist != 0.0) {
          g.n = (1.0 / dist) * dv;
          g.delta = r - dist;
          bary_[m] = N;
          tsel_[m] = cq.t;
          qsel_[m] = static_cast<std::uint32_t>(q);
          accept_[m] = 1;
          ++m;
        }
      }
    }
    if (m == 0) continue;
    // Selection and merging see the touching triangles in triangle order (deterministic, and
    // the order of the unsorted candidate lists of before).
    for (std::size_t a = 1; a < m; ++a)
      for (std::size_t b = a; b > 0 && tsel_[b - 1] > tsel_[b]; --b) {
        std::swap(tsel_[b - 1], tsel_[b]);
        std::swap(qsel_[b - 1], qsel_[b]);
        std::swap(geo_[b - 1], geo_[b]);
        std::swap(bary_[b - 1], bary_[b]);
      }
    std::size_t naccept = m;
    if (m > 1) {
      select_interface(topo_->tris, topo_->adj, [&](int v) { return vx_[v]; }, x, r, tsel_.data(), qsel_.data(),
                       cand_.data(), geo_.data(), accept_.data(), m, taken_);
      naccept = 0;
      for (std::size_t u = 0; u < m; ++u) naccept += accept_[u];
    }
    // Nearly parallel contacts are one contact of a (deformed, locally concave) smooth surface.
    // Contact q is weighted by w_q = delta_q / sum_j s_qj delta_j over the accepted contacts j,
    // with the similarity s_qj = 1 - min(1, (1 - cos a_qj)/(1 - cos theta_c)) of their normals
    // (s_qq = 1): coplanar contacts share one contact's worth of force (weighted by depth),
    // contacts more than theta_c apart (a real concave corner) count fully, and the weights are
    // continuous in the depths and normals and independent of the contacts' order, so the force
    // does not jump when the surface under a particle turns from convex (one vertex or edge
    // contact) to slightly concave (several face contacts). One accepted contact: weight 1.
    for (std::size_t u = 0; u < m; ++u) {
      double w = 1.0;
      if (!accept_[u]) continue;
      if (naccept > 1) {
        double den = 0;
        for (std::size_t v = 0; v < m; ++v) {
          if (!accept_[v]) continue;
          const double c = v == u ? 1.0 : dot(geo_[u].n, geo_[v].n);
          den += (1.0 - std::clamp((1.0 - c) / (1.0 - kSmoothSurfaceCos), 0.0, 1.0)) * geo_[v].delta;
        }
        w = geo_[u].delta / den;
      }
      weight_[u] = w;
    }
    // A new contact continues the history of one that ended in this step on the same smooth
    // surface (the particle moved on to the next triangle), else starts from zero.
    for (std::size_t u = 0; u < m; ++u)
      if (accept_[u] && stamp_[qsel_[u]] != now - 1) {
        carry_history(x, k, e, m, now);
        break;
      }
    const double ep = mats[p.mat[i]].young;
    const PairParams& pr = mats.pair(p.mat[i], prm_.material);
    for (std::size_t u = 0; u < m; ++u) {
      const std::size_t q = qsel_[u];
      if (!accept_[u]) continue;  // not active now: its history ends (stamp_)
      stamp_[q] = now;
      const WallGeom& g = geo_[u];
      const std::int32_t t = tsel_[u];
      const auto& tv = tv_[t];
      const std::array<double, 3>& N = bary_[u];
      const Vec3 vs = N[0] * vv_[tv[0]] + N[1] * vv_[tv[1]] + N[2] * vv_[tv[2]];
      const Vec3 la = (r - 0.5 * g.delta) * g.n;
      const Vec3 vrel = vs - (p.v[i] + cross(p.w[i], la));
      // The interface is flat: the particle's radius for both springs (linear) and R* = r (Hertz).
      const NormalLaw nl = normal_law(pr, ep, r, mi.young, r, r, g.delta);
      ContactForce cf = contact_force(g.n, nl, la, Vec3{}, vrel, p.w[i], r, pr, dt, state_[q]);
      const double wq = weight_[u];
      if (wq != 1.0) { cf.force_b *= wq; cf.torque_a *= wq; }
      add_fixed(group_sum_[contact_group(m, u)], cf.force_b);
      p.f[i] -= cf.force_b;
      p.t[i] += cf.torque_a;
      step_particle_ -= cf.force_b;
      sides_.push_back(Side{i, g.n, la, -1.0 * cf.force_b});
      // F_i = N_i F to the corners, each corner's share over its nodes by weight: the share
      // (N_c w) F of each node of corner c is summed per corner (flush_vertex_sums() adds it to
      // each of the corner's nodes) -- the same fixed-point terms as per node.
      for (int cc = 0; cc < 3; ++cc) {
        if (N[cc] == 0.0) continue;
        const std::int32_t v = tv[cc];
        const Vec3 fs = (N[cc] * vw_[v]) * cf.force_b;
        add_fixed(vsum_[v], fs);
        step_nodal_ += static_cast<double>(vnn_[v]) * fs;
      }
    }
  }
  ++substeps_;
}

void Coupler::carry_history(const Vec3& x, std::size_t k, std::size_t e, std::size_t m, std::uint64_t now) {
  // The particle's contacts that were active in the last call and are not now (its whole
  // candidate range: the scan may have stopped before them), with the normals they have now.
  ended_.clear();
  ended_n_.clear();
  for (std::size_t q = k; q < e; ++q) {
    if (stamp_[q] != now - 1) continue;
    bool still = false;
    for (std::size_t u = 0; u < m && !still; ++u) still = accept_[u] && qsel_[u] == q;
    if (still) continue;
    const auto& tv = cand_[q].v;
    int region = 0;
    std::array<double, 3> N;
    const Vec3 dv = closest_with_weights(x, vx_[tv[0]], vx_[tv[1]], vx_[tv[2]], region, N) - x;
    const double dist = norm(dv);
    if (dist == 0.0) continue;
    ended_.push_back(static_cast<std::uint32_t>(q));
    ended_n_.push_back((1.0 / dist) * dv);
  }
  for (std::size_t u = 0; u < m; ++u) {
    const std::size_t q = qsel_[u];
    if (!accept_[u] || stamp_[q] == now - 1) continue;
    const int j = continued_contact(geo_[u].n, ended_n_.data(), ended_n_.size());
    state_[q] = j < 0 ? ContactState{} : state_[ended_[j]];
  }
}

std::int32_t Coupler::contact_group(std::size_t m, std::size_t u) const {
  const WallGeom& g = geo_[u];
  std::int32_t grp = tgroup_[tsel_[u]];
  if (g.region == 0 || last_group_force_.size() < 2) return grp;
  // A contact on an edge or a corner belongs to the surface the particle pushes on most directly:
  // of its touching triangles, the one whose outward normal is closest to the direction from the
  // contact to the particle (a grain on the top-front edge of a thin rib pushes the rib's front
  // face -- bearing -- when it lies in front of the rib, its top -- friction -- when above it).
  double best = -2;
  for (std::size_t j = 0; j < m; ++j) {
    const auto& pl = plane_[tsel_[j]];
    const double c = -(pl[0] * g.n.x + pl[1] * g.n.y + pl[2] * g.n.z);
    if (c > best) { best = c; grp = tgroup_[tsel_[j]]; }
  }
  return grp;
}

void Coupler::end_step(std::int64_t step) {
  if (step % n_ == 0) fe_update();
}

void Coupler::fe_update() {
  // Every rank computes every DEM step (compute() is collective in effect), so substeps_ is the
  // same on all ranks: no collective is needed to agree on it.
  if (substeps_ == 0) return;
  const int m = substeps_;
  {
    Timer tm(timing_.reduce);
    flush_vertex_sums();
    // Exact sums (fixed point): the FE receives the same forces on any number of ranks.
    std::vector<PetscInt> g(gnode_);
    std::vector<exact::Int> f(3 * (need_nodes_.size() + carry_nodes_.size()));
    const double inv = 1.0 / m;
    const std::size_t ng = group_sum_.size();
    std::vector<exact::Int> tot(3 + 3 * ng, 0);  // total, then per group
    for (std::size_t s = 0; s < need_nodes_.size(); ++s)
      for (int d = 0; d < 3; ++d) { f[3 * s + d] = fsum_[s][d]; tot[d] += fsum_[s][d]; }
    for (std::size_t c = 0; c < carry_nodes_.size(); ++c) {
      g.push_back(carry_nodes_[c]);
      for (int d = 0; d < 3; ++d) {
        f[3 * (need_nodes_.size() + c) + d] = carry_forces_[c][d];
        tot[d] += carry_forces_[c][d];
      }
    }
    model_.set_interface_forces_exact(g, f, inv);
    for (std::size_t k = 0; k < ng; ++k)
      for (int d = 0; d < 3; ++d) tot[3 + 3 * k + d] = group_sum_[k][d];
    exact::allreduce_sum(tot.data(), static_cast<int>(tot.size()), comm_);
    last_update_force_ = {inv * exact::from_fixed(tot[0]), inv * exact::from_fixed(tot[1]), inv * exact::from_fixed(tot[2])};
    for (std::size_t k = 0; k < ng; ++k) {
      last_group_force_[k] = {inv * exact::from_fixed(tot[3 + 3 * k]), inv * exact::from_fixed(tot[4 + 3 * k]),
                              inv * exact::from_fixed(tot[5 + 3 * k])};
      group_sum_[k] = F3{};
    }
    carry_nodes_.clear();
    carry_forces_.clear();
    std::fill(fsum_.begin(), fsum_.end(), F3{});
    last_substeps_ = m;
    substeps_ = 0;
  }
  if (rigid_) {
    for (auto& v : nu_prev_) v = Vec3{};
    for (auto& v : vv_) v = Vec3{};
    // Back to the FE positions if the surface was being extrapolated when it was made rigid.
    if (vmax_ > 0) {
      for (std::int32_t v : seen_verts_) vx_[v] = vx_fe_[v];
      update_planes(seen_);
      vmax_ = 0;
    }
    return;
  }
  {
    Timer tm(timing_.fe);
    model_.step(dt_fe());
    ++fe_steps_;
  }
  scatter_positions();
  scatter_velocities(false);  // vmax_ from the maxima below (one collective instead of two)
  Timer tm(timing_.reduce);
  // Global: the largest vertex motion since the last build and the largest FE displacement.
  double loc[3] = {0, 0, 0}, g[3];
  for (std::size_t s = 0; s < nu_.size(); ++s) {
    loc[0] = std::max(loc[0], norm2(nu_[s] - nu_at_build_[s]));
    loc[2] = std::max(loc[2], norm2(nu_prev_[s]));
  }
  loc[0] = std::sqrt(loc[0]);
  loc[2] = std::sqrt(loc[2]);
  const std::vector<double> u = model_.owned_displacements();
  const int dim = model_.dim();
  for (std::size_t i = 0; i + dim <= u.size(); i += dim)
    loc[1] = std::max(loc[1], u[i] * u[i] + u[i + 1] * u[i + 1] + u[i + 2] * u[i + 2]);
  loc[1] = std::sqrt(loc[1]);
  MPI_Allreduce(loc, g, 3, MPI_DOUBLE, MPI_MAX, comm_);
  vmax_ = g[2];
  // Node motion since the build, plus the extrapolation at the build and from now on.
  moved_ = g[0] + (extrapolating() ? 2 * dt_fe() * vmax_ : 0.0);
  max_u_ = std::max(max_u_, g[1]);
}

void Coupler::save_history(const ParticleStore& p, std::vector<ContactRecord>& out) const {
  for (std::size_t k = 0; k < pi_.size(); ++k)
    if (stamp_[k] == ncompute_) out.push_back({p.id[pi_[k]], cand_[k].t, 2, -1, state_[k]});
}

std::size_t Coupler::n_active() const {
  return static_cast<std::size_t>(std::count(stamp_.begin(), stamp_.end(), ncompute_));
}

std::int64_t Coupler::global_active() {
  std::int64_t l = static_cast<std::int64_t>(n_active()), g = 0;
  MPI_Allreduce(&l, &g, 1, MPI_INT64_T, MPI_SUM, comm_);
  return g;
}

}  // namespace fdem::coupling
