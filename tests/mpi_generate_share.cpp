// fdem-test-ranks: 2 3
// Generated clouds without replicated particles (`placement: cells`, issue 20): each rank builds
// only its block of generation cells, the cloud is the same on any number of ranks, and a run
// started from the shares is the run started from the whole cloud on every rank, bitwise.
#include <gtest/gtest.h>

#include "support/mpi_util.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>

#include "app/driver.hpp"
#include "dem/generate.hpp"
#include "dem/health.hpp"
#include "io/case_file.hpp"
#include "support/dem_fixtures.hpp"
#include "support/mpi_tempdir.hpp"

using namespace fdem;
using namespace fdem::testing;

namespace {

// Two inline spheres (one with an explicit id, held by a constraint), a cells cloud of ~5 500
// grains in 2 x 1 x 2 generation cells (box / (20 d_max)), a sequential cloud above it.
const char* kCase = R"(
domain: {min: [0, 0, 0], max: [0.13, 0.065, 0.17]}
gravity: [0, 0, -98.1]
damping: 0.2
materials:
  - {name: sand, young: 5.0e6, kt_kn: 0.25, friction: 0.5, density: 2650}
particles:
  - inline:
      material: sand
      spheres:
        - {id: 9000, x: [0.005, 0.005, 0.165], r: 0.0015}
        - [0.125, 0.06, 0.165, 0.0012]
  - generate:
      material: sand
      box: {min: [0, 0, 0], max: [0.13, 0.065, 0.13]}
      porosity: 0.94
      seed: 42
      placement: cells
      size: {distribution: uniform, min: 0.002, max: 0.003}
  - generate:
      material: sand
      box: {min: [0, 0, 0.135], max: [0.13, 0.065, 0.16]}
      count: 150
      size: {distribution: uniform, min: 0.002, max: 0.003}
walls:
  - {name: floor, type: plane, material: sand, point: [0, 0, 0], normal: [0, 0, 1]}
constraints:
  - {ids: [9000], block: [x, y, z]}
time: {dt: 1.0e-5, steps: 10}
)";

/// The case file, written once (rank 0) into a directory every rank sees.
CaseConfig read_test_case(const TempDir& tmp, const std::string& extra = "") {
  const std::string path = tmp.path + "/cells.yaml";
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  if (rank == 0) std::ofstream(path) << kCase << extra;
  MPI_Barrier(MPI_COMM_WORLD);
  return read_case(path);
}

/// Every rank's share gathered on every rank, sorted by id: id, x, r, v, m, blocked, mat.
std::vector<std::array<double, 12>> gather_share(const ParticleStore& p, MPI_Comm comm) {
  std::vector<double> loc;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const double row[12] = {double(p.id[i]), p.x[i].x, p.x[i].y, p.x[i].z, p.r[i], p.v[i].x, p.v[i].y, p.v[i].z,
                            p.m[i], double(p.blocked[i]), double(p.mat[i]), p.x0[i].z};
    loc.insert(loc.end(), row, row + 12);
  }
  int size = 1;
  MPI_Comm_size(comm, &size);
  int n = static_cast<int>(loc.size());
  std::vector<int> counts(static_cast<std::size_t>(size)), displs(static_cast<std::size_t>(size));
  MPI_Allgather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, comm);
  int total = 0;
  for (int k = 0; k < size; ++k) { displs[k] = total; total += counts[k]; }
  std::vector<double> all(static_cast<std::size_t>(total));
  MPI_Allgatherv(loc.data(), n, MPI_DOUBLE, all.data(), counts.data(), displs.data(), MPI_DOUBLE, comm);
  std::vector<std::array<double, 12>> rows(all.size() / 12);
  for (std::size_t i = 0; i < rows.size(); ++i) std::copy(&all[12 * i], &all[12 * i] + 12, rows[i].begin());
  std::sort(rows.begin(), rows.end());
  return rows;
}


}  // namespace

// The cloud itself: non-overlapping, every grain inside its generation cell (so no two cells'
// grains can touch), each cell filled to the porosity within one grain, ids consecutive.
TEST(GenerateCells, CellsAreFilledIndependentlyToThePorosity) {
  TempDir tmp("fdem_gencells");
  const CaseConfig c = read_test_case(tmp);
  const ParticleSource& src = c.particles[1];
  const GenerationCells g = generation_cells(src);
  EXPECT_EQ(g.n[0], 2);
  EXPECT_EQ(g.n[1], 1);
  EXPECT_EQ(g.n[2], 2);
  const std::vector<SphereRecord> all = build_particles(c);
  std::vector<double> solid(static_cast<std::size_t>(g.count()), 0.0);
  std::vector<Vec3> x;
  std::vector<double> r;
  std::int64_t first_id = -1, prev = -1;
  for (const SphereRecord& q : all) {
    x.push_back(q.x);
    r.push_back(q.r);
    if (q.x.z > 0.13) continue;  // the inline spheres and the sequential cloud
    if (first_id < 0) first_id = q.id;
    if (prev >= 0) EXPECT_EQ(q.id, prev + 1);
    prev = q.id;
    int i[3];
    for (int k = 0; k < 3; ++k) {
      i[k] = std::min(g.n[k] - 1, static_cast<int>(std::floor((q.x[k] - g.lo[k]) / g.edge[k])));
      const double lo = g.lo[k] + i[k] * g.edge[k], hi = lo + g.edge[k];
      EXPECT_GE(q.x[k] - q.r, lo - 1e-15) << "grain " << q.id << " crosses its cell's face";
      EXPECT_LE(q.x[k] + q.r, hi + 1e-15) << "grain " << q.id << " crosses its cell's face";
    }
    solid[static_cast<std::size_t>((i[2] * g.n[1] + i[1]) * g.n[0] + i[0])] += 4.0 / 3.0 * M_PI * q.r * q.r * q.r;
  }
  EXPECT_EQ(first_id, 9002);  // after the largest explicit id (9000) and the second inline sphere (9001)
  const double cell_volume = g.edge.x * g.edge.y * g.edge.z, grain = M_PI / 6 * 0.003 * 0.003 * 0.003;
  for (double s : solid) EXPECT_NEAR(s, 0.06 * cell_volume, grain) << "a cell is not filled to porosity 0.94";
  EXPECT_EQ(deepest_overlap(x, r, 0.0).ratio, 0.0) << "the cloud overlaps";
}

// Each rank builds only its block of cells; together the blocks are the whole cloud, bitwise,
// whatever the number of ranks; a set-up that holds them (prepare) holds only its share.
TEST(GenerateCells, EachRankBuildsItsBlockOfTheSameCloud) {
  int world = 0, rank = 0;
  MPI_Comm_size(MPI_COMM_WORLD, &world);
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  TempDir tmp("fdem_gencells");
  const CaseConfig c = read_test_case(tmp);
  const fdem::Setup whole = prepare(c, RunOptions{}, MPI_COMM_SELF);  // one rank: the whole cloud
  const fdem::Setup part = prepare(c, RunOptions{}, MPI_COMM_WORLD);
  ASSERT_TRUE(part.shared);
  const std::int64_t n = static_cast<std::int64_t>(whole.particles.size());
  ASSERT_GT(n, 5000);
  // this rank's cells records: its block of the generation cells, no more
  const ParticleShareRecords sh = build_particle_share(c.particles, c.domain_min, c.domain_max, rank, world);
  const std::int64_t cells_here = std::count(sh.everywhere.begin(), sh.everywhere.end(), 0);
  const std::int64_t everywhere = std::count(sh.everywhere.begin(), sh.everywhere.end(), 1);
  EXPECT_EQ(everywhere, 152);
  EXPECT_EQ(static_cast<std::int64_t>(part.particles.size()), cells_here + (rank == 0 ? everywhere : 0));
  if (world > 1) EXPECT_LT(2 * cells_here, n) << "a rank built more than half of the cells cloud";
  // together: the whole cloud, bitwise (ids, centres, radii, masses, constraints)
  EXPECT_EQ(gather_share(part.particles, MPI_COMM_WORLD), gather_share(whole.particles, MPI_COMM_SELF));
  // and the same on a sub-communicator of 2 ranks (any rank count gives the same cloud)
  if (world > 2) {
    MPI_Comm two = first_ranks(2);
    if (two != MPI_COMM_NULL) {
      const fdem::Setup p2 = prepare(c, RunOptions{}, two);
      EXPECT_EQ(gather_share(p2.particles, two), gather_share(whole.particles, MPI_COMM_SELF));
      MPI_Comm_free(&two);
    }
  }
  // the constraint found its particle on the rank holding it
  const auto rows = gather_share(part.particles, MPI_COMM_WORLD);
  const auto held = std::find_if(rows.begin(), rows.end(), [](const auto& q) { return q[0] == 9000; });
  ASSERT_NE(held, rows.end());
  EXPECT_EQ((*held)[9], 7.0);
}

// The run from the shares is the run from the whole cloud on every rank (kReplicated), bitwise,
// and the same as on one rank.
TEST(GenerateCells, SharedStartRunsAsTheReplicatedOne) {
  int world = 0;
  MPI_Comm_size(MPI_COMM_WORLD, &world);
  TempDir tmp("fdem_gencells");
  const CaseConfig c = read_test_case(tmp);
  const int N = 300;
  Gathered rep, shared, one;
  {
    fdem::Setup s = prepare(c, RunOptions{}, MPI_COMM_SELF);
    DemEngine e(MPI_COMM_WORLD, s.params, s.materials, s.walls, std::move(s.particles));
    e.run(N);
    rep = gather(e);
  }
  {
    fdem::Setup s = prepare(c, RunOptions{}, MPI_COMM_WORLD);
    DemEngine e(MPI_COMM_WORLD, s.params, s.materials, s.walls, std::move(s.particles), {}, 0, 0,
                particle_input(s));
    EXPECT_EQ(e.particles().size(), e.particles().n_owned);  // owned only, no ghosts yet
    e.run(N);
    shared = gather(e);
  }
  {
    MPI_Comm c1 = first_ranks(1);
    if (c1 != MPI_COMM_NULL) {
      fdem::Setup s = prepare(c, RunOptions{}, c1);
      DemEngine e(c1, s.params, s.materials, s.walls, std::move(s.particles), {}, 0, 0, particle_input(s));
      e.run(N);
      one = gather(e);
      MPI_Comm_free(&c1);
    }
  }
  ASSERT_EQ(rep.id, shared.id);
  EXPECT_EQ(count_differing(rep, shared), 0u) << "shared start on " << world << " ranks differs from the replicated";
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  if (rank == 0) {
    ASSERT_EQ(rep.id, one.id);
    EXPECT_EQ(count_differing(rep, one), 0u) << world << " ranks differ from 1 rank";
  }
}

// A cell that cannot be filled is found by the rank building it; every rank throws its message.
TEST(GenerateCells, AnOverfullCellIsAnErrorOnEveryRank) {
  TempDir tmp("fdem_gencells");
  CaseConfig c = read_test_case(tmp);
  c.particles[1].porosity = 0.6;  // random addition cannot reach a solid fraction of 0.4
  c.particles[1].max_attempts = 20;
  try {
    (void)prepare(c, RunOptions{}, MPI_COMM_WORLD);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("generation cell 0 of 4"), std::string::npos) << e.what();
    EXPECT_EQ(e.line(), c.particles[1].line);
  }
}
