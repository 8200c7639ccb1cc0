#pragma once
// Specimen preparation (DESIGN.md 4.5; thesis ch. 3 and 4.3; docs/user-guide.md#making-specimens):
//
//   mpirun -n 2 fdem run cases/specimens/pack_layers_ci.yaml      (packs, reports, saves, ends)
//
// Two procedures, chosen by the case's `packing.method`:
//  - layers (the thesis's): per layer, a loose non-overlapping cloud (random sequential addition,
//    src/dem/generate.cpp) in the slab just above what is already packed, its solid volume sized
//    so that the specimen up to the layer's nominal top has the target porosity; gravity, every
//    contact frictionless (packing.friction), the named walls shaken laterally for a number of
//    cycles, then settling until the unbalanced-force ratio (and optionally the kinetic energy
//    per particle) is below the tolerance; then the next layer.
//  - expansion: one cloud in the whole box, radii grown by a constant factor per stage up to
//    the target solid volume, relaxed after each stage, then settled under gravity.
// The engine cannot add particles or change radii while it runs: between layers (and stages)
// each rank takes its share of the state -- the particles it owns with their positions,
// velocities and spins, the contact histories it is responsible for, the walls' positions --
// adds its share of the next cloud (every rank generates the layer's cloud, the same on any
// number of ranks, and keeps every P-th grain), and a new DemEngine is built from the shares
// (ParticleInput::kShare: sent to their owners, ordered by key), so the result is the same on
// any number of ranks and no rank holds more than its share of the specimen. What the layers
// need of the whole specimen is reduced: its top (a maximum), its solid volume and mean grain
// (exact sums), the grains removed where a structure joins (their ids, gathered).
//
// At the end, the case's friction is restored (optionally settled again, packing.final_steps),
// the specimen is measured (src/app/measurements.hpp: porosity, void ratio, coordination number,
// fabric, Love-Weber stress and K0 in an interior box clear of the walls and the loose top), the
// size distribution is compared with the requested one, and out_dir gets packing.json,
// specimen.txt (the thesis's sphere text format "id x y z r") and specimen.h5 (a checkpoint).
//
// After every finished layer the state (each rank its share) goes to out_dir/checkpoint.h5 with the packer's
// progress (io/packing_checkpoint.hpp); RunOptions::resume_packing (--restart of that file)
// rebuilds the state exactly and packs the remaining layers: the specimen is bitwise the one of
// an unstopped packing, on any number of ranks.
#include <mpi.h>

#include <array>
#include <vector>

#include "app/driver.hpp"
#include "io/case.hpp"

namespace fdem {

/// Collective. Pack the specimen of `c.packing`, starting from the particles of `s` (the case's
/// own sources, usually none); write the report and the specimen files into c.out_dir. Returns
/// the set-up to continue the case with: the packed particles and contact histories, the case's
/// materials (friction restored) and walls (at their positions after packing), step 0.
/// Throws InputError (exit 2) for settings that cannot work (a cloud that does not fit in the
/// domain).
Setup run_packing(const CaseConfig& c, Setup s, const RunOptions& opt, MPI_Comm comm);

/// A coupled case's structure as an obstacle while packing, mesh by mesh: each part is one
/// mesh's interface triangles as a rigid facet wall (reference positions, the coupling material)
/// and the axis-aligned boxes of its elements (a grain whose centre lies in one is inside the
/// solid). A part joins after layer c.packing.join_layer(mesh) (0: from the start; packing.structures,
/// else insert_structure_after_layer); grains overlapping it are removed then and from every
/// later cloud; at the end every part is dropped again (the coupled run's interface takes over;
/// contacts with it start afresh there). Parts are in joining order (layer, then mesh order), and
/// their walls follow the case's walls in that order.
struct PackingStructure {
  struct Part {
    std::string mesh;   // the mesh's name
    int after_layer = 0;
    Wall facets;        // no triangles: the mesh has no interface (its elements still exclude grains)
    std::vector<std::array<Vec3, 2>> solid_boxes;
  };
  std::vector<Part> parts;
  std::size_t n_triangles() const {
    std::size_t n = 0;
    for (const Part& p : parts) n += p.facets.tris.size();
    return n;
  }
};
Setup run_packing(const CaseConfig& c, Setup s, const RunOptions& opt, MPI_Comm comm,
                  const PackingStructure* structure);

/// Thrown (on every rank alike) when SIGINT/SIGTERM arrives while packing: the packing stops
/// without writing a partial specimen; the command line exits with 128 + signal.
struct PackingInterrupted {
  int signal = 0;
};

/// Print what `fdem check` says about a packing case (rank 0): the procedure, the box, the
/// estimated number of grains and the highest cloud.
void print_packing_check(const CaseConfig& c, MPI_Comm comm);

/// Grain size statistics by mass (as a sieve analysis): D10, D30, D50, D60 (m), Cu = D60/D10,
/// Cc = D30^2/(D10 D60), and the mass % passing at `sieves` (m).
struct GradingStats {
  double d10 = 0, d30 = 0, d50 = 0, d60 = 0, cu = 0, cc = 0;
  std::vector<double> passing;
};
GradingStats grading(std::vector<double> diameters, const std::vector<double>& sieves);

}  // namespace fdem
