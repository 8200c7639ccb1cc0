#pragma once
// FeModel: the explicit finite-element solver on PETSc (DESIGN.md sections 3 and 4.3).
//
// The mesh is replicated (read identically on every rank) and partitioned by element
// (FePartition), or each rank holds only its part (fem.distribute, partition/mesh_distribute.hpp:
// its elements and their nodes; indices given by the drivers are then the whole mesh's). A rank integrates its own elements; nodal fields are ghosted PETSc Vecs in the
// partition's global node numbering (block size = dim): internal forces are summed over ranks by
// a reverse ghost scatter (ADD_VALUES), displacements reach the ghosts by a forward scatter.
//
// Dynamic relaxation (eqs 4-12 ... 4-14): lumped mass M, mass-proportional damping c (fixed, or
// adaptive from the Rayleigh quotient of the last increment, c = 2 sqrt(du.df / du.M du)),
// central differences
//   v+ = [(1 - c dt/2) v- + dt M^-1 (lf P + B - F_int(u))] / (1 + c dt/2),  u += dt v+,
// stable step from the Gershgorin bound lambda_max <= max_i sum_j |K_ij| / M_ii.
// Restrained dofs are held at df * (prescribed displacement) (zero when none is given).
//
// solve_static(): the linear-elastic static solution K u = lf P + B with the same restraints,
// by PETSc KSP (CG + GAMG with rigid-body near-null space by default; -ksp_* / -pc_* options
// override), used to verify the relaxation and for purely elastic FE cases.
#include <mpi.h>
#include <petscksp.h>
#include <petscvec.h>

#include <array>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "fem/element.hpp"
#include "fem/fe_partition.hpp"
#include "fem/fe_state.hpp"
#include "fem/mesh.hpp"

namespace fdem::fem {

struct FeParams {
  std::array<double, 3> gravity_dir{0, 0, -1};  // unit vector of the body load gamma
  double damping = -1;    // c (1/s); < 0: adaptive (Rayleigh quotient)
};

class FeModel {
 public:
  FeModel(MPI_Comm comm, const Mesh& mesh, const FePartition& part, std::vector<FeMaterial> materials,
          const FeParams& prm = {});
  ~FeModel();
  FeModel(const FeModel&) = delete;
  FeModel& operator=(const FeModel&) = delete;

  // ---- boundary conditions, by mesh node INDEX (identical on every rank) ----
  /// Restrain dofs (fixed[d] true) with optional prescribed displacement (scaled by the
  /// displacement factor).
  void restrain(std::int32_t node, const std::array<bool, 3>& fixed, const std::array<double, 3>& disp = {0, 0, 0});
  /// Hold rotations of a shell node (no effect on meshes without shells).
  void restrain_rotations(std::int32_t node, const std::array<bool, 3>& fixed);
  /// Reference nodal load P (scaled by the load factor).
  void add_load(std::int32_t node, const std::array<double, 3>& force);
  void set_load_factor(double lf) { load_factor_ = lf; }
  void set_disp_factor(double df) { disp_factor_ = df; }
  /// Remove elements from the model: they carry no force from now on. By the whole mesh's element
  /// index (= the mesh's own index unless the mesh is a part: FePartition::elem_index), the same
  /// list on every rank; each rank removes those it has. Collective. The body load is re-assembled
  /// from the elements still active (a removed element's weight leaves with it); a node left with
  /// no active element (orphaned) is held where it is: its mass is set to 0, its velocity to 0.
  /// The other nodes keep their lumped mass (heavier than the active elements' alone: the stable
  /// time step does not shrink, and the relaxed static answer does not depend on the mass).
  void remove_elements(const std::vector<std::int32_t>& elems);
  /// Every material's density = its density at construction x s (> 0): the lumped masses, rotary
  /// inertias and the stable step (x sqrt(s)); the body load (unit_weight) is not. The same bits
  /// as a model built with the densities x s. Collective (fem.mass_scaling: auto).
  void set_density_scale(double s);
  /// Coupling (DESIGN.md 3): replace the interface force by the sum over ALL ranks of the given
  /// contributions (global node number from global_node(), 3 force components each; a node may
  /// appear on several ranks and several times). VecSetValues(ADD_VALUES) + VecAssembly into a
  /// PETSc Vec: the cross-rank reduction. Collective. The interface force is an external force
  /// on the translational dofs, not scaled by the load factor.
  void set_interface_forces(const std::vector<PetscInt>& global_nodes, const std::vector<double>& forces);
  /// The same with the contributions as 128-bit fixed-point integers (base/exact_sum.hpp,
  /// units 2^-64 N), times `scale`: the sum is exact, the same on any number of ranks.
  /// `same_nodes`: every rank passes a subset of the nodes of its last call with false (and its
  /// own), so the assembly reuses that call's communication pattern (PETSc's
  /// VEC_SUBSET_OFF_PROC_ENTRIES: no global reduction); must be the same on every rank.
  void set_interface_forces_exact(const std::vector<PetscInt>& global_nodes, const std::vector<__int128>& forces,
                                  double scale, bool same_nodes = false);
  /// Sum of the interface force over all nodes (after set_interface_forces; collective).
  std::array<double, 3> interface_force_total() const;
  /// This rank's owned interface-force values (n_owned * node_dofs, local owned-node order, i.e.
  /// the nodes local_nodes()[0 .. n_owned)).
  const std::vector<double>& owned_interface_forces() const { return iface_; }
  /// Global node number of any mesh node (identical on every rank).
  PetscInt global_node(std::int32_t mesh_node) const { return node_global_[mesh_node]; }
  /// The ghosted displacement Vec (global numbering, block size node_dofs()), for scatters.
  Vec displacement_vec() const { return u_; }

  // ---- solvers ----
  /// Critical step 2/sqrt(lambda_max) (Gershgorin); collective. `k_extra` (N/m) is added to the
  /// row sums of the translational dofs of `extra_nodes` (mesh node indices): the stiffness of
  /// a contact on those nodes (the FE-DE interface), which the FE step must also resolve.
  double critical_dt(const std::vector<std::int32_t>& extra_nodes = {}, double k_extra = 0);
  /// The same with a stiffness per node: k_extra[j] (N/m) on extra_nodes[j].
  double critical_dt(const std::vector<std::int32_t>& extra_nodes, const std::vector<double>& k_extra);
  /// One dynamic-relaxation step; collective.
  void step(double dt);
  /// Run steps until the unbalanced-force ratio is below tol (checked every `check` steps) or
  /// max_steps; returns the number of steps taken.
  std::int64_t relax(double dt, double tol, std::int64_t max_steps, int check = 50);
  /// Unbalanced-force ratio |R_free| / max(|lf P + B|, |reactions|); collective. With node groups
  /// (set_node_groups: the parts of a merged model) the largest of the groups' own ratios, so that
  /// a rigid part's reactions do not hide a deformable part's residual.
  double unbalanced();
  /// The group (0 .. n-1) of every node of the mesh given to the constructor, e.g. the case mesh it
  /// came from; the unbalanced ratios are then taken per group. Empty: one group (the default).
  /// Collective (the mesh may be a part: the group count is the largest over the ranks).
  void set_node_groups(const std::vector<std::int32_t>& group_of_node);
  /// {unbalanced(), resultant ratio}: the second is |sum of the free residual| / max(sum over the
  /// nodes of |free external force|, |sum of the reactions|) over the translational dofs -- small only
  /// when the structure is in global equilibrium (a residual spread coherently over many nodes,
  /// e.g. the damping force of a slowly creeping structure, hides in the norm); collective.
  std::array<double, 2> unbalanced_measures();
  /// The balance of one node group (a part of a merged model; the whole model without groups):
  /// its unbalanced ratio (norm), its resultant ratio (as unbalanced_measures) and its nodes'
  /// mass-weighted RMS speed sqrt(sum m |v|^2 / sum m) over the nodes, |v| of their free
  /// translational dofs (m/s; the scaled masses: a uniform fem.mass_scaling cancels), and its
  /// drift: the mass-weighted RMS displacement of those dofs since mark_check() (m; NaN before
  /// the first mark). A node chattering about a place of rest has a speed but no drift; a part
  /// creeping in any mode (sinking, sagging) drifts. NaN ratios as unbalanced_measures.
  /// `load` is the resultant ratio's scale (N: the larger of the sum over the nodes of their free
  /// external forces' magnitudes and the reactions' resultant), `mass` the nodes' mass (kg; 0 for
  /// a part held in every dof).
  struct PartBalance {
    double norm = 0, resultant = 0, speed = 0, drift = std::numeric_limits<double>::quiet_NaN();
    double load = 0, mass = 0;
  };
  /// One PartBalance per node group (set_node_groups; one without groups); collective, the same
  /// bits on any number of ranks.
  std::vector<PartBalance> part_balance();
  /// The worst of the parts' {norm, resultant} (NaN propagates; one part: its own).
  static std::array<double, 2> worst(const std::vector<PartBalance>& parts);
  /// The displacements now become the reference of PartBalance::drift (a hold's checks call it
  /// at the hold's start and after each check); checkpointed with the state. Collective.
  void mark_check();
  int node_groups() const { return n_groups_; }
  /// What a KSP static solve guarantees about its answer. CG stops when its (recursively
  /// updated) preconditioned residual is below rtol |B b| (PETSc's default test, B the GAMG
  /// preconditioner). The residual of the answer, r = b - A u, is then computed afresh (near
  /// rtol 1e-12 round-off makes it larger than CG's estimate), and the error of the displacements
  /// obeys |u - u*| / |u*| <= kappa |B r| / |B b|, kappa the condition number of B A, estimated
  /// by CG's Lanczos process. Two solves of one system (other rank counts, so another
  /// preconditioner, another initial guess) agree within the sum of their bounds, not to round-off.
  struct StaticSolveInfo {
    int iterations = 0;
    double rtol = 0;      ///< the relative tolerance used (after -ksp_rtol)
    double residual = 0;  ///< |B (b - A u)| / |B b| of the answer u
    double condition = 0; ///< kappa(B A), Lanczos estimate (>= 1)
    double error_bound() const { return condition * residual; }
  };
  /// Linear-elastic static solve with KSP (CG + GAMG, PETSc options apply); collective.
  StaticSolveInfo solve_static(double rtol = 1e-12);

  /// Run health (collective): the lowest mesh node index with a non-finite displacement or
  /// velocity (any dof; -1: none), and the largest translational displacement magnitude with
  /// its mesh node (the lowest index on a tie); the whole mesh's indices. The same on any number
  /// of ranks.
  struct Health {
    std::int64_t nonfinite_node = -1;
    double max_u = 0;
    std::int64_t max_node = -1;
  };
  Health health() const;

  // ---- restart ----
  /// Keyed by the whole mesh's node and element indices (FeState): the same on a part.
  FeState state() const;
  /// Collective (refreshes ghosts). `s` may hold the whole model (every rank reads the file).
  void restore(const FeState& s);

  // ---- results ----
  /// Displacements of all nodes, by the whole mesh's node index (n_nodes * dim), on every rank;
  /// collective.
  std::vector<double> gather_displacements() const;
  /// Sum of reaction forces (F_int - lf P - B) over the restrained dofs of the given nodes; collective.
  std::array<double, 3> reaction(const std::vector<std::int32_t>& nodes) const;
  /// Gauss-point states of this rank's elements (for output), in local element order.
  const std::vector<GaussState>& gauss_states() const { return gp_; }
  const std::vector<std::int32_t>& local_elements() const { return elems_; }
  /// Local nodes: mesh indices and global numbers; the first n_owned() are owned by this rank.
  const std::vector<std::int32_t>& local_nodes() const { return mesh_of_; }
  const std::vector<PetscInt>& local_global_numbers() const { return global_of_; }
  std::size_t n_owned() const { return n_owned_; }
  /// Displacements and velocities of the owned nodes (n_owned * dim).
  std::vector<double> owned_displacements() const;
  std::vector<double> owned_velocities() const;
  /// Is local element le active (not removed)?
  bool element_active(std::size_t le) const { return active_[le] != 0; }
  /// Gauss-point range of local element le in gauss_states().
  std::pair<std::int32_t, std::int32_t> gauss_range(std::size_t le) const { return {gp_off_[le], gp_off_[le + 1]}; }
  int dim() const { return dim_; }
  /// The mesh the model was built on (the whole mesh, or this rank's part of it).
  const Mesh& mesh() const { return mesh_; }
  /// Degrees of freedom per node: dim, or 6 when the mesh has shells.
  int node_dofs() const { return nf_; }
  std::int64_t n_elements_global() const { return n_elems_global_; }
  double damping_used() const { return c_last_; }
  /// A fixed mass-proportional damping c >= 0 (1/s) from the next step on (coupling.creep_damping);
  /// damping_used() reports it at once (a checkpoint keeps it; a restart sets it back from there).
  void set_damping(double c);
  /// The whole mesh's index of a node / element of mesh() (the same index unless it is a part).
  std::int64_t whole_node(std::int32_t n) const { return node_index_.empty() ? n : node_index_[n]; }
  std::int64_t whole_elem(std::int32_t e) const { return elem_index_.empty() ? e : elem_index_[e]; }

 private:
  void internal_force(bool commit);  // into f_ (owned entries complete after the call)
  void gather_element(std::size_t le, double* X, double* u, const double* ua) const;
  void prepare_elements();
  /// Call f(le, nodes, dofs per node, K) with the elastic stiffness of every active local element.
  template <class F> void for_each_stiffness(F&& f) const;
  /// Sum element nodal values into owned dofs exactly (base/exact_sum.hpp), the same on any
  /// number of ranks: per_element(le, vals) writes element le's values (node-major) and returns
  /// its dofs per node; out gets n_owned * nf values. dynamic_shift: the fixed-point unit from
  /// the largest value (else 2^-64, for forces in N); collective.
  template <class F> void assemble_exact(F&& per_element, double* out, bool dynamic_shift, bool active_only);

  // Construction steps.
  /// This rank's elements and nodes (owned, then ghosts, each by global number), the local
  /// connectivity and the Gauss-point ranges.
  void build_local_numbering(const FePartition& part);
  /// The way back from the whole mesh's index (-1: not in this part).
  std::int32_t part_node(std::int64_t n) const;
  std::int32_t part_elem(std::int64_t e) const;
  /// The ghosted Vecs and the owned-dof arrays (zero).
  void create_vectors(const FePartition& part);
  /// Lumped mass (every element, or the active ones) and body load (every element, or the active ones).
  void assemble_mass_and_body(bool active_only = false);
  void assemble_masses_after_removal();  // the masses of every element, zero where no active one
  void assemble_body(bool active_only);

  // solve_static steps (collective).
  /// The assembled elastic stiffness, every diagonal in its pattern (from this rank's elements
  /// only: the mesh may be a part).
  Mat assemble_stiffness(PetscInt nloc) const;
  /// b = lf P + B + interface force, x = the prescribed values; held_rows: the restrained dofs
  /// and those without mass (global row numbers).
  void fill_static_system(Vec b, Vec x, std::vector<PetscInt>& held_rows) const;
  /// The rigid-body near-null space set on A (nullptr if none); coords: the Vec it refers to
  /// (translational dofs only), to be destroyed with it.
  MatNullSpace set_near_null_space(Mat A, Vec x, Vec& coords) const;
  MatNullSpace set_shell_near_null_space(Mat A, Vec x) const;
  /// x (owned dofs) into the ghosted displacement Vec, ghosts refreshed.
  void copy_into_displacements(Vec x);

  MPI_Comm comm_;
  int rank_ = 0, size_ = 1, dim_ = 3, nf_ = 3;
  const Mesh& mesh_;
  std::vector<FeMaterial> mats_;
  std::vector<double> density0_;  // the materials' densities at construction (set_density_scale)
  FeParams prm_;
  std::int64_t n_elems_global_ = 0;
  // Local numbering: owned nodes (by global number), then ghosts.
  std::vector<std::int32_t> elems_;        // local elements (mesh indices)
  std::vector<std::uint8_t> active_;       // per local element
  std::vector<std::int64_t> removed_;      // all removed elements (the whole mesh's indices)
  std::vector<std::int64_t> node_index_, elem_index_;  // FePartition's (empty: the mesh is whole)
  std::int64_t n_nodes_global_ = 0;
  std::vector<std::int32_t> local_of_;     // mesh node index -> local node (-1: not here)
  std::vector<std::int32_t> mesh_of_;      // local node -> mesh node index
  std::vector<PetscInt> global_of_;        // local node -> global node number
  std::size_t n_owned_ = 0;
  std::vector<std::int32_t> elem_conn_;    // local element connectivity in local node numbers
  std::vector<std::int32_t> elem_off_{0};
  std::vector<GaussState> gp_;
  std::vector<std::int32_t> gp_off_{0};
  std::vector<std::int32_t> group_;        // per owned node: its group for the unbalanced ratios
  int n_groups_ = 1;
  std::vector<double> prep_;               // element_prepare's data of the local elements that keep some
  std::vector<std::int64_t> prep_off_{0};  // per local element (equal offsets: none)
  // Owned-dof data (n_owned * dim).
  std::vector<double> mass_, fext_, body_, v_, presc_;  // per dof (mass: translational or rotary)
  std::vector<std::uint8_t> fixed_;
  std::vector<double> f_prev_, u_prev_;
  std::vector<double> u_check_;            // the displacements at mark_check (PartBalance::drift)
  bool have_check_ = false;
  Vec u_ = nullptr, f_ = nullptr;          // ghosted
  Vec f4_ = nullptr;                       // ghosted, 4 limbs per dof (exact assembly)
  std::vector<double> ebuf_;               // exact assembly: element values
  std::vector<std::int8_t> eed_;           // exact assembly: dofs per node of each element (0: skipped)
  std::vector<__int128> acc_;              // exact assembly: per local dof
  Vec fi_ = nullptr;                       // interface force (coupling), not ghosted
  std::vector<double> iface_;              // its owned values (n_owned * nf)
  std::vector<PetscInt> node_global_;      // mesh node -> global node number
  double load_factor_ = 1, disp_factor_ = 1, c_last_ = 0;
  bool have_prev_ = false;
};

}  // namespace fdem::fem
