#pragma once
// Finite-element snapshots: parallel HDF5 (collective writes) + an XDMF sidecar that ParaView
// opens as an unstructured grid with nodal displacement/velocity and element stress/strain/
// plastic state, alongside the particle snapshots of the same run.
#include <mpi.h>

#include <cstdint>
#include <string>
#include <vector>

namespace fdem {

/// One rank's share of the FE state. Nodes: the nodes this rank OWNS (each node written once
/// over all ranks), numbered globally 0..N-1. Elements: this rank's elements, with their
/// connectivity in global node numbers. All elements of one snapshot have one VTK/XDMF type per
/// element (mixed meshes are written as an XDMF Mixed topology).
struct FeSnapshotData {
  int dim = 3;                                  // 2 or 3 (coordinates are always written as 3D)
  std::int64_t n_nodes_global = 0;
  std::vector<std::int64_t> node_global;        // owned nodes: global number
  std::vector<std::int64_t> node_id;            // owned nodes: user id (from the mesh file)
  std::vector<double> coords;                   // owned nodes: reference coordinates, 3 per node
  std::vector<double> displacement;             // owned nodes: 3 per node
  std::vector<double> velocity;                 // owned nodes: 3 per node
  std::vector<double> interface_force;          // owned nodes: 3 per node, N (coupling; empty: zeros)
  // Elements (local).
  std::vector<std::int64_t> elem_id;            // user ids
  std::vector<std::int64_t> elem_index;         // index in the case's meshes (empty: -1 written)
  std::vector<std::int8_t> elem_type;           // 0 hex8, 1 hex8r, 2 hex20, 3 quad4, 4 shell4 (fem::ElemType)
  std::vector<std::int64_t> elem_offset{0};     // CSR offsets into elem_conn
  std::vector<std::int64_t> elem_conn;          // global node numbers
  std::vector<double> stress;                   // 6 per element (mean over Gauss points), Pa, Voigt xx yy zz xy yz xz
  std::vector<double> strain;                   // 6 per element (mean), engineering shear
  std::vector<std::int32_t> plastic;            // Gauss points yielded in the element
  std::vector<std::int32_t> material;
  std::vector<std::int32_t> active;             // 0 for removed elements
};

class FeSnapshotWriter {
 public:
  /// Files: dir/<prefix>_<step>.h5 and dir/<prefix>.xdmf (prefix e.g. "fe" or a mesh name).
  FeSnapshotWriter(std::string dir, std::string prefix, MPI_Comm comm);
  /// Collective. A snapshot of a step already listed replaces that entry.
  void write(std::int64_t step, double time, const FeSnapshotData& d);

  /// Collective, for restarts: take over the snapshots dir/<prefix>_<step>.h5 already on disk
  /// with step <= max_step (rank 0 reads their step/time attributes and dataset shapes; files it
  /// cannot read or that are inconsistent are skipped) so that <prefix>.xdmf keeps listing them.
  /// Files of later steps (written after the checkpoint the run restarts from) are ignored and
  /// are overwritten when the run reaches those steps again.
  void adopt_existing(std::int64_t max_step);

 private:
  void write_xdmf() const;
  std::string dir_, prefix_;
  MPI_Comm comm_;
  struct Entry { std::int64_t step; double time; std::int64_t nodes, elems, conn_len; bool mixed; int xdmf_type; std::string file;
                 bool interface_force = true; };  // the file has /nodes/interface_force (files before 2026-12-03 do not)
  std::vector<Entry> entries_;
};

}  // namespace fdem
