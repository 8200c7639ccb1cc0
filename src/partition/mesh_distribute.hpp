#pragma once
// A finite-element mesh held in parts (issue 20: no replicated FE mesh where it matters). Rank 0
// reads or generates the whole mesh, partitions it (METIS, once) and sends every rank its part:
// its own elements and their nodes, plus the nodes it owns that no element uses; the named sets
// restricted to what the part holds. A part is an ordinary fem::Mesh in local indices, with a
// local FePartition (every element this rank's; node owners and global node numbers per local
// node; owned counts of all ranks), so that an FeModel built on it integrates the same elements
// and numbers the same nodes as one built on the replicated mesh -- bit for bit the same steps.
// The drivers run on parts with fem.distribute (app/fe_driver.hpp FeSetup; the coupled driver
// gets the interface from rank 0: docs/performance.md, "FE mesh memory").
#include <mpi.h>

#include <cstdint>
#include <vector>

#include "fem/fe_partition.hpp"
#include "fem/mesh.hpp"

namespace fdem {

struct MeshPart {
  fem::Mesh mesh;         ///< own elements (ascending global index) and the part's nodes (ascending)
  /// In local indices: elem_part all this rank, node_owner, node_global; node_index and
  /// elem_index: the whole mesh's index of each local node and element.
  fem::FePartition part;
  std::int64_t n_elements_global = 0;
  std::int64_t n_nodes_global = 0;
};

/// Rank `rank`'s part of `whole` under partition `p` (serial; the reference for distribute_mesh).
MeshPart mesh_part(const fem::Mesh& whole, const fem::FePartition& p, int rank);

/// Collective: `whole` is read on rank 0 only (other ranks pass any mesh, e.g. an empty one);
/// rank 0 partitions it into one part per rank (partition_mesh) and sends each rank its part.
MeshPart distribute_mesh(const fem::Mesh& whole, MPI_Comm comm);

}  // namespace fdem
