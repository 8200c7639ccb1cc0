#pragma once
// The exact reduction of the walls' resultant forces and servo stiffnesses over ranks (the DEM
// layer computes the local fixed-point sums without MPI: dem/walls.hpp WallSet::local_sums).
#include <mpi.h>

#include "dem/walls.hpp"

namespace fdem {

/// Sum the wall forces (and the servo stiffnesses) over ranks (exactly) into Wall::force
/// (Wall::stiffness). Collective.
void reduce_wall_forces(WallSet& ws, MPI_Comm comm);

}  // namespace fdem
