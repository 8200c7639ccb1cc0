#include "app/specimen.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "io/checkpoint.hpp"
#include "io/errors.hpp"

namespace fdem {

Setup reuse_specimen(const CaseConfig& c, Setup s, const std::string& path, MPI_Comm comm) {
  Checkpoint ck = read_checkpoint(path, comm);
  // A packing of a coupled case ends with the structure's obstacle as one more wall.
  const std::size_t nw = s.walls.size();
  const bool with_structure = ck.walls.size() == nw + 1;
  if (ck.walls.size() != nw && !(with_structure && c.coupling.present))
    throw InputError(path, 0, "the specimen has " + std::to_string(ck.walls.size()) + " walls but case '" + c.name +
                                  "' defines " + std::to_string(nw) +
                                  (c.coupling.present ? " (+1 for the structure while packing)" : "") +
                                  ": it was packed for another case");
  if (ck.particles.size() == 0) throw InputError(path, 0, "the specimen has no particles");
  ParticleStore& p = ck.particles;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (p.mat[i] < 0 || p.mat[i] >= s.materials.size())
      throw InputError(path, 0, "particle " + std::to_string(p.id[i]) + " uses material index " +
                                    std::to_string(p.mat[i]) + " which case '" + c.name + "' does not define");
    for (int d = 0; d < 3; ++d)
      if (p.x[i][d] < c.domain_min[d] || p.x[i][d] > c.domain_max[d])
        throw InputError(path, 0, "particle " + std::to_string(p.id[i]) + " lies outside the case's domain in " +
                                      std::string(1, "xyz"[d]) + ": it was packed for another case");
  }
  for (std::size_t w = 0; w < nw; ++w) {
    s.walls[w].disp = ck.walls[w].disp;
    s.walls[w].vel = Vec3{};
  }
  s.particles = std::move(ck.particles);
  s.particles.n_owned = s.particles.size();
  for (std::size_t i = 0; i < s.particles.size(); ++i) s.particles.x0[i] = s.particles.x[i];
  s.history.clear();
  for (const ContactRecord& rec : ck.contacts)
    if (!(rec.kind == 1 && rec.b >= static_cast<std::int64_t>(nw))) s.history.push_back(rec);
  s.wall_vel.clear();
  s.step = 0;
  s.time = 0;
  s.restarted = false;
  return s;
}

std::vector<double> place_walls_on_surface(const CaseConfig& c, Setup& s) {
  std::vector<double> moved;
  for (int w : c.packing.surface_walls) {
    Wall& wall = s.walls[static_cast<std::size_t>(w)];
    const Vec3 p = wall.point + wall.disp;
    double gap = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < s.particles.size(); ++i)
      gap = std::min(gap, dot(s.particles.x[i] - p, wall.normal) - s.particles.r[i]);
    if (!std::isfinite(gap)) gap = 0;
    wall.disp += gap * wall.normal;  // the wall's point moves along its normal by gap
    moved.push_back(gap);
  }
  return moved;
}

}  // namespace fdem
