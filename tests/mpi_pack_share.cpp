// fdem-test-ranks: 2 3
// Packing without replicated particles (issue 20): between its engines the packer holds each
// rank's share of the specimen only (app/packing.cpp), and the specimen it hands over is a
// share. The packing on P ranks is the packing on one rank, bit for bit, and no rank holds
// more than its share of the grains.
#include <gtest/gtest.h>

#include "support/mpi_util.hpp"

#include <algorithm>
#include <array>
#include <fstream>

#include "app/driver.hpp"
#include "app/packing.hpp"
#include "base/allgather.hpp"
#include "io/case_file.hpp"
#include "support/mpi_tempdir.hpp"

using namespace fdem;
using namespace fdem::testing;

namespace {

// Two frictionless layers with shaking, levelled at the box's top, a surcharge of a dense
// material rained on it, and final steps with the friction restored: every step of the packer
// that adds, removes or sums grains.
const char* kLayers = R"(
name: pack_share
domain: {min: [-0.005, -0.005, -0.005], max: [0.045, 0.045, 0.12]}
time: {safety: 0.3}
damping: 0.2
materials:
  - {name: sand, young: 5.0e6, density: 2650, kt_kn: 0.25, friction: 0.5}
  - {name: smooth, young: 5.0e6, density: 7850, friction: 0.0}
  - {name: heavy, young: 5.0e6, density: 9000, kt_kn: 0.25, friction: 0.5}
walls:
  - {name: bottom, type: plane, material: smooth, point: [0, 0, 0], normal: [0, 0, 1]}
  - {name: xmin, type: plane, material: smooth, point: [0, 0, 0], normal: [1, 0, 0]}
  - {name: xmax, type: plane, material: smooth, point: [0.04, 0, 0], normal: [-1, 0, 0]}
  - {name: ymin, type: plane, material: smooth, point: [0, 0, 0], normal: [0, 1, 0]}
  - {name: ymax, type: plane, material: smooth, point: [0, 0.04, 0], normal: [0, -1, 0]}
packing:
  material: sand
  box: {min: [0, 0, 0], max: [0.04, 0.04, 0.03]}
  layers: 2
  porosity: 0.36
  size: {distribution: uniform, min: 0.003, max: 0.005}
  seed: 11
  friction: 0
  cloud_fraction: 0.25
  shaking: {walls: [xmin, xmax], amplitude: 0.0002, frequency: 50, cycles: 2, direction: [1, 0, 0]}
  settle: {unbalanced: 0.05, max_steps: 20000, check_every: 200}
  level: true
  surcharge: {material: heavy, thickness: 0.006}
  final_steps: 300
)";

// Radius expansion in three stages.
const char* kExpansion = R"(
name: pack_share_expansion
domain: {min: [-0.005, -0.005, -0.005], max: [0.045, 0.045, 0.045]}
time: {safety: 0.3}
damping: 0.2
materials:
  - {name: sand, young: 5.0e6, density: 2650, kt_kn: 0.25, friction: 0.5}
walls:
  - {name: bottom, type: plane, material: sand, point: [0, 0, 0], normal: [0, 0, 1]}
  - {name: top, type: plane, material: sand, point: [0, 0, 0.04], normal: [0, 0, -1]}
  - {name: xmin, type: plane, material: sand, point: [0, 0, 0], normal: [1, 0, 0]}
  - {name: xmax, type: plane, material: sand, point: [0.04, 0, 0], normal: [-1, 0, 0]}
  - {name: ymin, type: plane, material: sand, point: [0, 0, 0], normal: [0, 1, 0]}
  - {name: ymax, type: plane, material: sand, point: [0, 0.04, 0], normal: [0, -1, 0]}
packing:
  method: expansion
  material: sand
  box: {min: [0, 0, 0], max: [0.04, 0.04, 0.04]}
  porosity: 0.42
  size: {distribution: uniform, min: 0.003, max: 0.005}
  seed: 5
  friction: 0
  cloud_fraction: 0.2
  expansion: {stages: 3, stage_steps: 400}
  settle: {unbalanced: 0.05, max_steps: 3000, check_every: 200}
)";

CaseConfig write_and_read(const TempDir& tmp, const std::string& name, const char* text) {
  const std::string path = tmp.path + "/" + name + ".yaml";
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  if (rank == 0) std::ofstream(path) << text;
  MPI_Barrier(MPI_COMM_WORLD);
  return read_case(path);
}

using Row = std::array<double, 15>;

/// Every rank's share gathered on every rank, sorted by id: id, x, v, w, r, m, mat.
std::vector<Row> gather_share(const ParticleStore& p, MPI_Comm comm) {
  std::vector<Row> mine;
  for (std::size_t i = 0; i < p.size(); ++i)
    mine.push_back({double(p.id[i]), p.x[i].x, p.x[i].y, p.x[i].z, p.v[i].x, p.v[i].y, p.v[i].z, p.w[i].x, p.w[i].y,
                    p.w[i].z, p.r[i], p.m[i], double(p.mat[i]), double(p.blocked[i]), 0.0});
  std::vector<Row> all = allgather(mine, comm);
  std::sort(all.begin(), all.end());
  return all;
}

/// Packs case `c` on `comm` (its output in `out`) and returns the set-up it hands over.
Setup pack(CaseConfig c, const std::string& out, MPI_Comm comm) {
  c.out_dir = out;
  RunOptions opt;
  opt.quiet = true;
  Setup s = prepare(c, opt, comm);
  return run_packing(c, std::move(s), opt, comm);
}

/// The packing on all ranks against the packing on one (every rank packs alone too, each in its
/// own directory): the same grains, bitwise; a shared set-up; disjoint shares, none holding more
/// than `most` of an even share.
void same_as_one_rank(const CaseConfig& c, const TempDir& tmp, double most) {
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  const Setup one = pack(c, tmp.path + "/one" + std::to_string(rank), MPI_COMM_SELF);
  const Setup all = pack(c, tmp.path + "/all", MPI_COMM_WORLD);
  ASSERT_TRUE(all.shared);
  // no forces of the packing's last step handed over: the run's first step (and its step-0
  // statistics) must not depend on the route the grains take to their owners (a scatter sends
  // none, one rank keeps its store)
  for (const Setup* s : {&all, &one})
    for (std::size_t i = 0; i < s->particles.size(); ++i)
      ASSERT_TRUE(norm2(s->particles.f[i]) == 0 && norm2(s->particles.t[i]) == 0)
          << "grain " << s->particles.id[i] << " handed over with a force";
  const std::vector<Row> a = gather_share(all.particles, MPI_COMM_WORLD);
  const std::vector<Row> b = gather_share(one.particles, MPI_COMM_SELF);
  ASSERT_GT(b.size(), 500u);
  ASSERT_EQ(a.size(), b.size()) << "the specimens differ in their number of grains";
  std::size_t differ = 0;
  for (std::size_t i = 0; i < a.size(); ++i) differ += a[i] != b[i];
  EXPECT_EQ(differ, 0u) << "grains of the " << size << "-rank packing differ from the 1-rank packing's";
  // shares: disjoint (ids once), every rank below `most` times N / P
  for (std::size_t i = 1; i < a.size(); ++i) ASSERT_LT(a[i - 1][0], a[i][0]) << "a grain is on two ranks";
  const double n = static_cast<double>(all.particles.size()), even = static_cast<double>(a.size()) / size;
  EXPECT_LE(n, most * even) << "rank " << rank << " holds " << n << " grains of " << a.size();
  // the contact histories handed over: each contact on one rank, as many as on one rank
  long long h = static_cast<long long>(all.history.size());
  MPI_Allreduce(MPI_IN_PLACE, &h, 1, MPI_LONG_LONG, MPI_SUM, MPI_COMM_WORLD);
  EXPECT_EQ(h, static_cast<long long>(one.history.size()));
}

}  // namespace

TEST(PackShare, LayersLevelSurchargeAsOnOneRank) {
  TempDir tmp("fdem_packshare");
  const CaseConfig c = write_and_read(tmp, "layers", kLayers);
  same_as_one_rank(c, tmp, 1.6);
  // the specimen files written from the shares: the same text as the one-rank packing's
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  if (rank == 0) {
    std::ifstream f1(tmp.path + "/one0/specimen.txt"), f2(tmp.path + "/all/specimen.txt");
    const std::string t1((std::istreambuf_iterator<char>(f1)), {}), t2((std::istreambuf_iterator<char>(f2)), {});
    EXPECT_GT(t1.size(), 10000u);
    EXPECT_EQ(t1, t2) << "specimen.txt written from the shares differs from the one-rank packing's";
  }
}

TEST(PackShare, ExpansionAsOnOneRank) {
  TempDir tmp("fdem_packshare");
  const CaseConfig c = write_and_read(tmp, "expansion", kExpansion);
  same_as_one_rank(c, tmp, 1.6);
}

// packing.placement: cells -- each rank generates only its block of every cloud's generation
// cells: a different specimen from the sequential clouds', the same on any number of ranks.
TEST(PackShare, CellsCloudsAsOnOneRank) {
  TempDir tmp("fdem_packshare");
  const CaseConfig c = write_and_read(tmp, "cells", (std::string(kLayers) + "  placement: cells\n").c_str());
  ASSERT_EQ(c.packing.placement, ParticleSource::kCells);
  same_as_one_rank(c, tmp, 1.6);
}
