#pragma once
// Internal to the mesh readers and generators (fem/mesh*.cpp): the small text helpers they share,
// the shape check of a read element, and the interval subdivision of the generators. Not for
// other files: the public API is fem/mesh.hpp.
#include <cstdint>
#include <string>
#include <vector>

#include "fem/mesh.hpp"

namespace fdem::fem::detail {

// ---- text (mesh.cpp) ----

/// The element type's name as in messages ("hex8", ...).
std::string type_name(ElemType t);
/// Whitespace-separated tokens.
std::vector<std::string> split(const std::string& s);
/// Tokens of a thesis-format line: '#' starts a comment; commas count as blanks.
std::vector<std::string> thesis_tokens(std::string line);
/// Whole-string integer / finite number; false (v unchanged) otherwise.
bool parse_int(const std::string& s, std::int64_t& v);
bool parse_double(const std::string& s, double& v);
/// A number for messages: 6 significant digits.
std::string fmt(double x);
/// The lines of a file (a trailing '\r' dropped); throws InputError naming `what` file.
std::vector<std::string> read_lines(const std::string& path, const char* what);

// ---- checks (mesh.cpp) ----

/// Throws InputError(file, line) if element e (just appended) is degenerate (a node twice),
/// inverted or degenerate (Jacobian determinant at a node or the centre, fem/element.hpp's
/// element_min_nodal_detj) or, for Hex20, has a mid-edge node too far from the middle of its edge
/// or a non-positive Jacobian determinant at a Gauss point. Messages: docs/mesh-formats.md.
void check_element_shape(const Mesh& m, std::size_t e, const std::string& file, int line);

// ---- generators (mesh.cpp) ----

/// Subdivision of [a, b] into n equal parts (the last point exactly b), appended to xs.
void append_points(std::vector<double>& xs, double a, double b, int n);
/// Parts of length at most h (up to round-off) for a length len; at least 1.
int parts(double len, double h);

}  // namespace fdem::fem::detail
