#pragma once
// Spatial domain decomposition for the DEM (DESIGN.md section 3).
//
// The domain box is split into a px x py x pz process grid chosen to minimise the total area
// of the cuts for the box's shape (the MPI_Dims_create idea, but shaped to the box), not cut
// across gravity when another grid fits, or given by the user (`decomposition.grid`). Each rank
// owns the particles whose centres lie in its half-open subdomain [lo, hi); the last rank in a
// direction also owns the upper domain face. Boundaries are not periodic.
#include <mpi.h>

#include <array>
#include <cstddef>
#include <vector>

#include "base/vec3.hpp"

namespace fdem {

/// How the process grid is chosen (Decomposition::create).
struct GridRequest {
  /// All > 0: exactly this grid (px*py*pz must be the rank count, every slab at least min_width
  /// wide, else create throws); {0,0,0}: chosen by choose_grid.
  std::array<int, 3> dims{0, 0, 0};
  /// A chosen grid does not split this axis (0, 1, 2) when a grid that leaves it whole fits;
  /// -1: none. The engine passes gravity's axis: grains under gravity end on the floor, and a
  /// cut across gravity has to chase them (rebalancing) where a cut along it stays balanced.
  int uncut_axis = -1;
};

struct Decomposition {
  MPI_Comm comm = MPI_COMM_NULL;
  int rank = 0, size = 1;
  std::array<int, 3> dims{1, 1, 1};
  std::array<int, 3> coords{0, 0, 0};
  std::array<int, 3> lo_neighbor{-1, -1, -1};  // rank below in each direction (-1: none)
  std::array<int, 3> hi_neighbor{-1, -1, -1};  // rank above in each direction (-1: none)
  Vec3 domain_min, domain_max;
  Vec3 lo, hi;  // this rank's subdomain
  std::array<std::vector<double>, 3> cuts;  // cut planes along each direction (dims[d]+1 values)
  double min_width = 0;                     // ghost-layer width: no slab may be thinner

  /// Build the grid on `comm` for the box. `min_width` is the smallest allowed subdomain width
  /// (the ghost-layer width): grids that would make a subdomain thinner are not used; if no grid
  /// of comm's size fits, throws std::runtime_error explaining why.
  static Decomposition create(MPI_Comm comm, const Vec3& dmin, const Vec3& dmax, double min_width,
                              const GridRequest& request = {});

  /// Rank owning a point (points outside the domain are clamped to the nearest subdomain).
  int owner_of(const Vec3& x) const;
  bool owns(const Vec3& x) const { return owner_of(x) == rank; }
  /// Index of the subdomain slab containing coordinate c along direction d.
  int slab(int d, double c) const;
  double cut(int d, int k) const { return cuts[d][k]; }  // k-th cut plane along d (0 .. dims[d])

  /// Load balance: move the cut planes of each split direction to the (weighted) quantiles
  /// of the owned particles' coordinates (collective; a global histogram per direction), keeping
  /// every slab at least min_width wide. Returns true if any cut moved. The grid stays a tensor
  /// product, so the balance is per direction (good for layered beds, which is what DEM
  /// settling makes).
  /// `weight` (may be null: 1 each) is the cost of each particle, e.g. 1 + its contacts.
  bool rebalance(const std::vector<Vec3>& x, std::size_t n, const double* weight = nullptr);
  /// The ghost layer's volume (width `w`, on the faces with a neighbour) over the subdomain's:
  /// the ghosts per owned particle of a uniform bed (storage is reserved for them ahead).
  double ghost_share(double w) const;
  /// max over ranks of the local load divided by the mean (collective).
  static double imbalance(MPI_Comm comm, double load);

 private:
  void set_bounds();
};

/// Choose process grid dims for P ranks and a box of extents L (pure function, for tests): the
/// smallest total cut area among the grids that keep every subdomain at least min_width wide and
/// leave `uncut_axis` (-1: none) whole; if none leaves it whole, among all grids.
/// Returns {0,0,0} if no grid keeps every subdomain at least min_width wide.
std::array<int, 3> choose_grid(int P, const Vec3& L, double min_width, int uncut_axis = -1);

/// The axis (0, 1, 2) gravity acts along: its largest component's, -1 for no gravity.
int gravity_axis(const Vec3& g);

}  // namespace fdem
