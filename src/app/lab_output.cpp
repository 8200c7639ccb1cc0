#include "app/lab_output.hpp"

#include <cmath>

namespace fdem {

namespace {

/// A servo wall's nominal area: its current servo parameters, else the first servo phase's.
double servo_area(const Wall& w) {
  if (w.servo.area > 0) return w.servo.area;
  for (const WallPhase& ph : w.schedule)
    if (ph.motion == Wall::kServo && ph.servo.area > 0) return ph.servo.area;
  return 0;
}

Vec3 servo_axis(const Wall& w) {
  if (w.motion == Wall::kServo || w.schedule.empty()) return w.servo.axis;
  for (const WallPhase& ph : w.schedule)
    if (ph.motion == Wall::kServo) return ph.servo.axis;
  return w.servo.axis;
}

/// Compressive stress on a plane wall: -F . n over the area.
double wall_stress(const Wall& w, double area) { return area > 0 ? -dot(w.force, w.normal) / area : 0.0; }

Wall at_start(Wall w) { w.disp = Vec3{}; return w; }

}  // namespace

DirectShearState direct_shear_state(const LabConfig& lab, const std::vector<Wall>& walls, double area) {
  DirectShearState s;
  const Wall& nw = walls[lab.normal_wall];
  const Vec3 axis = servo_axis(nw);
  s.shear_displacement = dot(walls[lab.shear_walls.front()].disp, lab.direction);
  s.normal_displacement = -dot(nw.disp, axis);
  if (area > 0) {
    s.sigma_n = -dot(nw.force, axis) / area;
    double fs = 0;
    for (int w : lab.shear_walls) fs += dot(walls[w].force, lab.direction);
    s.tau = -fs / area;
  }
  return s;
}

TriaxialState triaxial_state(const LabConfig& lab, const std::vector<Wall>& walls) {
  TriaxialState s;
  const auto& b = lab.box;
  const Wall& x0 = walls[b[0]]; const Wall& x1 = walls[b[1]];
  const Wall& y0 = walls[b[2]]; const Wall& y1 = walls[b[3]];
  const Wall& z0 = walls[b[4]]; const Wall& z1 = walls[b[5]];
  s.lx = plane_gap(x0, x1);
  s.ly = plane_gap(y0, y1);
  s.h = plane_gap(z0, z1);
  const double lx0 = plane_gap(at_start(x0), at_start(x1)), ly0 = plane_gap(at_start(y0), at_start(y1));
  const double h0 = plane_gap(at_start(z0), at_start(z1));
  s.eps_a = (h0 - s.h) / h0;
  s.eps_v = (lx0 * ly0 * h0 - s.lx * s.ly * s.h) / (lx0 * ly0 * h0);
  s.sigma_x = 0.5 * (wall_stress(x0, s.ly * s.h) + wall_stress(x1, s.ly * s.h));
  s.sigma_y = 0.5 * (wall_stress(y0, s.lx * s.h) + wall_stress(y1, s.lx * s.h));
  s.sigma_z = 0.5 * (wall_stress(z0, s.lx * s.ly) + wall_stress(z1, s.lx * s.ly));
  s.q = s.sigma_z - 0.5 * (s.sigma_x + s.sigma_y);
  s.p = (s.sigma_x + s.sigma_y + s.sigma_z) / 3.0;
  return s;
}

LabOutput::LabOutput(const LabConfig& lab, const std::vector<Wall>& walls, const std::string& dir, MPI_Comm comm,
                     bool append, double keep_up_to)
    : lab_(lab) {
  std::vector<std::string> cols{"step", "time"};
  if (lab.kind == LabConfig::kDirectShear) {
    area_ = lab.area > 0 ? lab.area : servo_area(walls[lab.normal_wall]);
    for (const char* c : {"shear_displacement", "normal_displacement", "sigma_n", "tau", "tau_over_sigma_n"}) cols.push_back(c);
  } else {
    for (const char* c : {"eps_a", "eps_v", "sigma_x", "sigma_y", "sigma_z", "q", "p", "lx", "ly", "h"}) cols.push_back(c);
  }
  csv_ = std::make_unique<CsvWriter>(dir + "/lab.csv", cols, comm, append, keep_up_to);
}

void LabOutput::row(double step, double time, const std::vector<Wall>& walls) {
  if (lab_.kind == LabConfig::kDirectShear) {
    const DirectShearState s = direct_shear_state(lab_, walls, area_);
    csv_->row({step, time, s.shear_displacement, s.normal_displacement, s.sigma_n, s.tau,
               s.sigma_n > 0 ? s.tau / s.sigma_n : 0.0});
  } else {
    const TriaxialState s = triaxial_state(lab_, walls);
    csv_->row({step, time, s.eps_a, s.eps_v, s.sigma_x, s.sigma_y, s.sigma_z, s.q, s.p, s.lx, s.ly, s.h});
  }
}

}  // namespace fdem
