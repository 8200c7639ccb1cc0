#pragma once
// The driver of coupled cases: particles + `fem` + `coupling` (DESIGN.md sections 3 and 4.4,
// thesis fig 4-5; docs/user-guide.md "Coupled runs").
//
//   mpirun -n 2 fdem run cases/coupling/sphere_on_plate.yaml --out out/sphere
//
// Set-up: the DEM side as run_case builds it (driver.hpp: Setup), the FE side as the pure-FE
// driver builds it (fe_driver.hpp: FeSetup), the interface triangles from the case's
// coupling.surfaces, and a coupling::Coupler attached to the DemEngine as its ContactSource.
// Time steps: dt_DEM = time.dt or time.safety x DEM critical step, clamped to at most
// dt_FE,stable = fem.safety x the FE model's Gershgorin step; the FE steps every n DEM steps
// (coupling.subcycle, or n = floor(dt_FE,stable / dt_DEM)), dt_FE = n dt_DEM.
// Loop: DEM steps (the coupler sums the interface forces and runs the FE every n steps); the
// structure is held rigid for coupling.rigid_steps steps, then released; with fem load_steps /
// displacement_steps every hold runs until the DEM and the FE unbalanced-force ratios are both
// below the tolerance (or fem.max_steps); without holds the run lasts time.steps / duration
// (time.stop_unbalanced: the same combined criterion).
// Output (one directory): what run_case writes (particle snapshots + particles.xdmf,
// history.csv, walls.csv, removed.csv, run.json, checkpoint.h5), FE snapshots fe_<step>.h5 +
// fe.xdmf at the same steps, reactions.csv, interface.csv, checkpoint.h5 (DEM + FE state, /fe).
#include <mpi.h>

#include <vector>

#include "app/driver.hpp"
#include "app/packing.hpp"
#include "app/fe_driver.hpp"
#include "coupling/interface.hpp"
#include "io/case.hpp"

namespace fdem {

/// The interface triangles of all coupling.surfaces, in merged-mesh node / element indices
/// (each surface is made on its own case mesh and shifted by its offsets). No MPI. Throws
/// InputError (case file, the surface's line) for unknown sets and surfaces without faces.
/// With element removals (fem.remove) the triangles are those of every hold's surface, and
/// `holds` (when given) says for each when it is on the surface (coupling::make_interface).
std::vector<coupling::InterfaceTriangle> build_coupling_interface(const CaseConfig& c, const FeMeshes& m,
                                                                 std::vector<coupling::HoldRange>* holds = nullptr);

/// Which triangles of `holds` are on the surface during hold `hold` (1 = yes).
std::vector<std::uint8_t> active_at_hold(const std::vector<coupling::HoldRange>& holds, std::size_t hold);

/// Throws InputError for what coupled runs do not support (--restart / restart.from).
void check_coupled_options(const CaseConfig& c, const RunOptions& opt);

/// `fdem check` of a coupled case: builds the FE side, the interface and the time steps
/// (collective; PETSc initialised) and prints a summary on rank 0. Throws InputError.
void check_coupled_case(const CaseConfig& c, Setup s, MPI_Comm comm);

/// The structure of a coupled case as an obstacle for packing (src/app/packing.hpp): its
/// interface surface at the reference positions as a rigid facet wall with the coupling
/// material, and its solid elements' boxes. Throws InputError for bad surfaces.
PackingStructure packing_structure(const CaseConfig& c);

/// Run a coupled case. Returns the exit code (0 finished, 128+signal when interrupted).
/// Throws InputError for bad input found at set-up (unknown sets, unstable sub-cycle).
int run_coupled_case(const CaseConfig& c, Setup s, const RunOptions& opt, MPI_Comm comm);

}  // namespace fdem
