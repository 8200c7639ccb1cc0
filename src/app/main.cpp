// fdem — coupled finite-discrete element code for soil-structure interaction.
//
//   mpirun -n 2 fdem run cases/demo/settle.yaml --out out/demo
//   mpirun -n 2 fdem run cases/coupling/sphere_on_plate.yaml --out out/sphere
//   fdem check cases/demo/settle.yaml
//   fdem --version
//
// Exit codes: 0 success, 1 internal/runtime failure, 2 bad input (case file, particle file,
// command line), 3 the run diverged (non-finite values, overlaps beyond the limit, particles
// ejected, FE displacements non-finite: fdem::RunDiverged; run.json "diverged", the last
// checkpoint written before it kept), 128+N stopped by signal N after writing a checkpoint.
#include <mpi.h>
#include <petscsys.h>
#include <xmmintrin.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <new>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "app/case_checks.hpp"
#include "app/coupled_driver.hpp"
#include "app/driver.hpp"
#include "app/pairs.hpp"
#include "app/fe_driver.hpp"
#include "app/packing.hpp"
#include "io/packing_checkpoint.hpp"
#include "app/specimen.hpp"
#include "io/case_file.hpp"
#include "io/case_schema.hpp"
#include "base/errors.hpp"

namespace {

const char* kUsage =
    "usage: fdem run CASE.yaml [--out DIR] [--set key=value ...] [--restart CHECKPOINT.h5]\n"
    "                [--specimen SPECIMEN.h5] [-q]\n"
    "       fdem check CASE.yaml [--set key=value ...] [--print-case]\n"
    "       fdem schema [--markdown SECTION | --docs FILE | --check-docs FILE]\n"
    "       fdem --version | --help\n"
    "Run with mpirun -n P for P ranks. Case files: docs/case-format.md.\n";

/// An internal failure after the run started: this rank's message, then the whole job stops
/// (exit code 1; other ranks may be blocked in a collective).
[[noreturn]] void abort_run(int rank, const std::exception& e) {
  std::fprintf(stderr, "fdem: rank %d: error: %s\n", rank, e.what());
  std::fflush(stderr);
  MPI_Abort(MPI_COMM_WORLD, 1);
  std::abort();
}

[[noreturn]] void abort_run(int rank, const std::string& what) {
  std::fprintf(stderr, "fdem: rank %d: error: %s\n", rank, what.c_str());
  std::fflush(stderr);
  MPI_Abort(MPI_COMM_WORLD, 1);
  std::abort();
}

/// Rank 0's string on every rank.
std::string bcast_string(const std::string& s, int rank) {
  unsigned long long n = rank == 0 ? s.size() : 0;
  MPI_Bcast(&n, 1, MPI_UNSIGNED_LONG_LONG, 0, MPI_COMM_WORLD);
  std::string r = rank == 0 ? s : std::string(static_cast<std::size_t>(n), '\0');
  if (n > 0) MPI_Bcast(r.data(), static_cast<int>(n), MPI_CHAR, 0, MPI_COMM_WORLD);
  return r;
}

int rank0_print(int rank, FILE* f, const std::string& s) {
  if (rank == 0) { std::fputs(s.c_str(), f); std::fflush(f); }
  return 0;
}

/// packing.place_on_surface: the listed plane walls onto the packed specimen (and say so).
void place_on_surface(const fdem::CaseConfig& c, fdem::Setup& s, int rank, bool quiet) {
  const std::vector<double> moved = fdem::place_walls_on_surface(c, s, MPI_COMM_WORLD);
  if (rank != 0 || quiet) return;
  for (std::size_t i = 0; i < moved.size(); ++i)
    std::printf("fdem: wall '%s' placed on the specimen (moved %.4g m along its %s)\n",
                c.walls[static_cast<std::size_t>(c.packing.surface_walls[i])].name.c_str(), moved[i],
                c.walls[static_cast<std::size_t>(c.packing.surface_walls[i])].kind == fdem::WallConfig::kPlane ? "normal" : "servo axis");
  std::fflush(stdout);
}

/// The command line, parsed.
struct Cli {
  std::string cmd, case_path, out_dir;
  std::vector<std::string> overrides;
  bool print_case = false;  // check --print-case
  fdem::RunOptions opt;
};

/// Where a command stands, for the one error handler (guarded): before `started` an error is the
/// input's (exit 2, printed once by rank 0); after it a failure of the run (the job stops, exit 1).
struct Phase {
  const Cli& cli;
  int rank = 0;
  bool reading = false;  ///< reading the case: "cannot read the case" / out of memory
  bool started = false;
};

/// Runs `fn` under the error rules of the header: InputError 2, RunDiverged 3, a packing
/// stopped by a signal 128 + N; any other error 2 before the run started, else MPI_Abort (1).
template <class Fn>
int guarded(Phase& ph, Fn&& fn) {
  const std::string& case_path = ph.cli.case_path;
  try {
    return fn();
  } catch (const fdem::PackingInterrupted& e) {
    return 128 + e.signal;
  } catch (const fdem::InputError& e) {
    rank0_print(ph.rank, stderr, std::string(e.what()) + "\n");
    return 2;
  } catch (const fdem::RunDiverged& e) {
    rank0_print(ph.rank, stderr, std::string("fdem: error: ") + e.what() + "\n");
    return 3;
  } catch (const std::bad_alloc& e) {
    if (ph.started) abort_run(ph.rank, e);
    rank0_print(ph.rank, stderr, case_path + (ph.reading ? ": error: out of memory while reading the case\n"
                                                         : ": error: out of memory\n"));
    return 2;
  } catch (const std::exception& e) {
    if (ph.started) abort_run(ph.rank, e);
    rank0_print(ph.rank, stderr, case_path + ": error: " + e.what() + "\n");
    return 2;
  } catch (...) {
    if (ph.started) abort_run(ph.rank, "unknown exception");
    rank0_print(ph.rank, stderr, case_path + (ph.reading ? ": error: cannot read the case\n" : ": error: invalid case\n"));
    return 2;
  }
}

/// PETSc for a case with finite elements (without its own signal handlers: ours write the
/// output), finalised before MPI.
class PetscScope {
 public:
  explicit PetscScope(bool on) : on_(on) {
    if (!on_) return;
    PetscOptionsSetValue(nullptr, "-no_signal_handler", nullptr);
    PetscInitializeNoArguments();
    fdem::install_signal_handlers();
  }
  ~PetscScope() {
    if (on_) PetscFinalize();
  }

 private:
  bool on_;
};

/// Parses the arguments after the command; returns an error message or "".
std::string parse_args(const std::vector<std::string>& args, Cli& cli) {
  for (std::size_t i = 1; i < args.size(); ++i) {
    const std::string& a = args[i];
    std::string err;
    auto value = [&](const char* name) -> std::string {
      if (i + 1 >= args.size()) { err = std::string(name) + " needs a value"; return ""; }
      return args[++i];
    };
    if (a == "--out" || a == "-o") cli.out_dir = value("--out");
    else if (a == "--set") cli.overrides.push_back(value("--set"));
    else if (a.rfind("--set=", 0) == 0) cli.overrides.push_back(a.substr(6));
    else if (a == "--restart") cli.opt.restart = value("--restart");
    else if (a == "--specimen") cli.opt.specimen = value("--specimen");
    else if (a == "-q" || a == "--quiet") cli.opt.quiet = true;
    else if (a == "--print-case" && cli.cmd == "check") cli.print_case = true;
    else if (!a.empty() && a[0] == '-') err = "unknown option '" + a + "'";
    else if (cli.case_path.empty()) cli.case_path = a;
    else err = "unexpected argument '" + a + "'";
    if (!err.empty()) return err;
  }
  return cli.case_path.empty() ? "no case file given" : "";
}

/// Reads and validates the case and the command line's files (every rank alike; throws).
fdem::CaseConfig read_input(Cli& cli) {
  fdem::RunOptions& opt = cli.opt;
  const std::string& case_path = cli.case_path;
  fdem::CaseConfig c = fdem::read_case(case_path, cli.overrides);
  if (!cli.out_dir.empty()) c.out_dir = cli.out_dir;
  if (!opt.specimen.empty() && !c.packing.present)
    throw fdem::InputError(case_path, 0, "--specimen: the case has no packing section (a specimen replaces its packing)");
  if (!opt.specimen.empty() && !opt.restart.empty())
    throw fdem::InputError(case_path, 0, "--specimen and --restart exclude each other");
  if (!opt.specimen.empty()) c.specimen_from = std::filesystem::absolute(opt.specimen).lexically_normal().string();
  // The checkpoint to restart from: a readable regular file (named by the flag or the key's line).
  auto checkpoint_problem = [](const std::string& path) {
    const std::string p = fdem::input_file_problem(path);
    return p.rfind("cannot read", 0) == 0 ? std::string("does not exist or cannot be read") : p;
  };
  if (!opt.specimen.empty()) {  // a missing specimen is reported by its reader; a FIFO would block it
    const std::string p = fdem::input_file_problem(opt.specimen);
    if (!p.empty() && p.rfind("cannot read", 0) != 0)
      throw fdem::InputError("--specimen " + opt.specimen, 0, "specimen '" + opt.specimen + "' " + p);
  }
  if (!opt.restart.empty()) {
    const std::string p = fdem::input_file_problem(opt.restart);
    if (!p.empty())
      throw fdem::InputError("--restart " + opt.restart, 0, "checkpoint '" + opt.restart + "' " + checkpoint_problem(opt.restart));
  } else if (!c.restart_from.empty() && !fdem::input_file_problem(c.restart_from).empty()) {
    throw fdem::InputError(c.restart_file.empty() ? c.file : c.restart_file, c.restart_line,
                           "restart.from: checkpoint '" + c.restart_from + "' " + checkpoint_problem(c.restart_from));
  }
  // A packing's checkpoint (the bed after its last finished layer): the packing goes on from it.
  const std::string restart = !opt.restart.empty() ? opt.restart : c.restart_from;
  if (c.packing.present && !restart.empty() && fdem::read_packing_progress(restart)) {
    opt.resume_packing = restart;
    opt.restart.clear();
    c.restart_from.clear();
  }
  // The reader accepts particles + fem only with a coupling section (and coupling only then).
  if (c.fem.present && c.has_particles()) fdem::check_coupled_options(c, opt);
  return c;
}

/// `fdem check`: what the case sets up, for every kind of case.
int cmd_check(const fdem::CaseConfig& c, Phase& ph) {
  const int rank = ph.rank;
  if (ph.cli.print_case) {  // the case as a run would write it to case.yaml
    rank0_print(rank, stdout, fdem::case_yaml_text(c));
    return 0;
  }
  const bool coupled = c.fem.present && c.has_particles();
  if (c.fem.present && !coupled) {
    fdem::check_fe_case(c, MPI_COMM_WORLD);
    return 0;
  }
  fdem::Setup setup = fdem::prepare(c, ph.cli.opt, MPI_COMM_WORLD);
  if (coupled && !(c.packing.present && ph.cli.opt.restart.empty())) {
    fdem::check_coupled_case(c, std::move(setup), MPI_COMM_WORLD);
    return 0;
  }
  if (c.packing.present) {  // (a packing case has no particles yet)
    // the structure first, on every rank: a mesh that cannot be built fails before "ok" is printed
    std::optional<fdem::PackingStructure> structure;
    if (coupled) structure = fdem::packing_structure(c);
    fdem::print_packing_check(c, MPI_COMM_WORLD);
    if (!ph.cli.opt.resume_packing.empty() && rank == 0) {
      const auto pr = fdem::read_packing_progress(ph.cli.opt.resume_packing);
      if (pr->layer_in_progress > 0)
        std::printf("  resumes     in layer %d of %d, settling (stopped %.0f s into it), from %s\n", pr->layer_in_progress,
                    pr->layers, pr->layer_elapsed, ph.cli.opt.resume_packing.c_str());
      else
        std::printf("  resumes     after layer %d of %d, from %s\n", pr->layers_done, pr->layers,
                    ph.cli.opt.resume_packing.c_str());
    }
    if (coupled && rank == 0) {
      const fdem::PackingStructure& ps = *structure;
      std::printf("  interface   %zu triangles from %zu surface(s), material %s (a rigid obstacle while packing)\n",
                  ps.n_triangles(), c.coupling.surfaces.size(), c.coupling.material_names(c.materials).c_str());
      for (const fdem::PackingStructure::Part& p : ps.parts)
        std::printf("  structure   mesh '%s': %zu triangles, %zu elements, joins %s\n", p.mesh.c_str(), p.facets.tris.size(),
                    p.solid_boxes.size(),
                    p.after_layer > 0 ? ("after layer " + std::to_string(p.after_layer)).c_str() : "from the start");
      fdem::print_pair_table(c);
    }
    return 0;
  }
  // Also check that the decomposition works for this number of ranks.
  fdem::DemEngine probe(MPI_COMM_WORLD, setup.params, setup.materials, setup.walls, setup.particles, {}, 0, 0,
                        fdem::particle_input(setup));
  fdem::print_check_summary(c, setup, MPI_COMM_WORLD);
  return 0;
}

/// `fdem run`: [packing | a saved specimen] -> walls placed on it -> the run (particles, FE or
/// both), whichever parts the case has. A packing case without steps ends after the packing;
/// --restart continues the run after it.
int cmd_run(const fdem::CaseConfig& c, Phase& ph) {
  const fdem::RunOptions& opt = ph.cli.opt;
  const bool coupled = c.fem.present && c.has_particles();
  if (c.fem.present && !coupled) {
    ph.started = true;
    return fdem::run_fe_case(c, opt, MPI_COMM_WORLD);
  }
  fdem::Setup setup = fdem::prepare(c, opt, MPI_COMM_WORLD);
  ph.started = true;
  if (c.packing.present && opt.restart.empty()) {
    if (!opt.specimen.empty()) {
      setup = fdem::reuse_specimen(c, std::move(setup), opt.specimen, MPI_COMM_WORLD);
      const long long n = fdem::summarize_particles(setup, MPI_COMM_WORLD).count;
      if (coupled && ph.rank == 0 && !opt.quiet)
        std::printf("fdem: specimen from %s (%lld particles; no packing)\n", opt.specimen.c_str(), n);
    } else if (coupled) {
      // Pack the soil around the structure (held as a rigid obstacle), then couple.
      const fdem::PackingStructure ps = fdem::packing_structure(c);
      setup = fdem::run_packing(c, std::move(setup), opt, MPI_COMM_WORLD, &ps);
    } else {
      setup = fdem::run_packing(c, std::move(setup), opt, MPI_COMM_WORLD);
    }
    place_on_surface(c, setup, ph.rank, opt.quiet);
    if (c.steps == 0 && c.duration == 0) return 0;
  }
  return coupled ? fdem::run_coupled_case(c, std::move(setup), opt, MPI_COMM_WORLD)
                 : fdem::run_case(c, std::move(setup), opt, MPI_COMM_WORLD);
}

struct Command {
  const char* name;
  int (*fn)(const fdem::CaseConfig&, Phase&);
};
const Command kCommands[] = {{"run", cmd_run}, {"check", cmd_check}};

int fdem_main(int argc, char** argv);

/// `fdem schema`: the case schema as JSON Schema (stdout), one section's key table as markdown
/// (--markdown SECTION, "top" for the top level, "ranges" for the ranges), docs/case-format.md
/// with its generated tables brought up to date (--docs FILE, to stdout), or a check that they
/// are (--check-docs FILE: exit 1 naming the first line that differs). Rank 0 only.
int cmd_schema(const std::vector<std::string>& args, int rank) {
  namespace S = fdem::schema;
  if (rank != 0) return 0;
  const auto usage = [] {
    std::fprintf(stderr, "fdem: error: usage: fdem schema [--markdown SECTION | --docs FILE | --check-docs FILE]\n");
    return 2;
  };
  if (args.size() == 1) {
    std::fputs(S::json_schema().c_str(), stdout);
    return 0;
  }
  if (args.size() != 3) return usage();
  const std::string& opt = args[1];
  const std::string& arg = args[2];
  try {
    if (opt == "--markdown") {
      std::fputs((arg == "ranges" ? S::markdown_ranges() : S::markdown_table(arg == "top" ? "" : arg)).c_str(), stdout);
      return 0;
    }
    if (opt != "--docs" && opt != "--check-docs") return usage();
    std::ifstream in(arg);
    if (!in) {
      std::fprintf(stderr, "%s: error: cannot open the file\n", arg.c_str());
      return 2;
    }
    std::stringstream buf;
    buf << in.rdbuf();
    const std::string old = buf.str(), now = S::regenerate_docs(old);
    if (opt == "--docs") {
      std::fputs(now.c_str(), stdout);
      return 0;
    }
    if (old == now) return 0;
    std::size_t i = 0, line = 1;
    while (i < old.size() && i < now.size() && old[i] == now[i]) line += old[i++] == '\n';
    std::fprintf(stderr, "%s:%zu: error: the key tables differ from the case schema (src/io/case_schema_table.cpp); "
                 "regenerate them: fdem schema --docs %s > new.md && mv new.md %s\n", arg.c_str(), line, arg.c_str(), arg.c_str());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: error: %s\n", arg.c_str(), e.what());
    return 2;
  }
}

}  // namespace

// Every exception is caught: inside fdem_main by the one handler (guarded: set-up errors are input
// errors, exit 2, printed once by rank 0; failures of a started run stop the job, exit 1), and
// here as a last resort, so that nothing escapes as std::terminate (SIGABRT, a backtrace per rank).
int main(int argc, char** argv) {
  try {
    return fdem_main(argc, argv);
  } catch (const std::exception& e) {
    int init = 0, rank = 0;
    MPI_Initialized(&init);
    if (init) MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    std::fprintf(stderr, "fdem: rank %d: internal error: %s\n", rank, e.what());
    if (init) MPI_Abort(MPI_COMM_WORLD, 1);
    return 1;
  } catch (...) {
    int init = 0, rank = 0;
    MPI_Initialized(&init);
    if (init) MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    std::fprintf(stderr, "fdem: rank %d: internal error: unknown exception\n", rank);
    if (init) MPI_Abort(MPI_COMM_WORLD, 1);
    return 1;
  }
}

namespace {

int fdem_main(int argc, char** argv) {
  // Flush subnormal numbers to zero (FTZ) and treat subnormal inputs as zero (DAZ): the tiny
  // velocities of a bed at rest otherwise decay into subnormals, which cost ~100x per operation.
  // Deterministic, and the same on every rank.
  _mm_setcsr(_mm_getcsr() | 0x8040);
  // Started without a launcher (a singleton: `fdem check`, a 1-rank run), Open MPI would start a
  // support daemon, needed only by programs that spawn processes (fdem never does), and probe
  // network transports one process never uses: 0.5 s of every start, `fdem check` 0.57 s instead
  // of 0.16 s (AMD guest, 2026-12-06). The tests set the same (CMakeLists.txt, FDEM_TEST_ENV).
  // Under mpirun or srun nothing is changed (the network transport stays the site's choice);
  // other MPI libraries ignore the variables; a user's own settings win.
  if (!std::getenv("OMPI_COMM_WORLD_SIZE") && !std::getenv("PMIX_RANK") && !std::getenv("PMI_RANK")) {
    setenv("OMPI_MCA_ess_singleton_isolated", "1", 0);
    setenv("OMPI_MCA_pml", "ob1", 0);
  }
  MPI_Init(&argc, &argv);
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  const std::vector<std::string> args(argv + 1, argv + argc);
  if (args.empty() || args[0] == "--help" || args[0] == "-h" || args[0] == "help") {
    rank0_print(rank, args.empty() ? stderr : stdout, kUsage);
    MPI_Finalize();
    return args.empty() ? 2 : 0;
  }
  if (args[0] == "--version" || args[0] == "version") {
    rank0_print(rank, stdout, std::string("fdem ") + FDEM_VERSION + "\n");
    MPI_Finalize();
    return 0;
  }
  if (args[0] == "schema") {
    const int code = cmd_schema(args, rank);
    MPI_Finalize();
    return code;
  }
  Cli cli;
  cli.cmd = args[0];
  const Command* command = nullptr;
  for (const Command& k : kCommands)
    if (cli.cmd == k.name) command = &k;
  const std::string arg_error = command ? parse_args(args, cli) : "unknown command '" + cli.cmd + "'";
  if (!arg_error.empty()) {
    rank0_print(rank, stderr, "fdem: error: " + arg_error + "\n" + kUsage);
    MPI_Finalize();
    return 2;
  }

  fdem::install_signal_handlers();
  // Set-up: every rank reads and validates the same input, so every rank fails alike; the
  // message is printed once, by rank 0, and the exit code is 2. Nothing has been written yet.
  Phase ph{cli, rank};
  ph.reading = true;
  fdem::CaseConfig c;
  int code = guarded(ph, [&] { c = read_input(cli); return 0; });
  ph.reading = false;
  if (code == 0) {
    // Pair parameters the case gives but no contact uses (printed once, also by `check`).
    if (c.has_particles() || c.packing.present)
      for (const std::string& w : fdem::pair_warnings(c)) rank0_print(rank, stderr, w + "\n");
    // Numbers that look like another unit, walls off the domain (printed once, also by `check`).
    for (const std::string& w : fdem::case_warnings(c)) rank0_print(rank, stderr, w + "\n");
    // The places the run writes to, before any work (rank 0 checks: it touches the file system).
    if (cli.cmd == "run") {
      std::string path_error;
      if (rank == 0) {
        try {
          fdem::check_output_paths(c, !cli.out_dir.empty());
        } catch (const std::exception& e) {
          path_error = e.what();
        }
      }
      path_error = bcast_string(path_error, rank);
      if (!path_error.empty()) {
        rank0_print(rank, stderr, path_error + "\n");
        code = 2;
      }
    }
  }
  if (code == 0) {
    PetscScope petsc(c.fem.present);
    code = guarded(ph, [&] { return command->fn(c, ph); });
  }
  MPI_Finalize();
  return code;
}

}  // namespace
