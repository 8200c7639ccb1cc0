// Coupled-step cost split (issue 4): a geogrid-sized FE-DE case, timed per stage.
//
//   bash scripts/mpirun.sh -n P build/bench_coupled_split [STEPS] [MASS_SCALE] [GEOMETRY]
//
// GEOMETRY `grid` (default): as below. `workstation`: the grid and box of
// cases/geogrid_pullout/workstation.yaml -- a 3 x 19-rib SS-1 slice (0.078 m wide, 0.65 m long)
// in a lattice filling 60 layers above and below it (0.62 m high, ~300 000 spheres): the
// per-step cost of that variant's coupled steps on a dense contact network.
//
// The thesis's SS-1 geogrid (cases/fem/geogrid_tension.yaml: 8 x 19 ribs, 4 mm x 0.9 mm, 1580
// Hex8, E = 2.8 GPa) embedded in a simple-cubic lattice of d = 5.1 mm spheres (E = 100 MPa,
// rho = 2640, spacing 0.999 d: every lattice neighbour in contact) filling a box 8 layers above
// and 6 below the grid, the first layers touching the grid's faces,, without the spheres that would overlap the grid by more than 2 % of r;
// the grid's clamp is held; box walls; gravity; local damping 0.2. The interface
// is the whole grid surface (tan phi = 0.95). The grid density is scaled by MASS_SCALE (default
// 1e4, dynamic relaxation: the static answer does not depend on it) so that the FE step allows
// sub-cycling; dt_DE = 0.3 x the DEM critical step (capped at 0.8 x the FE stable step, which
// includes the interface contact stiffness on the grid's nodes), n auto.
// After WARMUP steps, STEPS steps are timed. Per DEM step, per stage (max over ranks): DEM
// neighbours (incl. interface candidates), ghosts, particle contacts, walls, interface contacts,
// integration, FE update (averaging + VecAssembly reduction + FE step + position scatter),
// reductions. Per-contact costs: stage time / (candidates x steps).
#include <mpi.h>
#include <petscsys.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>
#include <ctime>

#include "app/engine.hpp"
#include "coupling/coupler.hpp"
#include "coupling/interface.hpp"
#include "dem/contact_law.hpp"
#include "fem/fe_model.hpp"
#include "fem/mesh.hpp"
#include "partition/mesh_partition.hpp"

using namespace fdem;

namespace {

// The SS-1 geogrid (as cases/fem/geogrid_tension.yaml; `workstation`: its 3-rib slice).
fem::GeogridSpec grid_spec(bool workstation) {
  fem::GeogridSpec gs;
  gs.length = 0.65; gs.width = workstation ? 0.078 : 0.27; gs.longitudinal_ribs = workstation ? 3 : 8;
  gs.transverse_ribs = 19;
  gs.rib_width = 0.004; gs.thickness = 0.0009; gs.clamp_length = 0.1; gs.clamp_gap = 0.03;
  gs.max_element_length = 0.0085;
  return gs;
}

// Element boxes (the generator's bricks are axis-aligned): min x, y, z then max x, y, z.
std::vector<std::array<double, 6>> element_boxes(const fem::Mesh& mesh) {
  std::vector<std::array<double, 6>> boxes;
  for (std::size_t e = 0; e < mesh.n_elements(); ++e) {
    std::array<double, 6> b{1e300, 1e300, 1e300, -1e300, -1e300, -1e300};
    for (std::int32_t k = mesh.elem_offset[e]; k < mesh.elem_offset[e + 1]; ++k) {
      const double* X = &mesh.coords[3 * static_cast<std::size_t>(mesh.elem_nodes[k])];
      for (int d = 0; d < 3; ++d) { b[d] = std::min(b[d], X[d]); b[3 + d] = std::max(b[3 + d], X[d]); }
    }
    boxes.push_back(b);
  }
  return boxes;
}

struct LatticeBox { double x0, x1, y0, y1, z0, z1; };

// The particles: a simple-cubic lattice (spacing s) of `layers` layers above and below the grid,
// without the spheres that would overlap an element by more than 2 % of r. `box`: the lattice's
// box (the walls).
ParticleStore lattice_particles(const fem::Mesh& mesh, const fem::GeogridSpec& gs, int layers, double r, double rho,
                                double s, LatticeBox& box) {
  const double gz0 = 0.0, gz1 = gs.thickness;
  const std::vector<std::array<double, 6>> boxes = element_boxes(mesh);
  const double x0 = -0.01, x1 = gs.length + 0.01, y0 = -0.01, y1 = gs.width + 0.01;
  // Layers touching the grid's faces (overlap 1 % of r), then every s above and below.
  std::vector<double> zs;
  for (int k = 0; k < layers; ++k) { zs.push_back(gz1 + 0.99 * r + k * s); zs.push_back(gz0 - 0.99 * r - k * s); }
  std::sort(zs.begin(), zs.end());
  box = LatticeBox{x0, x1, y0, y1, zs.front() - r, zs.back() + r};
  const int nx = static_cast<int>((x1 - x0 - 2 * r) / s) + 1, ny = static_cast<int>((y1 - y0 - 2 * r) / s) + 1;
  ParticleStore all;
  std::int64_t id = 0;
  for (double z : zs)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        const double x = x0 + r + i * s, y = y0 + r + j * s;
        bool keep = true;
        for (const auto& b : boxes) {
          double d2 = 0;
          const double p[3] = {x, y, z};
          for (int d = 0; d < 3; ++d) {
            const double q = std::clamp(p[d], b[d], b[3 + d]);
            d2 += (p[d] - q) * (p[d] - q);
          }
          if (d2 < 0.98 * 0.98 * r * r) { keep = false; break; }
        }
        if (keep) all.push_back({x, y, z}, {}, {}, r, sphere_mass(rho, r), id++, 0, 0, {x, y, z});
      }
  all.n_owned = all.size();
  return all;
}

std::vector<Wall> box_walls(const LatticeBox& b) {
  std::vector<Wall> walls;
  auto plane = [&](const char* name, Vec3 p, Vec3 n) {
    Wall w;
    w.kind = Wall::kPlane; w.name = name; w.point = p; w.normal = n; w.mat = 0;
    walls.push_back(w);
  };
  plane("xmin", {b.x0, 0, 0}, {1, 0, 0}); plane("xmax", {b.x1, 0, 0}, {-1, 0, 0});
  plane("ymin", {0, b.y0, 0}, {0, 1, 0}); plane("ymax", {0, b.y1, 0}, {0, -1, 0});
  plane("zmin", {0, 0, b.z0}, {0, 0, 1}); plane("zmax", {0, 0, b.z1}, {0, 0, -1});
  return walls;
}

// What the report gives besides the timings.
struct RunInfo {
  int size, steps;
  std::size_t n_elements;
  double dt, dt_dem_cr, dt_fe, mass_scale;
};

// The timed steps' figures: wall time, interface candidates (rank sum, per step), contacts, and
// per step per stage the max and sum over ranks (stages, then the coupler's reduce, FE step,
// scatter and contacts); on rank 0.
struct Figures {
  double wall = 0, cif_g = 0;
  EngineStats st;
  std::int64_t active_if = 0;
  std::vector<double> mx, sum;
};

// STEPS timed steps (after the warm-up) and their figures.
Figures timed_steps(DemEngine& eng, coupling::Coupler& cpl, int steps) {
  Figures fg;
  const auto t0 = eng.timings();
  const coupling::CouplerTimings c0 = cpl.timings();
  double cand_if = 0;
  MPI_Barrier(MPI_COMM_WORLD);
  const double w0 = MPI_Wtime();
  for (int k = 0; k < steps; ++k) {
    eng.step();
    cand_if += static_cast<double>(cpl.n_candidates());
  }
  MPI_Barrier(MPI_COMM_WORLD);
  fg.wall = MPI_Wtime() - w0;
  const auto t1 = eng.timings();
  const coupling::CouplerTimings c1 = cpl.timings();
  fg.st = eng.stats();
  fg.active_if = cpl.global_active();
  // Stage times per step, max over ranks.
  const int ns = static_cast<int>(Stage::kCount);
  std::vector<double> loc(ns + 4);
  fg.mx.resize(ns + 4);
  fg.sum.resize(ns + 4);
  for (int i = 0; i < ns; ++i) loc[i] = (t1[i] - t0[i]) / steps;
  loc[ns + 0] = (c1.reduce - c0.reduce) / steps;
  loc[ns + 1] = (c1.fe - c0.fe) / steps;
  loc[ns + 2] = (c1.scatter - c0.scatter) / steps;
  loc[ns + 3] = (c1.contacts - c0.contacts) / steps;
  MPI_Reduce(loc.data(), fg.mx.data(), ns + 4, MPI_DOUBLE, MPI_MAX, 0, MPI_COMM_WORLD);
  MPI_Reduce(loc.data(), fg.sum.data(), ns + 4, MPI_DOUBLE, MPI_SUM, 0, MPI_COMM_WORLD);
  double cif = cand_if / steps;
  MPI_Reduce(&cif, &fg.cif_g, 1, MPI_DOUBLE, MPI_SUM, 0, MPI_COMM_WORLD);
  return fg;
}

void print_report(const RunInfo& ri, const Figures& fg, const coupling::Coupler& cpl) {
  const int ns = static_cast<int>(Stage::kCount), steps = ri.steps;
  const EngineStats& st = fg.st;
  const std::vector<double>& mx = fg.mx;
  const std::int64_t active_if = fg.active_if;
  const double wall = fg.wall, cif_g = fg.cif_g;
  std::printf("coupled split: %d rank(s), %lld particles, %zu Hex8, %zu interface triangles, %d timed steps\n",
              ri.size, static_cast<long long>(st.particles), ri.n_elements, cpl.n_triangles(), steps);
  std::printf("dt_DE %.3e s (DEM critical %.3e, FE stable x0.8 %.3e), subcycle n = %d, mass scale %.0e\n", ri.dt,
              ri.dt_dem_cr, ri.dt_fe, cpl.subcycle(), ri.mass_scale);
  std::printf("contacts: particle-particle %lld, walls %lld, interface %lld (interface candidates %.0f)\n",
              static_cast<long long>(st.contacts), static_cast<long long>(st.wall_contacts),
              static_cast<long long>(active_if), cif_g);
  std::printf("wall time %.3f s, %.3f ms per DEM step, %.3e particle-steps/s\n", wall, 1e3 * wall / steps,
              static_cast<double>(st.particles) * steps / wall);
  std::printf("%-22s %12s %12s\n", "stage (per DEM step)", "max rank ms", "share");
  double tot = 0;
  for (int i = 0; i < ns; ++i) tot += mx[i];
  for (int i = 0; i < ns; ++i)
    std::printf("%-22s %12.4f %11.1f%%\n", stage_name(static_cast<Stage>(i)), 1e3 * mx[i], 100 * mx[i] / tot);
  std::printf("  of which fe_update:    reduce %.4f ms, FE step %.4f ms, scatter %.4f ms (per DEM step)\n",
              1e3 * mx[ns], 1e3 * mx[ns + 1], 1e3 * mx[ns + 2]);
  const double pp = fg.sum[static_cast<int>(Stage::kContacts)], ii = fg.sum[static_cast<int>(Stage::kInterface)];
  std::printf("per contact per step (rank sums): particle-particle %.1f ns (%lld contacts), interface %.1f ns "
              "(%lld contacts), ratio interface/particle %.2f\n",
              1e9 * pp / std::max<double>(1, st.contacts), static_cast<long long>(st.contacts),
              1e9 * ii / std::max<double>(1, active_if), static_cast<long long>(active_if),
              (ii / std::max<double>(1, active_if)) / (pp / std::max<double>(1, st.contacts)));
  std::printf("interface per candidate per step (rank sums): %.1f ns (%.0f candidates)\n",
              1e9 * ii / std::max(1.0, cif_g), cif_g);
  std::printf("FE: %.3e element updates/s (FE step time only)\n",
              ri.n_elements / (mx[ns + 1] * cpl.subcycle()));
}

// Developer probe (FDEM_IFACE_REPEAT=K, e.g. `FDEM_IFACE_REPEAT=200 bash scripts/mpirun.sh
// -n 1 -x FDEM_IFACE_REPEAT build/bench_coupled_split 20`): the interface stage alone, K
// times on the last step's particles, with 64 MB streamed through the caches before each
// call (as the particle stage evicts the interface data); CPU time, so a busy machine
// distorts it less than the wall-clock stages. Changes the coupler's state: after the report.
void interface_repeat_probe(const char* rep, DemEngine& eng, coupling::Coupler& cpl, const MaterialTable& mats,
                            double dt, int rank) {
  const int nrep = std::max(1, std::atoi(rep));
  std::vector<double> junk(8 << 20, 1.0);
  double sink = 0, tsum = 0;
  ParticleStore& ps = eng.particles();
  for (int k = 0; k < nrep; ++k) {
    if (!std::getenv("FDEM_IFACE_WARM"))
      for (std::size_t j = 0; j < junk.size(); j += 8) sink += junk[j]++;
    timespec a, b;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &a);
    cpl.compute(ps, mats, dt);
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &b);
    tsum += (b.tv_sec - a.tv_sec) + 1e-9 * (b.tv_nsec - a.tv_nsec);
  }
  double tmax = 0;
  MPI_Reduce(&tsum, &tmax, 1, MPI_DOUBLE, MPI_MAX, 0, MPI_COMM_WORLD);
  if (rank == 0)
    std::printf("interface stage alone (cold caches, CPU time, slowest rank): %.4f ms per call (%d calls)%s\n",
                1e3 * tmax / nrep, nrep, sink > 0 ? "" : " ");
}

}  // namespace

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  PetscOptionsSetValue(nullptr, "-no_signal_handler", nullptr);
  PetscInitializeNoArguments();
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  const int steps = argc > 1 ? std::atoi(argv[1]) : 1000;
  const double mass_scale = argc > 2 ? std::atof(argv[2]) : 1e4;
  const bool workstation = argc > 3 && std::string(argv[3]) == "workstation";
  const int warmup = 200;
  {
    // --- the geogrid (as cases/fem/geogrid_tension.yaml) ---
    const fem::GeogridSpec gs = grid_spec(workstation);
    fem::Mesh mesh = fem::make_geogrid(gs);
    fem::FePartition part = partition_mesh(mesh, size);
    fem::FeMaterial fm;
    fm.young = 2.8e9; fm.poisson = 0.3; fm.density = 950 * mass_scale;
    fem::FeModel model(MPI_COMM_WORLD, mesh, part, {fm});
    for (std::int32_t n : mesh.node_sets.at("clamp")) model.restrain(n, {true, true, true});
    const std::vector<coupling::InterfaceTriangle> tris = coupling::make_interface(mesh, "");

    // --- the particles: a simple-cubic lattice around the grid ---
    const double r = 0.00255, rho = 2640, s = 0.999 * 2 * r;
    LatticeBox box;
    ParticleStore all = lattice_particles(mesh, gs, workstation ? 60 : 6, r, rho, s, box);
    Material soil;
    soil.name = "soil"; soil.young = 1e8; soil.density = rho; soil.friction = 0.54; soil.kt_kn = 0.1;
    soil.rolling_stiffness = 0.05; soil.rolling_limit = 1.0;
    Material iface = soil;
    iface.name = "interface"; iface.friction = 0.95;
    MaterialTable mats({soil, iface});
    const std::vector<Wall> walls = box_walls(box);
    EngineParams ep;
    ep.domain_min = {box.x0 - 0.01, box.y0 - 0.01, box.z0 - 0.01};
    ep.domain_max = {box.x1 + 0.01, box.y1 + 0.01, box.z1 + 0.01};
    ep.gravity = {0, 0, -9.81};
    ep.damping = 0.2;
    const double dt_dem_cr = critical_dt(all, mats);
    // FE stable step with the interface contact stiffness (as the coupled driver does).
    const double k_if = normal_stiffness(soil.young, r, iface.young, r);
    const double dt_fe = 0.8 * model.critical_dt(coupling::interface_nodes(tris), k_if);
    ep.dt = std::min(0.3 * dt_dem_cr, dt_fe);
    coupling::CouplerParams cp;
    cp.material = 1;
    cp.subcycle = coupling::Coupler::auto_subcycle(dt_fe, ep.dt);
    coupling::Coupler cpl(MPI_COMM_WORLD, mesh, model, tris, cp, ep.dt);
    DemEngine eng(MPI_COMM_WORLD, ep, mats, walls, all);
    eng.attach(&cpl);

    eng.run(warmup);
    const Figures fg = timed_steps(eng, cpl, steps);
    if (rank == 0) print_report(RunInfo{size, steps, mesh.n_elements(), ep.dt, dt_dem_cr, dt_fe, mass_scale}, fg, cpl);
    if (const char* rep = std::getenv("FDEM_IFACE_REPEAT")) interface_repeat_probe(rep, eng, cpl, mats, ep.dt, rank);
  }
  PetscFinalize();
  MPI_Finalize();
  return 0;
}
