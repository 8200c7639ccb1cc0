#pragma once
// Partitioning a finite-element mesh over MPI ranks (DESIGN.md section 3): METIS on the
// element dual graph (elements are neighbours when they share a face), then a global node
// numbering derived from the partition. Every rank computes the same partition from the same
// (replicated) mesh, so no communication is needed here.
#include <cstdint>
#include <vector>

#include "fem/fe_partition.hpp"
#include "fem/mesh.hpp"

namespace fdem {

using MeshPartition = fem::FePartition;

/// Partition `mesh` into `nparts` parts. One part skips METIS (METIS 5.1 fails on 1 part).
/// Nodes used by no element are owned by rank 0.
MeshPartition partition_mesh(const fem::Mesh& mesh, int nparts);

}  // namespace fdem
