#pragma once
// Checks of a case that the key table cannot make (each key may be right alone, the case wrong):
// the grains against the walls and the domain, and numbers that look like another unit. What a
// user coming from YADE or LIGGGHTS gets wrong first (a `type: box` wall written as the
// container, a flipped floor normal, density in g/cm^3, friction in degrees). `fdem check` and
// `fdem run` make the same checks.
#include <mpi.h>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "app/driver.hpp"
#include "base/errors.hpp"
#include "io/case.hpp"

namespace fdem {

/// Warnings ("file:line: warning: ..."), from the case alone: a number that looks like another
/// unit (a grain density below 100 kg/m^3: g/cm^3?; a friction above 2: degrees?; a Young's
/// modulus below 1e4 Pa: MPa?; the same for FE materials), a wall that lies wholly outside the
/// domain (no grain reaches it before leaving the domain); and the reader's own (c.warnings: a --set
/// that addresses a named list item by its position).
std::vector<std::string> case_warnings(const CaseConfig& c);

/// Per wall of c.walls (at their positions in the case): the grains whose centre lies inside a
/// box wall or behind a plane (facet walls: 0), the lowest id among them and its centre; `total`
/// the grains looked at. Local: no communication.
struct WallTally {
  std::vector<long long> count, first;
  std::vector<Vec3> where;
  long long total = 0;
};
WallTally tally_grains_in_walls(const CaseConfig& c, std::size_t n, const Vec3* x, const std::int64_t* id);
/// The error for the first wall with grains in it (the wall's line; see check_grains_in_walls).
std::optional<InputError> grains_in_walls_error(const CaseConfig& c, const WallTally& t);

/// Collective. Throws InputError (the wall's line) when grains start inside a wall: centres
/// inside a `type: box` wall (it is solid: the hint names `type: container`) or behind a plane
/// (on the far side of its normal: the hint says to flip it when most grains are there). Such a
/// grain overlaps the wall by more than its radius and the run diverges in its first steps.
/// Facet walls are sheets with two sides: not checked. Call before the first step (the walls where
/// the case puts them).
void check_grains_in_walls(const CaseConfig& c, const Setup& s, MPI_Comm comm);

}  // namespace fdem
