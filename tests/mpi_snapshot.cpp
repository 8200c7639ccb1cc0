// fdem-test-ranks: 1 2
// Snapshots: two parallel writes, then rank 0 reopens the files with serial HDF5 and checks
// sizes and contents against the gathered input; the XDMF file must list both snapshots.
#include <gtest/gtest.h>

#include "support/mpi_tempdir.hpp"
#include <hdf5.h>
#include <mpi.h>
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "io/snapshot.hpp"

using namespace fdem;

namespace {

int rank_of() { int r; MPI_Comm_rank(MPI_COMM_WORLD, &r); return r; }
int size_of() { int s; MPI_Comm_size(MPI_COMM_WORLD, &s); return s; }

// TempDir: tests/support/mpi_tempdir.hpp


/// Rank r owns `count(r)` particles with ids 1000*r + i; one ghost is appended.
ParticleStore make(int step, int n_per_rank, bool last_rank_empty) {
  const int r = rank_of();
  ParticleStore p;
  const int n = (last_rank_empty && r == size_of() - 1) ? 0 : n_per_rank + r;
  for (int i = 0; i < n; ++i) {
    const double s = 1000.0 * r + i;
    p.push_back({s, 0.5 * s + step, -s / 3.0}, {1.0 * i, 2.0, 3.0 + step}, {0.1, 0.2, 0.3 * r},
                1e-3 * (1 + i % 4), 1.0, 1000 * r + i, i % 2, 0, {s, 0.5 * s, 0.0});
    p.f.back() = {0.0, 0.0, -9.81 * (i + 1)};
  }
  p.n_owned = p.size();
  p.push_back({-1, -1, -1}, {}, {}, 1.0, 1.0, 999999, 0, 0, {});  // ghost: must not be written
  return p;
}

/// Gathers a per-particle array of doubles (k per particle) to rank 0 in rank order.
std::vector<double> gather(const std::vector<double>& local) {
  const int P = size_of();
  int n = static_cast<int>(local.size());
  std::vector<int> counts(P), displs(P);
  MPI_Gather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, MPI_COMM_WORLD);
  int tot = 0;
  for (int i = 0; i < P; ++i) { displs[i] = tot; tot += counts[i]; }
  std::vector<double> all(rank_of() == 0 ? tot : 0);
  MPI_Gatherv(local.data(), n, MPI_DOUBLE, all.data(), counts.data(), displs.data(), MPI_DOUBLE,
              0, MPI_COMM_WORLD);
  return all;
}

template <class T>
std::vector<T> read_ds(hid_t f, const char* name, hid_t mtype, std::vector<hsize_t>& dims) {
  hid_t d = H5Dopen2(f, name, H5P_DEFAULT);
  EXPECT_GE(d, 0) << name;
  if (d < 0) return {};
  hid_t s = H5Dget_space(d);
  const int nd = H5Sget_simple_extent_ndims(s);
  dims.assign(nd, 0);
  H5Sget_simple_extent_dims(s, dims.data(), nullptr);
  hsize_t n = 1;
  for (hsize_t x : dims) n *= x;
  std::vector<T> out(n);
  if (n) EXPECT_GE(H5Dread(d, mtype, H5S_ALL, H5S_ALL, H5P_DEFAULT, out.data()), 0);
  H5Sclose(s);
  H5Dclose(d);
  return out;
}

void check_file(const std::string& file, std::int64_t step, double time, const ParticleStore& p) {
  // Gather the owned input in rank order (the file's order).
  std::vector<double> x, d, f, v, w, r, id, rk;
  for (std::size_t i = 0; i < p.n_owned; ++i) {
    for (int k = 0; k < 3; ++k) {
      x.push_back(p.x[i][k]); d.push_back(p.x[i][k] - p.x0[i][k]); f.push_back(p.f[i][k]);
      v.push_back(p.v[i][k]); w.push_back(p.w[i][k]);
    }
    r.push_back(p.r[i]);
    id.push_back(static_cast<double>(p.id[i]));
    rk.push_back(rank_of());
  }
  const auto X = gather(x), D = gather(d), F = gather(f), V = gather(v), W = gather(w),
             R = gather(r), ID = gather(id), RK = gather(rk);
  if (rank_of() != 0) return;
  const hsize_t N = R.size();

  hid_t h = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(h, 0) << file;
  std::int64_t st = -1;
  double t = -1;
  hid_t a = H5Aopen(h, "step", H5P_DEFAULT);
  H5Aread(a, H5T_NATIVE_INT64, &st);
  H5Aclose(a);
  a = H5Aopen(h, "time", H5P_DEFAULT);
  H5Aread(a, H5T_NATIVE_DOUBLE, &t);
  H5Aclose(a);
  EXPECT_EQ(st, step);
  EXPECT_EQ(t, time);

  std::vector<hsize_t> dims;
  auto cmp3 = [&](const char* name, const std::vector<double>& want) {
    auto got = read_ds<double>(h, name, H5T_NATIVE_DOUBLE, dims);
    ASSERT_EQ(dims.size(), 2u) << name;
    EXPECT_EQ(dims[0], N) << name;
    EXPECT_EQ(dims[1], 3u) << name;
    EXPECT_EQ(got, want) << name;
  };
  cmp3("position", X);
  cmp3("displacement", D);
  cmp3("force", F);
  cmp3("velocity", V);
  cmp3("angular_velocity", W);
  auto rad = read_ds<double>(h, "radius", H5T_NATIVE_DOUBLE, dims);
  ASSERT_EQ(dims, std::vector<hsize_t>{N});
  EXPECT_EQ(rad, R);
  auto ids = read_ds<std::int64_t>(h, "id", H5T_NATIVE_INT64, dims);
  ASSERT_EQ(dims, std::vector<hsize_t>{N});
  for (hsize_t i = 0; i < N; ++i) EXPECT_EQ(static_cast<double>(ids[i]), ID[i]);
  auto ranks = read_ds<std::int32_t>(h, "rank", H5T_NATIVE_INT32, dims);
  ASSERT_EQ(dims, std::vector<hsize_t>{N});
  for (hsize_t i = 0; i < N; ++i) EXPECT_EQ(static_cast<double>(ranks[i]), RK[i]);
  auto mats = read_ds<std::int32_t>(h, "material", H5T_NATIVE_INT32, dims);
  ASSERT_EQ(dims, std::vector<hsize_t>{N});
  for (hsize_t i = 0; i < N; ++i) EXPECT_EQ(mats[i], static_cast<std::int32_t>(ids[i] % 1000) % 2);
  H5Fclose(h);
}

std::string slurp(const std::string& path) {
  std::ifstream f(path);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

long long total_owned(const ParticleStore& p) {
  long long n = static_cast<long long>(p.n_owned), t = 0;
  MPI_Allreduce(&n, &t, 1, MPI_LONG_LONG, MPI_SUM, MPI_COMM_WORLD);
  return t;
}

}  // namespace

TEST(Snapshot, TwoSnapshotsAndXdmf) {
  fdem::testing::TempDir dir("fdem_snap");
  ASSERT_FALSE(dir.path.empty());
  SnapshotWriter w(dir.path, MPI_COMM_WORLD);
  const ParticleStore p1 = make(10, 5, false);
  // On more than one rank the last rank has no particles in the second snapshot.
  const ParticleStore p2 = make(20, 8, size_of() > 1);
  ASSERT_NO_THROW(w.write(10, 0.125, p1));
  ASSERT_NO_THROW(w.write(20, 0.25, p2));
  check_file(dir.path + "/particles_00000010.h5", 10, 0.125, p1);
  check_file(dir.path + "/particles_00000020.h5", 20, 0.25, p2);
  const long long n1 = total_owned(p1), n2 = total_owned(p2);

  if (rank_of() == 0) {
    const std::string x = slurp(dir.path + "/particles.xdmf");
    ASSERT_FALSE(x.empty());
    EXPECT_NE(x.find("CollectionType=\"Temporal\""), std::string::npos);
    EXPECT_NE(x.find("Polyvertex"), std::string::npos);
    EXPECT_NE(x.find("particles_00000010.h5:/position"), std::string::npos);
    EXPECT_NE(x.find("particles_00000020.h5:/position"), std::string::npos);
    EXPECT_NE(x.find("NumberOfElements=\"" + std::to_string(n1) + "\""), std::string::npos);
    EXPECT_NE(x.find("NumberOfElements=\"" + std::to_string(n2) + "\""), std::string::npos);
    EXPECT_NE(x.find("Dimensions=\"" + std::to_string(n2) + " 3\""), std::string::npos);
    EXPECT_NE(x.find("<Time Value=\"0.125\""), std::string::npos);
    EXPECT_NE(x.find("particles_00000020.h5:/displacement"), std::string::npos);
    EXPECT_FALSE(std::filesystem::exists(dir.path + "/particles.xdmf.tmp"));
  }

  // A restarted writer adopts the snapshots up to its restart step only.
  SnapshotWriter w2(dir.path, MPI_COMM_WORLD);
  w2.adopt_existing(15);
  ASSERT_NO_THROW(w2.write(30, 0.375, p1));
  if (rank_of() == 0) {
    const std::string x = slurp(dir.path + "/particles.xdmf");
    EXPECT_NE(x.find("particles_00000010.h5:/position"), std::string::npos);
    EXPECT_EQ(x.find("particles_00000020.h5"), std::string::npos);
    EXPECT_NE(x.find("particles_00000030.h5:/position"), std::string::npos);
  }
}

TEST(Snapshot, NoParticlesAtAll) {
  fdem::testing::TempDir dir("fdem_snap");
  SnapshotWriter w(dir.path, MPI_COMM_WORLD);
  ParticleStore empty;
  ASSERT_NO_THROW(w.write(0, 0.0, empty));
  check_file(dir.path + "/particles_00000000.h5", 0, 0.0, empty);
  if (rank_of() == 0) {
    // An empty snapshot is listed as a comment only (no zero-sized DataItems).
    const std::string x = slurp(dir.path + "/particles.xdmf");
    EXPECT_NE(x.find("particles_00000000.h5"), std::string::npos);
    EXPECT_EQ(x.find("<Grid Name=\"step_"), std::string::npos);
  }
}

TEST(Snapshot, MissingDirectoryThrows) {
  SnapshotWriter w("/nonexistent/fdem/dir", MPI_COMM_WORLD);
  ParticleStore p = make(0, 3, false);
  try {
    w.write(1, 0.0, p);
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/fdem/dir/particles_00000001.h5"),
              std::string::npos) << e.what();
  }
}
