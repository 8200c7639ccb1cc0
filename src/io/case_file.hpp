#pragma once
// Reading and validating case files (YAML). Every key: docs/case-format.md.
#include <string>
#include <vector>

#include "io/case.hpp"
#include "base/errors.hpp"
#include "base/files.hpp"  // input_file_problem (was declared here)

namespace fdem {

/// Read and validate a case file. `overrides` are "dotted.key=value" strings from --set
/// (e.g. "time.steps=500", "materials.0.young=5e7"), applied to the YAML tree before validation.
/// Throws InputError naming the file, the line and what is wrong.
CaseConfig read_case(const std::string& path, const std::vector<std::string>& overrides = {});

/// The places a run writes to, checked before any work: the output directory (created if
/// missing, a test file written and removed; directories created by the check are removed
/// again) and packing.save (its directory must be writable, the path must not be a directory).
/// `out_from_flag`: the directory came from --out (else output.dir or the default).
/// Call on one rank (it touches the file system). Throws InputError naming the flag or key.
void check_output_paths(const CaseConfig& c, bool out_from_flag);

}  // namespace fdem
