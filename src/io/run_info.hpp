#pragma once
// run.json: the record of one run (or one restart segment of a run), written by rank 0 at the
// start ("running"), at checkpoints and at the end ("finished" / "interrupted" / "diverged" /
// "failed", the last two with a "message").
#include <array>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace fdem {

/// One pair of materials that can touch, with the contact parameters in effect (app/pairs.hpp).
struct PairRecord {
  std::string a, b, touch, friction_from;
  std::string rolling_law = "incremental";  // written to run.json always
  std::string model = "linear";  // contact model; written to run.json only when not linear (older run.json files have none)
  double friction = 0, kt_kn = 0, beta_r = 0, eta_r = 0;
};

/// One rank's share of a particle run (RunInfo::ranks_detail).
struct RankRecord {
  std::int64_t owned = 0, ghosts = 0;   // particles it owns, ghosts it holds (at the end of the segment)
  std::uint64_t bytes = 0, messages = 0;  // sent over the segment (halo exchanges and migration)
  double peak_rss_mb = 0;                 // the process's peak resident memory so far (getrusage), MB
};

/// One rank's share of the FE mesh (RunInfo::fe_ranks).
struct FeRankRecord {
  std::int64_t elements = 0, nodes = 0;  // elements and nodes it owns
  std::int64_t mesh_nodes = 0;           // nodes its copy of the mesh holds (all of them unless fem.distribute)
  double peak_rss_mb = 0;                // the process's peak resident memory so far (getrusage), MB
};

struct RunInfo {
  std::string version;        // fdem version (FDEM_VERSION)
  std::string case_name;      // case file name / case title
  std::string case_file;      // the case file's path as given on the command line
  std::vector<std::string> overrides;  // its --set overrides
  std::string specimen;       // --specimen FILE (absolute path; written as "specimen" when not empty)
  int ranks = 1;
  double dt = 0;              // time step, s
  std::int64_t steps = 0;     // steps done (up to now)
  std::int64_t start_step = 0;  // first step of this segment (> 0 after a restart)
  double simulated_time = 0;  // s
  double wall_time = 0;       // s
  std::int64_t particles_initial = 0, particles_final = 0, particles_removed = 0;
  double particle_steps_per_second = 0;
  double element_updates_per_second = 0;  // FE: elements x steps / FE time
  std::int64_t rebuilds = 0;     // neighbour-list rebuilds (migration + ghost exchange)
  std::int64_t comm_bytes = 0;   // bytes sent by the busiest rank (halo + migration)
  std::string status = "running";  // "finished", "interrupted", "diverged", "failed" or "running"
  std::string message;             // why a run "diverged" or "failed" (written when not empty)
  std::vector<std::pair<std::string, double>> timings;  // stage name -> seconds (in order)
  /// Coupled runs only (written as "coupling": {...} when not empty): subcycle, dt_dem, dt_fe, ...
  std::vector<std::pair<std::string, double>> coupling;
  /// The contact pairs of the case (written as "pairs": [...] when not empty).
  std::vector<PairRecord> pairs;
  /// Particle runs: the process grid and each rank's share (written as "decomposition":
  /// {"grid": [px, py, pz], "ranks": [...]} when not empty).
  std::array<int, 3> grid{0, 0, 0};
  std::vector<RankRecord> ranks_detail;
  /// FE and coupled runs: each rank's share of the FE mesh (written as "fe_partition":
  /// {"ranks": [...]} when not empty).
  std::vector<FeRankRecord> fe_ranks;
};

/// Serialise as pretty JSON (keys below; non-finite numbers become null).
std::string run_json(const RunInfo& info);

/// Write run_json(info) to `path` atomically (path.tmp, then rename). Call on one rank only.
/// Throws std::runtime_error naming the file on failure.
void write_run_json(const std::string& path, const RunInfo& info);

/// JSON string literal (quotes included) with the required escapes.
std::string json_string(const std::string& s);
/// A number as JSON, `digits` significant digits ("%.*g"; 17 round-trips a double); null when
/// not finite.
std::string json_number(double v, int digits = 17);
/// A list of numbers as a JSON array (json_number each).
std::string json_array(const std::vector<double>& v, int digits = 17);

}  // namespace fdem
