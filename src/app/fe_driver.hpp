#pragma once
// The driver of pure finite-element cases (a case with `fem` and no particles): builds the
// meshes, partitions them, applies restraints, loads and prescribed displacements, and runs
// the holds (load / displacement steps) with dynamic relaxation or the static KSP solve.
#include <mpi.h>

#include <cstdint>
#include <string>
#include <vector>

#include "app/driver.hpp"
#include "fem/mesh.hpp"
#include "io/case.hpp"
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
  };
  std::vector<Part> parts;
};

/// Build all meshes of a case (identically on every rank). Throws InputError on bad meshes.
FeMeshes build_fe_meshes(const CaseConfig& c);

/// Check a pure FE case completely (meshes, sets, boundary files) and print a summary on rank 0.
void check_fe_case(const CaseConfig& c, MPI_Comm comm);

/// Run a pure FE case. Returns the exit code (0 finished, 128+signal when interrupted).
int run_fe_case(const CaseConfig& c, const RunOptions& opt, MPI_Comm comm);

}  // namespace fdem
