#pragma once
// Micro-mechanics measurements of a running DemEngine (DESIGN.md 4.2): the parallel collection
// around the pure kernels of src/dem/measure.hpp.
//
// Which rank adds what (so that the result does not depend on the number of ranks):
//  - a particle's own terms (box membership, contact count, displacement, solid volume) are
//    added by its owner;
//  - the side of a particle-particle contact belonging to particle P (lever from P's centre
//    to the contact point, force on P) is added by P's owner, which sees every contact of P
//    in its pair list (ghost partners included);
//  - the contact itself (rose diagrams, force network) is added by the owner of the lower id;
//  - wall contacts, and contacts with an attached ContactSource (the FE interface of a coupled
//    run), by the particle's owner.
// The box and cell sums and the rose histograms are then summed over ranks (MPI_Allreduce):
// the same numbers on any number of ranks up to the order of the floating-point sums.
#include <mpi.h>

#include <memory>
#include <string>

#include "app/engine.hpp"
#include "dem/measure.hpp"
#include "io/case.hpp"

namespace fdem {

/// The measurement spec of a case's `measure` section.
MeasureSpec measure_spec(const MeasureConfig& c);

/// Collective over the engine's communicator: measure the engine's current state.
/// Refreshes the ghosts first (DemEngine::sync_ghosts).
MeasureResult measure(DemEngine& e, const MeasureSpec& spec);

/// Make the current positions the reference of the displacement fields (x0 = x for the owned
/// particles; x0 migrates with the particles and is checkpointed). Local (no communication).
void reset_displacement_reference(DemEngine& e);

class MeasureWriter;

/// The measurements of a run (driver side): when to measure and where the output goes.
class MeasureRun {
 public:
  /// `append`: a restarted run continuing its files (rows after the restart step are dropped).
  MeasureRun(const MeasureConfig& c, DemEngine& e, const std::string& dir, bool append, MPI_Comm comm);
  ~MeasureRun();
  /// Collective: call after every step (and once before the first). Measures when the step is a
  /// multiple of `every` or `force` is set; resets the displacement reference at
  /// `displacement_from`.
  void at_step(bool force = false);
  /// Collective: the measurement of a fresh run's first state (step 0), taken inside its first
  /// step once the contact forces of that state are computed (before, there are none).
  void at_start();

 private:
  const MeasureConfig& c_;
  DemEngine& e_;
  MeasureSpec spec_;
  std::unique_ptr<MeasureWriter> out_;
  std::int64_t last_ = -1;
};

}  // namespace fdem
