// read_case(): a valid case maps to the right CaseConfig values and defaults; every kind of
// input error names the file, the line and what is wrong; --set overrides; the shipped cases
// (cases/demo, cases/examples) are valid and cases/bad/*.yaml fail as their first line says.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <string>

#include "app/case_checks.hpp"
#include "app/coupled_driver.hpp"
#include "app/fe_driver.hpp"
#include "dem/generate.hpp"
#include "dem/particles.hpp"
#include "io/case_file.hpp"

namespace fs = std::filesystem;
using namespace fdem;

namespace {

fs::path source_dir() {
  if (const char* s = std::getenv("FDEM_SOURCE_DIR")) return s;
  return fs::path(__FILE__).parent_path().parent_path();
}

class TempDir {
 public:
  TempDir() {
    path_ = fs::temp_directory_path() /
            ("fdem_case_test_" + std::to_string(::getpid()) + "_" + std::to_string(counter_++));
    fs::create_directories(path_);
  }
  ~TempDir() { std::error_code ec; fs::remove_all(path_, ec); }
  std::string write(const std::string& name, const std::string& text) const {
    std::ofstream(path_ / name) << text;
    return (path_ / name).string();
  }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
  static inline int counter_ = 0;
};

const char* kFull = R"(name: full
domain: {min: [0, 0, 0], max: [1, 2, 3]}
gravity: [0, -9.81, 0]
time:
  dt: 1.0e-5
  safety: 0.5
  steps: 1500
  stop_unbalanced: 0.01
damping: 0.1
neighbor: {skin: 0.002}
materials:
  - name: sand
    young: 1.0e8
    density: 2640
    kt_kn: 0.1
    friction: 0.54
    rolling_stiffness: 0.05
    rolling_limit: 1.0
  - name: steel
    young: 2.0e11
    density: 7850
interactions:
  - materials: [steel, sand]
    friction: 0.3
    rolling_limit: 0.5
particles:
  - inline:
      material: steel
      velocity: [1, 2, 3]
      spheres:
        - [0.5, 0.5, 0.5, 0.01]
        - {id: 7, x: [0.2, 0.3, 0.4], r: 0.02, v: [0, 0, -1]}
  - generate:
      material: sand
      box: {min: [0, 0, 0], max: [1, 1, 1]}
      porosity: 0.9
      seed: 5
      max_attempts: 50
      velocity: [0, 0, -2]
      size:
        distribution: sieve
        sizes: [0.01, 0.02, 0.04]
        passing: [0, 40, 100]
        max: 0.03
        scale: 2
  - file:
      path: sub/spheres.txt
      material: sand
      scale: 0.5
      offset: [1, 0, 0]
walls:
  - {name: floor, type: plane, material: steel, point: [0, 0, 0], normal: [0, 0, 2]}
  - name: block
    type: box
    material: sand
    min: [0.1, 0.1, 0.1]
    max: [0.2, 0.3, 0.4]
    motion: {velocity: [0, 0, -0.1]}
  - name: lid
    type: facets
    material: steel
    vertices: [[0, 0, 1], [1, 0, 1], [1, 1, 1]]
    triangles: [[0, 1, 2]]
    motion: {free: {mass: 2.5, dofs: [x, z], gravity: true, velocity: [0, 0, 1]}}
constraints:
  - ids: [1, 2]
    fixed: true
  - region: {min: [0, 0, 0], max: [1, 1, 0.1]}
    block: [x, z, ry]
    velocity: [0, 0, -0.01]
output:
  dir: results/full
  snapshot_every: 1000
  history_every: 10
  checkpoint_every: 5000
progress: {interval: 2}
restart: {from: ck/state.h5}
)";

const char* kMinimal = R"(domain: {min: [0, 0, 0], max: [1, 1, 1]}
time: {steps: 10}
materials: [{name: sand, young: 1.0e8, density: 2640}]
particles:
  - inline: {material: sand, spheres: [[0.5, 0.5, 0.5, 0.01]]}
)";

/// Runs read_case and returns the InputError (fails the test if none is thrown).
InputError expect_error(const std::string& path, const std::vector<std::string>& ov = {}) {
  try {
    read_case(path, ov);
  } catch (const InputError& e) {
    return e;
  }
  ADD_FAILURE() << "no InputError for " << path;
  return InputError("", -1, "none");
}

}  // namespace

TEST(CaseFile, FullCaseMapsToConfig) {
  TempDir d;
  fs::create_directories(d.path() / "sub");
  d.write("sub/spheres.txt", "1 0 0 0 0.01\n");
  const std::string f = d.write("full.yaml", kFull);
  const CaseConfig c = read_case(f);
  EXPECT_EQ(c.file, f);
  EXPECT_EQ(c.name, "full");
  EXPECT_DOUBLE_EQ(c.domain_max.y, 2.0);
  EXPECT_DOUBLE_EQ(c.domain_max.z, 3.0);
  EXPECT_DOUBLE_EQ(c.gravity.y, -9.81);
  EXPECT_DOUBLE_EQ(c.gravity.z, 0.0);
  EXPECT_DOUBLE_EQ(c.dt, 1.0e-5);
  EXPECT_DOUBLE_EQ(c.dt_safety, 0.5);
  EXPECT_EQ(c.steps, 1500);
  EXPECT_DOUBLE_EQ(c.duration, 0.0);
  EXPECT_DOUBLE_EQ(c.stop_unbalanced, 0.01);
  EXPECT_DOUBLE_EQ(c.damping, 0.1);
  EXPECT_DOUBLE_EQ(c.skin, 0.002);

  ASSERT_EQ(c.materials.size(), 2u);
  EXPECT_EQ(c.materials[0].name, "sand");
  EXPECT_DOUBLE_EQ(c.materials[0].young, 1.0e8);
  EXPECT_DOUBLE_EQ(c.materials[0].density, 2640);
  EXPECT_DOUBLE_EQ(c.materials[0].kt_kn, 0.1);
  EXPECT_DOUBLE_EQ(c.materials[0].friction, 0.54);
  EXPECT_DOUBLE_EQ(c.materials[0].rolling_stiffness, 0.05);
  EXPECT_DOUBLE_EQ(c.materials[0].rolling_limit, 1.0);
  // defaults
  EXPECT_DOUBLE_EQ(c.materials[1].kt_kn, 0.25);
  EXPECT_DOUBLE_EQ(c.materials[1].friction, 0.5);
  EXPECT_DOUBLE_EQ(c.materials[1].rolling_stiffness, 0.0);
  EXPECT_DOUBLE_EQ(c.materials[1].rolling_limit, 0.0);

  ASSERT_EQ(c.interactions.size(), 1u);
  EXPECT_EQ(c.interactions[0].a, 1);
  EXPECT_EQ(c.interactions[0].b, 0);
  EXPECT_TRUE(c.interactions[0].has_friction);
  EXPECT_DOUBLE_EQ(c.interactions[0].friction, 0.3);
  EXPECT_FALSE(c.interactions[0].has_kt_kn);
  EXPECT_FALSE(c.interactions[0].has_beta_r);
  EXPECT_TRUE(c.interactions[0].has_eta_r);
  EXPECT_DOUBLE_EQ(c.interactions[0].eta_r, 0.5);

  ASSERT_EQ(c.particles.size(), 3u);
  const auto& in = c.particles[0];
  EXPECT_EQ(in.kind, ParticleSource::kInline);
  EXPECT_EQ(in.material, 1);
  EXPECT_EQ(in.line, 27);
  EXPECT_EQ(in.source_file, f);
  ASSERT_EQ(in.spheres.size(), 2u);
  EXPECT_EQ(in.spheres[0].id, -1);
  EXPECT_DOUBLE_EQ(in.spheres[0].r, 0.01);
  EXPECT_DOUBLE_EQ(in.spheres[0].v.y, 2.0);  // entry velocity
  EXPECT_EQ(in.spheres[1].id, 7);
  EXPECT_DOUBLE_EQ(in.spheres[1].x.z, 0.4);
  EXPECT_DOUBLE_EQ(in.spheres[1].r, 0.02);
  EXPECT_DOUBLE_EQ(in.spheres[1].v.z, -1.0);  // own velocity wins
  EXPECT_DOUBLE_EQ(in.spheres[1].v.x, 0.0);
  const auto& g = c.particles[1];
  EXPECT_EQ(g.kind, ParticleSource::kGenerate);
  EXPECT_EQ(g.material, 0);
  EXPECT_EQ(g.count, 0);
  EXPECT_DOUBLE_EQ(g.porosity, 0.9);
  EXPECT_EQ(g.seed, 5u);
  EXPECT_EQ(g.max_attempts, 50);
  EXPECT_DOUBLE_EQ(g.velocity.z, -2.0);
  EXPECT_EQ(g.size.kind, SizeDistribution::kSieve);
  ASSERT_EQ(g.size.sieve_d.size(), 3u);
  EXPECT_DOUBLE_EQ(g.size.sieve_d[2], 0.04);
  EXPECT_DOUBLE_EQ(g.size.passing[1], 40);
  EXPECT_DOUBLE_EQ(g.size.dmax, 0.03);
  EXPECT_DOUBLE_EQ(g.size.dmin, 0.0);
  EXPECT_DOUBLE_EQ(g.size.scale, 2.0);
  const auto& fl = c.particles[2];
  EXPECT_EQ(fl.kind, ParticleSource::kFile);
  EXPECT_EQ(fs::path(fl.path), (d.path() / "sub/spheres.txt").lexically_normal());
  EXPECT_DOUBLE_EQ(fl.scale, 0.5);
  EXPECT_DOUBLE_EQ(fl.offset.x, 1.0);

  ASSERT_EQ(c.walls.size(), 3u);
  EXPECT_EQ(c.walls[0].kind, WallConfig::kPlane);
  EXPECT_DOUBLE_EQ(c.walls[0].normal.z, 1.0);  // normalised
  EXPECT_EQ(c.walls[0].motion.kind, WallMotion::kFixed);
  EXPECT_EQ(c.walls[0].material, 1);
  EXPECT_EQ(c.walls[1].kind, WallConfig::kBox);
  EXPECT_DOUBLE_EQ(c.walls[1].max.y, 0.3);
  EXPECT_EQ(c.walls[1].motion.kind, WallMotion::kVelocity);
  EXPECT_DOUBLE_EQ(c.walls[1].motion.velocity.z, -0.1);
  EXPECT_EQ(c.walls[1].line, 53);
  EXPECT_EQ(c.walls[2].kind, WallConfig::kFacets);
  ASSERT_EQ(c.walls[2].triangles.size(), 1u);
  EXPECT_EQ(c.walls[2].triangles[0][2], 2);
  EXPECT_DOUBLE_EQ(c.walls[2].vertices[1].x, 1.0);
  EXPECT_EQ(c.walls[2].motion.kind, WallMotion::kFree);
  EXPECT_DOUBLE_EQ(c.walls[2].motion.mass, 2.5);
  EXPECT_EQ(c.walls[2].motion.free_dofs, 1 | 4);
  EXPECT_TRUE(c.walls[2].motion.gravity);
  EXPECT_DOUBLE_EQ(c.walls[2].motion.velocity.z, 1.0);

  ASSERT_EQ(c.constraints.size(), 2u);
  EXPECT_EQ(c.constraints[0].ids, (std::vector<std::int64_t>{1, 2}));
  EXPECT_EQ(c.constraints[0].blocked, kDofAll);
  EXPECT_FALSE(c.constraints[0].has_velocity);
  EXPECT_TRUE(c.constraints[1].has_region);
  EXPECT_DOUBLE_EQ(c.constraints[1].region_max.z, 0.1);
  EXPECT_EQ(c.constraints[1].blocked, kDofX | kDofZ | kDofRY);
  EXPECT_TRUE(c.constraints[1].has_velocity);
  EXPECT_DOUBLE_EQ(c.constraints[1].velocity.z, -0.01);

  EXPECT_EQ(c.out_dir, "results/full");
  EXPECT_EQ(c.snapshot_every, 1000);
  EXPECT_EQ(c.history_every, 10);
  EXPECT_EQ(c.checkpoint_every, 5000);
  EXPECT_DOUBLE_EQ(c.progress_interval, 2.0);
  EXPECT_EQ(fs::path(c.restart_from), (d.path() / "ck/state.h5").lexically_normal());
}

TEST(CaseFile, Defaults) {
  TempDir d;
  const std::string f = d.write("my_case.yaml", kMinimal);
  const CaseConfig c = read_case(f);
  EXPECT_EQ(c.name, "my_case");  // file stem
  EXPECT_DOUBLE_EQ(c.gravity.x, 0.0);
  EXPECT_DOUBLE_EQ(c.gravity.z, -9.81);
  EXPECT_DOUBLE_EQ(c.dt, 0.0);  // auto
  EXPECT_DOUBLE_EQ(c.dt_safety, 0.3);
  EXPECT_EQ(c.steps, 10);
  EXPECT_DOUBLE_EQ(c.stop_unbalanced, 0.0);
  EXPECT_DOUBLE_EQ(c.damping, 0.2);
  EXPECT_DOUBLE_EQ(c.skin, 0.0);  // auto
  EXPECT_TRUE(c.interactions.empty());
  EXPECT_TRUE(c.walls.empty());
  EXPECT_TRUE(c.constraints.empty());
  EXPECT_EQ(c.out_dir, "out/my_case");
  EXPECT_EQ(c.snapshot_every, 0);
  EXPECT_EQ(c.history_every, 100);
  EXPECT_EQ(c.checkpoint_every, 0);
  EXPECT_DOUBLE_EQ(c.progress_interval, 5.0);
  EXPECT_TRUE(c.restart_from.empty());
  ASSERT_EQ(c.particles.size(), 1u);
  EXPECT_EQ(c.particles[0].spheres[0].id, -1);
}

// `type: container`: the grains' container read as its faces, planes facing in (the open ones left
// out), named <name>_<face>; the container's name stands for all its faces where a list of walls
// is meant, and a single-wall key that names it says which faces there are.
TEST(CaseFile, ContainerIsItsFacesFacingIn) {
  TempDir d;
  const std::string f = d.write("c.yaml", std::string(kMinimal) +
                                              "walls:\n  - {name: bin, type: container, material: sand, min: [0.1, 0.2, 0.3],\n"
                                              "     max: [0.9, 0.8, 0.7], open: [zmax]}\n");
  const CaseConfig c = read_case(f);
  ASSERT_EQ(c.walls.size(), 5u);
  const char* names[] = {"bin_xmin", "bin_xmax", "bin_ymin", "bin_ymax", "bin_zmin"};
  const Vec3 lo{0.1, 0.2, 0.3}, hi{0.9, 0.8, 0.7};
  for (int k = 0; k < 5; ++k) {
    const WallConfig& w = c.walls[static_cast<std::size_t>(k)];
    EXPECT_EQ(w.name, names[k]);
    EXPECT_EQ(w.kind, WallConfig::kPlane);
    EXPECT_EQ(w.line, 7);
    const int axis = k / 2;
    for (int j = 0; j < 3; ++j) EXPECT_EQ(w.normal[j], j == axis ? (k % 2 ? -1.0 : 1.0) : 0.0) << names[k];
    // the inside, the middle of the box, lies in front of every face
    const Vec3 mid = 0.5 * (lo + hi);
    EXPECT_GT(dot(mid - w.point, w.normal), 0.0) << names[k];
    EXPECT_EQ(w.point[axis], k % 2 ? hi[axis] : lo[axis]) << names[k];
  }
  ASSERT_EQ(c.wall_groups.size(), 1u);
  EXPECT_TRUE(c.wall_groups[0].container);
  EXPECT_EQ(c.wall_groups[0].count, 5);
  EXPECT_DOUBLE_EQ(c.stop_kinetic_ratio, 1e-3);  // (the default)
}

TEST(CaseFile, DurationAutoDtAndGenerateDefaults) {
  TempDir d;
  const std::string f = d.write("c.yaml", R"(domain: {min: [0, 0, 0], max: [1, 1, 1]}
time: {dt: auto, duration: 0.5}
neighbor: {skin: auto}
materials: [{name: sand, young: 1.0e8, density: 2640}]
particles:
  - generate:
      material: sand
      box: {min: [0, 0, 0], max: [1, 1, 1]}
      count: 1e3
      size: {distribution: normal, mean: 0.005, sd: 0.001}
)");
  const CaseConfig c = read_case(f);
  EXPECT_DOUBLE_EQ(c.dt, 0.0);
  EXPECT_EQ(c.steps, 0);
  EXPECT_DOUBLE_EQ(c.duration, 0.5);
  EXPECT_DOUBLE_EQ(c.skin, 0.0);
  const auto& g = c.particles[0];
  EXPECT_EQ(g.count, 1000);  // integral float accepted
  EXPECT_EQ(g.seed, 1u);
  EXPECT_EQ(g.max_attempts, 100);
  EXPECT_EQ(g.size.kind, SizeDistribution::kNormal);
  EXPECT_DOUBLE_EQ(g.size.mean, 0.005);
  EXPECT_DOUBLE_EQ(g.size.sd, 0.001);
  EXPECT_DOUBLE_EQ(g.size.scale, 1.0);
  EXPECT_DOUBLE_EQ(g.velocity.z, 0.0);
}

TEST(CaseFile, RestartWithoutParticles) {
  TempDir d;
  const std::string f = d.write("r.yaml", R"(domain: {min: [0, 0, 0], max: [1, 1, 1]}
time: {steps: 10}
materials: [{name: sand, young: 1.0e8, density: 2640}]
restart: {from: ../old/ck.h5}
)");
  const CaseConfig c = read_case(f);
  EXPECT_TRUE(c.particles.empty());
  EXPECT_EQ(fs::path(c.restart_from), (d.path().parent_path() / "old/ck.h5").lexically_normal());
}

// The contact model: `poisson` of a material (default 0.25), `model` of an `interactions`
// entry and the case-wide `contact_model` (default linear); the pair table resolves them.
TEST(CaseFile, ContactModelAndPoisson) {
  TempDir d;
  const std::string base = R"(domain: {min: [0, 0, 0], max: [1, 1, 1]}
time: {steps: 10}
materials:
  - {name: sand, young: 1.0e8, density: 2640, poisson: 0.3}
  - {name: steel, young: 2.0e11, density: 7800}
interactions:
  - {materials: [sand, steel], model: hertz_mindlin}
particles:
  - inline: {material: sand, spheres: [[0.5, 0.5, 0.5, 0.01]]}
)";
  const CaseConfig c = read_case(d.write("hm.yaml", base));
  ASSERT_EQ(c.materials.size(), 2u);
  EXPECT_DOUBLE_EQ(c.materials[0].poisson, 0.3);
  EXPECT_DOUBLE_EQ(c.materials[1].poisson, 0.25);  // default
  EXPECT_EQ(c.contact_model, ContactModel::kLinear);
  ASSERT_EQ(c.interactions.size(), 1u);
  EXPECT_TRUE(c.interactions[0].has_model);
  EXPECT_FALSE(c.interactions[0].has_friction);
  EXPECT_EQ(c.interactions[0].model, ContactModel::kHertzMindlin);
  const MaterialTable t(c.materials, c.interactions, c.contact_model);
  EXPECT_EQ(t.pair(0, 1).model, ContactModel::kHertzMindlin);
  EXPECT_EQ(t.pair(0, 0).model, ContactModel::kLinear);
  // The case-wide default, and an entry that takes one pair back to linear.
  const CaseConfig h = read_case(d.write("all.yaml", std::string(base) + "contact_model: hertz_mindlin\n"),
                                 {"interactions.0.model=linear"});
  EXPECT_EQ(h.contact_model, ContactModel::kHertzMindlin);
  const MaterialTable th(h.materials, h.interactions, h.contact_model);
  EXPECT_EQ(th.pair(0, 0).model, ContactModel::kHertzMindlin);
  EXPECT_EQ(th.pair(1, 0).model, ContactModel::kLinear);
  // A --set of a bad model names the override.
  try {
    read_case(d.write("ov.yaml", base), {"contact_model=hertz"});
    FAIL() << "no error for contact_model=hertz";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--set contact_model=hertz"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("valid: linear, hertz_mindlin"), std::string::npos) << e.what();
  }
}

// rolling_law: the case-wide default, per material, per pair; the total law's pairs take one
// beta_r and eta_r (the larger of the two materials'), as the thesis's engine's Ip2 functor; two
// materials of different laws need the pair's law in interactions.
TEST(CaseFile, RollingLawPerCaseMaterialAndPair) {
  TempDir d;
  const std::string base = R"(domain: {min: [0, 0, 0], max: [1, 1, 1]}
time: {steps: 10}
materials:
  - {name: sand, young: 1.0e8, density: 2640, rolling_stiffness: 0.05, rolling_limit: 1.0}
  - {name: wall, young: 1.0e8, density: 2640, friction: 0}
particles:
  - inline: {material: sand, spheres: [[0.5, 0.5, 0.5, 0.01]]}
)";
  const CaseConfig c = read_case(d.write("inc.yaml", base));
  EXPECT_EQ(c.rolling_law, RollingLaw::kIncremental);
  const MaterialTable ti(c.materials, c.interactions, c.contact_model);
  EXPECT_EQ(ti.pair(0, 1).rolling, RollingLaw::kIncremental);
  EXPECT_DOUBLE_EQ(ti.pair(0, 1).beta_r, 0.025);  // the mean
  EXPECT_DOUBLE_EQ(ti.pair(0, 1).eta_r, 0.5);
  const CaseConfig t = read_case(d.write("tot.yaml", base + "rolling_law: total\n"));
  const MaterialTable tt(t.materials, t.interactions, t.contact_model);
  for (int a = 0; a < 2; ++a)
    for (int b = 0; b < 2; ++b) {
      EXPECT_EQ(tt.pair(a, b).rolling, RollingLaw::kTotal);
      EXPECT_DOUBLE_EQ(tt.pair(a, b).beta_r, a + b == 2 ? 0.0 : 0.05);
      EXPECT_DOUBLE_EQ(tt.pair(a, b).eta_r, a + b == 2 ? 0.0 : 1.0);
    }
  // Per material: sand total, wall incremental -> the pair's law is required.
  const std::string mixed = base + "interactions:\n  - {materials: [sand, wall], rolling_law: total}\n";
  const CaseConfig m = read_case(d.write("mixed.yaml", mixed), {"materials.0.rolling_law=total"});
  const MaterialTable tm(m.materials, m.interactions, m.contact_model);
  EXPECT_EQ(tm.pair(0, 0).rolling, RollingLaw::kTotal);
  EXPECT_EQ(tm.pair(0, 1).rolling, RollingLaw::kTotal);
  EXPECT_DOUBLE_EQ(tm.pair(0, 1).beta_r, 0.05);
  EXPECT_EQ(tm.pair(1, 1).rolling, RollingLaw::kIncremental);
  const std::string f = d.write("nopair.yaml", base);
  try {
    read_case(f, {"materials.1.rolling_law=total"});
    FAIL() << "no error for two materials of different rolling laws";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("give their pair's law in interactions"), std::string::npos) << e.what();
  }
  try {
    read_case(f, {"rolling_law=totl"});
    FAIL() << "no error for rolling_law=totl";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("valid: incremental, total"), std::string::npos) << e.what();
  }
}

// ---- errors: each names the file, the line and the problem

struct BadCase {
  const char* name;
  std::string text;
  int line;
  const char* phrase;
};

class CaseErrors : public ::testing::TestWithParam<BadCase> {};

TEST_P(CaseErrors, NamesFileLineAndProblem) {
  const BadCase& b = GetParam();
  TempDir d;
  const std::string f = d.write(std::string(b.name) + ".yaml", b.text);
  const InputError e = expect_error(f);
  EXPECT_EQ(e.file(), f);
  EXPECT_EQ(e.line(), b.line) << e.what();
  EXPECT_NE(std::string(e.what()).find(b.phrase), std::string::npos) << e.what();
  EXPECT_NE(std::string(e.what()).find(f + (b.line > 0 ? ":" + std::to_string(b.line) : std::string())),
            std::string::npos)
      << e.what();
}

std::string with(const std::string& from, const std::string& to) {
  std::string s = kMinimal;
  const auto p = s.find(from);
  if (p == std::string::npos) throw std::logic_error("test text not found: " + from);
  return s.replace(p, from.size(), to);
}

INSTANTIATE_TEST_SUITE_P(
    All, CaseErrors,
    ::testing::Values(
        BadCase{"unknown_top", std::string(kMinimal) + "dampnig: 0.1\n", 6,
                "unknown key 'dampnig' at the top level (valid: name, domain, gravity, time, damping"},
        BadCase{"unknown_material_key", with("density: 2640}", "density: 2640, yuong: 1}"), 3,
                "unknown key 'yuong' in materials[0] (valid: name, young, density, kt_kn, friction, "
                "rolling_stiffness, rolling_limit, rolling_law, poisson)"},
        BadCase{"poisson_too_large", with("density: 2640}", "density: 2640, poisson: 0.5}"), 3,
                "materials[0].poisson: must be in (-1, 0.5), got 0.5"},
        BadCase{"poisson_not_number", with("density: 2640}", "density: 2640, poisson: soft}"), 3,
                "materials[0].poisson: expected a number, got 'soft'"},
        BadCase{"unknown_pair_model",
                std::string(kMinimal) + "interactions:\n  - materials: [sand, sand]\n    model: hertzian\n", 8,
                "interactions[0].model: unknown contact model 'hertzian' (valid: linear, hertz_mindlin)"},
        BadCase{"unknown_case_model", std::string(kMinimal) + "contact_model: Hertz\n", 6,
                "contact_model: unknown contact model 'Hertz' (valid: linear, hertz_mindlin)"},
        BadCase{"unknown_nested", with("time: {steps: 10}", "time:\n  steps: 10\n  dtt: 1"), 4,
                "unknown key 'dtt' in time"},
        BadCase{"wrong_type_int", with("steps: 10", "steps: abc"), 2, "time.steps: expected an integer, got 'abc'"},
        BadCase{"wrong_type_float_int", with("steps: 10", "steps: 2.5"), 2, "expected an integer, got '2.5'"},
        BadCase{"wrong_type_number", with("young: 1.0e8", "young: stiff"), 3,
                "materials[0].young: expected a number, got 'stiff'"},
        BadCase{"wrong_type_vec", with("max: [1, 1, 1]", "max: [1, 1]"), 1,
                "domain.max: expected a list of 3 numbers"},
        BadCase{"wrong_type_map", with("time: {steps: 10}", "time: 10"), 2, "time: expected a mapping"},
        BadCase{"missing_time", with("time: {steps: 10}\n", ""), 1, "missing required key 'time'"},
        BadCase{"missing_steps", with("time: {steps: 10}", "time: {dt: 1e-5}"), 2,
                "missing required key 'steps' or 'duration' in time"},
        BadCase{"missing_density", with(", density: 2640", ""), 3,
                "missing required key 'density' in materials[0]"},
        BadCase{"zero_density", with("density: 2640", "density: 0"), 3, "materials[0].density: must be positive"},
        BadCase{"negative_young", with("young: 1.0e8", "young: -5"), 3, "materials[0].young: must be positive"},
        BadCase{"negative_friction", with("density: 2640}", "density: 2640, friction: -0.1}"), 3,
                "materials[0].friction: must be >= 0"},
        BadCase{"negative_radius", with("0.5, 0.01]", "0.5, -0.01]"), 5, "radius must be positive, got -0.01"},
        BadCase{"zero_radius", with("0.5, 0.01]", "0.5, 0]"), 5, "radius must be positive"},
        BadCase{"unknown_material", with("material: sand", "material: snad"), 5,
                "particles[0].inline.material: unknown material 'snad' (valid: sand)"},
        BadCase{"duplicate_material",
                with("materials: [{name: sand, young: 1.0e8, density: 2640}]",
                     "materials:\n  - {name: sand, young: 1.0e8, density: 2640}\n  - {name: sand, young: 1, density: 1}"),
                5, "duplicate material name 'sand'"},
        BadCase{"duplicate_key", with("time: {steps: 10}", "time: {steps: 10, steps: 20}"), 2,
                "duplicate key 'steps' in time"},
        BadCase{"outside_domain", with("[[0.5, 0.5, 0.5, 0.01]]", "[[0.5, 1.5, 0.5, 0.01]]"), 5,
                "centre (0.5, 1.5, 0.5) lies outside the domain"},
        BadCase{"outside_domain_id", with("[[0.5, 0.5, 0.5, 0.01]]", "[{id: 9, x: [2, 0, 0], r: 0.1}]"), 5,
                "(id 9): centre (2, 0, 0) lies outside the domain"},
        BadCase{"missing_file", with("- inline: {material: sand, spheres: [[0.5, 0.5, 0.5, 0.01]]}",
                                     "- file: {path: nothere.txt, material: sand}"),
                5, "cannot read sphere file"},
        BadCase{"two_sources", with("- inline:", "- file: {path: x.txt, material: sand}\n    inline:"), 5,
                "exactly one of inline, generate, file"},
        BadCase{"bad_domain", with("max: [1, 1, 1]", "max: [1, -1, 1]"), 1, "min must be below max"},
        BadCase{"syntax", with("time: {steps: 10}", "time: {steps: [10}"), 2, "YAML syntax error"},
        BadCase{"bad_distribution",
                with("- inline: {material: sand, spheres: [[0.5, 0.5, 0.5, 0.01]]}",
                     "- generate: {material: sand, box: {min: [0,0,0], max: [1,1,1]}, count: 5,\n"
                     "      size: {distribution: lognormal, d: 1}}"),
                6, "unknown distribution 'lognormal' (valid: constant, uniform, normal, sieve)"},
        BadCase{"sieve_not_100",
                with("- inline: {material: sand, spheres: [[0.5, 0.5, 0.5, 0.01]]}",
                     "- generate:\n      material: sand\n      box: {min: [0,0,0], max: [1,1,1]}\n      count: 5\n"
                     "      size: {distribution: sieve, sizes: [1, 2], passing: [0, 90]}"),
                9, "the last value must be 100"},
        BadCase{"generate_box_outside",
                with("- inline: {material: sand, spheres: [[0.5, 0.5, 0.5, 0.01]]}",
                     "- generate:\n      material: sand\n      box: {min: [0,0,0], max: [2,1,1]}\n      count: 5\n"
                     "      size: {distribution: constant, d: 0.01}"),
                7, "box: must lie inside the domain"},
        BadCase{"generate_bad_placement",
                with("- inline: {material: sand, spheres: [[0.5, 0.5, 0.5, 0.01]]}",
                     "- generate:\n      material: sand\n      box: {min: [0,0,0], max: [1,1,1]}\n      count: 5\n"
                     "      placement: cell\n      size: {distribution: constant, d: 0.01}"),
                9, "placement: unknown placement 'cell' (valid: sequential, cells)"},
        BadCase{"wall_bad_triangle",
                std::string(kMinimal) + "walls:\n  - name: w\n    type: facets\n    material: sand\n"
                                        "    vertices: [[0,0,0],[1,0,0],[0,1,0]]\n    triangles: [[0, 1, 3]]\n",
                11, "vertex index 3 out of range [0, 3)"},
        BadCase{"wall_degenerate",
                std::string(kMinimal) + "walls:\n  - name: w\n    type: facets\n    material: sand\n"
                                        "    vertices: [[0,0,0],[1,0,0],[2,0,0]]\n    triangles: [[0, 1, 2]]\n",
                11, "degenerate triangle"},
        BadCase{"wall_zero_normal",
                std::string(kMinimal) + "walls:\n  - {name: w, type: plane, material: sand, point: [0,0,0], normal: [0,0,0]}\n",
                7, "normal: must be non-zero"},
        BadCase{"wall_duplicate",
                std::string(kMinimal) + "walls:\n  - {name: w, type: plane, material: sand, point: [0,0,0], normal: [0,0,1]}\n"
                                        "  - {name: w, type: plane, material: sand, point: [0,0,0], normal: [0,0,1]}\n",
                8, "duplicate wall name 'w'"},
        BadCase{"wall_type",
                std::string(kMinimal) + "walls:\n  - {name: w, type: cylinder, material: sand}\n", 7,
                "unknown wall type 'cylinder' (valid: plane, box, container, facets)"},
        BadCase{"after_and_from_step",
                std::string(kMinimal) + "walls:\n  - {name: w, type: plane, material: sand, point: [0,0,0], normal: [0,0,1],\n"
                                        "     motion: [fixed, {from_step: 5, after: {steps: 5}, velocity: [0, 0, 1]}]}\n",
                8, "give from_step or after, not both"},
        BadCase{"after_then_from_step",
                std::string(kMinimal) + "walls:\n  - {name: w, type: plane, material: sand, point: [0,0,0], normal: [0,0,1],\n"
                                        "     motion: [fixed, {after: {unbalanced: 0.01}, velocity: [0, 0, 1]}, {from_step: 9, fixed: true}]}\n",
                8, "follows a phase that starts `after:` a condition, so it must start `after:` one too"},
        BadCase{"after_empty",
                std::string(kMinimal) + "walls:\n  - {name: w, type: plane, material: sand, point: [0,0,0], normal: [0,0,1],\n"
                                        "     motion: [fixed, {after: {kinetic_ratio: 0.01}, velocity: [0, 0, 1]}]}\n",
                8, "give at least one condition: unbalanced, servo, time, steps or stage"},
        BadCase{"after_unknown_key",
                std::string(kMinimal) + "walls:\n  - {name: w, type: plane, material: sand, point: [0,0,0], normal: [0,0,1],\n"
                                        "     motion: [fixed, {after: {when: shear}, velocity: [0, 0, 1]}]}\n",
                8, "unknown key 'when' in walls[0].motion[1].after"},
        BadCase{"after_unknown_stage",
                std::string(kMinimal) + "walls:\n  - {name: w, type: plane, material: sand, point: [0,0,0], normal: [0,0,1],\n"
                                        "     motion: [fixed, {name: shear, after: {steps: 3}, fixed: true}, {after: {stage: shaer}, fixed: true}]}\n",
                8, "walls[0].motion[2].after.stage: no motion phase is named 'shaer' (names: shear)"},
        BadCase{"after_stage_and_condition",
                std::string(kMinimal) + "walls:\n  - {name: w, type: plane, material: sand, point: [0,0,0], normal: [0,0,1],\n"
                                        "     motion: [fixed, {after: {stage: x, steps: 4}, fixed: true}]}\n",
                8, "starts with the phase it names; give no other condition"},
        BadCase{"phase_name_twice",
                std::string(kMinimal) + "walls:\n  - {name: w, type: plane, material: sand, point: [0,0,0], normal: [0,0,1],\n"
                                        "     motion: [{name: a, fixed: true}, {name: a, from_step: 5, fixed: true}]}\n",
                8, "phase name 'a' is already used by walls[0].motion[0]"},
        BadCase{"expansion_layers",
                "domain: {min: [0, 0, 0], max: [1, 1, 1]}\nmaterials: [{name: sand, young: 1.0e8, density: 2640}]\n"
                "packing:\n  method: expansion\n  layers: 3\n  material: sand\n  box: {min: [0,0,0], max: [1,1,1]}\n"
                "  porosity: 0.4\n  size: {distribution: constant, d: 0.1}\n",
                5, "packing.layers: only with method: layers"},
        BadCase{"container_bad_face",
                std::string(kMinimal) + "walls:\n  - {name: bin, type: container, material: sand, min: [0,0,0], max: [1,1,1],\n"
                                        "     open: [top]}\n",
                8, "walls[0].open: unknown face 'top' (valid: xmin, xmax, ymin, ymax, zmin, zmax)"},
        BadCase{"container_all_open",
                std::string(kMinimal) + "walls:\n  - {name: bin, type: container, material: sand, min: [0,0,0], max: [1,1,1],\n"
                                        "     open: [xmin, xmax, ymin, ymax, zmin, zmax]}\n",
                8, "every face is open"},
        BadCase{"container_moving",
                std::string(kMinimal) + "walls:\n  - {name: bin, type: container, material: sand, min: [0,0,0], max: [1,1,1],\n"
                                        "     motion: {velocity: [0, 0, 1]}}\n",
                8, "unknown key 'motion' in walls[0]"},
        BadCase{"segments_plane",
                std::string(kMinimal) + "walls:\n  - {name: w, type: plane, material: sand, point: [0,0,1], normal: [0,0,-1],\n"
                                        "     segments: [2, 1]}\n",
                8, "unknown key 'segments' in walls[0]"},
        BadCase{"segments_not_servo",
                std::string(kMinimal) + "walls:\n  - {name: top, type: box, material: sand, min: [0,0,0.9], max: [1,1,1],\n"
                                        "     segments: [2, 1]}\n",
                8, "walls[0].segments: only a servo-controlled box can be split into segments"},
        BadCase{"segments_area",
                std::string(kMinimal) + "walls:\n  - {name: top, type: box, material: sand, min: [0,0,0.9], max: [1,1,1],\n"
                                        "     segments: [2, 1], motion: {servo: {stress: 1, axis: [0,0,-1], area: 1, max_velocity: 1}}}\n",
                8, "a segmented wall's servo area is each segment's own face: remove 'area'"},
        BadCase{"segments_oblique",
                std::string(kMinimal) + "walls:\n  - {name: top, type: box, material: sand, min: [0,0,0.9], max: [1,1,1],\n"
                                        "     segments: [2, 1], motion: {servo: {stress: 1, axis: [0,1,-1], max_velocity: 1}}}\n",
                8, "segments need a servo axis along x, y or z"},
        BadCase{"segments_count",
                std::string(kMinimal) + "walls:\n  - {name: top, type: box, material: sand, min: [0,0,0.9], max: [1,1,1],\n"
                                        "     segments: [0, 1], motion: {servo: {stress: 1, axis: [0,0,-1], max_velocity: 1}}}\n",
                8, "walls[0].segments: each count must be in [1, 1000], got 0"},
        BadCase{"segments_name_taken",
                std::string(kMinimal) + "walls:\n  - {name: top, type: box, material: sand, min: [0,0,0.9], max: [1,1,1],\n"
                                        "     segments: [2, 1], motion: {servo: {stress: 1, axis: [0,0,-1], max_velocity: 1}}}\n"
                                        "  - {name: top_2, type: plane, material: sand, point: [0,0,0], normal: [0,0,1]}\n",
                9, "walls[1].name: 'top_2' is the name of a segment of wall 'top'"},
        BadCase{"constraint_dof",
                std::string(kMinimal) + "constraints:\n  - {ids: [1], block: [x, q]}\n", 7,
                "unknown degree of freedom 'q' (valid: x, y, z, rx, ry, rz)"},
        BadCase{"motion_free_mass",
                std::string(kMinimal) + "walls:\n  - name: w\n    type: plane\n    material: sand\n"
                                        "    point: [0,0,0]\n    normal: [0,0,1]\n    motion: {free: {mass: 0}}\n",
                12, "mass: must be positive"},
        BadCase{"dt_word", with("time: {steps: 10}", "time: {steps: 10, dt: fast}"), 2,
                "time.dt: expected a positive number or 'auto', got 'fast'"},
        BadCase{"damping_range", std::string(kMinimal) + "damping: 1.0\n", 6, "damping: must be in [0, 1)"},
        BadCase{"empty_file", "", 0, "the case file is empty"}),
    [](const ::testing::TestParamInfo<BadCase>& i) { return std::string(i.param.name); });

TEST(CaseFile, MissingFileHasLineZero) {
  const InputError e = expect_error("/nonexistent/dir/case.yaml");
  EXPECT_EQ(e.line(), 0);
  EXPECT_EQ(e.file(), "/nonexistent/dir/case.yaml");
  EXPECT_NE(std::string(e.what()).find("cannot read the case file"), std::string::npos) << e.what();
  EXPECT_EQ(std::string(e.what()).find("/nonexistent/dir/case.yaml:"), 0u) << e.what();
}

// ---- --set overrides

TEST(CaseFile, OverridesChangeValues) {
  TempDir d;
  const std::string f = d.write("o.yaml", kMinimal);
  const CaseConfig c = read_case(f, {"time.steps=500", "materials.0.young=5e7", "domain.max=[2, 3, 4]",
                                     "particles.0.inline.spheres.0=[1, 1, 1, 0.2]", "neighbor.skin=0.003",
                                     "materials.1={name: steel, young: 2e11, density: 7850}", "name=renamed"});
  EXPECT_EQ(c.steps, 500);
  EXPECT_DOUBLE_EQ(c.materials[0].young, 5e7);
  EXPECT_DOUBLE_EQ(c.materials[0].density, 2640);  // untouched
  EXPECT_DOUBLE_EQ(c.domain_max.x, 2.0);
  EXPECT_DOUBLE_EQ(c.domain_max.z, 4.0);
  EXPECT_DOUBLE_EQ(c.particles[0].spheres[0].x.y, 1.0);
  EXPECT_DOUBLE_EQ(c.particles[0].spheres[0].r, 0.2);
  EXPECT_DOUBLE_EQ(c.skin, 0.003);  // created a new map
  ASSERT_EQ(c.materials.size(), 2u);  // appended at index == size
  EXPECT_EQ(c.materials[1].name, "steel");
  EXPECT_EQ(c.name, "renamed");
  EXPECT_EQ(c.out_dir, "out/renamed");
}

// A phase that starts `after:` a condition is read with its conditions (kinetic_ratio's default
// 1e-3 guards `unbalanced`); the phases after it must start on a condition too.
TEST(CaseFile, PhaseStartsAfterACondition) {
  TempDir d;
  const std::string f = d.write("a.yaml", std::string(kMinimal) +
                                              "walls:\n  - {name: w, type: plane, material: sand, point: [0,0,0], normal: [0,0,1],\n"
                                              "     motion: [fixed, {after: {unbalanced: 0.02, servo: 0.01}, velocity: [0, 0, 1]},\n"
                                              "              {after: {time: 0.5, steps: 7}, fixed: true}]}\n");
  const CaseConfig c = read_case(f);
  ASSERT_EQ(c.walls[0].schedule.size(), 3u);
  const WallMotion& a = c.walls[0].schedule[1];
  EXPECT_TRUE(a.after);
  EXPECT_DOUBLE_EQ(a.after_unbalanced, 0.02);
  EXPECT_DOUBLE_EQ(a.after_kinetic, 1e-3);
  EXPECT_DOUBLE_EQ(a.after_servo, 0.01);
  EXPECT_EQ(a.kind, WallMotion::kVelocity);
  const WallMotion& b = c.walls[0].schedule[2];
  EXPECT_TRUE(b.after);
  EXPECT_DOUBLE_EQ(b.after_time, 0.5);
  EXPECT_EQ(b.after_steps, 7);
  EXPECT_FALSE(c.walls[0].schedule[0].after);
  // a coupled case's stages are its holds: refused there
  const InputError e = expect_error((source_dir() / "cases/coupling/footing_on_plate_ci.yaml").string(),
                                    {"walls[0].motion=[fixed, {after: {steps: 5}, velocity: [0, 0, 1]}]"});
  EXPECT_NE(std::string(e.what()).find("a phase that starts on a condition is for particle runs"), std::string::npos)
      << e.what();
}

// --set selects a list item by its name (walls[top]) or number (walls[1], walls.1); by position in a
// list whose items have names it warns (the target moves when an item is added), by name it does not.
TEST(CaseFile, OverridesSelectListItemsByName) {
  TempDir d;
  const std::string f = d.write("n.yaml", std::string(kMinimal) +
                                              "walls:\n"
                                              "  - {name: floor, type: plane, material: sand, point: [0,0,0], normal: [0,0,1]}\n"
                                              "  - {name: top, type: plane, material: sand, point: [0,0,1], normal: [0,0,-1]}\n");
  const CaseConfig a = read_case(f, {"walls[top].point=[0, 0, 0.8]", "materials[sand].young=5e7"});
  EXPECT_DOUBLE_EQ(a.walls[1].point.z, 0.8);
  EXPECT_DOUBLE_EQ(a.walls[0].point.z, 0.0);
  EXPECT_DOUBLE_EQ(a.materials[0].young, 5e7);
  EXPECT_TRUE(a.warnings.empty());
  const CaseConfig b = read_case(f, {"walls.1.point=[0, 0, 0.7]", "walls[0].point=[0, 0, 0.1]"});
  EXPECT_DOUBLE_EQ(b.walls[1].point.z, 0.7);
  EXPECT_DOUBLE_EQ(b.walls[0].point.z, 0.1);
  ASSERT_EQ(b.warnings.size(), 1u);  // walls.1 warns; walls[0] (a number chosen in brackets) does not
  EXPECT_NE(b.warnings[0].find("walls.1 is the item named 'top' by its position: write walls[top]"), std::string::npos)
      << b.warnings[0];
  const InputError e = expect_error(f, {"walls[roof].point=[0, 0, 1]"});
  EXPECT_NE(std::string(e.what()).find("no item named 'roof' in walls (names: floor, top)"), std::string::npos) << e.what();
  const InputError g = expect_error(f, {"walls.top.point=[0, 0, 1]"});
  EXPECT_NE(std::string(g.what()).find("select an item by name, walls[name], or by number"), std::string::npos) << g.what();
  const InputError h = expect_error(f, {"time[steps]=3"});
  EXPECT_NE(std::string(h.what()).find("'time' is not a list"), std::string::npos) << h.what();
}

// A servo box with segments: [n1, n2] is read as n1 x n2 servo boxes <name>_1 ... that tile it
// exactly (numbered along the first cut direction first), each with the wall's motion; --set on
// the entry reaches every segment; naming the split wall where one wall is meant is an error.
TEST(CaseFile, SegmentedServoBoxTilesTheBox) {
  TempDir d;
  const std::string f = d.write("seg.yaml", std::string(kMinimal) +
                                    "walls:\n"
                                    "  - {name: floor, type: plane, material: sand, point: [0,0,0], normal: [0,0,1]}\n"
                                    "  - name: top\n    type: box\n    material: sand\n"
                                    "    min: [0.1, 0.2, 0.9]\n    max: [0.7, 0.8, 1.0]\n    segments: [3, 2]\n"
                                    "    motion: {servo: {stress: 1000, axis: [0, 0, -1], max_velocity: 0.1}}\n");
  const CaseConfig c = read_case(f, {"walls.1.motion.servo.stress=2500"});
  ASSERT_EQ(c.walls.size(), 7u);
  ASSERT_EQ(c.wall_groups.size(), 1u);
  EXPECT_EQ(c.wall_groups[0].name, "top");
  EXPECT_EQ(c.wall_groups[0].first, 1);
  EXPECT_EQ(c.wall_groups[0].count, 6);
  double area = 0;
  for (int k = 0; k < 6; ++k) {
    const WallConfig& w = c.walls[static_cast<std::size_t>(1 + k)];
    EXPECT_EQ(w.name, "top_" + std::to_string(k + 1));
    EXPECT_EQ(w.kind, WallConfig::kBox);
    EXPECT_EQ(w.node, 1);
    EXPECT_EQ(w.motion.kind, WallMotion::kServo);
    EXPECT_DOUBLE_EQ(w.motion.servo.stress, 2500);  // --set on the entry reaches every segment
    EXPECT_DOUBLE_EQ(w.motion.servo.area, 0);         // auto: the segment's own face
    EXPECT_DOUBLE_EQ(w.min.z, 0.9);
    EXPECT_DOUBLE_EQ(w.max.z, 1.0);
    // numbered along x first: k = j * 3 + i
    const int i = k % 3, j = k / 3;
    EXPECT_NEAR(w.min.x, 0.1 + 0.2 * i, 1e-15);
    EXPECT_NEAR(w.max.x, 0.1 + 0.2 * (i + 1), 1e-15);
    EXPECT_NEAR(w.min.y, 0.2 + 0.3 * j, 1e-15);
    EXPECT_NEAR(w.max.y, 0.2 + 0.3 * (j + 1), 1e-15);
    area += (w.max.x - w.min.x) * (w.max.y - w.min.y);
  }
  EXPECT_EQ(c.walls[3].max.x, 0.7);  // the last segment ends exactly at the box's face
  EXPECT_EQ(c.walls[6].max.y, 0.8);
  EXPECT_NEAR(area, 0.6 * 0.6, 1e-15);
  // [1, 1] is one rigid box plate
  const CaseConfig one = read_case(f, {"walls.1.segments=[1, 1]"});
  ASSERT_EQ(one.walls.size(), 2u);
  EXPECT_EQ(one.walls[1].name, "top_1");
  EXPECT_EQ(one.walls[1].max.x, 0.7);
  // a lab or shaking entry must name one segment
  const InputError e = expect_error(f, {"lab={direct_shear: {shear_walls: [floor], normal_wall: top}}"});
  EXPECT_NE(std::string(e.what()).find("wall 'top' is split into segments (top_1 ... top_6): name one of them"),
            std::string::npos)
      << e.what();
}

TEST(CaseFile, BadOverridesReportedAsSet) {
  TempDir d;
  const std::string f = d.write("o.yaml", kMinimal);
  struct Case { std::string ov, phrase; };
  const std::vector<Case> cases = {
      {"time.stpes=5", "unknown key 'stpes' in time (valid: dt, safety, steps, duration, stop_unbalanced, stop_kinetic_ratio)"},
      {"materials.0.yuong=5", "unknown key 'yuong' in materials[0]"},
      {"bogus=1", "unknown key 'bogus' at the top level"},
      {"time.steps=abc", "time.steps: expected an integer, got 'abc'"},
      {"materials.5.young=1", "index 5 out of range"},
      {"materials.x=1", "select an item by name, materials[name], or by number"},
      {"time.steps.x=1", "is a value, it has no key 'x'"},
      {"time.steps", "expected key.path=value"},
      {"domain.max=[1, 1", "cannot parse the value"},
  };
  for (const auto& k : cases) {
    const InputError e = expect_error(f, {k.ov});
    EXPECT_EQ(e.file().rfind("--set", 0), 0u) << k.ov << ": " << e.what();
    EXPECT_EQ(e.line(), 0) << k.ov;
    EXPECT_NE(std::string(e.what()).find(k.phrase), std::string::npos) << k.ov << ": " << e.what();
  }
  // an error in the file itself is still reported at its line even with overrides present
  const std::string g = d.write("g.yaml", with("density: 2640", "density: -1"));
  const InputError e = expect_error(g, {"time.steps=5"});
  EXPECT_EQ(e.file(), g);
  EXPECT_EQ(e.line(), 3);
}

// ---- the shipped cases

TEST(ShippedCases, DemoAndExamplesAreValid) {
  const fs::path root = source_dir() / "cases";
  const std::vector<std::string> files = {"demo/settle.yaml", "examples/inline.yaml", "examples/sieve.yaml",
                                          "examples/sphere_file.yaml", "examples/walls.yaml"};
  for (const auto& f : files) {
    SCOPED_TRACE(f);
    CaseConfig c;
    ASSERT_NO_THROW(c = read_case((root / f).string())) << f;
    std::vector<SphereRecord> p;
    try {
      p = build_particles(c);
    } catch (const InputError& e) {
      FAIL() << e.what();
    }
    EXPECT_GT(p.size(), 0u);
  }
  const CaseConfig demo = read_case((root / "demo/settle.yaml").string());
  EXPECT_EQ(demo.name, "settle");
  EXPECT_EQ(build_particles(demo).size(), 3000u);
  const CaseConfig sf = read_case((root / "examples/sphere_file.yaml").string());
  const auto ps = build_particles(sf);
  ASSERT_EQ(ps.size(), 8u);
  EXPECT_EQ(ps[6].id, 13);  // auto ids after the largest explicit id (12)
  EXPECT_EQ(ps[7].id, 14);
  EXPECT_DOUBLE_EQ(ps[0].x.z, 0.015);  // offset applied
  const CaseConfig w = read_case((root / "examples/walls.yaml").string());
  ASSERT_EQ(w.walls.size(), 4u);
  EXPECT_EQ(w.walls[2].motion.kind, WallMotion::kVelocity);
  EXPECT_EQ(w.walls[3].motion.kind, WallMotion::kFree);
}

TEST(ShippedCases, CoupledCasesAreValid) {
  const fs::path root = source_dir() / "cases/coupling";
  const CaseConfig c = read_case((root / "sphere_on_plate.yaml").string());
  ASSERT_TRUE(c.coupling.present);
  ASSERT_TRUE(c.fem.present);
  EXPECT_EQ(c.materials[c.coupling.material].name, "iface");
  ASSERT_EQ(c.coupling.surfaces.size(), 1u);
  EXPECT_EQ(c.coupling.surfaces[0].mesh, 0);
  EXPECT_EQ(c.coupling.surfaces[0].face_set, "zmax");
  EXPECT_EQ(c.coupling.subcycle, 0);       // defaults
  EXPECT_EQ(c.coupling.rigid_steps, 0);
  EXPECT_EQ(c.coupling.tolerance, 0.0);    // 0: fem.tolerance
  // 8 x 8 top faces, 4 triangles each.
  EXPECT_EQ(build_coupling_interface(c, build_fe_meshes(c)).size(), 256u);
  const CaseConfig a = read_case((root / "appendix_problem3.yaml").string());
  EXPECT_EQ(a.coupling.subcycle, 10);
  EXPECT_EQ(build_particles(a).size(), 2u);
  // Bad values name the key.
  try {
    read_case((root / "sphere_on_plate.yaml").string(), {"coupling.subcycle=-1"});
    FAIL() << "no error for a negative subcycle";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("coupling.subcycle: must be >= 0"), std::string::npos) << e.what();
  }
  try {
    read_case((root / "sphere_on_plate.yaml").string(), {"coupling.rigid=1"});
    FAIL() << "no error for an unknown key";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("unknown key 'rigid' in coupling"), std::string::npos) << e.what();
  }
}

class BadCaseFiles : public ::testing::TestWithParam<std::string> {};

TEST_P(BadCaseFiles, FailAsTheirFirstLineSays) {
  const fs::path f = source_dir() / "cases/bad" / GetParam();
  std::ifstream in(f);
  ASSERT_TRUE(in) << f;
  std::string first;
  std::getline(in, first);
  std::smatch m;
  ASSERT_TRUE(std::regex_match(first, m, std::regex("# expected error: ([^:]+):([0-9]+): (.*)"))) << first;
  const std::string file = m[1], phrase = m[3];
  const int line = std::stoi(m[2]);
  try {
    const CaseConfig c = read_case(f.string());
    const auto recs = build_particles(c);  // what the command line does next
    std::vector<Vec3> x;
    std::vector<std::int64_t> id;
    for (const auto& r : recs) {
      x.push_back(r.x);
      id.push_back(r.id);
    }
    const auto in_walls = grains_in_walls_error(c, tally_grains_in_walls(c, x.size(), x.data(), id.data()));
    if (in_walls) throw *in_walls;
    if (c.coupling.present) build_coupling_interface(c, build_fe_meshes(c));  // coupled set-up
    FAIL() << "no error for " << f;
  } catch (const InputError& e) {
    EXPECT_EQ(fs::path(e.file()).filename().string(), file) << e.what();
    EXPECT_EQ(e.line(), line) << e.what();
    EXPECT_GT(e.line(), 0);
    EXPECT_NE(std::string(e.what()).find(phrase), std::string::npos) << e.what();
  }
}

std::vector<std::string> bad_case_names() {
  std::vector<std::string> v;
  for (const auto& e : fs::directory_iterator(source_dir() / "cases/bad"))
    if (e.path().extension() == ".yaml") v.push_back(e.path().filename().string());
  std::sort(v.begin(), v.end());
  return v;
}

INSTANTIATE_TEST_SUITE_P(All, BadCaseFiles, ::testing::ValuesIn(bad_case_names()),
                         [](const ::testing::TestParamInfo<std::string>& i) {
                           std::string s = fs::path(i.param).stem().string();
                           for (char& ch : s)
                             if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
                           return s;
                         });

TEST(BadCaseFilesPresent, AtLeastTheRequiredKinds) { EXPECT_GE(bad_case_names().size(), 10u); }

// The laboratory cases: servo walls, motion schedules and the lab section map to the config.
TEST(ShippedCases, LabCasesServoSchedulesAndLab) {
  const fs::path root = source_dir() / "cases";
  const CaseConfig ds = read_case((root / "lab/direct_shear_ci.yaml").string());
  ASSERT_EQ(ds.walls.size(), 10u);
  const WallConfig& top = ds.walls[9];
  EXPECT_EQ(top.name, "top");
  ASSERT_EQ(top.schedule.size(), 2u);
  EXPECT_EQ(top.schedule[0].kind, WallMotion::kServo);
  EXPECT_EQ(top.schedule[0].from_step, 0);
  EXPECT_DOUBLE_EQ(top.schedule[0].servo.stress, 13600.0);
  EXPECT_DOUBLE_EQ(top.schedule[0].servo.gain, 0.5);  // default
  EXPECT_DOUBLE_EQ(top.schedule[0].servo.area, 0.0);  // auto: the box's face
  EXPECT_DOUBLE_EQ(top.schedule[0].servo.axis.z, -1.0);
  EXPECT_EQ(top.schedule[1].from_step, 36000);
  EXPECT_DOUBLE_EQ(top.schedule[1].servo.velocity.x, 0.05);
  const WallConfig& up = ds.walls[5];
  ASSERT_EQ(up.schedule.size(), 2u);
  EXPECT_EQ(up.schedule[0].kind, WallMotion::kFixed);
  EXPECT_EQ(up.schedule[1].kind, WallMotion::kVelocity);
  EXPECT_EQ(ds.lab.kind, LabConfig::kDirectShear);
  EXPECT_EQ(ds.lab.normal_wall, 9);
  EXPECT_EQ(ds.lab.shear_walls.size(), 5u);

  const CaseConfig tx = read_case((root / "lab/triaxial_ci.yaml").string());
  ASSERT_EQ(tx.walls.size(), 6u);
  EXPECT_EQ(tx.walls[0].motion.kind, WallMotion::kServo);
  EXPECT_FALSE(tx.walls[0].motion.servo.has_axis);  // a plane: its normal (set in make_wall)
  const std::array<int, 4> between{2, 3, 4, 5};              // [[ymin, ymax], [bottom, top]]
  EXPECT_EQ(tx.walls[0].motion.servo.area_wall_index, between);
  EXPECT_EQ(tx.lab.kind, LabConfig::kTriaxial);
  const std::array<int, 6> box{0, 1, 2, 3, 4, 5};
  EXPECT_EQ(tx.lab.box, box);
}

// The specimen cases: packing sections map to the config.
TEST(ShippedCases, SpecimenPackingCases) {
  const CaseConfig a = read_case((source_dir() / "cases/specimens/pack_layers_ci.yaml").string());
  ASSERT_TRUE(a.packing.present);
  EXPECT_EQ(a.packing.method, PackingConfig::kLayers);
  EXPECT_EQ(a.packing.layers, 4);
  EXPECT_DOUBLE_EQ(a.packing.porosity, 0.37);
  EXPECT_EQ(a.packing.shake_walls.size(), 2u);
  EXPECT_DOUBLE_EQ(a.packing.shake_frequency, 50);
  EXPECT_EQ(a.steps, 0);  // packs only
  EXPECT_TRUE(a.particles.empty());
  const CaseConfig b = read_case((source_dir() / "cases/specimens/pack_expansion_ci.yaml").string());
  EXPECT_EQ(b.packing.method, PackingConfig::kExpansion);
  EXPECT_EQ(b.packing.expansion_stages, 40);
}
