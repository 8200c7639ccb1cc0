// Checkpoint and restart with parallel HDF5 (see checkpoint.hpp).
//
// File layout (format "fdem-checkpoint", version 2; version 1, still read, is the same without
// checksums):
//   attributes on /: format (string), version (int32), step (int64), time, dt (double)
//   /particles/{x, v, w, x0} N x 3 double, {r, m} N double, id N int64, mat N int32,
//              blocked N uint8; key N int64 (the order keys, particles.hpp; optional when read:
//              a checkpoint written before they existed gets keys from its positions at the
//              restart, and its continuation sums contacts in another order: equal to round-off,
//              not bitwise)
//   /contacts/{a, b} M int64, {kind, sub} M int32, {ft, rot} M x 3 double
//   /walls/{disp, vel} W x 3 double (rank 0's copy); with load holds also /walls/start W x 3
//   (each wall's displacement when the run began) and the attributes hold, hold_start on /
//   /fe (coupled runs only): the FE state, src/io/fe_checkpoint.cpp
// Rows are in rank order of the writer (each rank's block at an MPI_Exscan offset). Doubles are
// stored as IEEE little-endian binary64, so values round-trip bitwise. Version 2: every
// non-empty dataset is chunked with HDF5's Fletcher32 filter and the file uses the HDF5 1.8+
// format, whose superblock and object headers (the attributes) carry checksums; a corrupted
// byte fails the read, which is reported as an input error naming the dataset.
//
// The file is written to path + ".tmp" and renamed to `path` by rank 0 once it is closed, so a
// crash during the write never leaves a truncated file under the checkpoint's name.
#include "io/checkpoint.hpp"

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <optional>
#include <type_traits>
#include <filesystem>
#include <system_error>

#include "base/collective_error.hpp"
#include "base/errors.hpp"
#include "io/h5_util.hpp"

namespace fdem {

namespace {

constexpr const char* kFormat = "fdem-checkpoint";
constexpr std::int32_t kVersion = kCheckpointVersion;
static_assert(std::is_same_v<hid_t, std::int64_t>, "CheckpointExtra passes hid_t as int64");

/// Test hook (tests/cli_kill_restart.sh): FDEM_TEST_DIE_IN_CHECKPOINT=N makes the N-th checkpoint
/// this process writes end the process with _exit(86) halfway through the file (after the
/// particles, flushed), as a kill -9 during the write would.
void test_die_in_checkpoint(hid_t file) {
  static long count = 0;
  const char* env = std::getenv("FDEM_TEST_DIE_IN_CHECKPOINT");
  if (!env || !*env) return;
  if (++count != std::strtol(env, nullptr, 10)) return;
  H5Fflush(file, H5F_SCOPE_GLOBAL);
  std::fflush(stdout);
  _exit(86);
}

void write_file(const std::string& tmp, MPI_Comm comm, const Checkpoint& c, const CheckpointExtra& extra) {
  using namespace h5;
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  const ParticleStore& p = c.particles_view ? *c.particles_view : c.particles;
  const std::size_t n = std::min(p.n_owned, p.size());
  constexpr bool ck = true;  // Fletcher32 on every dataset

  Handle file = create_parallel(tmp, comm, true);
  Handle dxpl = collective_dxpl(tmp);

  write_attr_string(file, "format", kFormat, tmp);
  write_attr<std::int32_t>(file, "version", kVersion, tmp);
  write_attr<std::int64_t>(file, "step", c.step, tmp);
  write_attr<double>(file, "time", c.time, tmp);
  write_attr<double>(file, "dt", c.dt, tmp);
  if (c.hold >= 0) {  // a run with load holds on walls: where it stands
    write_attr<std::int64_t>(file, "hold", c.hold, tmp);
    write_attr<std::int64_t>(file, "hold_start", c.hold_start, tmp);
  }

  {
    Handle g = create_group(file, "particles", tmp);
    const RowRange rows = row_range(n, comm);
    // Owned particles are the prefix [0, n) of every array, so the arrays are written in place.
    write_rows(g, "x", p.x, rows, dxpl, tmp, ck);
    write_rows(g, "v", p.v, rows, dxpl, tmp, ck);
    write_rows(g, "w", p.w, rows, dxpl, tmp, ck);
    write_rows(g, "x0", p.x0, rows, dxpl, tmp, ck);
    write_rows(g, "r", p.r, rows, dxpl, tmp, ck);
    write_rows(g, "m", p.m, rows, dxpl, tmp, ck);
    write_rows(g, "id", p.id, rows, dxpl, tmp, ck);
    write_rows(g, "mat", p.mat, rows, dxpl, tmp, ck);
    write_rows(g, "blocked", p.blocked, rows, dxpl, tmp, ck);
    write_rows(g, "key", p.key, rows, dxpl, tmp, ck);
  }
  test_die_in_checkpoint(file);
  {
    Handle g = create_group(file, "contacts", tmp);
    const std::size_t m = c.contacts.size();
    const RowRange rows = row_range(m, comm);
    std::vector<std::int64_t> a(m), b(m);
    std::vector<std::int32_t> kind(m), sub(m);
    std::vector<Vec3> ft(m), rot(m);
    for (std::size_t i = 0; i < m; ++i) {
      const ContactRecord& r = c.contacts[i];
      a[i] = r.a; b[i] = r.b; kind[i] = r.kind; sub[i] = r.sub;
      ft[i] = r.state.ft; rot[i] = r.state.rot;
    }
    write_rows(g, "a", a, rows, dxpl, tmp, ck);
    write_rows(g, "b", b, rows, dxpl, tmp, ck);
    write_rows(g, "kind", kind, rows, dxpl, tmp, ck);
    write_rows(g, "sub", sub, rows, dxpl, tmp, ck);
    write_rows(g, "ft", ft, rows, dxpl, tmp, ck);
    write_rows(g, "rot", rot, rows, dxpl, tmp, ck);
  }
  {
    // Walls are replicated; rank 0's copy is written. Every rank must agree on the count
    // (dataset shapes are collective), so rank 0's count is broadcast.
    Handle g = create_group(file, "walls", tmp);
    long long w = static_cast<long long>(c.walls.size());
    MPI_Bcast(&w, 1, MPI_LONG_LONG, 0, comm);
    RowRange rows;
    rows.total = static_cast<hsize_t>(w);
    rows.local = rank == 0 ? rows.total : 0;
    std::vector<Vec3> disp, vel;
    if (rank == 0) {
      for (const WallState& s : c.walls) { disp.push_back(s.disp); vel.push_back(s.vel); }
    }
    write_rows(g, "disp", disp, rows, dxpl, tmp, ck);
    write_rows(g, "vel", vel, rows, dxpl, tmp, ck);
    if (c.hold >= 0) write_rows(g, "start", rank == 0 ? c.wall_start : std::vector<Vec3>{}, rows, dxpl, tmp, ck);
    long long nc = static_cast<long long>(c.wall_check.size());
    MPI_Bcast(&nc, 1, MPI_LONG_LONG, 0, comm);
    if (c.hold >= 0 && nc == w) write_rows(g, "check", rank == 0 ? c.wall_check : std::vector<Vec3>{}, rows, dxpl, tmp, ck);
    long long np = static_cast<long long>(c.phase_from.size());
    MPI_Bcast(&np, 1, MPI_LONG_LONG, 0, comm);
    if (np > 0) {
      RowRange ph;
      ph.total = static_cast<hsize_t>(np);
      ph.local = rank == 0 ? ph.total : 0;
      write_rows(g, "phase_from", rank == 0 ? c.phase_from : std::vector<std::int64_t>{}, ph, dxpl, tmp, ck);
    }
  }
  if (extra) extra(file.get(), dxpl.get(), tmp);
  dxpl.close();
  if (file.close() < 0) fail(tmp, "cannot close file");
}

/// The checkpoint's datasets, read whole; a missing or mis-sized one is an input error naming it.
struct DatasetReader {
  hid_t file;
  const std::string& path;

  void need(const std::string& e) const { if (!e.empty()) throw InputError(path, 0, e); }
  void same(hsize_t got, hsize_t want, const std::string& name) const {
    if (got != want)
      throw InputError(path, 0, "dataset " + name + " has " + std::to_string(got) + " rows, expected " +
                                    std::to_string(want));
  }
};

void read_particles(const DatasetReader& in, ParticleStore& p, const h5::RowShare& sh, std::int64_t& total) {
  using h5::read_rows;
  const hid_t file = in.file;
  std::vector<double> x, v, w, x0;
  hsize_t n = 0, k = 0;
  in.need(read_rows(file, "particles/x", 3, x, n, sh));
  in.need(read_rows(file, "particles/v", 3, v, k, sh)); in.same(k, n, "/particles/v");
  in.need(read_rows(file, "particles/w", 3, w, k, sh)); in.same(k, n, "/particles/w");
  in.need(read_rows(file, "particles/x0", 3, x0, k, sh)); in.same(k, n, "/particles/x0");
  in.need(read_rows(file, "particles/r", 1, p.r, k, sh)); in.same(k, n, "/particles/r");
  in.need(read_rows(file, "particles/m", 1, p.m, k, sh)); in.same(k, n, "/particles/m");
  in.need(read_rows(file, "particles/id", 1, p.id, k, sh)); in.same(k, n, "/particles/id");
  in.need(read_rows(file, "particles/mat", 1, p.mat, k, sh)); in.same(k, n, "/particles/mat");
  in.need(read_rows(file, "particles/blocked", 1, p.blocked, k, sh));
  in.same(k, n, "/particles/blocked");
  const std::size_t N = p.r.size();
  if (h5::exists(file, "particles/key")) {
    in.need(read_rows(file, "particles/key", 1, p.key, k, sh)); in.same(k, n, "/particles/key");
  } else {
    p.key.assign(N, kNoKey);
  }
  total = static_cast<std::int64_t>(n);
  p.x.resize(N); p.v.resize(N); p.w.resize(N); p.x0.resize(N);
  p.f.assign(N, Vec3{}); p.t.assign(N, Vec3{});
  for (std::size_t i = 0; i < N; ++i) {
    p.x[i] = {x[3 * i], x[3 * i + 1], x[3 * i + 2]};
    p.v[i] = {v[3 * i], v[3 * i + 1], v[3 * i + 2]};
    p.w[i] = {w[3 * i], w[3 * i + 1], w[3 * i + 2]};
    p.x0[i] = {x0[3 * i], x0[3 * i + 1], x0[3 * i + 2]};
  }
  p.n_owned = N;
}

void read_contacts(const DatasetReader& in, std::vector<ContactRecord>& contacts, const h5::RowShare& sh) {
  using h5::read_rows;
  const hid_t file = in.file;
  std::vector<std::int64_t> a, b;
  std::vector<std::int32_t> kind, sub;
  std::vector<double> ft, rot;
  hsize_t m = 0, k = 0;
  in.need(read_rows(file, "contacts/a", 1, a, m, sh));
  in.need(read_rows(file, "contacts/b", 1, b, k, sh)); in.same(k, m, "/contacts/b");
  in.need(read_rows(file, "contacts/kind", 1, kind, k, sh)); in.same(k, m, "/contacts/kind");
  in.need(read_rows(file, "contacts/sub", 1, sub, k, sh)); in.same(k, m, "/contacts/sub");
  in.need(read_rows(file, "contacts/ft", 3, ft, k, sh)); in.same(k, m, "/contacts/ft");
  in.need(read_rows(file, "contacts/rot", 3, rot, k, sh)); in.same(k, m, "/contacts/rot");
  contacts.resize(a.size());
  for (std::size_t i = 0; i < contacts.size(); ++i) {
    ContactRecord& r = contacts[i];
    r.a = a[i]; r.b = b[i]; r.kind = kind[i]; r.sub = sub[i];
    r.state.ft = {ft[3 * i], ft[3 * i + 1], ft[3 * i + 2]};
    r.state.rot = {rot[3 * i], rot[3 * i + 1], rot[3 * i + 2]};
  }
}

/// c.hold must be read already: only a run with load holds has the walls' start and check rows.
void read_walls(const DatasetReader& in, Checkpoint& c) {
  using h5::read_rows;
  const hid_t file = in.file;
  std::vector<double> disp, vel;
  hsize_t nw = 0, k = 0;
  in.need(read_rows(file, "walls/disp", 3, disp, nw));
  in.need(read_rows(file, "walls/vel", 3, vel, k)); in.same(k, nw, "/walls/vel");
  c.walls.resize(static_cast<std::size_t>(nw));
  for (std::size_t i = 0; i < c.walls.size(); ++i) {
    c.walls[i].disp = {disp[3 * i], disp[3 * i + 1], disp[3 * i + 2]};
    c.walls[i].vel = {vel[3 * i], vel[3 * i + 1], vel[3 * i + 2]};
  }
  if (c.hold >= 0 && h5::exists(file, "walls/start")) {
    std::vector<double> start;
    in.need(read_rows(file, "walls/start", 3, start, k)); in.same(k, nw, "/walls/start");
    for (std::size_t i = 0; i < c.walls.size(); ++i) c.wall_start.push_back({start[3 * i], start[3 * i + 1], start[3 * i + 2]});
  }
  if (c.hold >= 0 && h5::exists(file, "walls/check")) {
    std::vector<double> chk;
    in.need(read_rows(file, "walls/check", 3, chk, k)); in.same(k, nw, "/walls/check");
    for (std::size_t i = 0; i < c.walls.size(); ++i) c.wall_check.push_back({chk[3 * i], chk[3 * i + 1], chk[3 * i + 2]});
  }
  if (h5::exists(file, "walls/phase_from")) in.need(read_rows(file, "walls/phase_from", 1, c.phase_from, k));
}

}  // namespace

void write_checkpoint(const std::string& path, MPI_Comm comm, const Checkpoint& local,
                      const CheckpointExtra& extra) {
  const std::string tmp = path + ".tmp";
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  try {
    h5::Quiet quiet;
    write_file(tmp, comm, local, extra);  // collective; throws on every rank alike for create errors
  } catch (...) {
    if (rank == 0) {  // do not leave a partial .tmp behind (the real name was never touched)
      std::error_code ec;
      std::filesystem::remove(tmp, ec);
    }
    throw;
  }
  // The file is closed on every rank (H5Fclose is collective): rank 0 moves it into place.
  int ok = 1;
  std::string err;
  if (rank == 0) {
    std::error_code ec;
    std::filesystem::rename(tmp, path, ec);
    if (ec) { ok = 0; err = ec.message(); }
  }
  MPI_Bcast(&ok, 1, MPI_INT, 0, comm);
  if (!ok) {
    throw std::runtime_error(path + ": cannot rename " + tmp + " to the checkpoint name" +
                             (err.empty() ? std::string() : ": " + err));
  }
}

namespace {

/// Every rank opens the file on its own (serial driver) and reads all of it, or `share` of the
/// particle and contact rows (a hyperslab of each dataset).
Checkpoint read_file(const std::string& path, const h5::RowShare& share) {
  using namespace h5;
  auto bad = [&](const std::string& what) -> InputError { return InputError(path, 0, what); };

  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) throw bad("checkpoint file not found");
  if (!std::filesystem::is_regular_file(path, ec)) throw bad("checkpoint is not a regular file");

  Quiet quiet;
  std::string why;
  Handle file = open_read(path, why);
  if (file.get() < 0) throw bad(why + " (cannot read it as a checkpoint)");

  std::string format;
  if (!read_attr_string(file, "format", format) || format != kFormat)
    throw bad("not an fdem checkpoint (attribute format is not \"" + std::string(kFormat) +
              "\")");
  std::int32_t version = 0;
  if (!read_attr(file, "version", version)) throw bad("checkpoint has no version attribute");
  if (version < kCheckpointVersionMin || version > kVersion)
    throw bad("checkpoint format version " + std::to_string(version) + ", this fdem reads " +
              std::to_string(kCheckpointVersionMin) + "-" + std::to_string(kVersion));

  Checkpoint c;
  if (!read_attr(file, "step", c.step)) throw bad("checkpoint has no step attribute");
  if (!read_attr(file, "time", c.time)) throw bad("checkpoint has no time attribute");
  if (!read_attr(file, "dt", c.dt)) throw bad("checkpoint has no dt attribute");
  if (!read_attr(file, "hold", c.hold) || !read_attr(file, "hold_start", c.hold_start)) c.hold = c.hold_start = -1;

  const DatasetReader in{file.get(), path};
  read_particles(in, c.particles, share, c.particles_total);
  read_contacts(in, c.contacts, share);
  read_walls(in, c);
  return c;
}

}  // namespace

Checkpoint read_checkpoint(const std::string& path, MPI_Comm comm, ReadPart part) {
  if (part == ReadPart::kWhole) return read_file(path, {});
  h5::RowShare share;
  MPI_Comm_rank(comm, &share.part);
  MPI_Comm_size(comm, &share.parts);
  // A share reads (and checksums) only its rows: a bad row fails on one rank. Every rank throws
  // the same error, the lowest failing rank's, so that it is reported once and no rank waits.
  Checkpoint c;
  std::optional<InputError> err;
  try {
    c = read_file(path, share);
  } catch (const InputError& e) {
    err = e;
  }
  agree_on_input_error(err, comm);
  return c;
}

}  // namespace fdem
