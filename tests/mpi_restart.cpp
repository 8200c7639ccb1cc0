// fdem-test-ranks: 2 3
// Checkpoint and restart: a run of 2N steps and a run of N steps, checkpointed to HDF5 and
// restarted on a different number of ranks for N more, end in the same state (bitwise).
#include <gtest/gtest.h>

#include "support/mpi_util.hpp"

#include <cstdio>

#include "app/driver.hpp"
#include "io/checkpoint.hpp"
#include "support/dem_fixtures.hpp"
#include "support/mpi_tempdir.hpp"

using namespace fdem;
using namespace fdem::testing;

namespace {

struct Scene {
  EngineParams prm;
  MaterialTable mats;
  std::vector<Wall> walls;
  ParticleStore p;
};

Scene scene() {
  Scene s;
  const double rho = 2650;
  s.mats = MaterialTable({make_material("sand", 5e6, rho, 0.5, 0.25, 0.05, 1.0),
                          make_material("wall", 5e6, 7800, 0.3)});
  s.p = lattice_block({0.0005, 0.0005, 0.0005}, 10, 8, 10, 1.5e-3, rho, 7, 0.9, 2.02);
  s.walls = {make_plane("floor", {0, 0, 0}, {0, 0, 1}, 1), make_plane("x0", {0, 0, 0}, {1, 0, 0}, 1),
             make_plane("x1", {0.034, 0, 0}, {-1, 0, 0}, 1)};
  // A wall moving with a prescribed velocity: its displacement must be restored too.
  Wall lid = make_plane("lid", {0, 0, 0.05}, {0, 0, -1}, 1);
  lid.motion = Wall::kVelocity;
  lid.vel = {0, 0, -0.2};
  s.walls.push_back(lid);
  s.prm.domain_min = {0, 0, 0};
  s.prm.domain_max = {0.034, 0.028, 0.05};
  s.prm.gravity = {0, 0, -9.81 * 20};
  s.prm.damping = 0.2;
  return s;
}


}  // namespace

TEST(Restart, ContinuesTheSameTrajectoryOnAnotherRankCount) {
  int world = 0, rank = 0;
  MPI_Comm_size(MPI_COMM_WORLD, &world);
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  const int N = 600;
  fdem::testing::TempDir tmp("fdem_restart");
  const std::string path = tmp.path + "/restart.h5";
  Gathered straight, restarted;
  // Reference: 2N steps on all ranks; write a checkpoint at N from a run on 1 rank.
  {
    Scene s = scene();
    DemEngine e(MPI_COMM_WORLD, s.prm, s.mats, s.walls, s.p);
    e.run(2 * N);
    straight = gather(e);
  }
  {
    MPI_Comm one = fdem::testing::first_ranks(1);
    if (one != MPI_COMM_NULL) {
      Scene s = scene();
      DemEngine e(one, s.prm, s.mats, s.walls, s.p);
      e.run(N);
      write_checkpoint(path, one, engine_checkpoint(e));
      MPI_Comm_free(&one);
    }
    MPI_Barrier(MPI_COMM_WORLD);
  }
  {
    Checkpoint ck = read_checkpoint(path, MPI_COMM_WORLD);
    ASSERT_EQ(ck.step, N);
    ASSERT_GT(ck.contacts.size(), 100u);  // history is carried
    Scene s = scene();
    for (std::size_t w = 0; w < s.walls.size(); ++w) { s.walls[w].disp = ck.walls[w].disp; s.walls[w].vel = ck.walls[w].vel; }
    s.prm.dt = ck.dt;
    DemEngine e(MPI_COMM_WORLD, s.prm, s.mats, s.walls, ck.particles, ck.contacts, ck.step, ck.time);
    e.run(N);
    restarted = gather(e);
    EXPECT_EQ(e.step_count(), 2 * N);
  }
  ASSERT_EQ(straight.id, restarted.id);
  std::size_t differ = 0;
  for (std::size_t i = 0; i < straight.id.size(); ++i)
    if (straight.x[i].x != restarted.x[i].x || straight.x[i].y != restarted.x[i].y ||
        straight.x[i].z != restarted.x[i].z || straight.w[i].x != restarted.w[i].x)
      ++differ;
  EXPECT_EQ(differ, 0u) << "restart on " << world << " ranks did not continue bitwise";
}

// Without the contact history the restarted run must differ: the test above can fail.
TEST(Restart, DroppingHistoryChangesTheTrajectory) {
  const int N = 600;
  Scene s = scene();
  DemEngine a(MPI_COMM_WORLD, s.prm, s.mats, s.walls, s.p);
  a.run(N);
  Checkpoint ck = engine_checkpoint(a);
  // Gather the checkpoint on every rank through a file, then restart without history.
  int world = 0, rank = 0;
  MPI_Comm_size(MPI_COMM_WORLD, &world);
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  fdem::testing::TempDir tmp("fdem_restart");
  const std::string path = tmp.path + "/nohist.h5";
  write_checkpoint(path, MPI_COMM_WORLD, ck);
  Checkpoint all = read_checkpoint(path, MPI_COMM_WORLD);
  for (std::size_t w = 0; w < s.walls.size(); ++w) { s.walls[w].disp = all.walls[w].disp; s.walls[w].vel = all.walls[w].vel; }
  s.prm.dt = all.dt;
  DemEngine b(MPI_COMM_WORLD, s.prm, s.mats, s.walls, all.particles, {}, all.step, all.time);
  a.run(N);
  b.run(N);
  const Gathered ga = gather(a), gb = gather(b);
  double maxdiff = 0;
  for (std::size_t i = 0; i < ga.id.size(); ++i) maxdiff = std::max(maxdiff, norm(ga.x[i] - gb.x[i]));
  EXPECT_GT(maxdiff, 1e-9);
}
