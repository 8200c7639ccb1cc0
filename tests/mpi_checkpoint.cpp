// fdem-test-ranks: 1 2 3
// Checkpoint round trip: every rank writes its own particles/contacts, every rank reads the
// whole file back; all values must come back bitwise, each particle exactly once.
#include <gtest/gtest.h>

#include "support/mpi_tempdir.hpp"
#include <mpi.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include "io/checkpoint.hpp"
#include "base/errors.hpp"
#include "io/fe_checkpoint.hpp"

using namespace fdem;

namespace {

int rank_of(MPI_Comm c = MPI_COMM_WORLD) { int r; MPI_Comm_rank(c, &r); return r; }
int size_of(MPI_Comm c = MPI_COMM_WORLD) { int s; MPI_Comm_size(c, &s); return s; }

/// A fresh directory shared by all ranks (made by rank 0), removed by the destructor.
// TempDir: tests/support/mpi_tempdir.hpp


bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }
bool same_bits(const Vec3& a, const Vec3& b) {
  return same_bits(a.x, b.x) && same_bits(a.y, b.y) && same_bits(a.z, b.z);
}

// Deterministic, awkward values derived from the id (non-terminating fractions, a negative
// zero, a subnormal, huge and tiny magnitudes) so that any conversion would show.
Vec3 vec_of(std::int64_t id, int k) {
  const double b = static_cast<double>(id) + 0.1 * k;
  Vec3 v{b / 3.0, std::sqrt(b + 2.0) * 1e-7, -b / 7.0 * 1e12};
  if (id % 5 == 0) v.x = -0.0;
  if (id % 7 == 3) v.y = std::numeric_limits<double>::denorm_min() * (k + 1);
  return v;
}
double r_of(std::int64_t id) { return 1e-3 * (1.0 + std::fmod(id * 0.618033988749895, 1.0)); }
double m_of(std::int64_t id) { return 2650.0 * 4.18879020478639 * std::pow(r_of(id), 3); }

/// Rank r owns ids r, r+P, r+2P, ... below n_total (or nothing if `empty_rank` == r).
/// Two ghosts are appended to check that only owned particles are written.
ParticleStore make_particles(int n_total, int empty_rank) {
  const int r = rank_of(), P = size_of();
  ParticleStore p;
  if (r != empty_rank) {
    for (std::int64_t id = r; id < n_total; id += P)
      p.push_back(vec_of(id, 0), vec_of(id, 1), vec_of(id, 2), r_of(id), m_of(id), id,
                  static_cast<std::int32_t>(id % 3), static_cast<std::uint8_t>(id % 64),
                  vec_of(id, 3));
  }
  p.n_owned = p.size();
  for (int g = 0; g < 2; ++g)
    p.push_back({1, 2, 3}, {}, {}, 1.0, 1.0, 1000000 + r * 10 + g, 0, 0, {});
  return p;
}

std::vector<ContactRecord> make_contacts(const ParticleStore& p) {
  std::vector<ContactRecord> c;
  for (std::size_t i = 0; i < p.n_owned; ++i) {
    const std::int64_t id = p.id[i];
    ContactRecord pp;
    pp.a = id; pp.b = id + 1; pp.kind = 0; pp.sub = -1;
    pp.state.ft = vec_of(id, 4); pp.state.rot = vec_of(id, 5);
    c.push_back(pp);
    if (id % 2 == 0) {
      ContactRecord pw;
      pw.a = id; pw.b = id % 4; pw.kind = 1; pw.sub = static_cast<std::int32_t>(id % 6) - 1;
      pw.state.ft = vec_of(id, 6); pw.state.rot = vec_of(id, 7);
      c.push_back(pw);
    }
  }
  return c;
}

std::vector<WallState> make_walls(int rank) {
  std::vector<WallState> w(3);
  for (int i = 0; i < 3; ++i) {
    // Only rank 0's copy is written: other ranks pass different values to check that.
    w[i].disp = rank == 0 ? vec_of(100 + i, 0) : Vec3{-1, -1, -1};
    w[i].vel = rank == 0 ? vec_of(200 + i, 1) : Vec3{-2, -2, -2};
  }
  return w;
}

void round_trip(int n_total, int empty_rank, const std::string& path) {
  const int P = size_of();
  Checkpoint local;
  local.step = 123456789012LL;
  local.time = 1.0 / 3.0;
  local.dt = 2.718281828459045e-6;
  local.particles = make_particles(n_total, empty_rank);
  local.contacts = make_contacts(local.particles);
  local.walls = make_walls(rank_of());

  ASSERT_NO_THROW(write_checkpoint(path, MPI_COMM_WORLD, local));
  EXPECT_TRUE(std::filesystem::exists(path));
  EXPECT_FALSE(std::filesystem::exists(path + ".tmp"));

  Checkpoint c;
  ASSERT_NO_THROW(c = read_checkpoint(path, MPI_COMM_WORLD));
  EXPECT_EQ(c.step, local.step);
  EXPECT_TRUE(same_bits(c.time, local.time));
  EXPECT_TRUE(same_bits(c.dt, local.dt));

  // Expected global particle set: every id below n_total not owned by the empty rank.
  std::map<std::int64_t, int> expected;  // id -> count found
  for (std::int64_t id = 0; id < n_total; ++id)
    if (static_cast<int>(id % P) != empty_rank) expected[id] = 0;
  const ParticleStore& p = c.particles;
  EXPECT_EQ(p.n_owned, p.size());
  ASSERT_EQ(p.size(), expected.size());
  ASSERT_EQ(p.f.size(), p.size());
  for (std::size_t i = 0; i < p.size(); ++i) {
    const std::int64_t id = p.id[i];
    auto it = expected.find(id);
    ASSERT_NE(it, expected.end()) << "unexpected id " << id;
    ++it->second;
    EXPECT_TRUE(same_bits(p.x[i], vec_of(id, 0))) << id;
    EXPECT_TRUE(same_bits(p.v[i], vec_of(id, 1))) << id;
    EXPECT_TRUE(same_bits(p.w[i], vec_of(id, 2))) << id;
    EXPECT_TRUE(same_bits(p.x0[i], vec_of(id, 3))) << id;
    EXPECT_TRUE(same_bits(p.r[i], r_of(id))) << id;
    EXPECT_TRUE(same_bits(p.m[i], m_of(id))) << id;
    EXPECT_EQ(p.mat[i], id % 3);
    EXPECT_EQ(p.blocked[i], id % 64);
  }
  for (const auto& [id, n] : expected) EXPECT_EQ(n, 1) << "id " << id;

  // Contacts: the union of every rank's records, each exactly once.
  std::map<std::tuple<std::int64_t, std::int64_t, int>, int> seen;
  std::size_t n_expected = 0;
  for (const auto& [id, n] : expected) n_expected += (id % 2 == 0) ? 2 : 1;
  ASSERT_EQ(c.contacts.size(), n_expected);
  for (const ContactRecord& r : c.contacts) {
    ++seen[{r.a, r.b, r.kind}];
    ASSERT_TRUE(expected.count(r.a)) << r.a;
    if (r.kind == 0) {
      EXPECT_EQ(r.b, r.a + 1);
      EXPECT_EQ(r.sub, -1);
      EXPECT_TRUE(same_bits(r.state.ft, vec_of(r.a, 4)));
      EXPECT_TRUE(same_bits(r.state.rot, vec_of(r.a, 5)));
    } else {
      EXPECT_EQ(r.kind, 1);
      EXPECT_EQ(r.b, r.a % 4);
      EXPECT_EQ(r.sub, static_cast<std::int32_t>(r.a % 6) - 1);
      EXPECT_TRUE(same_bits(r.state.ft, vec_of(r.a, 6)));
      EXPECT_TRUE(same_bits(r.state.rot, vec_of(r.a, 7)));
    }
  }
  for (const auto& [k, n] : seen) EXPECT_EQ(n, 1);

  const std::vector<WallState> w0 = make_walls(0);
  ASSERT_EQ(c.walls.size(), w0.size());
  for (std::size_t i = 0; i < w0.size(); ++i) {
    EXPECT_TRUE(same_bits(c.walls[i].disp, w0[i].disp));
    EXPECT_TRUE(same_bits(c.walls[i].vel, w0[i].vel));
  }
}

}  // namespace

TEST(Checkpoint, RoundTripBitwise) {
  fdem::testing::TempDir d("fdem_ckpt");
  ASSERT_FALSE(d.path.empty());
  round_trip(23, -1, d.path + "/state.h5");
}

TEST(Checkpoint, RankWithoutParticles) {
  fdem::testing::TempDir d("fdem_ckpt");
  // The last rank owns nothing (on one rank: no particles at all, N = 0).
  round_trip(17, size_of() - 1, d.path + "/state.h5");
}

TEST(Checkpoint, OverwriteExisting) {
  fdem::testing::TempDir d("fdem_ckpt");
  const std::string path = d.path + "/state.h5";
  round_trip(5, -1, path);
  round_trip(29, -1, path);  // replaces the first file
}

TEST(Checkpoint, MissingFileThrowsInputError) {
  fdem::testing::TempDir d("fdem_ckpt");
  const std::string path = d.path + "/nope.h5";
  try {
    read_checkpoint(path, MPI_COMM_WORLD);
    FAIL() << "no exception";
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), path);
    EXPECT_NE(std::string(e.what()).find("not found"), std::string::npos) << e.what();
  }
}

TEST(Checkpoint, WrongFormatThrowsInputError) {
  fdem::testing::TempDir d("fdem_ckpt");
  const std::string text = d.path + "/text.h5";
  if (rank_of() == 0) std::ofstream(text) << "this is not HDF5\n";
  MPI_Barrier(MPI_COMM_WORLD);
  EXPECT_THROW(read_checkpoint(text, MPI_COMM_WORLD), InputError);
}

TEST(Checkpoint, UnwritableDirectoryThrows) {
  fdem::testing::TempDir d("fdem_ckpt");
  Checkpoint local;
  EXPECT_THROW(write_checkpoint(d.path + "/no/such/dir/state.h5", MPI_COMM_WORLD, local),
               std::runtime_error);
}

namespace {
/// Rank 0 overwrites the first occurrence of `bytes` in the file with 0xA5 bytes (collective).
bool overwrite_in_file(const std::string& path, const void* bytes, std::size_t n) {
  MPI_Barrier(MPI_COMM_WORLD);  // every rank has finished reading the intact file
  int found = 0;
  if (rank_of() == 0) {
    std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
    std::vector<char> data((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
    const char* b = static_cast<const char*>(bytes);
    auto it = std::search(data.begin(), data.end(), b, b + n);
    if (it != data.end()) {
      f.clear();
      f.seekp(it - data.begin());
      f.write(std::string(n, '\xA5').data(), static_cast<std::streamsize>(n));
      found = f.good() ? 1 : 0;
    }
  }
  MPI_Bcast(&found, 1, MPI_INT, 0, MPI_COMM_WORLD);
  return found == 1;
}
}  // namespace

// Every dataset carries a Fletcher32 checksum: a changed byte in the data is an input error
// naming the dataset (before, it read back as a wrong number).
TEST(Checkpoint, CorruptedDatasetThrowsInputError) {
  fdem::testing::TempDir d("fdem_ckpt");
  const std::string path = d.path + "/state.h5";
  round_trip(23, -1, path);
  const Vec3 x0 = vec_of(0, 0);  // particle 0's position (rank 0's first row of /particles/x)
  ASSERT_TRUE(overwrite_in_file(path, &x0, sizeof x0));
  try {
    read_checkpoint(path, MPI_COMM_WORLD);
    FAIL() << "no exception";
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), path);
    EXPECT_NE(std::string(e.what()).find("checksum mismatch in dataset /particles/x"), std::string::npos) << e.what();
  }
}

// A coupled checkpoint: the FE state is the group /fe of the same file; it round-trips bitwise
// and read_fe_checkpoint finds it there.
TEST(Checkpoint, CoupledCheckpointHoldsFeState) {
  fdem::testing::TempDir d("fdem_ckpt");
  const std::string path = d.path + "/checkpoint.h5";
  Checkpoint dem;
  dem.step = 840;
  dem.particles = make_particles(11, -1);
  FeCheckpoint fe;
  fe.hold = 2;
  fe.step = 840;
  fe.hold_start = 400;
  fe.dim = 3;
  const int r = rank_of(), P = size_of();
  for (std::int64_t n = r; n < 10; n += P) {
    fe.state.node.push_back(n);
    for (int k = 0; k < 3; ++k) {
      fe.state.u.push_back(vec_of(n, 8)[k]);
      fe.state.v.push_back(vec_of(n, 9)[k]);
    }
  }
  fe.state.c_last = 0.125;
  if (r == 0) fe.state.removed = {3, 5};
  ASSERT_NO_THROW(write_coupled_checkpoint(path, MPI_COMM_WORLD, dem, fe));
  EXPECT_FALSE(std::filesystem::exists(path + ".tmp"));
  EXPECT_TRUE(has_fe_state(path));
  EXPECT_EQ(read_checkpoint(path, MPI_COMM_WORLD).particles.size(), 11u);
  const FeCheckpoint back = read_fe_checkpoint(path);
  EXPECT_EQ(back.step, 840);
  EXPECT_EQ(back.hold, 2);
  EXPECT_EQ(back.hold_start, 400);
  ASSERT_EQ(back.state.node.size(), 10u);
  std::map<std::int64_t, std::size_t> row;
  for (std::size_t i = 0; i < back.state.node.size(); ++i) row[back.state.node[i]] = i;
  for (std::int64_t n = 0; n < 10; ++n)
    for (int k = 0; k < 3; ++k) {
      EXPECT_TRUE(same_bits(back.state.u[3 * row.at(n) + k], vec_of(n, 8)[k]));
      EXPECT_TRUE(same_bits(back.state.v[3 * row.at(n) + k], vec_of(n, 9)[k]));
    }
  EXPECT_EQ(back.state.removed, (std::vector<std::int64_t>{3, 5}));
  // A particle-only checkpoint has no FE state.
  const std::string plain = d.path + "/plain.h5";
  write_checkpoint(plain, MPI_COMM_WORLD, dem);
  EXPECT_FALSE(has_fe_state(plain));
  EXPECT_THROW(read_fe_checkpoint(plain), InputError);
}
