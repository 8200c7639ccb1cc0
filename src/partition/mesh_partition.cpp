#include "partition/mesh_partition.hpp"

#include <metis.h>

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <string>

namespace fdem {

namespace {

/// The element parts of `mesh` (METIS on the dual graph; round robin with fewer elements than
/// parts; all 0 for one part).
std::vector<std::int32_t> element_parts(const fem::Mesh& mesh, int nparts) {
  const std::size_t ne = mesh.n_elements(), nn = mesh.n_nodes();
  std::vector<std::int32_t> elem_part(ne, 0);
  if (nparts > 1 && ne >= static_cast<std::size_t>(nparts)) {
    // Corner nodes only (a Hex20's mid-edge nodes do not change the face adjacency).
    std::vector<idx_t> eptr{0}, eind;
    int ncommon = 4;
    for (std::size_t e = 0; e < ne; ++e) {
      const std::int32_t* nodes;
      mesh.nodes_of(e, nodes);
      const fem::ElemType t = mesh.elem_type[e];
      const bool surface = t == fem::ElemType::kQuad4 || t == fem::ElemType::kShell4;
      const int corners = surface ? 4 : 8;
      if (surface) ncommon = 2;
      for (int k = 0; k < corners; ++k) eind.push_back(nodes[k]);
      eptr.push_back(static_cast<idx_t>(eind.size()));
    }
    idx_t ne_i = static_cast<idx_t>(ne), nn_i = static_cast<idx_t>(nn), nc = ncommon, np = nparts, objval = 0;
    idx_t options[METIS_NOPTIONS];
    METIS_SetDefaultOptions(options);
    options[METIS_OPTION_SEED] = 1;  // reproducible
    std::vector<idx_t> epart(ne), npart(nn);
    const int rc = METIS_PartMeshDual(&ne_i, &nn_i, eptr.data(), eind.data(), nullptr, nullptr, &nc, &np,
                                      nullptr, options, &objval, epart.data(), npart.data());
    if (rc != METIS_OK) throw std::runtime_error("METIS_PartMeshDual failed (code " + std::to_string(rc) + ")");
    for (std::size_t e = 0; e < ne; ++e) elem_part[e] = epart[e];
  } else if (nparts > 1) {
    // Fewer elements than ranks: round robin (some ranks own nothing).
    for (std::size_t e = 0; e < ne; ++e) elem_part[e] = static_cast<std::int32_t>(e % nparts);
  }
  return elem_part;
}

/// The node owners and the global numbering from the element parts.
MeshPartition from_element_parts(const fem::Mesh& mesh, int nparts, std::vector<std::int32_t> elem_part) {
  MeshPartition p;
  p.nparts = nparts;
  const std::size_t ne = mesh.n_elements(), nn = mesh.n_nodes();
  p.elem_part = std::move(elem_part);
  p.node_owner.assign(nn, std::numeric_limits<std::int32_t>::max());
  for (std::size_t e = 0; e < ne; ++e) {
    const std::int32_t* nodes;
    const int n = mesh.nodes_of(e, nodes);
    for (int k = 0; k < n; ++k) p.node_owner[nodes[k]] = std::min(p.node_owner[nodes[k]], p.elem_part[e]);
  }
  for (std::size_t i = 0; i < nn; ++i)  // a tied node goes with the node it became (its output copies it)
    if (!mesh.tied_to.empty() && mesh.tied_to[i] >= 0) p.node_owner[i] = p.node_owner[mesh.tied_to[i]];
  for (auto& o : p.node_owner)
    if (o == std::numeric_limits<std::int32_t>::max()) o = 0;
  p.owned_count.assign(nparts, 0);
  for (std::int32_t o : p.node_owner) ++p.owned_count[o];
  std::vector<std::int32_t> next(nparts, 0);
  for (int r = 1; r < nparts; ++r) next[r] = next[r - 1] + p.owned_count[r - 1];
  p.node_global.resize(nn);
  for (std::size_t i = 0; i < nn; ++i) p.node_global[i] = next[p.node_owner[i]]++;
  return p;
}

}  // namespace

MeshPartition partition_mesh(const fem::Mesh& mesh, int nparts) {
  return from_element_parts(mesh, nparts, element_parts(mesh, nparts));
}

MeshPartition partition_mesh(const fem::Mesh& mesh, MPI_Comm comm) {
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  std::vector<std::int32_t> parts;
  if (rank == 0) parts = element_parts(mesh, size);
  else parts.resize(mesh.n_elements());
  // (in pieces: MPI counts are int)
  constexpr std::size_t kChunk = std::size_t{1} << 30;
  for (std::size_t off = 0; off < parts.size(); off += kChunk)
    MPI_Bcast(parts.data() + off, static_cast<int>(std::min(kChunk, parts.size() - off)), MPI_INT32_T, 0, comm);
  return from_element_parts(mesh, size, std::move(parts));
}

}  // namespace fdem
