#include "app/specimen.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <utility>

#include "io/checkpoint.hpp"
#include "base/collective_error.hpp"
#include "base/errors.hpp"

namespace fdem {

Setup reuse_specimen(const CaseConfig& c, Setup s, const std::string& path, MPI_Comm comm) {
  Checkpoint ck = read_checkpoint(path, comm, ReadPart::kShare);
  // A packing of a coupled case ends with the structure's obstacles as more walls (one per mesh
  // with interface triangles, app/packing.hpp).
  const std::size_t nw = s.walls.size();
  const std::size_t parts = c.coupling.present ? c.fem.meshes.size() : 0;
  if (ck.walls.size() < nw || ck.walls.size() > nw + parts)
    throw InputError(path, 0, "the specimen has " + std::to_string(ck.walls.size()) + " walls but case '" + c.name +
                                  "' defines " + std::to_string(nw) +
                                  (parts ? " (+ up to " + std::to_string(parts) + " for the structure while packing)" : "") +
                                  ": it was packed for another case");
  if (ck.particles_total == 0) throw InputError(path, 0, "the specimen has no particles");
  ParticleStore& p = ck.particles;
  std::optional<InputError> bad;  // in this rank's share: thrown on every rank
  for (std::size_t i = 0; i < p.size() && !bad; ++i) {
    if (p.mat[i] < 0 || p.mat[i] >= s.materials.size()) {
      bad = InputError(path, 0, "particle " + std::to_string(p.id[i]) + " uses material index " +
                                    std::to_string(p.mat[i]) + " which case '" + c.name + "' does not define");
      break;
    }
    for (int d = 0; d < 3 && !bad; ++d)
      if (p.x[i][d] < c.domain_min[d] || p.x[i][d] > c.domain_max[d])
        bad = InputError(path, 0, "particle " + std::to_string(p.id[i]) + " lies outside the case's domain in " +
                                      std::string(1, "xyz"[d]) + ": it was packed for another case");
  }
  agree_on_input_error(bad, comm);
  for (std::size_t w = 0; w < nw; ++w) {
    s.walls[w].disp = ck.walls[w].disp;
    s.walls[w].vel = Vec3{};
  }
  s.particles = std::move(ck.particles);
  s.particles.n_owned = s.particles.size();
  s.shared = true;
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

std::vector<double> place_walls_on_surface(const CaseConfig& c, Setup& s, MPI_Comm comm) {
  std::vector<double> moved;
  for (int w : c.packing.surface_walls) {
    Wall& wall = s.walls[static_cast<std::size_t>(w)];
    double gap = std::numeric_limits<double>::infinity();
    Vec3 dir;
    if (wall.kind == Wall::kPlane) {
      dir = wall.normal;
      const Vec3 p = wall.point + wall.disp;
      for (std::size_t i = 0; i < s.particles.size(); ++i)
        gap = std::min(gap, dot(s.particles.x[i] - p, dir) - s.particles.r[i]);
    } else {
      // a servo box moves along its (first) servo axis, a coordinate direction or not: its
      // leading face is the corner reaching furthest along the axis; the grains that can meet
      // it are those within a radius of its footprint across the axis (the face is a bound:
      // a grain beside the footprint meets an edge later, so nothing overlaps)
      const WallConfig& wc = c.walls[static_cast<std::size_t>(w)];
      dir = wc.motion.servo.axis;
      if (wc.motion.kind != WallMotion::kServo)
        for (const WallMotion& m : wc.schedule)
          if (m.kind == WallMotion::kServo) { dir = m.servo.axis; break; }
      const Vec3 lo = wall.bmin + wall.disp, hi = wall.bmax + wall.disp;
      double lead = -std::numeric_limits<double>::infinity();
      for (int k = 0; k < 8; ++k)
        lead = std::max(lead, dot(Vec3{(k & 1) ? hi[0] : lo[0], (k & 2) ? hi[1] : lo[1], (k & 4) ? hi[2] : lo[2]}, dir));
      for (std::size_t i = 0; i < s.particles.size(); ++i) {
        const Vec3& x = s.particles.x[i];
        const double r = s.particles.r[i];
        bool beside = false;
        for (int d = 0; d < 3; ++d)
          if (std::fabs(dir[d]) < 1 - 1e-12 && (x[d] < lo[d] - r || x[d] > hi[d] + r)) beside = true;
        if (!beside) gap = std::min(gap, dot(x, dir) - r - lead);
      }
    }
    if (s.shared) MPI_Allreduce(MPI_IN_PLACE, &gap, 1, MPI_DOUBLE, MPI_MIN, comm);  // exact
    if (!std::isfinite(gap)) gap = 0;
    wall.disp += gap * dir;  // the wall moves along dir by gap
    moved.push_back(gap);
  }
  return moved;
}

}  // namespace fdem
