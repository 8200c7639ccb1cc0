#pragma once
// Reading and validating case files (YAML). Every key: docs/case-format.md.
#include <string>
#include <vector>

#include "io/case.hpp"
#include "io/errors.hpp"

namespace fdem {

/// Read and validate a case file. `overrides` are "dotted.key=value" strings from --set
/// (e.g. "time.steps=500", "materials.0.young=5e7"), applied to the YAML tree before validation.
/// Throws InputError naming the file, the line and what is wrong.
CaseConfig read_case(const std::string& path, const std::vector<std::string>& overrides = {});

}  // namespace fdem
