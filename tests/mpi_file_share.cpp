// fdem-test-ranks: 2 3
// Sphere files without replicated particles (issue 20): each rank reads the lines in its byte
// range of the file, and the particles, ids, messages and the run are those of a 1-rank read.
#include <gtest/gtest.h>

#include "support/mpi_util.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "app/driver.hpp"
#include "app/particle_input.hpp"
#include "dem/generate.hpp"
#include "io/case_file.hpp"
#include "support/dem_fixtures.hpp"
#include "support/mpi_tempdir.hpp"

using namespace fdem;
using namespace fdem::testing;

namespace {

const int kNx = 20, kNy = 8, kNz = 10;  // 1 600 grains on a 5 mm lattice, jittered

// The sphere file's lines: a header comment, then "id x y z r" with scattered ids (not in line
// order), a blank line and a comment every 100 lines, CRLF endings on every seventh line.
std::vector<std::string> sphere_lines() {
  std::vector<std::string> out{"# id x y z r (test file)"};
  int k = 0;
  for (int iz = 0; iz < kNz; ++iz)
    for (int iy = 0; iy < kNy; ++iy)
      for (int ix = 0; ix < kNx; ++ix, ++k) {
        const double j = 0.0004 * std::sin(1.7 * k);  // deterministic jitter
        char buf[160];
        std::snprintf(buf, sizeof buf, "%d %.17g %.17g %.17g %.17g%s", (k * 7919) % 100003 + 10,
                      0.0035 + 0.005 * ix + j, 0.0035 + 0.005 * iy - j, 0.0035 + 0.005 * iz + 0.5 * j,
                      0.002 + 0.0002 * std::cos(k), k % 7 == 3 ? "\r" : "");
        out.push_back(buf);
        if (k % 100 == 99 && k + 1 < kNx * kNy * kNz) {
          out.push_back("");
          out.push_back("   # comment after sphere " + std::to_string(k));
        }
      }
  return out;
}

// The case: the sphere file, then two inline spheres (an explicit id and an automatic one).
const char* kCase = R"(
domain: {min: [0, 0, 0], max: [0.1, 0.045, 0.12]}
gravity: [0, 0, -9.81]
damping: 0.2
materials:
  - {name: sand, young: 5.0e6, kt_kn: 0.25, friction: 0.5, density: 2650}
particles:
  - file: {path: spheres.txt, material: sand}
  - inline:
      material: sand
      spheres:
        - {id: 5, x: [0.01, 0.01, 0.11], r: 0.002}
        - [0.05, 0.02, 0.11, 0.002]
walls:
  - {name: floor, type: plane, material: sand, point: [0, 0, 0], normal: [0, 0, 1]}
constraints:
  - {ids: [5], block: [x, y, z]}
time: {dt: 1.0e-5, steps: 10}
)";

/// The case and its sphere file (`lines`), written once (rank 0) where every rank sees them.
CaseConfig write_case(const TempDir& tmp, const std::vector<std::string>& lines) {
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  if (rank == 0) {
    std::ofstream f(tmp.path + "/spheres.txt", std::ios::binary);
    for (const std::string& l : lines) f << l << "\n";
    std::ofstream(tmp.path + "/case.yaml") << kCase;
  }
  MPI_Barrier(MPI_COMM_WORLD);
  return read_case(tmp.path + "/case.yaml");
}

/// Records gathered from every rank of `comm`, sorted by id: id, x, y, z, r, mat.
std::vector<std::array<double, 6>> gather_records(const std::vector<SphereRecord>& recs, const std::vector<char>& everywhere,
                                                  MPI_Comm comm) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  std::vector<double> loc;
  for (std::size_t k = 0; k < recs.size(); ++k) {
    if (everywhere[k] && rank != 0) continue;
    const SphereRecord& q = recs[k];
    const double row[6] = {double(q.id), q.x.x, q.x.y, q.x.z, q.r, double(q.mat)};
    loc.insert(loc.end(), row, row + 6);
  }
  const std::vector<double> all = allgather(loc, comm);
  std::vector<std::array<double, 6>> rows(all.size() / 6);
  for (std::size_t i = 0; i < rows.size(); ++i) std::copy(&all[6 * i], &all[6 * i] + 6, rows[i].begin());
  std::sort(rows.begin(), rows.end());
  return rows;
}

/// The error `prepare` throws on `comm` (every rank must throw one): file, line, message.
std::array<std::string, 3> prepare_error(const CaseConfig& c, MPI_Comm comm) {
  try {
    (void)prepare(c, RunOptions{}, comm);
  } catch (const InputError& e) {
    return {e.file(), std::to_string(e.line()), e.what()};
  }
  return {"", "", "no error"};
}

/// The same error on every rank of the world as on one rank, naming `file`:`line`, with `text`.
void expect_error(const CaseConfig& c, const std::string& file, int line, const std::string& text) {
  const auto one = prepare_error(c, MPI_COMM_SELF);
  const auto all = prepare_error(c, MPI_COMM_WORLD);
  EXPECT_EQ(all, one) << "the error differs from the 1-rank one";
  EXPECT_EQ(all[0], file);
  EXPECT_EQ(all[1], std::to_string(line));
  EXPECT_NE(all[2].find(text), std::string::npos) << all[2];
}

}  // namespace

// The byte ranges: the parts cover the file, each line once, cut at line starts, numbered as the
// file's lines.
TEST(FileShare, PartsCoverTheFileAtLineStarts) {
  TempDir tmp("fdem_fileshare");
  const std::vector<std::string> lines = sphere_lines();
  const CaseConfig c = write_case(tmp, lines);
  const std::string path = c.particles[0].path;
  const FilePart whole = sphere_file_part(path, 0, 1);
  EXPECT_EQ(whole.newlines, static_cast<std::int64_t>(lines.size()));
  for (int parts : {1, 2, 3, 7, 5000}) {
    std::uint64_t at = 0;
    std::int64_t newlines = 0;
    std::vector<std::int64_t> all_lines;
    std::size_t spheres = 0;
    for (int k = 0; k < parts; ++k) {
      FilePart p = sphere_file_part(path, k, parts);
      EXPECT_EQ(p.begin, at) << "part " << k << " of " << parts;
      at = p.end;
      p.first_line = 1 + newlines;
      newlines += p.newlines;
      spheres += read_sphere_file(path, 1.0, Vec3{}, 0, p, &all_lines).size();
    }
    EXPECT_EQ(at, whole.end) << parts << " parts";
    EXPECT_EQ(newlines, whole.newlines);
    ASSERT_EQ(spheres, static_cast<std::size_t>(kNx * kNy * kNz));
    // the line of sphere k is the line it is on in the file
    for (std::size_t k = 0, s = 0; k < lines.size(); ++k)
      if (!lines[k].empty() && lines[k].find('#') == std::string::npos) {
        ASSERT_EQ(all_lines[s], static_cast<std::int64_t>(k + 1)) << "sphere " << s << ", " << parts << " parts";
        ++s;
      }
  }
}

// Each rank reads its part, and together they are the 1-rank particles (ids, centres, radii,
// the automatic id after the largest explicit one); no rank holds more than its share.
TEST(FileShare, EachRankReadsItsPartOfTheSameParticles) {
  int world = 0, rank = 0;
  MPI_Comm_size(MPI_COMM_WORLD, &world);
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  TempDir tmp("fdem_fileshare");
  const CaseConfig c = write_case(tmp, sphere_lines());
  ASSERT_TRUE(shared_particle_input(c));
  const std::vector<SphereRecord> whole = build_particles(c);  // the replicated read
  const std::int64_t N = kNx * kNy * kNz;
  ASSERT_EQ(static_cast<std::int64_t>(whole.size()), N + 2);
  std::int64_t max_file_id = 0;
  for (std::size_t k = 0; k < static_cast<std::size_t>(N); ++k) max_file_id = std::max(max_file_id, whole[k].id);
  EXPECT_EQ(whole.back().id, max_file_id + 1);  // the automatic id of the second inline sphere
  const ParticleShareRecords sh = read_particle_share(c, MPI_COMM_WORLD);
  const std::int64_t here = std::count(sh.everywhere.begin(), sh.everywhere.end(), 0);
  EXPECT_EQ(static_cast<std::int64_t>(sh.count[0]), here);
  // the lines are of one width within a few characters: each rank holds its N / P within 2 %
  EXPECT_NEAR(static_cast<double>(here), static_cast<double>(N) / world, 0.02 * N / world + 2)
      << "rank " << rank << " read " << here << " of " << N;
  std::vector<char> all_everywhere(whole.size(), 0);
  EXPECT_EQ(gather_records(sh.records, sh.everywhere, MPI_COMM_WORLD),
            gather_records(whole, all_everywhere, MPI_COMM_SELF));
  // the set-up: this rank's part (+ the inline spheres on rank 0), the constraint on its grain
  const fdem::Setup s = prepare(c, RunOptions{}, MPI_COMM_WORLD);
  ASSERT_TRUE(s.shared);
  EXPECT_EQ(static_cast<std::int64_t>(s.particles.size()), here + (rank == 0 ? 2 : 0));
  std::int64_t held = 0;
  for (std::size_t i = 0; i < s.particles.size(); ++i) held += s.particles.blocked[i] == 7 && s.particles.id[i] == 5;
  MPI_Allreduce(MPI_IN_PLACE, &held, 1, MPI_INT64_T, MPI_SUM, MPI_COMM_WORLD);
  EXPECT_EQ(held, 1);
  // and on 2 ranks of 3
  if (world > 2) {
    MPI_Comm two = first_ranks(2);
    if (two != MPI_COMM_NULL) {
      const ParticleShareRecords s2 = read_particle_share(c, two);
      EXPECT_EQ(gather_records(s2.records, s2.everywhere, two), gather_records(whole, all_everywhere, MPI_COMM_SELF));
      MPI_Comm_free(&two);
    }
  }
}

// The run from the file's parts is the run from the whole file on every rank, bitwise.
TEST(FileShare, SharedStartRunsAsTheReplicatedOne) {
  TempDir tmp("fdem_fileshare");
  const CaseConfig c = write_case(tmp, sphere_lines());
  const int N = 300;
  Gathered rep, shared;
  {
    fdem::Setup s = prepare(c, RunOptions{}, MPI_COMM_SELF);  // the whole file, as every rank read it before
    DemEngine e(MPI_COMM_WORLD, s.params, s.materials, s.walls, std::move(s.particles));
    e.run(N);
    rep = gather(e);
  }
  {
    fdem::Setup s = prepare(c, RunOptions{}, MPI_COMM_WORLD);
    DemEngine e(MPI_COMM_WORLD, s.params, s.materials, s.walls, std::move(s.particles), {}, 0, 0, particle_input(s));
    e.run(N);
    shared = gather(e);
  }
  ASSERT_EQ(rep.id.size(), static_cast<std::size_t>(kNx * kNy * kNz + 2));
  ASSERT_EQ(rep.id, shared.id);
  EXPECT_EQ(count_differing(rep, shared), 0u);
}

// Errors found in one rank's part, or only over all parts, are thrown on every rank with the
// message and line of a 1-rank read.
TEST(FileShare, ErrorsNameTheFileLineOnEveryRank) {
  TempDir tmp("fdem_fileshare");
  const std::vector<std::string> good = sphere_lines();
  const std::size_t last = good.size();  // the last line's number (1-based)
  const std::string path = tmp.path + "/spheres.txt";
  auto field = [](const std::string& l, int k) {
    std::istringstream is(l);
    std::string t;
    for (int i = 0; i <= k; ++i) is >> t;
    return t;
  };
  {  // a malformed line near the end (in the last rank's part)
    auto l = good;
    l[last - 2] = "17 0.01 0.02";
    expect_error(write_case(tmp, l), path, static_cast<int>(last - 1), "expected 5 values 'id x y z r', got 3");
  }
  {  // the last line repeats the id of the second line (parts of different ranks)
    auto l = good;
    const std::string id = field(l[1], 0);
    l[last - 1] = id + " 0.09 0.04 0.1 0.002";
    const CaseConfig c = write_case(tmp, l);
    expect_error(c, c.particles[0].source_file, c.particles[0].line,
                 "duplicate particle id " + id + ": given in " + path + ":2 (sphere file of particles[0]) and in " +
                     path + ":" + std::to_string(last) + " (sphere file of particles[0])");
  }
  {  // the inline sphere's explicit id 5 given in the file's last line
    auto l = good;
    l[last - 1] = "5 " + field(l[last - 1], 1) + " " + field(l[last - 1], 2) + " " + field(l[last - 1], 3) + " 0.002";
    const CaseConfig c = write_case(tmp, l);
    const std::string yaml = c.particles[1].source_file + ":" + std::to_string(c.particles[1].line);
    expect_error(c, c.particles[1].source_file, c.particles[1].line,
                 "duplicate particle id 5: given in " + path + ":" + std::to_string(last) +
                     " (sphere file of particles[0]) and in " + yaml + " (particles[1].inline.spheres[0])");
  }
  {  // the last line's sphere coincides with the second line's (far apart in the file)
    auto l = good;
    l[last - 1] = "999999 " + field(l[1], 1) + " " + field(l[1], 2) + " " + field(l[1], 3) + " " + field(l[1], 4);
    expect_error(write_case(tmp, l), path, static_cast<int>(last),
                 "particles " + field(l[1], 0) + " and 999999 overlap by");
  }
  {  // a sphere outside the domain on the last line
    auto l = good;
    l[last - 1] = "999999 0.5 0.02 0.02 0.002";
    expect_error(write_case(tmp, l), path, static_cast<int>(last), "particle id 999999 (particles[0]) at (0.5, 0.02, 0.02) lies outside the domain");
  }
  {  // only comments
    expect_error(write_case(tmp, {"# nothing", "", "  # here"}), path, 0, "the sphere file has no spheres");
  }
}
