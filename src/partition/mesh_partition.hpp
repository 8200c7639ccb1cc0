#pragma once
// Partitioning a finite-element mesh over MPI ranks (DESIGN.md section 3): METIS on the
// element dual graph (elements are neighbours when they share a face), then a global node
// numbering derived from the partition. METIS runs once, on rank 0 of the communicator, and
// the element parts are broadcast (partition_mesh with a communicator); the serial form is the
// same partition computed where it is called.
#include <mpi.h>

#include <cstdint>
#include <vector>

#include "fem/fe_partition.hpp"
#include "fem/mesh.hpp"

namespace fdem {

using MeshPartition = fem::FePartition;

/// Partition `mesh` into `nparts` parts. One part skips METIS (METIS 5.1 fails on 1 part).
/// Nodes used by no element are owned by rank 0.
MeshPartition partition_mesh(const fem::Mesh& mesh, int nparts);

/// Collective: the partition of `mesh` (the same on every rank of `comm`) into one part per
/// rank, METIS run on rank 0 only (its time and its graph's memory: once, not on every rank) and
/// the element parts broadcast; equal to partition_mesh(mesh, size of comm).
MeshPartition partition_mesh(const fem::Mesh& mesh, MPI_Comm comm);

}  // namespace fdem
