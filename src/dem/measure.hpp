#pragma once
// Micro-mechanical measurements on the granular soil (DESIGN.md 4.2; thesis eqs 3-11 ... 3-13,
// 4-18): Love-Weber average stress, fabric tensor, coordination numbers, porosity, mean
// displacement in measurement boxes, and contact-orientation histograms (rose diagrams).
//
// Pure functions over plain values: no MPI, no I/O. The parallel collection (which rank adds
// what, so that every contact is counted once) is in src/app/measurements.cpp.
//
// Conventions (docs/user-guide.md, "Measurements"):
//  - A box is half-open, [lo, hi) in every direction; a particle belongs to a box when its
//    centre lies in it.
//  - Stress sign: geotechnical, COMPRESSION POSITIVE. Units Pa.
//    sigma_ij = -(1/V) sum_{p in box} sum_{c of p} l^{pc}_i f^{pc}_j  (symmetric part reported)
//    with l^{pc} the vector from the centre of particle p to the contact point and f^{pc} the
//    force on p. For a particle pair with both centres in the box the two sides add up to
//    l_i f_j with l = x_B - x_A (branch vector) and f the force on B, the textbook Love-Weber
//    term; a pair crossing the box boundary contributes the side of the particle inside only
//    (the weighting by particle centres). Wall contacts contribute their particle's side.
//  - Coordination, fabric: over the particle-particle contact "sides" of the particles in the
//    box (a pair with both particles inside counts twice, as 2 N_c / N_p does).
//    Z = sides / N_p; Z_mech = the same over the particles with >= 2 contacts (rattlers with
//    0 or 1 contact excluded: Thornton's (2 N_c - N_1) / (N_p - N_0 - N_1)).
//    Fabric phi_ij = sum n_i n_j / sides (trace 1; isotropic: I/3).
//  - Porosity: 1 - (solid volume inside the box) / V, with the exact sphere-box intersection
//    volume (sphere_box_volume) of every particle, whatever box its centre is in.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "base/vec3.hpp"

namespace fdem {

/// Axis-aligned box [lo, hi).
struct MeasureBox {
  Vec3 lo, hi;
  bool contains(const Vec3& x) const {
    return x.x >= lo.x && x.x < hi.x && x.y >= lo.y && x.y < hi.y && x.z >= lo.z && x.z < hi.z;
  }
  double volume() const { return (hi.x - lo.x) * (hi.y - lo.y) * (hi.z - lo.z); }
};

/// A regular grid of boxes over [lo, hi) with n[0] x n[1] x n[2] cells.
/// Cell (i, j, k) has linear index (k n[1] + j) n[0] + i (x fastest: the XDMF/VTK order).
struct MeasureGrid {
  Vec3 lo, hi;
  std::array<int, 3> n{1, 1, 1};
  std::size_t cells() const { return static_cast<std::size_t>(n[0]) * n[1] * n[2]; }
  Vec3 spacing() const { return {(hi.x - lo.x) / n[0], (hi.y - lo.y) / n[1], (hi.z - lo.z) / n[2]}; }
  /// Index of the cell containing x, -1 if none.
  long cell_of(const Vec3& x) const;
  MeasureBox cell(std::size_t c) const;
  /// Range of cell indices along axis d overlapped by [a, b] (empty: first > last).
  std::array<int, 2> range(int d, double a, double b) const;
};

/// Additive sums of one box; boxes are reduced over ranks by summing these.
struct MeasureSums {
  double stress[9] = {};   // -sum l_i f_j (row-major), compression positive, N m
  double fabric[6] = {};   // sum n n over contact sides (xx, yy, zz, xy, xz, yz)
  double sides = 0;        // particle-particle contact sides of the particles in the box
  double particles = 0;    // particles with their centre in the box
  double mech_sides = 0;   // the same over the particles with >= 2 contacts
  double mech_particles = 0;
  double solid = 0;        // sphere volume inside the box, m^3
  double disp[3] = {};     // sum of the particles' displacements, m
  static constexpr int kDoubles = 9 + 6 + 4 + 1 + 3;
  double* data() { return stress; }
  const double* data() const { return stress; }
};
static_assert(sizeof(MeasureSums) == MeasureSums::kDoubles * sizeof(double), "MeasureSums must be flat");

/// A particle with its centre in the box: `contacts` its particle-particle contacts.
void add_particle(MeasureSums& s, int contacts, const Vec3& displacement);
/// One contact side of a particle in the box: lever = contact point - particle centre,
/// force = contact force on the particle, n = unit contact normal (either sign);
/// particle_pair: false for wall (or interface) contacts, which add to the stress only.
void add_contact_side(MeasureSums& s, const Vec3& lever, const Vec3& force, const Vec3& n, bool particle_pair);

/// The measured values of a box of volume V.
struct BoxMeasure {
  double stress[6] = {};   // xx, yy, zz, xy, xz, yz; Pa, compression positive
  double p = 0;            // mean stress trace/3, Pa
  double q = 0;            // deviatoric (von Mises) stress sqrt(3 J2), Pa
  double z = 0;            // coordination number (NaN when no particle)
  double z_mech = 0;       // mechanical coordination number (NaN when no non-rattler)
  double porosity = 0;
  double fabric[6] = {};   // NaN when no contact
  double displacement[3] = {};  // mean over the particles (NaN when none), m
  double particles = 0, contacts = 0;  // contacts: contact sides / 2
};
BoxMeasure finish(const MeasureSums& s, double volume);

// ---- geometry ----

/// Area of the disc of radius rho centred at the origin intersected with [y0, y1] x [z0, z1]
/// (closed form).
double disc_rect_area(double rho, double y0, double y1, double z0, double z1);
/// Volume of the sphere (centre c, radius r) inside the box [lo, hi]. The integral over x of
/// the exact disc-rectangle area, split at every x where the slice changes shape and mapped
/// with a smoothstep substitution (removes the square-root end-point behaviour) and adaptive
/// 20-point Gauss-Legendre rules: relative error ~1e-15 (tests/unit_measure.cpp).
/// Exact shortcuts for a sphere wholly inside (4/3 pi r^3) or outside (0).
double sphere_box_volume(const Vec3& c, double r, const Vec3& lo, const Vec3& hi);
/// Volume of a spherical cap of height h (0 <= h <= 2r).
inline double sphere_cap_volume(double r, double h) { return M_PI * h * h * (3 * r - h) / 3.0; }

// ---- rose diagrams ----

/// Bin of the contact line orientation in the plane spanned by axes (a0, a1) (e.g. xz: 0, 2):
/// the angle theta = atan2(n[a1], n[a0]) folded into [0, pi) (n and -n are the same line),
/// bins of pi/bins. -1 when n has no component in the plane.
int rose_bin(const Vec3& n, int a0, int a1, int bins);

/// Symmetric 3x3 tensor in (xx, yy, zz, xy, xz, yz) order: p = trace/3 and q = sqrt(3 J2).
void invariants(const double t[6], double& p, double& q);

}  // namespace fdem

namespace fdem {

// ---- what one measurement produces (filled by src/app/measurements.cpp, written by
// ---- src/io/measure_output.cpp) ----

/// What to measure (from the case's `measure` section).
struct MeasureSpec {
  std::vector<std::string> box_names;
  std::vector<MeasureBox> boxes;
  bool has_grid = false;
  MeasureGrid grid;
  struct Rose { int a0 = 0, a1 = 2, bins = 36; std::string plane = "xz"; };
  std::vector<Rose> roses;
  bool force_network = false;
  bool particle_displacements = false;
};

/// One segment of the contact force network: the centres of A and B, the normal force and the
/// total contact force on B.
struct ForceSegment {
  std::int64_t id_a = 0, id_b = 0;
  Vec3 xa, xb;
  double fn = 0;
  Vec3 force;
};

struct MeasureResult {
  std::int64_t step = 0;
  double time = 0;
  std::vector<BoxMeasure> boxes;   // one per spec box (same on every rank)
  std::vector<BoxMeasure> cells;   // one per grid cell (same on every rank)
  std::vector<std::vector<double>> rose_count, rose_fn;  // per rose and bin: contacts, sum of fn (N)
  std::vector<ForceSegment> network;  // THIS RANK's share (each contact on exactly one rank)
  std::vector<std::int64_t> particle_id;   // THIS RANK's owned particles (if requested)
  std::vector<Vec3> particle_x, particle_disp;
};

}  // namespace fdem
