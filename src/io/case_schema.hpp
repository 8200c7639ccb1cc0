#pragma once
// The case schema, declared once: every key of a case file with its type, units, default,
// allowed range and meaning (src/io/case_schema.cpp). The table drives
//   - the reader's key checks (`Reader::check_keys` asks it which keys a mapping may have),
//   - the reader's range checks (docs/case-format.md#ranges),
//   - `fdem schema` (a JSON Schema for editors' YAML plugins) and
//   - the key tables of docs/case-format.md (`fdem schema --markdown`; the test
//     `schema_docs` fails when the page and the table drift apart).
// The reader (io/case_file.cpp) still does what a table cannot: cross-key rules, names that must
// exist, geometry that must fit.
#include <string>
#include <vector>

namespace fdem::schema {

enum class Type {
  kNumber,   // a real number
  kInteger,  // an integer (1e5 allowed)
  kBool,     // true | false
  kString,   // a non-empty string
  kEnum,     // one of `values`
  kVec3,     // [x, y, z]
  kNumbers,  // a list of numbers
  kStrings,  // a list of strings (names)
  kMap,      // a mapping: the keys of `section`
  kList,     // a list of mappings: the keys of `section`
  kAny,      // several forms (the `type` text says which); the reader checks it
};

/// The physical range of a number: lo <= |v| <= hi for a nonzero v. `sign` says which signs the
/// key's own check allows ('+' positive, '0' zero or positive, '~' any), for the message only.
struct Range {
  double lo = 0, hi = 0;  // lo == hi == 0: no entry (the generic |v| <= 1e15 applies)
  char sign = '~';
  bool defined() const { return lo != 0 || hi != 0; }
};

struct Key {
  std::string name;
  Type type = Type::kAny;
  std::string type_text;   // the type as the docs show it ("" = derived from `type`)
  std::string units;       // "m", "Pa", "steps", ... ("" = none)
  std::string def;         // the default as the docs show it; "**required**"; "" = none
  std::string help;        // the meaning (markdown)
  std::string section;     // kMap / kList (and kAny with a mapping form): the child section's path
  std::vector<std::string> values;  // kEnum: the allowed words
  Range range;             // numbers (and lists of numbers): the allowed magnitude
  std::string range_unit;  // the unit the range is given in ("" = `units`)
  /// The default depends on other keys (a thesis mesh's dim is 2 for quad4, the first layer
  /// after which a structure joins, ...): `def` documents it, but the resolved case (case.yaml)
  /// leaves the key out instead of writing `def`.
  bool conditional = false;
};

struct Section {
  std::string path;   // "" (top level), "time", "packing.settle", "walls.motion.servo", ...
  std::vector<Key> keys;
  /// Mappings whose keys depend on one key's value (walls by `type`, size by `distribution`):
  /// the key and, per value, the keys allowed with it (in the order the messages list them).
  std::string variant_key;
  std::vector<std::pair<std::string, std::vector<std::string>>> variants;
};

/// Every section, the top level first.
const std::vector<Section>& sections();

/// A path without list indices ("walls.motion.servo"); "" is the top level.
const Section* find_section(const std::string& path);
/// The key at a path without list indices ("packing.settle.max_steps"), or nullptr.
const Key* find_key(const std::string& path);
/// The keys a mapping at `path` may have, in the table's order; with `variant` (e.g. "box" for a
/// wall) only that variant's keys. Throws std::logic_error for a path the table lacks.
std::vector<std::string> key_names(const std::string& path, const std::string& variant = "");

/// "walls[2].motion[0].velocity[1]" -> "walls.motion.velocity".
std::string strip_indices(const std::string& path);

/// The key table of one section as markdown (| key | type | units | default | meaning |).
std::string markdown_table(const std::string& path);
/// The table of ranges (docs/case-format.md#ranges) as markdown.
std::string markdown_ranges();
/// A JSON Schema (draft-07) of a case file.
std::string json_schema();

/// `text` (docs/case-format.md) with every generated block replaced by the table's current
/// form: the lines between "<!-- schema: PATH -->" and "<!-- /schema -->" become
/// markdown_table(PATH) ("top" for the top level; several paths separated by spaces when their
/// tables are the same), those between "<!-- schema: ranges -->" and "<!-- /schema -->"
/// markdown_ranges(). Throws std::runtime_error naming the line of a malformed block.
std::string regenerate_docs(const std::string& text);

}  // namespace fdem::schema
