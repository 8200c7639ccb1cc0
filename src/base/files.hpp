#pragma once
// Checks on input files before they are opened.
#include <string>

namespace fdem {

/// A path that is read as an input file must be a regular file (not a directory, FIFO or
/// device: opening a FIFO would block). Returns "" when fine, else why not ("is a directory", ...).
std::string input_file_problem(const std::string& path);

}  // namespace fdem
