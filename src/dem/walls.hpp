#pragma once
// Rigid walls (DESIGN.md 4.1): infinite planes, solid axis-aligned boxes and rigid triangle
// meshes (facets). Walls are replicated on every rank; each rank computes the contacts of its
// owned particles with them. Wall-particle contacts use the same law as particle pairs, with the
// particle as body A and the wall as body B, the wall's normal stiffness taken with the
// particle's radius (k = 2 E_w r), as YADE does for walls and facets.
//
// A wall is fixed, moved with a prescribed velocity, free (a rigid body of given mass that
// moves under the particles' forces, optionally gravity, on chosen translational dofs), or
// servo-controlled (a stress-controlled plate, see ServoParams). A wall may change its motion
// at given steps (Wall::schedule: e.g. servo during consolidation, then a constant velocity).
// Resultant forces on walls and the servo stiffnesses are reduced over ranks exactly
// (fixed-point integer sums), so they do not depend on the number of ranks: this layer has no
// MPI; WallSet hands out its local sums and partition/wall_reduce.hpp reduces them.
#include <array>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "base/fixed_point.hpp"
#include "dem/contact_history.hpp"
#include "dem/contact_law.hpp"
#include "dem/facet_geometry.hpp"
#include "dem/facet_grid.hpp"
#include "dem/material.hpp"
#include "dem/particles.hpp"

namespace fdem {

/// Stress-controlled (servo) plate: the loading controller of the thesis (ch. 3-4), YADE's
/// TriaxialStressController, LIGGGHTS's servo walls. Every step, with F the wall force reduced
/// over ranks, K = sum over the wall's active contacts of k_n (n . axis)^2 (reduced exactly too)
/// and sigma = -F . axis / A the measured stress (compression positive), the wall moves along
/// `axis` by
///     dz = gain * (sigma0 - sigma) * A / K,   |dz| <= max_velocity * dt
/// (dz = max_velocity * dt towards the particles when K = 0 and sigma0 > 0). The thesis writes
/// dz = (sigma - sigma0) / K with the force difference meant. Stability: behind the plate the
/// specimen is a spring in series with the plate contacts, of stiffness K_eff <= K, so in the
/// quasi-static limit the force error is multiplied by (1 - gain K_eff / K) in [0, 1) each
/// step for 0 < gain <= 1: monotone, never past the target. The velocity cap bounds the
/// approach step when no contact exists yet (a first overshoot <= max_velocity dt) and the
/// kinetic energy fed to the specimen.
struct ServoParams {
  Vec3 axis{0, 0, -1};      // unit; the direction in which the wall compresses the specimen
  double stress = 0;        // sigma0, Pa (>= 0, compression positive)
  double area = 0;          // A, m^2 (when area_walls is unset)
  std::array<int, 4> area_walls{-1, -1, -1, -1};  // A = gap(w0, w1) * gap(w2, w3) (plane walls)
  double gain = 0.5;        // in (0, 1]
  double stiffness = 0;     // N/m: a fixed K used while the wall has contacts (0: K from the contacts)
  double max_velocity = 0;  // m/s, > 0
  Vec3 velocity;            // prescribed velocity across the axis (its axis component is ignored)
};

/// A phase that starts `after:` a condition instead of at a given step (case key
/// walls.motion.after): every condition given must hold at a history row, counted from the
/// previous phase's start. The run decides (app/driver.cpp) and sets the phase's from_step.
struct PhaseCondition {
  bool on = false;
  double unbalanced = 0;    // the unbalanced-force ratio below this (0: not checked)
  double kinetic = 0;       // the kinetic energy per grain below this x m g d (0: not checked)
  double servo = 0;         // every servo wall's misfit |sigma - sigma0| / sigma0 below this (0: not checked)
  double time = 0;          // at least this long (s) after the previous phase began (0: not checked)
  std::int64_t steps = 0;   // at least this many steps after the previous phase began
  int stage_wall = -1, stage_phase = -1;  // `stage`: starts when that wall's phase starts (>= 0: set)
};

/// from_step of a phase waiting for its condition: it never applies until the run sets it.
inline constexpr std::int64_t kPhasePending = std::numeric_limits<std::int64_t>::max();

/// One entry of a wall's motion schedule: from step `from_step` on, the wall moves this way.
struct WallPhase {
  std::int64_t from_step = 0;
  PhaseCondition after;     // on: from_step is kPhasePending until the condition is met
  int motion = 0;           // Wall::Motion
  Vec3 velocity;            // velocity walls; free walls: the velocity when the phase starts
  double mass = 0;
  std::uint8_t free_dofs = 7;
  bool gravity = false;
  ServoParams servo;
};

struct Wall {
  enum Kind { kPlane, kBox, kFacets } kind = kPlane;
  enum Motion { kFixed, kVelocity, kFree, kServo } motion = kFixed;
  std::string name;
  int mat = 0;
  Vec3 point, normal;        // plane (normal: unit, towards the particles)
  Vec3 bmin, bmax;           // box
  std::vector<Vec3> verts;   // facets: vertices at the initial position
  std::vector<std::array<int, 3>> tris;
  Vec3 vel;                  // current velocity
  double mass = 0;           // free walls
  std::uint8_t free_dofs = 7;
  bool gravity = false;
  Vec3 disp;                 // displacement from the initial position
  Vec3 force;                // resultant force of the particles on the wall (all ranks)
  ServoParams servo;         // servo walls
  double stiffness = 0;      // K: sum of k_n (n . axis)^2 over the active contacts (all ranks; servo walls)
  double stress = 0;         // servo walls: the measured stress -F . axis / A (Pa) at the last step
  double area_now = 0;       // servo walls: the area A used at the last step (m^2)
  std::vector<WallPhase> schedule;  // empty: `motion` for the whole run; else sorted by from_step
  // Force bands: the resultant force also summed per band of the contacting grains' centres c,
  // band k holding band_edges[k] <= c . band_axis < band_edges[k + 1] (empty: none).
  Vec3 band_axis;
  std::vector<double> band_edges;
  std::vector<Vec3> band_force;  // per band: the particles' force on the wall (all ranks)
};

/// The band of coordinate s (= centre . axis) among `edges` (strictly increasing), or -1 outside.
int band_of(const std::vector<double>& edges, double s);

/// Gap between two plane walls at their current positions: (p1 - p0) . n0 (m).
double plane_gap(const Wall& a, const Wall& b);
/// Projected area of a box or facet wall on the plane normal to `axis` (m^2): for a box its
/// face across the axis; for facets the triangles' projected areas (a flat plate counts once).
double projected_area(const Wall& w, const Vec3& axis);
/// The servo plate's move along its axis for one step (ServoParams): pure function of the
/// reduced force, stiffness and area.
double servo_step(const ServoParams& s, double force_along_axis, double stiffness, double area, double dt);

/// Geometry of one particle-wall contact candidate.
struct WallGeom {
  Vec3 n;          // unit normal from the particle centre towards the wall
  double delta;    // overlap (> 0: touching)
  int region;      // facets: 0 face, 1..3 edge (v0v1, v1v2, v2v0), 4..6 vertex v0, v1, v2
};

// closest_on_triangle (`region` as in WallGeom): dem/facet_geometry.hpp.

/// Geometry of particle (x, r) against wall w (sub: triangle index for facets).
WallGeom wall_geometry(const Wall& w, int sub, const Vec3& x, double r);

/// Adjacency of a facet mesh: the triangles on each edge, the edges at each vertex.
struct FacetTopology {
  // Compressed adjacency (flat arrays: the contact selection runs for every particle touching
  // more than one facet, every step). Edge k of triangle t runs from t[k] to t[(k + 1) % 3].
  std::vector<std::int32_t> edge_group;        // 3 t + k -> its edge's group
  std::vector<std::int32_t> group_off{0};      // group -> range in group_tris
  std::vector<std::int32_t> group_tris;        // the triangles sharing the edge (t included)
  std::vector<std::int32_t> vert_off{0};       // vertex -> range in vert_nbrs
  std::vector<std::int32_t> vert_nbrs;         // the other end of each edge at the vertex
  static FacetTopology build(const Wall& w);
  static FacetTopology build(const std::vector<std::array<int, 3>>& tris);
};

class WallSet {
 public:
  std::vector<Wall> walls;

  /// Rebuild the candidate list for owned particles (surfaces closer than `margin`),
  /// restoring histories from `history` (kind-1 records).
  void build(const ParticleStore& p, double margin, const HistoryMap& history);
  /// Compute contact forces and add them to the owned particles' f and t; accumulate the
  /// forces on the walls locally (reduce_wall_forces, partition/wall_reduce.hpp, sums over ranks).
  void compute(ParticleStore& p, const MaterialTable& mats, double dt);
  /// This rank's wall forces and servo stiffnesses as fixed-point integers (base/fixed_point.hpp),
  /// four per wall (Fx, Fy, Fz, K), then three per force band (Fx, Fy, Fz; walls in order): what
  /// reduce_wall_forces (partition/wall_reduce.hpp) sums over ranks.
  std::vector<exact::Int> local_sums();
  /// Set Wall::force and Wall::stiffness from the global sums (the layout of local_sums).
  void set_reduced_sums(const std::vector<exact::Int>& sums);
  /// Apply the motion schedules for step `step` (call before compute; cheap, no communication).
  void apply_schedule(std::int64_t step);
  /// Do any walls need their forces reduced every step (free and servo walls)?
  bool needs_reduction() const;
  /// Advance the walls by one step (velocity walls: prescribed; free walls: F/m + gravity
  /// with local damping lambda; servo walls: ServoParams, after reduce_wall_forces).
  void integrate(double dt, const Vec3& gravity, double damping);
  /// The largest distance any wall moved since the last build().
  double moved_since_build() const;
  /// Append the active contact records (kind 1).
  void save_history(const ParticleStore& p, std::vector<ContactRecord>& out) const;
  std::size_t n_candidates() const { return pi_.size(); }
  /// One active wall contact (for measurements): particle index (owned), wall index, unit normal
  /// from the particle towards the wall, overlap, normal force magnitude and the total force on
  /// the wall (the particle receives its negative). The geometry and the normal force are those
  /// of the current positions, the tangential force the last step's.
  struct ContactView {
    std::uint32_t particle;
    int wall;
    Vec3 n;
    double delta, fn;
    Vec3 force_wall;
  };
  template <class F>
  void for_each_active(const ParticleStore& p, const MaterialTable& mats, F&& fn) const {
    for (std::size_t k = 0; k < pi_.size(); ++k) {
      if (!active_[k]) continue;
      const std::uint32_t i = pi_[k];
      const Wall& w = walls[wi_[k]];
      const WallGeom g = wall_geometry(w, sub_[k] < 0 ? 0 : sub_[k], p.x[i], p.r[i]);
      const double ri = p.r[i];
      const double f = g.delta > 0 ? normal_law(mats.pair(p.mat[i], w.mat), mats[p.mat[i]].young, ri,
                                                mats[w.mat].young, ri, ri, g.delta).fn
                                   : 0.0;
      const Vec3 ft = state_[k].ft - dot(state_[k].ft, g.n) * g.n;
      fn(ContactView{i, static_cast<int>(wi_[k]), g.n, g.delta, f, f * g.n + ft});
    }
  }
  std::size_t n_active() const;

 private:
  std::vector<std::uint32_t> pi_;  // particle index
  std::vector<std::uint16_t> wi_;  // wall index
  std::vector<std::int32_t> sub_;  // triangle index (-1: plane/box)
  std::vector<ContactState> state_;
  std::vector<std::uint8_t> active_;
  std::vector<Vec3> disp_at_build_;
  std::vector<std::array<__int128, 3>> local_force_;
  std::vector<__int128> local_k_;
  std::vector<std::array<__int128, 3>> local_band_;  // the force bands of every wall, in order
  std::vector<std::size_t> band_off_;                // wall -> its first band in local_band_
  void size_bands();
  void select_facet_contacts(std::size_t w, const Vec3& x, double r, std::size_t k, std::size_t e,
                             const std::vector<WallGeom>& geo, std::vector<std::uint8_t>& accept) const;
  std::vector<FacetTopology> topo_;
  /// Facet walls with many triangles: the triangles (reference positions) binned in a hash grid
  /// of cell h (origin 0), each in every cell its box grown by h/2 overlaps (so a particle's own
  /// cell lists every triangle within h/2 of it); triangles spanning too many cells are always
  /// candidates.
  struct WallGrid {
    FacetGrid grid;
    std::vector<std::int32_t> large;
  };
  std::vector<WallGrid> grids_;
  std::vector<std::int32_t> cand_;
  mutable std::vector<Vec3> taken_;
  std::vector<WallGeom> geo_;
  std::vector<std::size_t> ended_;  // carry_history(): the group's contacts that ended this step
  std::vector<Vec3> ended_n_;       // and their normals now
  /// Facet wall group k..e of the particle at x: its new contacts continue the history of an
  /// ended one on the same smooth surface (fdem::continued_contact, dem/facet_select.hpp).
  void carry_history(const Wall& wall, const Vec3& x, std::size_t k, std::size_t e,
                     const std::vector<WallGeom>& geo, const std::vector<std::uint8_t>& accept);
};

}  // namespace fdem
