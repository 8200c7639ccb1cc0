#include "partition/mesh_distribute.hpp"

#include <algorithm>
#include <string>

#include "base/bytes.hpp"
#include "base/sorted_index.hpp"
#include "partition/mesh_partition.hpp"

namespace fdem {

namespace {

/// The fields of a part in message order, for writing (Out) and reading (In) alike.
struct Out {
  Bytes& b;
  template <class T> void operator()(const T& v) { b.put(v); }
  template <class T> void num(const T& v) { b.put_size(static_cast<std::uint64_t>(v)); }
  template <class M> void map(const M& m) {
    b.put_size(m.size());
    for (const auto& [name, v] : m) { b.put(name); b.put(v); }
  }
};
struct In {
  Bytes& b;
  template <class T> void operator()(T& v) { b.get(v); }
  template <class T> void num(T& v) { v = static_cast<T>(b.get_size()); }
  template <class M> void map(M& m) {
    std::string name;
    for (std::uint64_t k = b.get_size(); k > 0; --k) { b.get(name); b.get(m[name]); }
  }
};

template <class Ar, class Part>
void fields(Ar& ar, Part& m) {
  auto& x = m.mesh;
  ar.num(x.dim);
  ar(x.node_id);
  ar(x.coords);
  ar(x.elem_id);
  ar(x.elem_type);
  ar(x.elem_offset);
  ar(x.elem_nodes);
  ar(x.elem_material);
  ar(x.tied_to);
  ar.map(x.node_sets);
  ar.map(x.element_sets);
  ar.map(x.face_sets);
  ar.num(m.part.nparts);
  ar(m.part.elem_part);
  ar(m.part.node_owner);
  ar(m.part.node_global);
  ar(m.part.owned_count);
  ar(m.part.elem_index);
  ar(m.part.node_index);
  ar.num(m.n_elements_global);
  ar.num(m.n_nodes_global);
}

}  // namespace

MeshPart mesh_part(const fem::Mesh& whole, const fem::FePartition& p, int rank) {
  MeshPart m;
  m.n_elements_global = static_cast<std::int64_t>(whole.n_elements());
  m.n_nodes_global = static_cast<std::int64_t>(whole.n_nodes());
  // The part's nodes: those it owns and those of its elements, ascending.
  std::vector<std::uint8_t> in(whole.n_nodes(), 0);
  for (std::size_t i = 0; i < whole.n_nodes(); ++i) in[i] = p.node_owner[i] == rank;
  for (std::size_t e = 0; e < whole.n_elements(); ++e) {
    if (p.elem_part[e] != rank) continue;
    m.part.elem_index.push_back(static_cast<std::int64_t>(e));
    const std::int32_t* nodes;
    const int n = whole.nodes_of(e, nodes);
    for (int k = 0; k < n; ++k) in[nodes[k]] = 1;
  }
  for (std::size_t i = 0; i < whole.n_nodes(); ++i)
    if (in[i]) m.part.node_index.push_back(static_cast<std::int64_t>(i));
  auto local_node = [&](std::int64_t i) { return find_sorted(m.part.node_index, i); };
  fem::Mesh& x = m.mesh;
  x.dim = whole.dim;
  const auto dim = static_cast<std::size_t>(whole.dim);
  for (std::int64_t i : m.part.node_index) {
    x.node_id.push_back(whole.node_id[i]);
    for (std::size_t d = 0; d < dim; ++d) x.coords.push_back(whole.coords[i * dim + d]);
    m.part.node_owner.push_back(p.node_owner[i]);
    m.part.node_global.push_back(p.node_global[i]);
  }
  if (!whole.tied_to.empty())
    for (std::int64_t i : m.part.node_index)
      x.tied_to.push_back(whole.tied_to[i] < 0 ? -1 : local_node(whole.tied_to[i]));
  std::vector<std::int32_t> conn;
  for (std::int64_t e : m.part.elem_index) {
    const std::int32_t* nodes;
    const int n = whole.nodes_of(static_cast<std::size_t>(e), nodes);
    conn.clear();
    for (int k = 0; k < n; ++k) conn.push_back(local_node(nodes[k]));
    x.add_element(whole.elem_id[e], whole.elem_type[e], conn, whole.elem_material[e]);
  }
  for (const auto& [name, s] : whole.node_sets) {
    std::vector<std::int32_t>& out = x.node_sets[name];
    for (std::int32_t i : s)
      if (const std::int32_t l = local_node(i); l >= 0) out.push_back(l);
  }
  auto local_elem = [&](std::int32_t e) { return find_sorted(m.part.elem_index, e); };
  for (const auto& [name, s] : whole.element_sets) {
    std::vector<std::int32_t>& out = x.element_sets[name];
    for (std::int32_t e : s)
      if (const std::int32_t l = local_elem(e); l >= 0) out.push_back(l);
  }
  for (const auto& [name, s] : whole.face_sets) {
    std::vector<std::array<std::int32_t, 2>>& out = x.face_sets[name];
    for (const auto& f : s)
      if (const std::int32_t l = local_elem(f[0]); l >= 0) out.push_back({l, f[1]});
  }
  m.part.nparts = p.nparts;
  m.part.elem_part.assign(m.part.elem_index.size(), rank);
  m.part.owned_count = p.owned_count;
  return m;
}

MeshPart distribute_mesh(const fem::Mesh& whole, MPI_Comm comm) {
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  if (rank != 0) {
    Bytes b;
    recv_bytes(b.data(), 0, comm);
    MeshPart m;
    In in{b};
    fields(in, m);
    return m;
  }
  const fem::FePartition p = partition_mesh(whole, size);  // (METIS here only)
  for (int r = 1; r < size; ++r) {
    Bytes b;
    Out out{b};
    const MeshPart part = mesh_part(whole, p, r);
    fields(out, part);
    send_bytes(b.data(), r, comm);
  }
  return mesh_part(whole, p, 0);
}

}  // namespace fdem
