#pragma once
// InterfaceForces: the forces of the interface contacts (DESIGN.md 4.1, 4.4) and their exact
// sums -- the force half of the coupler's contact stage (the geometry is FacetContacts').
//
// * apply_law(): the DEM law of DESIGN.md 4.1 with the interface's DEM material (particle = body
//   A, triangle = body B, k_n from the particle's radius as for walls), the surface velocity at
//   the contact point interpolated from the vertices' with the barycentric N, the force scaled
//   by the contact's merging weight; -F and the torque to the particle.
// * distribute(): F_i = N_i F to the triangle's corners, each corner's share (N_c w) F added once
//   per vertex in fixed point (base/fixed_point.hpp; the node sums are formed from these at an FE
//   update, InterfaceExchange::collect_vertex_sums); F also to its surface group's sum.
// Fixed-point sums are exact, so the totals do not depend on the order or the number of ranks.
// Pure: no MPI, no PETSc.
#include <array>
#include <cstdint>
#include <vector>

#include "coupling/facet_contacts.hpp"
#include "coupling/interface_surface.hpp"
#include "dem/contact_source.hpp"
#include "dem/material.hpp"
#include "dem/particles.hpp"

namespace fdem::coupling {

using F3 = std::array<__int128, 3>;  // a force as three fixed-point integers

class InterfaceForces {
 public:
  InterfaceForces(std::size_t n_vertices, int n_groups);

  /// Forces of the accepted contacts of `c` (material `material` of `mats`) on the particles.
  /// `group_material`: the interface material of each surface group (InterfaceSurface::group).
  void apply_law(ParticleStore& p, const MaterialTable& mats, const std::vector<int>& group_material,
                 const InterfaceSurface& s,
                 FacetContacts& c, double dt);
  /// The forces of the last apply_law() into the vertex and surface-group sums.
  void distribute(const InterfaceSurface& s, const FacetContacts& c);

  /// Per vertex: the sum of the shares each of its nodes receives (zeroed by whoever moves it on).
  std::vector<F3>& vertex_sums() { return vertex_sum_; }
  /// Per surface group: the sum of the forces given to the structure.
  std::vector<F3>& group_sums() { return group_sum_; }
  /// This rank's sums over the last call: the forces given to FE nodes and to the particles (-F).
  Vec3 step_nodal_force() const { return step_nodal_; }
  Vec3 step_particle_force() const { return step_particle_; }
  /// The sides of the active contacts of the last call (ContactSource::sides()).
  const std::vector<ContactSource::Side>& sides() const { return sides_; }

 private:
  /// The surface group a contact's force is reported in (entries b..e of one particle, u the
  /// accepted one).
  std::int32_t contact_group(const InterfaceSurface& s, const TouchingContacts& tc, std::size_t b, std::size_t e,
                             std::size_t u) const;

  std::vector<F3> vertex_sum_;
  std::vector<F3> group_sum_;
  std::vector<Vec3> force_;                // per touching contact of the last call: the force on the surface
  Vec3 step_nodal_, step_particle_;
  std::vector<ContactSource::Side> sides_;
};

}  // namespace fdem::coupling
