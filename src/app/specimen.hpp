#pragma once
// Reusing a packed specimen (`fdem run CASE --specimen DIR/specimen.h5`): a packing case run
// once writes specimen.h5 (src/app/packing.cpp); later runs of the same case -- another normal
// stress, another number of ranks -- start from it instead of packing again (the expensive part
// of a soil-structure case is done once per case, as the thesis did).
#include <mpi.h>

#include <string>
#include <vector>

#include "app/driver.hpp"
#include "io/case.hpp"

namespace fdem {

/// Collective. The set-up to run case `c` from the packed specimen in `path` (a specimen.h5 that
/// a packing of this case wrote): its particles (positions, velocities, spins), contact
/// histories (those with the structure's packing obstacle dropped: the coupled interface starts
/// its own) and wall positions; step 0, time 0, the case's materials, dt and walls. Throws
/// InputError naming `path` when the file is not such a specimen (another case's walls,
/// materials the case lacks, particles outside the domain). Each rank reads its share of the
/// particles and contacts (Setup::shared; the engine sends them to their owners).
Setup reuse_specimen(const CaseConfig& c, Setup s, const std::string& path, MPI_Comm comm);

/// packing.place_on_surface: move each listed plane wall along its normal, and each listed servo
/// box along its servo axis, until it just touches the specimen (the particle reaching furthest
/// towards it; for a box, among the grains under its face), e.g. a servo top plate, or the
/// segments of one, that stood above the packing clouds. Collective; identical on every rank (a
/// shared set-up's nearest grain is reduced over `comm`). Returns, per listed wall, the distance
/// moved (m; > 0 towards the particles).
std::vector<double> place_walls_on_surface(const CaseConfig& c, Setup& s, MPI_Comm comm);

}  // namespace fdem
