#pragma once
// ContactSource: contacts of the particles with something other than particles and rigid walls
// (the FE interface of src/coupling), plugged into the DEM engine's step (DESIGN.md 4.4, fig 4-5).
//
// The engine calls, on every rank of its communicator:
//   build()      at every neighbour-list rebuild, after migration and ghost exchange (collective);
//   compute()    every step after the particle and wall contacts: adds forces to the OWNED
//                particles' f and t;
//   end_step()   at the end of every step, after the particles moved (collective; the FE update
//                of a sub-cycled coupling happens here): adds the values it needs summed or
//                maximised over ranks to the step's StepSums, reduced with the engine's own in
//                one collective (a small coupled step is latency-bound);
//   finish_step()  after that reduction, before the rebuild check: reads them back;
//   moved_since_build()  in the rebuild check: how far the surface moved since build(); must be
//                identical on every rank (it is part of a global decision). Infinity: the
//                source changed (triangles taken out or added): the engine rebuilds before its
//                next step.
// Contact histories are records of kind 2 (a particle id, b triangle index, sub -1): the engine
// hands them back through `history` at build() after migration, so they travel with particles.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "base/step_sums.hpp"
#include "dem/contact_history.hpp"
#include "dem/material.hpp"
#include "dem/particles.hpp"

namespace fdem {

class ContactSource {
 public:
  virtual ~ContactSource() = default;
  /// Candidates for the owned particles of `p` (subdomain [lo, hi)) within `margin` (the skin).
  virtual void build(const ParticleStore& p, const Vec3& lo, const Vec3& hi, double margin,
                     const HistoryMap& history) = 0;
  virtual void compute(ParticleStore& p, const MaterialTable& mats, double dt) = 0;
  virtual void end_step(std::int64_t step, exact::StepSums& sums) = 0;
  virtual void finish_step(const exact::StepSums& sums) = 0;
  virtual double moved_since_build() const = 0;
  /// Append the active contacts' records (kind 2).
  virtual void save_history(const ParticleStore& p, std::vector<ContactRecord>& out) const = 0;
  /// Active contacts on this rank.
  virtual std::size_t n_active() const = 0;

  /// One contact of an owned particle with this source at the last compute(), for the
  /// micro-mechanics measurements (src/app/measurements.cpp; the Love-Weber stress adds the
  /// particle's side, as for a wall contact): `particle` a local index into the particle store
  /// (valid until the next step's rebuild), `n` the unit normal from the particle towards the
  /// contact, `lever` the contact point minus the particle's centre (m), `force` the contact
  /// force on the particle (N).
  struct Side {
    std::uint32_t particle;
    Vec3 n, lever, force;
  };
  /// The sides of this rank's active contacts at the last compute() (default: none recorded).
  virtual const std::vector<Side>& sides() const {
    static const std::vector<Side> none;
    return none;
  }
};

}  // namespace fdem
