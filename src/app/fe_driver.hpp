#pragma once
// The driver of pure finite-element cases (a case with `fem` and no particles): builds the
// meshes, partitions them, applies restraints, loads and prescribed displacements, and runs
// the holds (load / displacement steps) with dynamic relaxation or the static KSP solve.
#include <mpi.h>

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "app/driver.hpp"
#include "fem/fe_model.hpp"
#include "fem/fe_partition.hpp"
#include "fem/mesh.hpp"
#include "io/case.hpp"
#include "io/fe_checkpoint.hpp"
#include "io/fe_output.hpp"

namespace fdem {

/// The case's meshes merged into one (materials set per mesh), with, per case mesh, the offset
/// of its nodes and elements and its own sets (by merged index).
struct FeMeshes {
  fem::Mesh merged;
  struct Part {
    std::string name;
    std::int32_t node_offset = 0, elem_offset = 0;
    fem::Mesh mesh;  // the mesh as built (own numbering), for thesis-format boundary files
    bool is_geogrid = false;
    fem::GeogridInfo geogrid;  // the generator's layout (is_geogrid)
  };
  std::vector<Part> parts;
  std::vector<std::int64_t> tie_counts;  // per fem.ties entry: nodes joined
  /// The merged index of node `local` of a part: part.node_offset + local, or, for a node tied
  /// to another mesh (fem.ties), the node it became.
  std::int32_t node(const Part& part, std::int32_t local) const {
    const std::int32_t n = part.node_offset + local;
    return merged.tied_to.empty() || merged.tied_to[n] < 0 ? n : merged.tied_to[n];
  }
};

/// Collective: each rank's owned elements and nodes and its peak resident memory, gathered on
/// rank 0 into info.fe_ranks (run.json's "fe_partition").
void gather_fe_ranks(const fem::FeModel& model, MPI_Comm comm, RunInfo& info);

/// Build all meshes of a case (identically on every rank). Throws InputError on bad meshes.
FeMeshes build_fe_meshes(const CaseConfig& c);

/// "pipe -> soil: 119 nodes; ..." for fem.ties (empty without ties).
std::string ties_text(const CaseConfig& c, const FeMeshes& m);

/// structures.json in `dir` (rank 0): each FE mesh's name, size, offsets in the merged mesh,
/// bounding box and, for a generated geogrid, its layout (apertures, pitches, the x of every
/// transverse rib's front face, the y of every longitudinal rib's -y side, plan area, volume),
/// so that post-processing reads the structure instead of re-deriving it.
void write_structures(const FeMeshes& m, const std::string& dir);
/// The contents of structures.json.
std::string structures_json(const FeMeshes& m);

/// The boundary conditions of a case, resolved to merged node indices.
struct FeBoundary {
  struct Restr { std::int32_t node; std::array<bool, 3> fixed; std::array<double, 3> disp; std::array<bool, 3> rot{}; };
  struct Load { std::int32_t node; std::array<double, 3> force; };
  std::vector<Restr> restraints;   // restraints and prescribed displacements
  std::vector<Load> loads;
  struct Group { std::string name; std::vector<std::int32_t> nodes; };
  std::vector<Group> reaction_groups;  // one per restraint / displacement entry
};

/// The FE side of a case ready to run (shared by the pure-FE and the coupled driver): merged
/// meshes, resolved boundary conditions, the partition over the communicator's ranks and the
/// FeModel with its restraints and reference loads applied. Not movable (the model refers to
/// the mesh): held by unique_ptr.
/// With fem.distribute the merged mesh is built on rank 0 only and each rank holds its part
/// (`local`, in the part's own indices: part.node_index / elem_index give the merged ones); the
/// boundary conditions are resolved on rank 0 and every rank keeps those of its part, in its
/// part's indices.
struct FeSetup {
  FeMeshes meshes;    // fem.distribute: the case meshes on rank 0 only (merged: dropped once distributed)
  FeBoundary bc;      // node indices of mesh()
  fem::FePartition part;
  MPI_Comm comm = MPI_COMM_NULL;
  bool distributed = false;
  fem::Mesh local;    // fem.distribute: this rank's part of the merged mesh
  std::int64_t n_nodes = 0, n_elements = 0;           // of the merged mesh
  std::vector<std::int32_t> node_offsets;            // per case mesh: its first merged node
  std::vector<std::vector<std::int32_t>> removals;   // per fem.remove entry: merged element indices
  std::string structures;                            // structures.json (rank 0 at least)
  std::unique_ptr<fem::FeModel> model;
  const fem::Mesh& mesh() const { return distributed ? local : meshes.merged; }
  /// The merged index of node n of mesh().
  std::int64_t merged_node(std::int32_t n) const { return distributed ? part.node_index[n] : n; }
  std::int64_t merged_element(std::int32_t e) const { return distributed ? part.elem_index[e] : e; }
};

/// Build the FE side of a case (collective; throws InputError on bad meshes, sets or
/// boundary files, and for the static solver with Mohr-Coulomb materials). `on_whole`, when
/// given, is called with the case's whole meshes where they are built -- on every rank, or with
/// fem.distribute on rank 0 alone, before it sends the parts -- e.g. to make the coupling
/// interface; an InputError it throws is every rank's.
std::unique_ptr<FeSetup> make_fe_setup(const CaseConfig& c, MPI_Comm comm,
                                       const std::function<void(const FeMeshes&)>& on_whole = {});
/// Whether the case has holds (fem.load_steps or fem.displacement_steps): a coupled run then ends
/// with its last hold; without them, at time.steps / duration (or time.stop_unbalanced).
bool fe_holds_mode(const CaseConfig& c);
/// Number of holds: max(1, load_steps, displacement_steps).
std::size_t fe_hold_count(const CaseConfig& c);
/// Start hold h (0-based): set its load and displacement factors and remove the elements due at
/// it. Returns true when elements were removed (the stable step changed).
bool begin_fe_hold(const CaseConfig& c, FeSetup& fe, std::size_t h);
/// Load and displacement factor of hold h (1 when the case gives no steps).
double fe_load_factor(const CaseConfig& c, std::size_t h);
double fe_disp_factor(const CaseConfig& c, std::size_t h);
/// This rank's share of an FE snapshot (FeSnapshotWriter::write).
FeSnapshotData fe_snapshot_data(const FeSetup& fe);
/// Largest nodal displacement magnitude over all ranks (collective).
double fe_max_displacement(const fem::FeModel& model, MPI_Comm comm);
/// Run-health check of the FE side (collective; docs/user-guide.md "Runs that diverge"): throws
/// RunDiverged (the same message on every rank), naming `when` (e.g. "hold 2 (load factor 1),
/// step 340"), the node and an element of it, when a displacement or velocity is non-finite,
/// `unbalanced` is non-finite, or the largest displacement exceeds the size of the mesh (its
/// bounding-box diagonal: far beyond the small strains of the elements -- the model blew up).
void fe_check_health(const FeSetup& fe, const std::string& when, double unbalanced);
/// solver: static needs the rigid-body motions restrained: throws InputError naming fem.restraints
/// when some direction has no fixed or prescribed translational dof at all.
void check_static_restraints(const CaseConfig& c, const FeBoundary& bc, int dim);
/// Columns of reactions.csv: hold, step, then <group>_rx/_ry/_rz per restraint/displacement entry.
std::vector<std::string> fe_reaction_columns(const FeSetup& fe);
/// A row of reactions.csv (collective).
std::vector<double> fe_reaction_row(const FeSetup& fe, double hold, double step);

/// Check a pure FE case completely (meshes, sets, boundary files) and print a summary on rank 0.
void check_fe_case(const CaseConfig& c, MPI_Comm comm);

/// Read an FE checkpoint and check that it belongs to this model and mesh (InputError naming
/// the file otherwise, the same on every rank). By rows: each rank reads 1/P of the node and
/// Gauss-point rows and they are routed to their owners (partition/rendezvous.hpp), so no rank
/// holds more than its share of the state; the result holds this rank's rows (owned nodes, local
/// elements) for FeModel::restore. Collective over `comm` (the model's).
FeCheckpoint read_fe_checkpoint_for(const std::string& path, const fem::FeModel& model, std::int64_t n_nodes,
                                    std::int64_t n_elements, MPI_Comm comm);

/// Run a pure FE case. Returns the exit code (0 finished, 128+signal when interrupted).
int run_fe_case(const CaseConfig& c, const RunOptions& opt, MPI_Comm comm);

}  // namespace fdem
