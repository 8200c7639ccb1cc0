#pragma once
// Finite-element kernels (DESIGN.md 4.3): shape functions, element stiffness, internal force,
// lumped mass, body force, for the thesis's element types. Plain arrays in, plain arrays out:
// no MPI, no PETSc, no mesh. Small-strain kinematics, or total Lagrangian (FeMaterial::nlgeom)
// for elastic bricks and quads.
//
// Conventions
//  - X: reference nodal coordinates, row-major n x dim (dim 3 for bricks, 2 for the quad);
//    u: nodal displacements, same layout; f: nodal forces, n*dim; K: (n*dim)^2 row-major.
//  - Node ordering: Hex8 as Gmsh/VTK (bottom face 0-1-2-3 counter-clockwise seen from +z... i.e.
//    the standard isoparametric order with xi,eta,zeta = -1/+1 corners), Hex20 as Gmsh
//    (corners 0-7, then the 12 mid-edge nodes in Gmsh order), Quad4 counter-clockwise.
//  - Stress/strain Voigt order: xx, yy, zz, xy, yz, xz; strains with engineering shear
//    (gamma = 2 eps). Plane strain keeps zz (stress) with eps_zz = 0. Tension positive.
//  - Units SI: m, N, Pa, kg. Quad4 (plane strain) works per unit thickness: forces in N/m,
//    masses in kg/m.
//  - Integration points: index g = i + 2 j (+ 4 k), natural coordinates -/+ 1/sqrt(3) along
//    xi, eta (, zeta); Hex8R's single point is the centre. Hex20 with 2x2x2 points has 6
//    spurious zero-energy modes as a lone element; they are not communicable in meshes of
//    two or more elements (tests/unit_fem_element.cpp checks both).
//  - Hex8R: uniform (volume-averaged) gradients and Flanagan-Belytschko stiffness hourglass
//    control, k = hourglass * G * (2/3) V (bbar:bbar) = hourglass * G * L for a cube of side L
//    (see element.cpp). The hourglass part is elastic also for Mohr-Coulomb.
//  - element_internal_force with an elastic material ignores the stored state and, when
//    commit is true and states is not null, stores the strain and stress into it.
#include <cstdint>
#include <string>
#include <vector>

#include "fem/element_types.hpp"

namespace fdem::fem {


// The element facts, read from the one table (fem/element_types.hpp).
inline int element_nodes(ElemType t) { return element_traits(t).nodes; }
/// The dimension of the space the element lives in: 2 for quad4 (plane strain), else 3.
inline int element_dim(ElemType t) { return element_traits(t).space_dim; }
inline int element_gauss_points(ElemType t) { return element_traits(t).gauss_points; }
/// Degrees of freedom per node: 6 for shells (3 translations, 3 rotations), else element_dim.
inline int element_node_dofs(ElemType t) { return element_traits(t).node_dofs; }
inline const char* element_name(ElemType t) { return element_traits(t).name; }
/// Parse a name (element_type_names(); case-insensitive); false if unknown.
bool parse_element_type(const std::string& name, ElemType& out);

/// Material of a finite element.
struct FeMaterial {
  enum Kind : std::int8_t { kElastic, kMohrCoulomb } kind = kElastic;
  double young = 0;    // E, Pa
  double poisson = 0;  // nu
  double density = 0;  // kg/m^3 (mass for the explicit solver)
  double unit_weight = 0;  // gamma, N/m^3 (body load, acts along the gravity direction)
  double cohesion = 0;     // c, Pa          (Mohr-Coulomb)
  double friction = 0;     // phi, radians   (Mohr-Coulomb)
  double dilation = 0;     // psi, radians   (Mohr-Coulomb)
  double hourglass = 0.05; // Hex8R: hourglass stiffness as a fraction of the element's shear stiffness
  double thickness = 0;    // Shell4: thickness, m
  /// Geometrically nonlinear (Abaqus's NLGEOM): total Lagrangian, St Venant-Kirchhoff, for
  /// elastic hex8, hex20 and quad4 (a membrane that sags: a geogrid over a void). The stored
  /// strain is Green-Lagrange, the stored stress Cauchy.
  bool nlgeom = false;
};

/// State at one Gauss point (committed each solver step).
struct GaussState {
  double stress[6] = {0, 0, 0, 0, 0, 0};
  double strain[6] = {0, 0, 0, 0, 0, 0};
  double plastic_strain[6] = {0, 0, 0, 0, 0, 0};
  bool yielded = false;
};

/// Smallest Jacobian determinant over the Gauss points and nodes (<= 0: inverted/degenerate).
double element_min_detj(ElemType t, const double* X);

/// The mesh readers' shape check (fem/mesh_detail.hpp): the smallest Jacobian determinant over
/// the element's nodes and then its centre, and where it first occurs (`where`: the local node,
/// 0-based; -1: the centre). Shell4: at each corner a, the cross product of its edges to corners
/// a+1 and a-1 projected on the unit normal (X2 - X0) x (X3 - X1) / |..| (0 and -1 if that
/// normal vanishes).
double element_min_nodal_detj(ElemType t, const double* X, int& where);

/// Jacobian determinant at the natural coordinates xi (dim of the element's parametric space)
/// of a brick or quad4, with the shape functions of the kernels. Shell4: std::logic_error.
double element_detj_at(ElemType t, const double* X, const double* xi);

/// Linear-elastic element stiffness (uses young, poisson; Hex8R includes the hourglass part).
void element_stiffness(ElemType t, const double* X, const FeMaterial& m, double* K);

/// Internal force of the element for the total displacement u. Elastic: K u (nlgeom: the total
/// Lagrangian force, nonlinear in u; hex8r and shell4 throw std::logic_error). Mohr-Coulomb:
/// stresses integrated from the strain increment since the stored state (closest-point return
/// map), and `states` (element_gauss_points entries) updated when commit is true.
/// `prep`: what element_prepare stored for this element and material, or null (then computed
/// here): the same force to the last bit either way.
void element_internal_force(ElemType t, const double* X, const double* u, const FeMaterial& m,
                            GaussState* states, bool commit, double* f, const double* prep = nullptr);
/// Doubles of the data element_prepare computes once per element, for element_internal_force to
/// reuse every step (0: the type recomputes everything each call). Today only hex8i: its
/// gradients at the points, its incompatible modes' gradients and the Cholesky factor of their
/// 9 x 9 stiffness (353 doubles), which otherwise cost twice its force.
int element_prepared_size(ElemType t, const FeMaterial& m);
/// Fill `prep` (element_prepared_size doubles) for the reference coordinates X and material m.
void element_prepare(ElemType t, const double* X, const FeMaterial& m, double* prep);

/// Lumped (diagonal) mass per node: row-sum for linear elements, HRZ for Hex20 (all positive).
/// Shell4: translational mass rho t int N_a dA (needs the thickness: use the FeMaterial form).
void element_lumped_mass(ElemType t, const double* X, double density, double* mass);

/// Shell4: rotational inertia per node (4 values, see shell4_lumped_mass); other types: zeros.
void element_rotary_inertia(ElemType t, const double* X, double density, double thickness, double* j);

/// Consistent nodal forces of a body load b (N/m^3 vector, e.g. gamma * gravity direction).
void element_body_force(ElemType t, const double* X, const double* b, double* f);

/// Mohr-Coulomb perfectly plastic closest-point return in principal stresses: given the trial
/// stress (Voigt), returns the corrected stress; `yielded` tells whether a correction was made.
/// Non-associated flow with dilation psi; apex and edge returns handled.
void mohr_coulomb_return(const double* trial, const FeMaterial& m, double* stress, bool& yielded);

/// Isotropic elastic matrix D (6x6, row-major, Voigt as above, engineering shear strains).
void elastic_matrix(double young, double poisson, double* D);

}  // namespace fdem::fem
