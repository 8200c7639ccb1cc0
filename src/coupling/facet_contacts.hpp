#pragma once
// FacetContacts: which particles touch which interface triangles, where, and with what history
// (DESIGN.md 4.4). The geometry half of the coupler's contact stage; the forces are
// coupling/interface_forces.hpp's.
//
// * build(): the candidates -- owned particles within the skin of a seen triangle -- from a
//   candidate grid (dem/facet_grid.hpp) over the triangles where they are now, grouped by
//   particle, nearest first; histories restored from kind-2 records.
// * scan(): per particle, the candidates that touch now (closest point with barycentric weights,
//   dem/facet_geometry.hpp), after a quick rejection by the distance at the build and the
//   triangle's plane.
// * select(): per touching particle, in triangle order: the face / edge / vertex selection of
//   rigid facet walls (dem/facet_select.hpp: a smooth surface pushes back once), the smooth
//   merging of nearly parallel contacts (weights, see select()), and the history carry-over of a
//   contact moving on to the next triangle (fdem::continued_contact). The accepted contacts
//   become the active ones.
// Pure: no MPI, no PETSc.
#include <array>
#include <cstdint>
#include <vector>

#include "coupling/interface_surface.hpp"
#include "dem/contact_history.hpp"
#include "dem/particles.hpp"
#include "dem/walls.hpp"

namespace fdem::coupling {

/// One candidate (particle, triangle) of a particle's list, in one cache-friendly record: the
/// closest-point distance at the build, the triangle, its corners (vertex indices) and, per
/// edge, the vertex opposite it in the other triangle sharing it (InterfaceSurface::opposite).
struct InterfaceCandidate {
  double d0;
  std::int32_t t;
  std::array<std::int32_t, 3> v, nb;
};

/// The touching contacts of one call, particle by particle: particle[j] (an owned index) touches
/// with entries begin[j] .. begin[j + 1] - 1, in triangle order. Entry u: the geometry (normal
/// from the particle, overlap, region), the barycentric coordinates N of the contact point, the
/// triangle, the candidate (its history), whether it counts, and its weight in the merging.
struct TouchingContacts {
  std::vector<std::uint32_t> particle, begin{0};
  std::vector<WallGeom> geo;
  std::vector<std::array<double, 3>> N;
  std::vector<std::int32_t> tri;
  std::vector<std::uint32_t> cand;
  std::vector<std::uint8_t> accept;
  std::vector<double> weight;
};

class FacetContacts {
 public:
  /// Candidates of the owned particles of `p` within `margin` (the skin) of triangles `seen` of
  /// `s` at their current positions, in the subdomain [lo, hi]; histories from `history`.
  void build(const ParticleStore& p, const InterfaceSurface& s, const std::vector<std::int32_t>& seen,
             const Vec3& lo, const Vec3& hi, double margin, const HistoryMap& history);
  /// Start a call: the touching contacts of every particle with candidates. `moved`: how far the
  /// surface moved since the build (all ranks); `slack`: how far the triangles may be from the
  /// planes of their FE positions.
  void scan(const ParticleStore& p, const InterfaceSurface& s, double moved, double slack);
  /// Selection, merging weights and history carry-over of the touching contacts; the accepted
  /// ones are the active contacts of this call.
  void select(const ParticleStore& p, const InterfaceSurface& s);

  const TouchingContacts& touching() const { return touching_; }
  /// The contact history of candidate q (TouchingContacts::cand).
  ContactState& state(std::uint32_t q) { return state_[q]; }
  /// The vertices of the candidates' triangles (ascending).
  const std::vector<std::int32_t>& candidate_vertices() const { return candidate_vertices_; }
  std::size_t n_candidates() const { return candidates_.size(); }
  /// Active contacts (accepted in the last call).
  std::size_t n_active() const;
  /// Append the active contacts' records (kind 2).
  void save_history(const ParticleStore& p, std::vector<ContactRecord>& out) const;

 private:
  void find_candidates(const ParticleStore& p, const InterfaceSurface& s, const std::vector<std::int32_t>& seen,
                       const Vec3& lo, const Vec3& hi, double margin, const HistoryMap& history);
  void group_by_particle(const ParticleStore& p);
  void order_by_triangle(std::size_t b, std::size_t e);
  void merge_weights(std::size_t b, std::size_t e, std::size_t naccept);
  /// The new contacts among entries b..e of the particle at x (candidates k..ke) take the history
  /// of an ended contact on the same smooth surface (fdem::continued_contact), or start from zero.
  void carry_history(const InterfaceSurface& s, const Vec3& x, std::size_t k, std::size_t ke, std::size_t b,
                     std::size_t e);

  // Candidates, grouped by particle, nearest first.
  std::vector<std::uint32_t> cand_particle_;          // the candidate's particle (owned index)
  std::vector<InterfaceCandidate> candidates_;
  std::vector<ContactState> state_;
  // Calls so far; a candidate accepted in a call gets its number: it is active (in the last
  // call) iff stamp_ == calls_, and its history continues iff it was active in the call before
  // (so candidates out of reach are never visited to reset them). 0 = never.
  std::vector<std::uint64_t> stamp_;
  std::uint64_t calls_ = 1;
  std::vector<std::uint32_t> particles_, first_;     // particles with candidates, their candidate ranges
  std::vector<Vec3> pos_at_build_;                    // and their positions at the build
  std::vector<std::int32_t> candidate_vertices_;
  TouchingContacts touching_;
  std::vector<std::uint32_t> touching_group_;        // per touching particle: its index in particles_
  std::vector<Vec3> taken_;                           // scratch of the selection
  std::vector<std::uint32_t> ended_;                  // carry_history(): contacts ended this call
  std::vector<Vec3> ended_n_;                         // and their normals now
};

}  // namespace fdem::coupling
