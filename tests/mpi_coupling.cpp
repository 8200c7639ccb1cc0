// fdem-test-ranks: 1 2 3
// FE-DE coupling (DESIGN.md 3 and 4.4): interface contacts, the cross-rank force reduction, the
// sub-cycled FE update. Particles and the plate's partition are both split across the ranks.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>

#include "coupling/coupler.hpp"
#include "coupling/interface.hpp"
#include "fem/fe_model.hpp"
#include "fem/mesh.hpp"
#include "io/case_file.hpp"
#include "partition/mesh_partition.hpp"
#include "support/dem_fixtures.hpp"
#include "support/mpi_util.hpp"

using namespace fdem;
using namespace fdem::testing;
using fdem::coupling::Coupler;
using fdem::coupling::CouplerParams;

namespace {

const double kG = 9.81;
const double kR = 0.01, kRho = 2650, kE = 1e7;  // DEM spheres

// A 0.2 x 0.2 x 0.01 m Hex8 plate (8 x 8 x 1) with its four sides clamped; the interface is its
// top face ("zmax", quads split around their centres). rho_fe is mass-scaled (1e5) so that the
// FE stable step allows sub-cycling; the static answer does not depend on it.
struct Rig {
  fem::Mesh mesh;
  fem::FePartition part;
  std::unique_ptr<fem::FeModel> model;
  std::unique_ptr<Coupler> cpl;
  std::unique_ptr<DemEngine> eng;
  double dt = 0;

  Rig(MPI_Comm comm, const ParticleStore& p, int subcycle, bool rigid, double damping = 0.7, double mu = 0.5,
      int nxy = 8, double e_fe = 1e8, double jitter = 0, const MaterialTable* table = nullptr, int iface = 1) {
    int size = 1;
    MPI_Comm_size(comm, &size);
    mesh = fem::make_block({0, 0, 0}, {0.2, 0.2, 0.01}, nxy, nxy, 1);
    if (jitter > 0) {
      // Move the interior columns of nodes in x and y only: the top stays one flat plane.
      for (std::size_t n = 0; n < mesh.n_nodes(); ++n) {
        double* X = &mesh.coords[3 * n];
        const double h = 0.2 / nxy;
        const int i = static_cast<int>(std::lround(X[0] / h)), j = static_cast<int>(std::lround(X[1] / h));
        if (i == 0 || j == 0 || i == nxy || j == nxy) continue;
        X[0] += jitter * h * std::sin(7.3 * i + 3.1 * j);
        X[1] += jitter * h * std::cos(5.7 * i - 2.3 * j);
      }
    }
    part = partition_mesh(mesh, size);
    fem::FeMaterial fm;
    fm.young = e_fe; fm.poisson = 0.3; fm.density = 1e5;
    model = std::make_unique<fem::FeModel>(comm, mesh, part, std::vector<fem::FeMaterial>{fm});
    for (const char* side : {"xmin", "xmax", "ymin", "ymax"})
      for (std::int32_t n : mesh.node_sets.at(side)) model->restrain(n, {true, true, true});
    // Rolling resistance (thesis: beta_r, eta_r): spheres on a deflected plate would otherwise
    // roll down its slopes for ever and a bed would never come to rest.
    const double br = mu > 0 ? 0.5 : 0.0, er = mu > 0 ? 1.0 : 0.0;
    MaterialTable mats({make_material("sand", kE, kRho, mu, 0.25, br, er), make_material("iface", kE, kRho, mu, 0.25, br, er)});
    if (table) mats = *table;  // a case's materials (the particles carry their material index)
    EngineParams e;
    e.domain_min = {0, 0, -0.02}; e.domain_max = {0.2, 0.2, 0.1};
    e.gravity = {0, 0, -kG}; e.damping = damping;
    dt = 1e-5;
    e.dt = dt;
    CouplerParams cp;
    cp.material = iface; cp.subcycle = subcycle; cp.rigid = rigid;
    cpl = std::make_unique<Coupler>(comm, mesh, *model, coupling::make_interface(mesh, "zmax"), cp, dt);
    eng = std::make_unique<DemEngine>(comm, e, mats, std::vector<Wall>{}, p);
    eng->attach(cpl.get());
  }
  /// Largest |u_z| of the plate (all ranks).
  double max_deflection() const {
    const std::vector<double> u = model->gather_displacements();
    double m = 0;
    for (std::size_t k = 2; k < u.size(); k += 3) m = std::max(m, std::abs(u[k]));
    return m;
  }
};

ParticleStore one_sphere(double x = 0.1, double y = 0.1) {
  ParticleStore p;
  add_sphere(p, 0, {x, y, 0.01 + kR + 2e-4}, kR, kRho);
  return p;
}

// A two-layer bed: 5 x 5 touching spheres (square packing) on the plate, 4 x 4 in their hollows.
ParticleStore bed() {
  ParticleStore p;
  std::int64_t id = 0;
  const double s = 2 * kR;
  for (int j = 0; j < 5; ++j)
    for (int i = 0; i < 5; ++i) add_sphere(p, id++, {0.06 + s * i, 0.06 + s * j, 0.01 + kR + 1e-4}, kR, kRho);
  // Upper layer: resting on four lower spheres (centre distance 2r).
  const double hz = std::sqrt(4 * kR * kR - 2 * (s / 2) * (s / 2));
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 4; ++i)
      add_sphere(p, id++, {0.06 + s * (i + 0.5), 0.06 + s * (j + 0.5), 0.01 + kR + hz + 2e-4}, kR, kRho);
  return p;
}

Vec3 allsum(const Vec3& v, MPI_Comm comm) {
  double l[3] = {v.x, v.y, v.z}, g[3];
  MPI_Allreduce(l, g, 3, MPI_DOUBLE, MPI_SUM, comm);
  return {g[0], g[1], g[2]};
}

int world_rank() {
  int r = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &r);
  return r;
}

}  // namespace

// A sphere resting on the clamped plate: the interface nodal forces sum to its weight, and the
// plate's deflection is the KSP static solution under the same nodal forces.
TEST(Coupling, SphereRestingOnClampedPlate) {
  Rig rig(MPI_COMM_WORLD, one_sphere(), 1, false);
  const double W = sphere_mass(kRho, kR) * kG;
  rig.eng->run(40000);
  const Vec3 f = rig.cpl->last_update_force();
  const auto tot = rig.model->interface_force_total();
  const double unb = rig.model->unbalanced();
  const double defl = rig.max_deflection();
  if (world_rank() == 0)
    std::printf("sphere on plate: interface force %.15e N, weight %.15e N (rel %.2e), FE unbalanced %.2e, "
                "deflection %.4e m\n", -f.z, W, std::abs(-f.z / W - 1), unb, defl);
  EXPECT_NEAR(-f.z / W, 1.0, 1e-10);
  EXPECT_NEAR(f.x / W, 0.0, 1e-10);
  EXPECT_NEAR(f.y / W, 0.0, 1e-10);
  EXPECT_NEAR(tot[2], f.z, 1e-12 * W);
  ASSERT_GT(defl, 1e-7);
  // The same plate, static KSP solve under the converged interface forces.
  fem::FeMaterial fm;
  fm.young = 1e8; fm.poisson = 0.3; fm.density = 1e5;
  fem::FeModel st(MPI_COMM_WORLD, rig.mesh, rig.part, {fm});
  for (const char* side : {"xmin", "xmax", "ymin", "ymax"})
    for (std::int32_t n : rig.mesh.node_sets.at(side)) st.restrain(n, {true, true, true});
  std::vector<PetscInt> g;
  for (std::size_t i = 0; i < rig.model->n_owned(); ++i) g.push_back(rig.model->local_global_numbers()[i]);
  st.set_interface_forces(g, rig.model->owned_interface_forces());
  st.solve_static();
  const std::vector<double> us = st.gather_displacements(), ud = rig.model->gather_displacements();
  double num = 0, den = 0;
  for (std::size_t k = 0; k < us.size(); ++k) { num += (ud[k] - us[k]) * (ud[k] - us[k]); den += us[k] * us[k]; }
  const double rel = std::sqrt(num / den);
  if (world_rank() == 0) std::printf("coupled plate vs KSP: relative difference %.3e\n", rel);
  EXPECT_LT(rel, 1e-4);
}

// Newton's third law at every step: the nodal forces given to the FE and the forces applied to
// the particles cancel (over all ranks); the FE receives the sub-cycle average (impulse).
TEST(Coupling, NewtonAndImpulseEveryStep) {
  const int n = 10;
  Rig rig(MPI_COMM_WORLD, bed(), n, false);
  MPI_Comm comm = MPI_COMM_WORLD;
  Vec3 sub_sum;
  double worst_newton = 0, worst_impulse = 0, fmax = 0;
  int updates = 0;
  for (int k = 0; k < 3000; ++k) {
    rig.eng->step();
    const Vec3 fn = allsum(rig.cpl->step_nodal_force(), comm), fp = allsum(rig.cpl->step_particle_force(), comm);
    const double scale = std::max(norm(fn), 1e-300);
    fmax = std::max(fmax, norm(fn));
    if (norm(fn) > 0) worst_newton = std::max(worst_newton, norm(fn + fp) / scale);
    sub_sum += fn;
    if (rig.eng->step_count() % n == 0) {
      const Vec3 avg = (1.0 / n) * sub_sum;
      const Vec3 got = rig.cpl->last_update_force();
      ASSERT_EQ(rig.cpl->last_update_substeps(), n);
      if (norm(avg) > 0) worst_impulse = std::max(worst_impulse, norm(got - avg) / norm(avg));
      sub_sum = Vec3{};
      ++updates;
    }
  }
  if (world_rank() == 0)
    std::printf("Newton: worst |sum F_nodes + sum F_particles| / |sum F_nodes| = %.2e; impulse: worst %.2e over %d "
                "sub-cycles; largest interface force %.3e N\n", worst_newton, worst_impulse, updates, fmax);
  ASSERT_GT(fmax, 0.0);
  EXPECT_LT(worst_newton, 1e-12);
  EXPECT_LT(worst_impulse, 1e-12);
  EXPECT_EQ(updates, 300);
}

// A sphere sliding at a fixed height over a flat plate made of many (distorted) triangles,
// straight and diagonally, through edges, nodes and quad centres: the normal force stays
// k_n delta and there is no tangential force (frictionless).
TEST(Coupling, SmoothNormalForceAcrossTriangles) {
  const double delta = 1e-5;
  const double kn = normal_stiffness(kE, kR, kE, kR);
  for (const Vec3& vel : {Vec3{5, 0, 0}, Vec3{5, 5, 0}, Vec3{3, 5, 0}}) {
    ParticleStore p;
    add_sphere(p, 0, {0.03, 0.025, 0.01 + kR - delta}, kR, kRho, 0, vel, kDofAll);
    Rig rig(MPI_COMM_WORLD, p, 1, true, 0.0, 0.0, 8, 1e8, 0.2);
    double fmin = 1e300, fmax = -1e300, ft = 0;
    for (int k = 0; k < 2000; ++k) {
      rig.eng->step();
      const Vec3 f = allsum(rig.cpl->step_particle_force(), MPI_COMM_WORLD);
      fmin = std::min(fmin, f.z);
      fmax = std::max(fmax, f.z);
      ft = std::max(ft, std::hypot(f.x, f.y));
    }
    if (world_rank() == 0)
      std::printf("sliding (%.1f, %.1f): F_z in [%.12e, %.12e] x k_n delta, |F_t| <= %.1e k_n delta\n", vel.x, vel.y,
                  fmin / (kn * delta), fmax / (kn * delta), ft / (kn * delta));
    EXPECT_NEAR(fmin / (kn * delta), 1.0, 1e-9);
    EXPECT_NEAR(fmax / (kn * delta), 1.0, 1e-9);
    EXPECT_LT(ft, 1e-9 * kn * delta);
  }
}

// A sphere dragged with friction at a fixed height and a slow fixed velocity over the distorted
// triangulated plate, through edges, nodes and quad centres: once the tangential spring has built
// up, the friction force stays at the Coulomb limit mu k_n delta, opposite to the motion -- the
// contact's history carries over when the sphere moves on to the next triangle of the flat
// surface instead of restarting from zero there (which would make the friction drop at every
// triangle edge).
TEST(Coupling, SlidingFrictionCarriesAcrossTriangles) {
  const double delta = 1e-5, mu = 0.5;
  const double kn = normal_stiffness(kE, kR, kE, kR);
  for (const Vec3& dir : {Vec3{1, 0, 0}, Vec3{0.6, 0.8, 0}, Vec3{0.8, 0.6, 0}}) {
    const double v = 0.5;  // 5e-6 m per step: the spring (mu k_n delta / k_t = 2e-5 m) needs 4 steps
    ParticleStore p;
    add_sphere(p, 0, {0.03, 0.025, 0.01 + kR - delta}, kR, kRho, 0, v * dir, kDofAll);
    Rig rig(MPI_COMM_WORLD, p, 1, true, 0.0, mu, 8, 1e8, 0.2);
    double tmin = 1e300, tmax = -1e300, along = 1e300;
    for (int k = 0; k < 24000; ++k) {  // 0.12 m: over 4 to 5 quads (8 to 10 triangles) of the plate
      rig.eng->step();
      const Vec3 f = allsum(rig.cpl->step_particle_force(), MPI_COMM_WORLD);
      if (k < 20) continue;
      const double ft = std::hypot(f.x, f.y);
      tmin = std::min(tmin, ft);
      tmax = std::max(tmax, ft);
      along = std::min(along, -dot(f, dir) / ft);  // 1: exactly against the motion
    }
    if (world_rank() == 0)
      std::printf("friction (%.1f, %.1f): |F_t| in [%.12f, %.12f] x mu k_n delta, direction cos >= %.12f\n", dir.x,
                  dir.y, tmin / (mu * kn * delta), tmax / (mu * kn * delta), along);
    EXPECT_NEAR(tmin / (mu * kn * delta), 1.0, 1e-9);
    EXPECT_NEAR(tmax / (mu * kn * delta), 1.0, 1e-9);
    EXPECT_GT(along, 1 - 1e-9);
  }
}

// The pullout cases' interface (thesis Table 4-1, section 4.4: tan phi = 0.95 between the grains
// and the grid): a grain of the case's soil material dragged along the plate made of the case's
// interface material, with the case's pair table (`interactions`), feels |F_t| = 0.95 F_N.
TEST(Coupling, PulloutCasesInterfaceFriction) {
  const char* src = std::getenv("FDEM_SOURCE_DIR");
  ASSERT_NE(src, nullptr);
  for (const char* name : {"ci", "slice_ci", "slice", "workstation", "full"}) {
    const CaseConfig c = read_case(std::string(src) + "/cases/geogrid_pullout/" + name + ".yaml");
    ASSERT_TRUE(c.coupling.present);
    const MaterialTable table(c.materials, c.interactions);
    const int grain = c.packing.material, iface = c.coupling.material;
    const double delta = 1e-5, v = 0.5;
    ParticleStore p;
    add_sphere(p, 0, {0.03, 0.025, 0.01 + kR - delta}, kR, kRho, grain, v * Vec3{1, 0, 0}, kDofAll);
    Rig rig(MPI_COMM_WORLD, p, 1, true, 0.0, 0.0, 8, 1e8, 0.2, &table, iface);
    double rmin = 1e300, rmax = -1e300;
    for (int k = 0; k < 4000; ++k) {
      rig.eng->step();
      const Vec3 f = allsum(rig.cpl->step_particle_force(), MPI_COMM_WORLD);
      if (k < 200) continue;  // the tangential spring builds up
      const double ratio = std::hypot(f.x, f.y) / f.z;
      rmin = std::min(rmin, ratio);
      rmax = std::max(rmax, ratio);
    }
    if (world_rank() == 0)
      std::printf("%s: grain '%s' on interface '%s': |F_t| / F_N in [%.12f, %.12f]\n", name,
                  c.materials[grain].name.c_str(), c.materials[iface].name.c_str(), rmin, rmax);
    EXPECT_NEAR(rmin, 0.95, 1e-9);
    EXPECT_NEAR(rmax, 0.95, 1e-9);
  }
}

// A sphere rolling (v = omega r, friction and rolling resistance on) under gravity across the
// distorted triangulated plate, started at its equilibrium overlap: the normal force stays m g.
TEST(Coupling, RollingSphereFeelsItsWeightOnly) {
  const double m = sphere_mass(kRho, kR), W = m * kG;
  const double kn = normal_stiffness(kE, kR, kE, kR);
  for (const Vec3& dir : {Vec3{1, 0, 0}, Vec3{0.6, 0.8, 0}}) {
    const double v = 2.0;
    ParticleStore p;
    add_sphere(p, 0, {0.03, 0.03, 0.01 + kR - W / kn}, kR, kRho, 0, v * dir);
    p.w[0] = (v / kR) * cross(Vec3{0, 0, 1}, dir);
    Rig rig(MPI_COMM_WORLD, p, 1, true, 0.0, 0.5, 8, 1e8, 0.2);
    double fmin = 1e300, fmax = -1e300;
    for (int k = 0; k < 6000; ++k) {
      rig.eng->step();
      const Vec3 f = allsum(rig.cpl->step_particle_force(), MPI_COMM_WORLD);
      fmin = std::min(fmin, f.z);
      fmax = std::max(fmax, f.z);
    }
    const Gathered g = gather(*rig.eng);
    if (world_rank() == 0)
      std::printf("rolling (%.1f, %.1f): F_z in [%.10f, %.10f] x m g, travelled %.3f m\n", dir.x, dir.y, fmin / W,
                  fmax / W, norm(g.x[0] - Vec3{0.03, 0.03, g.x[0].z}));
    EXPECT_NEAR(fmin / W, 1.0, 1e-9);
    EXPECT_NEAR(fmax / W, 1.0, 1e-9);
    EXPECT_GT(norm(g.x[0] - Vec3{0.03, 0.03, g.x[0].z}), 0.1);  // crossed many triangles
  }
}

// Sub-cycling: one FE step per DEM step and one per 10 DEM steps reach the same equilibrium.
TEST(Coupling, SubcyclingReachesTheSameStaticAnswer) {
  double d[2], f[2];
  int k = 0;
  for (int n : {1, 10}) {
    Rig rig(MPI_COMM_WORLD, one_sphere(), n, false);
    EXPECT_EQ(rig.cpl->subcycle(), n);
    rig.eng->run(60000);
    d[k] = rig.max_deflection();
    f[k] = rig.cpl->last_update_force().z;
    ++k;
  }
  const double W = sphere_mass(kRho, kR) * kG;
  if (world_rank() == 0)
    std::printf("subcycle 1 vs 10: deflection %.10e / %.10e (rel %.2e), force %.3e / %.3e of W\n", d[0], d[1],
                std::abs(d[1] / d[0] - 1), -f[0] / W, -f[1] / W);
  EXPECT_NEAR(d[1] / d[0], 1.0, 1e-6);
  EXPECT_NEAR(-f[0] / W, 1.0, 1e-9);
  EXPECT_NEAR(-f[1] / W, 1.0, 1e-9);
}

// The auto sub-cycle is the largest n with n dt_DE <= dt_FE.
TEST(Coupling, AutoSubcycle) {
  EXPECT_EQ(Coupler::auto_subcycle(1e-4, 1e-5), 10);
  EXPECT_EQ(Coupler::auto_subcycle(1.05e-4, 1e-5), 10);
  EXPECT_EQ(Coupler::auto_subcycle(0.99e-4, 1e-5), 9);
  EXPECT_EQ(Coupler::auto_subcycle(1e-6, 1e-5), 1);
}

// Surface groups: the plate's top split into two halves (two interface surfaces), a sphere on
// each: each group's force is its sphere's weight, and the groups add up to the total.
TEST(Coupling, ForcesPerSurfaceGroup) {
  ParticleStore p;
  add_sphere(p, 0, {0.05, 0.1, 0.01 + kR + 2e-4}, kR, kRho);
  add_sphere(p, 1, {0.15, 0.1, 0.01 + 1.2 * kR + 2e-4}, 1.2 * kR, kRho);
  int size = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  fem::Mesh mesh = fem::make_block({0, 0, 0}, {0.2, 0.2, 0.01}, 8, 8, 1);
  for (const auto& f : mesh.face_sets.at("zmax")) {
    const std::int32_t* nd;
    const int nn = mesh.nodes_of(f[0], nd);
    double xc = 0;
    for (int k = 0; k < nn; ++k) xc += mesh.coords[3 * static_cast<std::size_t>(nd[k])] / nn;
    mesh.face_sets[xc < 0.1 ? "left" : "right"].push_back(f);
  }
  const fem::FePartition part = partition_mesh(mesh, size);
  fem::FeMaterial fm;
  fm.young = 1e8; fm.poisson = 0.3; fm.density = 1e5;
  fem::FeModel model(MPI_COMM_WORLD, mesh, part, {fm});
  for (const char* side : {"xmin", "xmax", "ymin", "ymax"})
    for (std::int32_t n : mesh.node_sets.at(side)) model.restrain(n, {true, true, true});
  auto tris = coupling::make_interface(mesh, "left");
  auto right = coupling::make_interface(mesh, "right");
  for (auto& t : right) t.group = 1;
  tris.insert(tris.end(), right.begin(), right.end());
  MaterialTable mats({make_material("sand", kE, kRho, 0.5, 0.25, 0.5, 1.0), make_material("iface", kE, kRho, 0.5, 0.25, 0.5, 1.0)});
  EngineParams e;
  e.domain_min = {0, 0, -0.02}; e.domain_max = {0.2, 0.2, 0.1};
  e.gravity = {0, 0, -kG}; e.damping = 0.7; e.dt = 1e-5;
  CouplerParams cp;
  cp.material = 1; cp.subcycle = 10;
  Coupler cpl(MPI_COMM_WORLD, mesh, model, tris, cp, e.dt);
  DemEngine eng(MPI_COMM_WORLD, e, mats, {}, p);
  eng.attach(&cpl);
  eng.run(60000);
  ASSERT_EQ(cpl.n_groups(), 2);
  const double W0 = sphere_mass(kRho, kR) * kG, W1 = sphere_mass(kRho, 1.2 * kR) * kG;
  const auto& g = cpl.last_group_forces();
  const Vec3 tot = cpl.last_update_force();
  if (world_rank() == 0)
    std::printf("groups: left %.12e N (weight %.12e), right %.12e N (weight %.12e), total %.12e N\n", -g[0].z, W0,
                -g[1].z, W1, -tot.z);
  EXPECT_NEAR(-g[0].z / W0, 1.0, 1e-9);
  EXPECT_NEAR(-g[1].z / W1, 1.0, 1e-9);
  EXPECT_NEAR((g[0].z + g[1].z) / tot.z, 1.0, 1e-12);
}

// The FE stable step with the interface contact stiffness (Gershgorin, k added to the row of
// every interface node): for one free cube, all 8 nodes alike, lambda = lambda_FE + k / m_node.
TEST(Coupling, StableStepIncludesTheInterfaceStiffness) {
  MPI_Comm one = first_ranks(1);  // one element: on one rank
  if (one == MPI_COMM_NULL) return;
  const fem::Mesh mesh = fem::make_block({0, 0, 0}, {0.1, 0.1, 0.1}, 1, 1, 1);
  fem::FeMaterial fm;
  fm.young = 1e7; fm.poisson = 0.25; fm.density = 1000;
  {
    fem::FeModel model(one, mesh, partition_mesh(mesh, 1), {fm});
    const double dt0 = model.critical_dt();
    const double k = 3e6, m_node = 1000 * 1e-3 / 8;
    const auto tris = coupling::make_interface(mesh, "zmax");
    const std::vector<std::int32_t> nodes = coupling::interface_nodes(tris);
    EXPECT_EQ(nodes.size(), 4u);
    const double dtk = model.critical_dt(nodes, k);
    EXPECT_NEAR(dtk / (2 / std::sqrt(4 / (dt0 * dt0) + k / m_node)), 1.0, 1e-12);
    EXPECT_LT(dtk, dt0);
    // a stiffness per node (several contacts on one): the stiffest node rules
    const double dtv = model.critical_dt(nodes, {k, 4 * k, k, 0.5 * k});
    EXPECT_NEAR(dtv / (2 / std::sqrt(4 / (dt0 * dt0) + 4 * k / m_node)), 1.0, 1e-12);
  }
  MPI_Comm_free(&one);
}

// Held rigid, the plate does not move but carries the weight on it; released, it deflects to
// the same equilibrium as a plate that was never held (a single sphere at the plate's centre:
// no path dependence; a frictional bed may settle differently on a rigid and on a flexible plate).
TEST(Coupling, RigidThenRelease) {
  const double W = sphere_mass(kRho, kR) * kG;
  {
    Rig bedrig(MPI_COMM_WORLD, bed(), 10, true);
    bedrig.eng->run(20000);
    EXPECT_EQ(bedrig.max_deflection(), 0.0);
    EXPECT_EQ(bedrig.cpl->fe_steps(), 0);
    EXPECT_NEAR(-bedrig.cpl->last_update_force().z / (41 * W), 1.0, 1e-2);
  }
  Rig held(MPI_COMM_WORLD, one_sphere(), 10, true);
  held.eng->run(20000);
  EXPECT_EQ(held.max_deflection(), 0.0);
  EXPECT_EQ(held.cpl->fe_steps(), 0);
  EXPECT_NEAR(-held.cpl->last_update_force().z / W, 1.0, 1e-6);
  held.cpl->set_rigid(false);
  held.eng->run(40000);
  EXPECT_EQ(held.cpl->fe_steps(), 4000);
  Rig never(MPI_COMM_WORLD, one_sphere(), 10, false);
  never.eng->run(60000);
  const double a = held.max_deflection(), b = never.max_deflection();
  if (world_rank() == 0) std::printf("held then released %.12e m, never held %.12e m\n", a, b);
  EXPECT_GT(a, 1e-7);
  EXPECT_NEAR(a / b, 1.0, 1e-9);
  EXPECT_NEAR(-held.cpl->last_update_force().z / W, 1.0, 1e-10);
}

// A bed settling on the flexible plate: 1, 2 and 3 ranks give the same plate deflection -- to the
// last bit (exact fixed-point sums in the FE assembly and the interface-force reduction).
TEST(Coupling, BedOnPlateSameOn1To3Ranks) {
  int world = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &world);
  std::vector<std::vector<double>> res;
  std::vector<double> force;
  for (int n = 1; n <= world; ++n) {
    MPI_Comm sub = first_ranks(n);
    std::vector<double> u;
    double fz = 0;
    if (sub != MPI_COMM_NULL) {
      Rig rig(sub, bed(), 10, false);
      rig.eng->run(80000);
      u = rig.model->gather_displacements();
      fz = rig.cpl->last_update_force().z;
      MPI_Comm_free(&sub);
    }
    res.push_back(u);
    force.push_back(fz);
    MPI_Barrier(MPI_COMM_WORLD);
  }
  if (world_rank() != 0) return;
  double umax = 0;
  for (double x : res[0]) umax = std::max(umax, std::abs(x));
  ASSERT_GT(umax, 1e-6);
  const double W = 41 * sphere_mass(kRho, kR) * kG;
  EXPECT_NEAR(-force[0] / W, 1.0, 1e-8);
  for (int n = 2; n <= world; ++n) {
    double d = 0;
    for (std::size_t k = 0; k < res[0].size(); ++k) d = std::max(d, std::abs(res[n - 1][k] - res[0][k]));
    std::printf("bed on plate, 1 vs %d ranks: max deflection difference %.3e of %.4e m\n", n, d / umax, umax);
    EXPECT_EQ(d, 0.0);
    EXPECT_EQ(force[n - 1], force[0]);
  }
}
