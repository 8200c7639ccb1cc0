#pragma once
// Which rank owns which element and node of a finite-element mesh, and the global node
// numbering (made by partition_mesh in src/partition/mesh_partition.hpp).
#include <cstdint>
#include <vector>

namespace fdem::fem {

struct FePartition {
  int nparts = 1;
  std::vector<std::int32_t> elem_part;   // rank of each element
  std::vector<std::int32_t> node_owner;  // rank owning each node: the lowest rank among its elements
  std::vector<std::int32_t> node_global; // global node number: rank 0's owned nodes first (in
                                         // mesh order), then rank 1's, ...
  std::vector<std::int32_t> owned_count; // owned nodes per rank
  // When the mesh is one rank's part of a larger one (partition/mesh_distribute.hpp): the whole
  // mesh's index of each node and element of the part, ascending. Empty: the mesh is whole.
  std::vector<std::int64_t> node_index;
  std::vector<std::int64_t> elem_index;
};

}  // namespace fdem::fem
