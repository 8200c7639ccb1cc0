#pragma once
// Input errors: always-on verification of user input (case files, particle and mesh files,
// command-line options). The message names the file, the line and what is wrong; the command
// line prints it once (rank 0) and exits with code 2.
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

}  // namespace fdem
