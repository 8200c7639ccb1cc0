#pragma once
// Coupler: the FE-DE coupling (DESIGN.md sections 3 and 4.4; thesis 4.2.3, figs 4-2 ... 4-5), a
// ContactSource of the DEM engine that sequences the sub-cycle over four parts:
//   InterfaceSurface   (interface_surface.hpp)  vertices, topology, positions, planes;
//   FacetContacts      (facet_contacts.hpp)     candidates, closest points, selection, merging,
//                                               contact history;
//   InterfaceForces    (interface_forces.hpp)   the contact law, exact vertex and group sums;
//   InterfaceExchange  (interface_exchange.hpp) VecScatter of positions / velocities, force
//                                               reduction into the FE model, MPI maxima and sums.
//
// * Seen set: the triangle list is the same on every rank (as is the mesh it indexes: the FE
//   mesh, or the interface's own nodes when the FE mesh is in parts), but the CURRENT
//   vertex positions are known on a DEM rank only for the triangles it sees: those whose
//   reference bounding box, grown by the largest FE displacement and the contact reach, overlaps
//   its subdomain. The seen set is chosen at every neighbour rebuild; the exchange is rebuilt
//   (collectively) when it changed on any rank.
// * Every DEM step, compute(): extrapolate the candidates' vertices, scan, select, contact law,
//   distribute (stages below). The surface velocity at a contact point is the FE nodal velocity
//   of the last FE step interpolated with the shape functions. Between FE updates (n > 1) the
//   surface is extrapolated with that velocity, x = x_FE + k dt_DE v, so it moves smoothly instead
//   of jumping by dt_FE v every n steps (which pumps energy into resting particles); the remaining
//   jump at an update is O(dt_FE^2 a).
// * Every n steps, fe_update(): the nodal forces summed over the sub-cycle, averaged
//   (impulse-conserving), go into the FE model (the cross-rank reduction); the FE takes one
//   relaxation step of dt_FE = n dt_DE; the new interface positions and velocities are gathered.
// * Rigid: while rigid, the FE is not stepped (the structure stays where it is) but the forces
//   are still reduced into the FE model each sub-cycle (reactions, output, convergence).
// * Timings: each stage under a ScopedTimer (CouplerTimings, named by CouplerTimings::stages():
//   run.json and bench/interface_breakdown.sh read them).
#include <mpi.h>

#include <array>
#include <cstdint>
#include <utility>
#include <vector>

#include "coupling/facet_contacts.hpp"
#include "coupling/interface.hpp"
#include "coupling/interface_exchange.hpp"
#include "coupling/interface_forces.hpp"
#include "coupling/interface_surface.hpp"
#include "dem/contact_source.hpp"
#include "fem/fe_model.hpp"
#include "fem/mesh.hpp"

namespace fdem::coupling {

struct CouplerParams {
  int material = 0;      // DEM material (index into the engine's MaterialTable) of the interface
  std::vector<int> group_material;  // per surface group, its own material (empty: `material` for all)
  int subcycle = 1;      // n >= 1: one FE step every n DEM steps, dt_FE = n dt_DE
  bool rigid = false;    // start with the structure held rigid
};

/// Seconds spent in the coupling's stages on this rank.
struct CouplerTimings {
  double contacts = 0;    // all of the contact stages below (inside the DEM step)
  double candidates = 0;  //   build(): candidate grid and lists
  double scan = 0;        //   compute(): extrapolation, quick rejection, closest points
  double select = 0;      //   compute(): face/edge/vertex selection, merging, history carry-over
  double law = 0;         //   compute(): contact law, particle forces, contact records
  double distribute = 0;  //   compute(): fixed-point vertex (nodal) and surface-group sums
  double reduce = 0;      // VecSetValues + VecAssembly of the averaged nodal forces, MPI maxima
  double fe = 0;          // FE relaxation steps
  double scatter = 0;     // interface positions back to the DEM ranks (+ seen-set rebuilds)
  /// The stages by their stable names ("coupling_contacts", "coupling_scan", ...), in this order.
  std::vector<std::pair<const char*, double>> stages() const;
};

class Coupler : public ContactSource {
 public:
  /// `mesh` and `model` must outlive the coupler; `tris` from make_interface (same on every
  /// rank); `dt_dem` the DEM step. Collective over `comm` (the FE model's communicator, also
  /// the DEM engine's). `mesh` is the model's mesh, or (the model on a part of the mesh,
  /// fem.distribute) a mesh of the interface's nodes alone, with `global_of_node` the model's
  /// global node number of each of its nodes (InterfaceExchange).
  Coupler(MPI_Comm comm, const fem::Mesh& mesh, fem::FeModel& model, std::vector<InterfaceTriangle> tris,
          const CouplerParams& prm, double dt_dem, std::vector<PetscInt> global_of_node = {});
  ~Coupler() override = default;
  Coupler(const Coupler&) = delete;
  Coupler& operator=(const Coupler&) = delete;

  /// n = the largest integer with n dt_dem <= dt_fe_stable (at least 1) (DESIGN.md 4.4).
  static int auto_subcycle(double dt_fe_stable, double dt_dem);

  // ---- ContactSource ----
  void build(const ParticleStore& p, const Vec3& lo, const Vec3& hi, double margin,
             const HistoryMap& history) override;
  void compute(ParticleStore& p, const MaterialTable& mats, double dt) override;
  void end_step(std::int64_t step, exact::StepSums& sums) override;
  void finish_step(const exact::StepSums& sums) override;
  double moved_since_build() const override { return moved_; }
  void save_history(const ParticleStore& p, std::vector<ContactRecord>& out) const override;
  std::size_t n_active() const override { return contacts_.n_active(); }
  const std::vector<Side>& sides() const override { return forces_.sides(); }

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
  /// Which interface triangles take part in contacts (InterfaceSurface::set_active; the same on
  /// every rank): a removal's new surface. The contacts are rebuilt before the next DEM step;
  /// contacts with triangles taken out end there.
  void set_active_triangles(const std::vector<std::uint8_t>& active);
  std::size_t n_active_triangles() const { return surface_.n_active_triangles(); }

  // ---- results ----
  /// This rank's sums over the last DEM step: the forces given to FE nodes, and the forces
  /// (-F) applied to particles by the interface. Newton: their global sums cancel.
  Vec3 step_nodal_force() const { return forces_.step_nodal_force(); }
  Vec3 step_particle_force() const { return forces_.step_particle_force(); }
  /// Global sum of the averaged nodal forces handed to the FE at the last update (all ranks).
  Vec3 last_update_force() const { return last_update_force_; }
  /// Per surface group (InterfaceTriangle::group, 0 .. n_groups()-1): the global sum of the
  /// averaged forces handed to the FE at the last update, by the triangles of that group.
  const std::vector<Vec3>& last_group_forces() const { return last_group_force_; }
  int n_groups() const { return static_cast<int>(last_group_force_.size()); }
  /// Number of DEM sub-steps averaged at the last update.
  int last_update_substeps() const { return last_substeps_; }
  std::int64_t fe_steps() const { return fe_steps_; }
  std::size_t n_triangles() const { return surface_.n_triangles(); }
  /// Triangles this rank sees (has positions for) and candidate contacts at the last build.
  std::size_t n_seen() const { return seen_.size(); }
  std::size_t n_candidates() const { return contacts_.n_candidates(); }
  /// Collective: number of active interface contacts over all ranks.
  std::int64_t global_active();
  const CouplerTimings& timings() const { return timing_; }
  const std::vector<InterfaceTriangle>& triangles() const { return surface_.triangles(); }
  /// Current position of vertex v (valid for the vertices of seen triangles).
  Vec3 vertex_position(std::int32_t v) const { return surface_.position(v); }
  /// Vertex indices of triangle t.
  const std::array<std::int32_t, 3>& triangle_vertices(std::size_t t) const { return surface_.corners(t); }

 private:
  /// The seen set for the subdomain [lo, hi] and the contact reach; when it changed on any rank,
  /// the exchange's nodes and the surface's positions and velocities (collective).
  void update_seen(const Vec3& lo, const Vec3& hi, double reach);
  void gather_positions();                      // the seen vertices' positions (collective)
  // The seen vertices' velocities, and (reduce_vmax) vmax_ (collective).
  void gather_velocities(bool reduce_vmax = true);
  bool extrapolating() const;
  // fe_update in two halves around the reduction of its totals and motion maxima (in `sums`,
  // with the DEM step's own when called from end_step): start returns false when there was
  // nothing to do.
  bool fe_update_start(exact::StepSums& sums);
  void fe_update_finish(const exact::StepSums& sums);
  struct PendingUpdate {
    bool active = false;
    std::size_t totals = 0, motion = 0;  // first slots in the StepSums
    bool has_motion = false;
    double inv = 1;
  } pending_;

  fem::FeModel& model_;
  CouplerParams prm_;
  double dt_dem_ = 0;
  int n_ = 1;
  bool rigid_ = false;
  InterfaceSurface surface_;
  std::vector<int> group_material_;             // per surface group: its interface material
  FacetContacts contacts_;
  InterfaceForces forces_;
  InterfaceExchange exchange_;

  std::vector<std::int32_t> seen_;              // seen triangles, ascending
  std::vector<std::int32_t> seen_vertices_;     // their vertices, ascending
  double vmax_ = 0;                             // largest interface node speed of the last FE step (global)
  double max_fe_disp_ = 0;                      // largest FE displacement so far (global)
  double moved_ = 0;                            // global max vertex motion since build
  int substeps_ = 0;                            // DEM steps summed since the last FE update
  Vec3 last_update_force_;
  std::vector<Vec3> last_group_force_;
  int last_substeps_ = 0;
  std::int64_t fe_steps_ = 0;
  CouplerTimings timing_;
};

}  // namespace fdem::coupling
