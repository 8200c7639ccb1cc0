#pragma once
// Laboratory tests made of walls (docs/user-guide.md#laboratory-tests): the stresses and strains
// of a direct shear box or a triaxial cell, computed from the walls' reduced forces and current
// positions, and the lab.csv file that reports them. Pure functions of the walls (replicated on
// every rank, forces already summed over ranks), so the numbers do not depend on the rank count.
//
// Sign conventions: stresses compression positive (Pa); strains compression positive.
#include <mpi.h>

#include <memory>
#include <string>
#include <vector>

#include "dem/walls.hpp"
#include "io/case.hpp"
#include "io/csv.hpp"

namespace fdem {

struct DirectShearState {
  double shear_displacement = 0;   // m: displacement of the first shear wall along the direction
  double normal_displacement = 0;  // m: the normal wall's displacement against its axis (> 0: dilation)
  double sigma_n = 0;              // Pa: -F . axis / A of the normal wall
  double tau = 0;                  // Pa: -sum F . direction / A over the shear walls
};

/// `area`: the nominal cross-section A (m^2).
DirectShearState direct_shear_state(const LabConfig& lab, const std::vector<Wall>& walls, double area);

struct TriaxialState {
  double lx = 0, ly = 0, h = 0;    // m: current gaps between the wall pairs
  double eps_a = 0, eps_v = 0;     // axial (z) and volumetric strain from the wall positions
  double sigma_x = 0, sigma_y = 0, sigma_z = 0;  // Pa: mean of the two walls of each pair
  double q = 0, p = 0;             // deviator sigma_z - (sigma_x + sigma_y)/2; mean stress
};

TriaxialState triaxial_state(const LabConfig& lab, const std::vector<Wall>& walls);

/// lab.csv: one row per history row (collective like CsvWriter; writes on rank 0).
class LabOutput {
 public:
  LabOutput(const LabConfig& lab, const std::vector<Wall>& walls, const std::string& dir, MPI_Comm comm,
            bool append, double keep_up_to);
  /// Call after the wall forces were reduced.
  void row(double step, double time, const std::vector<Wall>& walls);

 private:
  LabConfig lab_;
  double area_ = 0;
  std::unique_ptr<CsvWriter> csv_;
};

}  // namespace fdem
