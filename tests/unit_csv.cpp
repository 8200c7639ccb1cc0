// CsvWriter and run.json: content checks, numbers parse back to the same doubles.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "io/csv.hpp"
#include "io/run_info.hpp"

using namespace fdem;

namespace {

struct TempDir {
  std::string path;
  TempDir() {
    std::string t = (std::filesystem::temp_directory_path() / "fdem_csv_XXXXXX").string();
    std::vector<char> buf(t.begin(), t.end());
    buf.push_back('\0');
    if (mkdtemp(buf.data())) path = buf.data();
  }
  ~TempDir() { if (!path.empty()) std::filesystem::remove_all(path); }
};

std::vector<std::string> lines(const std::string& path) {
  std::ifstream f(path);
  std::vector<std::string> out;
  for (std::string l; std::getline(f, l);) out.push_back(l);
  return out;
}

std::vector<double> parse(const std::string& line) {
  std::vector<double> v;
  std::stringstream s(line);
  for (std::string cell; std::getline(s, cell, ',');) v.push_back(std::strtod(cell.c_str(), nullptr));
  return v;
}

std::string slurp(const std::string& path) {
  std::ifstream f(path);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

/// Value of "key": <number> in a flat scan of the JSON text (first occurrence).
double json_number(const std::string& j, const std::string& key) {
  const std::string k = "\"" + key + "\":";
  const auto p = j.find(k);
  EXPECT_NE(p, std::string::npos) << key;
  if (p == std::string::npos) return NAN;
  return std::strtod(j.c_str() + p + k.size(), nullptr);
}

}  // namespace

TEST(Csv, HeaderAndFullPrecisionRows) {
  TempDir d;
  const std::string path = d.path + "/history.csv";
  const std::vector<double> r1 = {0, 0, 100, 1.0 / 3.0, 1e-300, 7};
  const std::vector<double> r2 = {10, 2.5e-5, 99, 0.1 + 0.2, -0.0, 12345678901234567.0};
  {
    CsvWriter w(path, {"step", "time", "particles", "kinetic_energy", "unbalanced", "contacts"});
    EXPECT_TRUE(w.active());
    w.row(r1);
    // Flushed per row: readable while the writer is still open.
    EXPECT_EQ(lines(path).size(), 2u);
    w.row(r2);
    EXPECT_THROW(w.row({1, 2}), std::invalid_argument);
  }
  const auto l = lines(path);
  ASSERT_EQ(l.size(), 3u);
  EXPECT_EQ(l[0], "step,time,particles,kinetic_energy,unbalanced,contacts");
  EXPECT_EQ(parse(l[1]), r1);
  const auto p2 = parse(l[2]);
  ASSERT_EQ(p2.size(), r2.size());
  for (std::size_t i = 0; i < r2.size(); ++i)
    EXPECT_EQ(std::memcmp(&p2[i], &r2[i], sizeof(double)), 0) << i;
  EXPECT_EQ(l[1].substr(0, 4), "0,0,");
}

TEST(Csv, InactiveRankWritesNothing) {
  TempDir d;
  const std::string path = d.path + "/walls.csv";
  CsvWriter w(path, {"step", "time"}, false, /*active=*/false);
  EXPECT_FALSE(w.active());
  w.row({1, 2});
  EXPECT_FALSE(std::filesystem::exists(path));
}

TEST(Csv, AppendForRestartDropsLaterRows) {
  TempDir d;
  const std::string path = d.path + "/history.csv";
  {
    CsvWriter w(path, {"step", "time"});
    for (int s = 0; s <= 50; s += 10) w.row({double(s), s * 0.1});
  }
  {
    // Restart from the checkpoint at step 30: rows 40, 50 are dropped, no second header.
    CsvWriter w(path, {"step", "time"}, /*append=*/true, true, /*keep_up_to=*/30);
    w.row({40, 4.0});
  }
  const auto l = lines(path);
  ASSERT_EQ(l.size(), 6u);
  EXPECT_EQ(l[0], "step,time");
  EXPECT_EQ(parse(l[4]), (std::vector<double>{30, 30 * 0.1}));
  EXPECT_EQ(parse(l[5]), (std::vector<double>{40, 4.0}));
  // Append to a missing file writes the header.
  {
    CsvWriter w(d.path + "/new.csv", {"a"}, true);
    w.row({1});
  }
  EXPECT_EQ(lines(d.path + "/new.csv"), (std::vector<std::string>{"a", "1"}));
  // A different header is refused.
  EXPECT_THROW(CsvWriter(path, {"step", "other"}, true), std::runtime_error);
}

// A last column of text (holds.csv's held_by): written as given after the numbers; with a comma,
// quote or line break in it (a mesh or wall name) quoted as RFC 4180 says; a wrong count refused.
TEST(Csv, TextColumnLast) {
  TempDir d;
  const std::string path = d.path + "/holds.csv";
  {
    CsvWriter w(path, {"hold", "step", "held_by"});
    w.row({1, 500}, "fe:grid+dem");
    w.row({2, 1000}, "none");
    EXPECT_THROW(w.row({3}, "none"), std::invalid_argument);
  }
  EXPECT_EQ(lines(path), (std::vector<std::string>{"hold,step,held_by", "1,500,fe:grid+dem", "2,1000,none"}));
  {
    CsvWriter w(d.path + "/q.csv", {"hold", "held_by"});
    w.row({1}, "fe:a,b");
    w.row({2}, "creep:say \"x\"");
  }
  EXPECT_EQ(lines(d.path + "/q.csv"),
            (std::vector<std::string>{"hold,held_by", "1,\"fe:a,b\"", "2,\"creep:say \"\"x\"\"\""}));
  {  // a restart keeps the rows up to its step by the numeric key column
    CsvWriter w(path, {"hold", "step", "held_by"}, /*append=*/true, true, /*keep_up_to=*/1);
    w.row({2, 900}, "servo");
  }
  EXPECT_EQ(lines(path), (std::vector<std::string>{"hold,step,held_by", "1,500,fe:grid+dem", "2,900,servo"}));
}

TEST(Csv, UnwritablePathThrows) {
  EXPECT_THROW(CsvWriter("/nonexistent/dir/x.csv", {"a"}), std::runtime_error);
}

TEST(RunJson, ContentAndAtomicWrite) {
  TempDir d;
  const std::string path = d.path + "/run.json";
  RunInfo r;
  r.version = "0.1.0";
  r.case_name = "settle \"demo\"\n";
  r.ranks = 3;
  r.dt = 1.0 / 3.0 * 1e-6;
  r.steps = 20000;
  r.start_step = 5000;
  r.simulated_time = 0.0066666666666666671;
  r.wall_time = 12.5;
  r.particles_initial = 1000;
  r.particles_final = 990;
  r.particles_removed = 10;
  r.particle_steps_per_second = 1.5e6;
  r.status = "finished";
  r.timings = {{"settle", 10.25}, {"load", 2.25}};
  write_run_json(path, r);
  EXPECT_FALSE(std::filesystem::exists(path + ".tmp"));
  const std::string j = slurp(path);
  ASSERT_FALSE(j.empty());
  EXPECT_EQ(json_number(j, "ranks"), 3);
  EXPECT_EQ(json_number(j, "dt"), r.dt);
  EXPECT_EQ(json_number(j, "steps"), 20000);
  EXPECT_EQ(json_number(j, "start_step"), 5000);
  EXPECT_EQ(json_number(j, "simulated_time"), r.simulated_time);
  EXPECT_EQ(json_number(j, "wall_time_s"), 12.5);
  EXPECT_EQ(json_number(j, "initial"), 1000);
  EXPECT_EQ(json_number(j, "final"), 990);
  EXPECT_EQ(json_number(j, "removed"), 10);
  EXPECT_EQ(json_number(j, "particle_steps_per_second"), 1.5e6);
  EXPECT_EQ(json_number(j, "settle"), 10.25);
  EXPECT_EQ(json_number(j, "load"), 2.25);
  EXPECT_NE(j.find("\"status\": \"finished\""), std::string::npos);
  EXPECT_NE(j.find("\"case\": \"settle \\\"demo\\\"\\n\""), std::string::npos) << j;
  EXPECT_NE(j.find("\"version\": \"0.1.0\""), std::string::npos);
  EXPECT_LT(j.find("settle\":"), j.find("load\":"));  // stage order kept

  // Rewrite (e.g. status update) replaces the file; non-finite numbers become null.
  r.status = "interrupted";
  r.particle_steps_per_second = NAN;
  r.timings.clear();
  write_run_json(path, r);
  const std::string j2 = slurp(path);
  EXPECT_NE(j2.find("\"status\": \"interrupted\""), std::string::npos);
  EXPECT_NE(j2.find("\"particle_steps_per_second\": null"), std::string::npos);
  EXPECT_NE(j2.find("\"timings\": {}"), std::string::npos);
  EXPECT_THROW(write_run_json("/nonexistent/dir/run.json", r), std::runtime_error);
}

TEST(RunJson, ValidJsonAccordingToPython) {
  // Cross-check with a real JSON parser when python3 is available.
  if (std::system("python3 -c 'import json' >/dev/null 2>&1") != 0) GTEST_SKIP();
  TempDir d;
  const std::string path = d.path + "/run.json";
  RunInfo r;
  r.case_name = "tab\there \\ back";
  r.timings = {{"a", 1}, {"b", 2e-9}};
  write_run_json(path, r);
  const std::string cmd = "python3 -c \"import json,sys; d=json.load(open('" + path +
                          "')); sys.exit(0 if d['case']=='tab\\there \\\\\\\\ back' and "
                          "d['timings']['b']==2e-9 else 1)\"";
  EXPECT_EQ(std::system(cmd.c_str()), 0) << slurp(path);
}
