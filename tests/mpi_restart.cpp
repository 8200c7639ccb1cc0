// fdem-test-ranks: 2 3
// Checkpoint and restart: a run of 2N steps and a run of N steps, checkpointed to HDF5 and
// restarted on a different number of ranks for N more, end in the same state (bitwise).
#include <gtest/gtest.h>

#include "support/mpi_util.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>

#include <hdf5.h>

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

Scene scene(RollingLaw law = RollingLaw::kIncremental) {
  Scene s;
  const double rho = 2650;
  std::vector<Material> m{make_material("sand", 5e6, rho, 0.5, 0.25, 0.05, 1.0), make_material("wall", 5e6, 7800, 0.3)};
  for (Material& q : m) q.rolling_law = law;
  s.mats = MaterialTable(m);
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

namespace {

void restart_continues(RollingLaw law) {
  int world = 0, rank = 0;
  MPI_Comm_size(MPI_COMM_WORLD, &world);
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  const int N = 600;
  fdem::testing::TempDir tmp("fdem_restart");
  const std::string path = tmp.path + "/restart.h5";
  Gathered straight, restarted;
  // Reference: 2N steps on all ranks; write a checkpoint at N from a run on 1 rank.
  {
    Scene s = scene(law);
    DemEngine e(MPI_COMM_WORLD, s.prm, s.mats, s.walls, s.p);
    e.run(2 * N);
    straight = gather(e);
  }
  {
    MPI_Comm one = fdem::testing::first_ranks(1);
    if (one != MPI_COMM_NULL) {
      Scene s = scene(law);
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
    Scene s = scene(law);
    for (std::size_t w = 0; w < s.walls.size(); ++w) { s.walls[w].disp = ck.walls[w].disp; s.walls[w].vel = ck.walls[w].vel; }
    s.prm.dt = ck.dt;
    DemEngine e(MPI_COMM_WORLD, s.prm, s.mats, s.walls, ck.particles, ck.contacts, ck.step, ck.time);
    e.run(N);
    restarted = gather(e);
    EXPECT_EQ(e.step_count(), 2 * N);
  }
  ASSERT_EQ(straight.id, restarted.id);
  EXPECT_EQ(count_differing(straight, restarted), 0u) << "restart on " << world << " ranks did not continue bitwise";
}

}  // namespace

TEST(Restart, ContinuesTheSameTrajectoryOnAnotherRankCount) { restart_continues(RollingLaw::kIncremental); }

// The total rolling law's history (the whole relative rotation) is checkpointed and continues bitwise.
TEST(Restart, ContinuesTheSameTrajectoryTotalRollingLaw) { restart_continues(RollingLaw::kTotal); }

namespace {
std::vector<std::int64_t> owned_ids(const DemEngine& e) {
  const ParticleStore& p = e.particles();
  std::vector<std::int64_t> ids(p.id.begin(), p.id.begin() + static_cast<std::ptrdiff_t>(p.n_owned));
  std::sort(ids.begin(), ids.end());
  return ids;
}
std::vector<std::array<double, 10>> sorted_records(const std::vector<ContactRecord>& rs) {
  std::vector<std::array<double, 10>> out;
  for (const ContactRecord& r : rs)
    out.push_back({double(r.a), double(r.b), double(r.kind), double(r.sub), r.state.ft.x, r.state.ft.y, r.state.ft.z,
                   r.state.rot.x, r.state.rot.y, r.state.rot.z});
  std::sort(out.begin(), out.end());
  return out;
}
}  // namespace

// Start-up without replicated particles (ParticleInput::kShare): each rank reads a block of the
// checkpoint's rows (never more than its share), the engine routes particles and contact records
// to their owners, and the run is the replicated restart's, bitwise.
TEST(Restart, SharedReadHoldsOnlyItsShareAndContinuesBitwise) {
  // A domain whose first cut (z, 2 ranks) runs through the bed: records of pairs across it must
  // reach both owners (the upper half of scene()'s domain is empty at the checkpoint).
  auto scene = [] {
    Scene s = ::scene();
    s.prm.domain_max.z = 0.034;
    return s;
  };
  int world = 0, rank = 0;
  MPI_Comm_size(MPI_COMM_WORLD, &world);
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  const int N = 600;
  fdem::testing::TempDir tmp("fdem_restart");
  const std::string path = tmp.path + "/restart.h5";
  Gathered straight, shared;
  {
    Scene s = scene();
    DemEngine e(MPI_COMM_WORLD, s.prm, s.mats, s.walls, s.p);
    e.run(2 * N);
    straight = gather(e);
  }
  {
    Scene s = scene();
    DemEngine e(MPI_COMM_WORLD, s.prm, s.mats, s.walls, s.p);
    e.run(N);
    write_checkpoint(path, MPI_COMM_WORLD, engine_checkpoint(e));  // rows in the writer's rank order
  }
  const Checkpoint whole = read_checkpoint(path, MPI_COMM_WORLD);
  const Checkpoint part = read_checkpoint(path, MPI_COMM_WORLD, ReadPart::kShare);
  const std::int64_t n = static_cast<std::int64_t>(whole.particles.size());
  const std::int64_t m = static_cast<std::int64_t>(whole.contacts.size());
  ASSERT_EQ(part.particles_total, n);
  ASSERT_GT(m, 100);
  // Rank k holds rows [n k / P, n (k + 1) / P): its share and nothing more.
  EXPECT_EQ(static_cast<std::int64_t>(part.particles.size()), n * (rank + 1) / world - n * rank / world);
  EXPECT_EQ(static_cast<std::int64_t>(part.contacts.size()), m * (rank + 1) / world - m * rank / world);
  if (part.particles.size() > 0)
    EXPECT_EQ(part.particles.id[0], whole.particles.id[static_cast<std::size_t>(n * rank / world)]);
  std::int64_t counts[2] = {static_cast<std::int64_t>(part.particles.size()), static_cast<std::int64_t>(part.contacts.size())};
  MPI_Allreduce(MPI_IN_PLACE, counts, 2, MPI_INT64_T, MPI_SUM, MPI_COMM_WORLD);
  EXPECT_EQ(counts[0], n);
  EXPECT_EQ(counts[1], m);

  Scene s = scene();
  for (std::size_t w = 0; w < s.walls.size(); ++w) { s.walls[w].disp = whole.walls[w].disp; s.walls[w].vel = whole.walls[w].vel; }
  s.prm.dt = whole.dt;
  DemEngine rep(MPI_COMM_WORLD, s.prm, s.mats, s.walls, whole.particles, whole.contacts, whole.step, whole.time);
  DemEngine e(MPI_COMM_WORLD, s.prm, s.mats, s.walls, part.particles, part.contacts, part.step, part.time,
              ParticleInput::kShare);
  // The same particles owned on every rank, the same records handed back, the same step.
  EXPECT_EQ(owned_ids(e), owned_ids(rep));
  EXPECT_EQ(e.particles().size(), e.particles().n_owned);  // no ghosts yet
  EXPECT_EQ(sorted_records(e.history_records()), sorted_records(rep.history_records()));
  EXPECT_EQ(e.dt(), rep.dt());
  EXPECT_EQ(e.critical_dt_estimate(), rep.critical_dt_estimate());
  e.run(N);
  shared = gather(e);
  EXPECT_EQ(e.step_count(), 2 * N);
  ASSERT_EQ(straight.id, shared.id);
  EXPECT_EQ(count_differing(straight, shared), 0u) << "shared restart on " << world << " ranks did not continue bitwise";
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

// A checkpoint written before the order keys existed (no /particles/key): the restart gives its
// particles keys from their positions there, so it continues on the same trajectory to round-off
// but sums contacts in another order (not bitwise); with the keys it is bitwise (tests above).
TEST(Restart, CheckpointWithoutOrderKeysContinuesToRoundOff) {
  const int N = 600;
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  Scene s = scene();
  DemEngine a(MPI_COMM_WORLD, s.prm, s.mats, s.walls, s.p);
  a.run(N);
  fdem::testing::TempDir tmp("fdem_restart");
  const std::string path = tmp.path + "/nokeys.h5";
  write_checkpoint(path, MPI_COMM_WORLD, engine_checkpoint(a));
  int deleted = 0;
  if (rank == 0) {  // the older layout: the same file without the keys' dataset
    const hid_t f = H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    deleted = f >= 0 && H5Ldelete(f, "/particles/key", H5P_DEFAULT) >= 0 ? 1 : 0;
    if (f >= 0) H5Fclose(f);
  }
  MPI_Bcast(&deleted, 1, MPI_INT, 0, MPI_COMM_WORLD);
  ASSERT_EQ(deleted, 1);
  Checkpoint ck = read_checkpoint(path, MPI_COMM_WORLD);
  ASSERT_EQ(ck.particles.key.size(), ck.particles.size());
  for (std::int64_t k : ck.particles.key) ASSERT_EQ(k, kNoKey);
  for (std::size_t w = 0; w < s.walls.size(); ++w) { s.walls[w].disp = ck.walls[w].disp; s.walls[w].vel = ck.walls[w].vel; }
  s.prm.dt = ck.dt;
  DemEngine b(MPI_COMM_WORLD, s.prm, s.mats, s.walls, ck.particles, ck.contacts, ck.step, ck.time);
  // the keys it gave: from the positions at the restart
  const ParticleStore& q = b.particles();
  for (std::size_t i = 0; i < q.n_owned; ++i) ASSERT_EQ(q.key[i], order_key(q.x[i], s.prm.domain_min, s.prm.domain_max));
  a.run(N);
  b.run(N);
  const Gathered ga = gather(a), gb = gather(b);
  ASSERT_EQ(ga.id, gb.id);
  double maxdiff = 0;
  for (std::size_t i = 0; i < ga.id.size(); ++i) maxdiff = std::max(maxdiff, norm(ga.x[i] - gb.x[i]));
  if (rank == 0)
    std::printf("[restart] without order keys: %zu of %zu grains differ, largest position difference %.3e m\n",
                count_differing(ga, gb), ga.id.size(), maxdiff);
  EXPECT_GT(count_differing(ga, gb), 0u);  // another summation order (the test can tell)
  EXPECT_LT(maxdiff, 1e-9);                // round-off (grains of 1.5 mm)
}
