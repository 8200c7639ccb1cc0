#pragma once
// Input errors: always-on verification of user input (case files, particle and mesh files,
// command-line options). The message names the file, the line and what is wrong; the command
// line prints it once (rank 0) and exits with code 2.
//
// Also the checks of the program's own invariants (not of user input): FDEM_VERIFY(cond, msg),
// always on, throws InternalError (a std::logic_error) naming the source file:line, the
// condition and msg; FDEM_ASSERT(cond, msg) is the same in debug builds and nothing under NDEBUG
// (for checks on hot paths).
#include <stdexcept>
#include <string>

namespace fdem {

class InputError : public std::runtime_error {
 public:
  InputError(std::string file, int line, const std::string& what)
      : std::runtime_error(format(file, line, what)), file_(std::move(file)), line_(line) {}
  const std::string& file() const { return file_; }
  int line() const { return line_; }

  static std::string format(const std::string& file, int line, const std::string& what) {
    std::string s = file;
    if (line > 0) s += ":" + std::to_string(line);
    return s + ": error: " + what;
  }

 private:
  std::string file_;
  int line_;
};

/// A run that went non-finite or exploded (particles ejected, overlaps beyond the limit, NaN
/// displacements): thrown on every rank alike (the decision comes from a global reduction), the
/// message names the step, the particle / element / node and the likely cause. The command line
/// prints it once (rank 0) and exits with code 3; run.json says "diverged"; no checkpoint of the
/// bad state is written (the last one written before it is kept).
class RunDiverged : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A broken invariant of the program itself (a bug, not bad input): thrown by FDEM_VERIFY /
/// FDEM_ASSERT with the source file:line, the failed condition and a message.
class InternalError : public std::logic_error {
 public:
  InternalError(const char* file, int line, const char* cond, const std::string& what)
      : std::logic_error(std::string(file) + ":" + std::to_string(line) + ": internal error: " + what + " (" + cond +
                         " is false)"),
        file_(file), line_(line) {}
  const char* file() const { return file_; }
  int line() const { return line_; }

 private:
  const char* file_;
  int line_;
};

}  // namespace fdem

/// Always-on check of an invariant: throws fdem::InternalError naming file:line when cond is false.
#define FDEM_VERIFY(cond, msg)                                                    \
  do {                                                                            \
    if (!(cond)) throw ::fdem::InternalError(__FILE__, __LINE__, #cond, (msg));   \
  } while (0)

/// Debug-only check (compiled out under NDEBUG, i.e. in Release builds): as FDEM_VERIFY.
#ifdef NDEBUG
#define FDEM_ASSERT(cond, msg) \
  do {                         \
  } while (0)
#else
#define FDEM_ASSERT(cond, msg) FDEM_VERIFY(cond, msg)
#endif
