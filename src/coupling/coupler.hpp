#pragma once
// Coupler: the FE-DE coupling (DESIGN.md sections 3 and 4.4; thesis 4.2.3, figs 4-2 ... 4-5).
//
// * The interface is a triangulated surface on the FE mesh (coupling/interface.hpp): its
//   vertices are FE nodes and quad centres (weighted node combinations); the triangle list is
//   built identically on every rank (as the FE mesh is), but the CURRENT vertex positions are
//   known on a DEM rank only for the triangles it sees: those whose reference bounding box,
//   grown by the largest FE displacement and the contact reach, overlaps its subdomain. Their
//   nodes' displacements come from the FE displacement Vec through a VecScatter built from that
//   set, rebuilt (collectively) at a neighbour rebuild when the set changed on any rank.
// * Particle-triangle contact: closest point with face / edge / vertex regions and the same
//   selection as rigid facet walls (a smooth surface pushes back once; no force jump across
//   edges), the DEM law of DESIGN.md 4.1 with the interface's DEM material (particle = body A,
//   triangle = body B, k_n from the particle's radius as for walls), contact history kept.
//   Several contacts of one particle with nearly parallel normals (a deformed surface that is
//   locally slightly concave) are merged smoothly: contact q is weighted by
//   delta_q / sum_j s_qj delta_j, s_qj = 1 - min(1, (1 - cos a_qj)/(1 - cos 15 deg)) for the
//   angle a_qj between the normals (coplanar contacts share one contact's force, contacts 15 deg
//   or more apart count fully; continuous and independent of the contacts' order).
//   The surface velocity at the contact point is the FE nodal velocity of the last FE step
//   (displacement increment / dt_FE) interpolated with the shape functions. Between FE updates
//   (n > 1) the surface is extrapolated with that velocity, x = x_FE + k dt_DE v, so it moves
//   smoothly instead of jumping by dt_FE v every n steps (which pumps energy into resting
//   particles); the remaining jump at an update is O(dt_FE^2 a).
// * Force transfer: F_i = N_i F (coupling::distribute_force) to the FE nodes, -F (and the
//   contact torque) to the particle. Nodal forces are summed locally over the n DEM sub-steps
//   of a sub-cycle; every n steps the average (impulse-conserving) goes into the FE model's
//   interface-force Vec with VecSetValues(ADD_VALUES) + VecAssembly (the cross-rank reduction),
//   the FE takes one relaxation step of dt_FE = n dt_DE, and the new interface positions are
//   scattered back.
// * Rigid: while rigid, the FE is not stepped (the structure stays where it is) but the forces
//   are still reduced into the FE model each sub-cycle (reactions, output, convergence).
#include <mpi.h>
#include <petscvec.h>

#include <array>
#include <cstdint>
#include <vector>

#include "coupling/interface.hpp"
#include "dem/contact_source.hpp"
#include "dem/walls.hpp"
#include "fem/fe_model.hpp"
#include "fem/mesh.hpp"

namespace fdem::coupling {

/// One candidate (particle, triangle) of a particle's list, in one cache-friendly record: the
/// closest-point distance at the build, the triangle, its corners (vertex indices) and, per
/// edge, the vertex opposite it in the other triangle sharing it (see select_interface).
struct InterfaceCandidate {
  double d0;
  std::int32_t t;
  std::array<std::int32_t, 3> v, nb;
};

struct CouplerParams {
  int material = 0;      // DEM material (index into the engine's MaterialTable) of the interface
  int subcycle = 1;      // n >= 1: one FE step every n DEM steps, dt_FE = n dt_DE
  bool rigid = false;    // start with the structure held rigid
};

/// Seconds spent in the coupling's stages on this rank.
struct CouplerTimings {
  double contacts = 0;   // particle-triangle contacts (inside the DEM step)
  double reduce = 0;     // VecSetValues + VecAssembly of the averaged nodal forces
  double fe = 0;         // FE relaxation steps
  double scatter = 0;    // interface positions back to the DEM ranks (+ seen-set rebuilds)
};

class Coupler : public ContactSource {
 public:
  /// `mesh` and `model` must outlive the coupler; `tris` from make_interface (same on every
  /// rank); `dt_dem` the DEM step. Collective over `comm` (the FE model's communicator, also
  /// the DEM engine's).
  Coupler(MPI_Comm comm, const fem::Mesh& mesh, fem::FeModel& model, std::vector<InterfaceTriangle> tris,
          const CouplerParams& prm, double dt_dem);
  ~Coupler() override;
  Coupler(const Coupler&) = delete;
  Coupler& operator=(const Coupler&) = delete;

  /// n = the largest integer with n dt_dem <= dt_fe_stable (at least 1) (DESIGN.md 4.4).
  static int auto_subcycle(double dt_fe_stable, double dt_dem);

  // ---- ContactSource ----
  void build(const ParticleStore& p, const Vec3& lo, const Vec3& hi, double margin,
             const HistoryMap& history) override;
  void compute(ParticleStore& p, const MaterialTable& mats, double dt) override;
  void end_step(std::int64_t step) override;
  double moved_since_build() const override { return moved_; }
  void save_history(const ParticleStore& p, std::vector<ContactRecord>& out) const override;
  std::size_t n_active() const override;
  const std::vector<Side>& sides() const override { return sides_; }

  // ---- control ----
  void set_rigid(bool rigid) { rigid_ = rigid; }
  bool rigid() const { return rigid_; }
  int subcycle() const { return n_; }
  double dt_fe() const { return n_ * dt_dem_; }
  /// Do the FE update now with the forces summed so far (collective); end_step() calls it
  /// every n steps. A no-op when no sub-step was summed since the last update.
  void fe_update();
  /// Re-read the interface positions from the FE model (collective), e.g. after the FE model
  /// was changed outside the coupler. (A coupler made after the FE state was restored from a
  /// checkpoint needs nothing: its first build reads positions and velocities.)
  void refresh_positions();

  // ---- results ----
  /// This rank's sums over the last DEM step: the forces given to FE nodes, and the forces
  /// (-F) applied to particles by the interface. Newton: their global sums cancel.
  Vec3 step_nodal_force() const { return step_nodal_; }
  Vec3 step_particle_force() const { return step_particle_; }
  /// Global sum of the averaged nodal forces handed to the FE at the last update (all ranks).
  Vec3 last_update_force() const { return last_update_force_; }
  /// Per surface group (InterfaceTriangle::group, 0 .. n_groups()-1): the global sum of the
  /// averaged forces handed to the FE at the last update, by the triangles of that group.
  const std::vector<Vec3>& last_group_forces() const { return last_group_force_; }
  int n_groups() const { return static_cast<int>(last_group_force_.size()); }
  /// Number of DEM sub-steps averaged at the last update.
  int last_update_substeps() const { return last_substeps_; }
  std::int64_t fe_steps() const { return fe_steps_; }
  std::size_t n_triangles() const { return tris_.size(); }
  /// Triangles this rank sees (has positions for) and candidate contacts at the last build.
  std::size_t n_seen() const { return seen_.size(); }
  std::size_t n_candidates() const { return pi_.size(); }
  /// Collective: number of active interface contacts over all ranks.
  std::int64_t global_active();
  const CouplerTimings& timings() const { return timing_; }
  const std::vector<InterfaceTriangle>& triangles() const { return tris_; }
  /// Current position of vertex v (valid for the vertices of seen triangles).
  Vec3 vertex_position(std::int32_t v) const { return vx_[v]; }
  /// Vertex indices of triangle t.
  const std::array<std::int32_t, 3>& triangle_vertices(std::size_t t) const { return tv_[t]; }

 private:
  /// The surface group a contact's force is reported in (the m touching candidates of one
  /// particle in geo_/tsel_, u the accepted one).
  std::int32_t contact_group(std::size_t m, std::size_t u) const;
  using F3 = std::array<__int128, 3>;  // a force as three fixed-point integers
  void choose_seen(const Vec3& lo, const Vec3& hi, double reach);
  void build_scatter();
  void scatter_positions();  // nu_ and the seen vertices' positions from the FE displacements (collective)
  // nu_prev_ and the seen vertices' velocities from the FE velocities, and (reduce_vmax) vmax_ (collective)
  void scatter_velocities(bool reduce_vmax = true);
  void update_planes(const std::vector<std::int32_t>& tris);  // plane_ of these triangles from vx_
  bool extrapolating() const;

  MPI_Comm comm_;
  const fem::Mesh& mesh_;
  fem::FeModel& model_;
  std::vector<InterfaceTriangle> tris_;
  CouplerParams prm_;
  double dt_dem_ = 0;
  int n_ = 1;
  bool rigid_ = false;

  // Vertices: unique corners (a real node, or a quad centre = 4 nodes x 1/4).
  struct Vertex { std::array<std::int32_t, 4> nodes; std::array<double, 4> w; };
  std::vector<Vertex> verts_;
  std::vector<std::array<std::int32_t, 3>> tv_;       // triangle -> vertices
  std::vector<std::array<Vec3, 2>> ref_box_;          // reference bounding box per triangle
  std::vector<std::array<double, 8>> plane_;          // per seen triangle AT THE FE POSITIONS: unit normal,
                                                      // offset (n.x = d), centroid, bounding radius
  struct Topo;                                        // facet adjacency (edges, vertex neighbours)
  std::vector<std::array<std::int32_t, 3>> tnb_;      // per edge: the opposite vertex across it (-1 none, -2 general)
  Topo* topo_ = nullptr;

  // Seen set and the nodes it needs.
  std::vector<std::int32_t> seen_;                    // triangle indices, ascending
  std::vector<std::int32_t> need_nodes_;              // mesh node indices, ascending
  std::vector<std::int32_t> node_slot_;               // mesh node -> slot in need_nodes_ (-1)
  std::vector<Vec3> vx_, vv_;                         // vertex position / velocity (all vertices; valid if seen)
  std::vector<Vec3> vx_fe_;                           // vertex position at the last FE update
  std::vector<std::int32_t> seen_verts_;              // vertices of the seen triangles
  std::vector<std::int32_t> cand_verts_;              // vertices of the candidates' triangles
  double vmax_ = 0;                                   // largest interface node speed of the last FE step (global)
  std::vector<Vec3> nu_;                              // displacement of needed nodes (slot order)
  std::vector<Vec3> nu_prev_;                         // nodal velocity of the last FE step (slot order)
  VecScatter scatter_ = nullptr;
  Vec local_ = nullptr;
  Vec vel_ = nullptr;                                 // FE velocities in the displacement layout
  double max_u_ = 0;                                  // largest FE displacement (global)
  double moved_ = 0;                                  // global max vertex motion since build
  std::vector<Vec3> nu_at_build_;
  std::vector<PetscInt> gnode_;                       // global FE node number per slot
  std::vector<PetscInt> carry_nodes_;                 // forces summed on nodes dropped at a rebuild
  std::vector<F3> carry_forces_;
  std::vector<std::int32_t> tgroup_;                  // triangle -> its surface group
  // Scratch of compute(), per touching candidate of one particle (sized at build() for the
  // largest candidate count of a particle).
  std::vector<std::uint8_t> accept_;
  std::vector<WallGeom> geo_;
  std::vector<std::array<double, 3>> bary_;           // barycentric coordinates of the contact point
  std::vector<std::int32_t> tsel_;                    // triangle
  std::vector<std::uint32_t> qsel_;                   // candidate index
  std::vector<Vec3> taken_;
  std::vector<double> weight_;
  std::vector<std::uint32_t> ended_;                  // carry_history(): contacts ended this call
  std::vector<Vec3> ended_n_;                         // and their normals now
  /// The new contacts among the m touching candidates of a particle at x (candidates k..e) take
  /// the history of an ended contact on the same smooth surface (fdem::continued_contact), or
  /// start from zero.
  void carry_history(const Vec3& x, std::size_t k, std::size_t e, std::size_t m, std::uint64_t now);

  // Candidates, grouped by particle, nearest first (see build()).
  std::vector<std::uint32_t> pi_;
  std::vector<InterfaceCandidate> cand_;              // parallel to pi_
  double rmax_build_ = 0;                             // largest owned radius at the build
  std::vector<std::uint32_t> gi_, gbeg_;              // particles with candidates, their candidate ranges
  std::vector<Vec3> gxb_;                             // and their positions at the build
  std::vector<ContactState> state_;
  // compute() calls so far; a candidate accepted in a call gets its number: it is active (in the
  // last call) iff stamp_ == ncompute_, and its history continues iff it was active in the call
  // before (so candidates out of reach are never visited to reset them). 0 = never.
  std::vector<std::uint64_t> stamp_;
  std::uint64_t ncompute_ = 1;

  // Nodal force sums over the current sub-cycle (slot order) and step sums.
  std::vector<F3> fsum_;  // exact fixed-point sums (base/exact_sum.hpp): rank-independent
  // Per vertex (all vertices; used for the candidates' ones): the sum of the shares N_c w F each
  // of its nodes receives (all nodes of a vertex have the same weight w: 1, or 1/4 at a quad
  // centre), spread to the nodes' fsum_ by flush_vertex_sums() -- at an FE update and before a
  // build changes the candidates -- instead of per contact.
  std::vector<F3> vsum_;
  std::vector<double> vw_;            // the weight w of the vertex's nodes
  std::vector<std::uint8_t> vnn_;     // its number of nodes
  void flush_vertex_sums();
  std::vector<F3> group_sum_;
  std::vector<Vec3> last_group_force_;    // per group: this rank's sub-cycle sum, last update
  std::vector<Side> sides_;                           // the active contacts of the last compute()
  int substeps_ = 0;
  Vec3 step_nodal_, step_particle_, last_update_force_;
  int last_substeps_ = 0;
  std::int64_t fe_steps_ = 0;
  CouplerTimings timing_;
};

}  // namespace fdem::coupling
