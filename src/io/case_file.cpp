// Reading and validating case files (YAML) into a CaseConfig. The schema is documented key by
// key in docs/case-format.md; keep the two in step.
//
// Every problem is reported as InputError(file, line, message) with the 1-based line of the
// offending node (yaml-cpp marks are 0-based). Values created by --set overrides are reported
// with file "--set" and line 0, quoting the override.
#include "io/case_file.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <cstring>
#include <system_error>
#include <tuple>

#include <sys/stat.h>
#include <unistd.h>

#include "dem/particles.hpp"
#include "fem/element_types.hpp"
#include "io/case_schema.hpp"

namespace fdem {
namespace {

namespace fs = std::filesystem;

std::string join(const std::vector<std::string>& v) {
  std::string s;
  for (std::size_t i = 0; i < v.size(); ++i) s += (i ? ", " : "") + v[i];
  return s;
}

std::string scalar_text(const YAML::Node& n) {
  if (n.IsScalar()) return n.Scalar();
  if (n.IsSequence()) return "a list";
  if (n.IsMap()) return "a mapping";
  return "nothing";
}

// ---------------------------------------------------------------- physical ranges
//
// Every number read from a case file is checked against the range of its key in the case schema
// (io/case_schema_table.cpp; docs/case-format.md#ranges). A range bounds the magnitude of a nonzero
// value: lo <= |v| <= hi. Signs and zero are the business of the key's own check (positive,
// non-negative, ...), which keeps the older messages ("must be positive") for those mistakes.
// A key is found by its path without list indices ("walls.motion.velocity"); keys without a range
// get the generic bound |v| <= 1e15.
struct Range {
  double lo, hi;
  std::string unit;
  char sign;  // '+' positive, '0' zero or positive, '~' any sign (for the message)
};

/// The range of the key at `key` (a path without list indices) from the case schema.
std::optional<Range> find_range(const std::string& key) {
  const schema::Key* k = schema::find_key(key);
  if (!k || !k->range.defined()) return std::nullopt;
  return Range{k->range.lo, k->range.hi, !k->range_unit.empty() ? k->range_unit : (k->units == "–" ? "" : k->units),
               k->range.sign};
}

std::string short_num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

/// "" if `v` is within the range of the key of `path`, else the message.
std::string range_problem(const std::string& path, double v) {
  const std::string key = schema::strip_indices(path);
  const std::optional<Range> found = find_range(key);
  if (!found && std::getenv("FDEM_RANGE_DEBUG")) std::fprintf(stderr, "range: no entry for %s\n", key.c_str());
  const Range r = found ? *found : Range{1e-300, 1e15, "", '~'};
  const double a = std::fabs(v);
  if (v == 0 || (a >= r.lo && a <= r.hi)) return "";
  if (v < 0 && r.sign != '~') return "";  // the key's own check says "must be positive / >= 0"
  const std::string unit = r.unit.empty() ? std::string() : " " + r.unit;
  const std::string lo = short_num(r.lo), hi = short_num(r.hi);
  std::string allowed;
  if (r.lo <= 1e-300) allowed = "[-" + hi + ", " + hi + "]" + unit;
  else if (r.sign == '+') allowed = "[" + lo + ", " + hi + "]" + unit;
  else if (r.sign == '0') allowed = "0 or [" + lo + ", " + hi + "]" + unit;
  else allowed = "0 or a magnitude in [" + lo + ", " + hi + "]" + unit;
  return "out of range, got " + short_num(v) + "; allowed: " + allowed + " (docs/case-format.md#ranges)";
}

/// "" if `s` is valid UTF-8 without control characters, else what is wrong.
std::string text_problem(const std::string& s) {
  for (std::size_t i = 0; i < s.size();) {
    const unsigned char c = static_cast<unsigned char>(s[i]);
    if (c < 0x20 || c == 0x7f) return "contains a control character (byte " + std::to_string(c) + " at " + std::to_string(i) + ")";
    std::size_t len = c < 0x80 ? 1 : (c >= 0xc2 && c <= 0xdf) ? 2 : (c >= 0xe0 && c <= 0xef) ? 3 : (c >= 0xf0 && c <= 0xf4) ? 4 : 0;
    bool ok = len > 0 && i + len <= s.size();
    for (std::size_t k = 1; ok && k < len; ++k) ok = (static_cast<unsigned char>(s[i + k]) & 0xc0) == 0x80;
    if (!ok) return "is not valid UTF-8 text (byte " + std::to_string(c) + " at " + std::to_string(i) + ")";
    i += len;
  }
  return "";
}

/// Validation context: the file name, the case directory and the paths created by --set.
class Reader {
 public:
  Reader(std::string file, fs::path dir) : file_(std::move(file)), dir_(std::move(dir)) {}

  // ---- errors ----
  [[noreturn]] void fail(const YAML::Node& n, const std::string& path, const std::string& msg) const {
    const std::string* ov = override_for(path);
    if (ov) throw InputError("--set " + *ov, 0, msg);  // "--set key=value: error: ..."
    int line = 0;
    if (n.IsDefined() && !n.Mark().is_null()) line = n.Mark().line + 1;
    throw InputError(file_, line, msg);
  }

  /// The override that created `path` or one of its parents, if any.
  const std::string* override_for(const std::string& path) const {
    for (const auto& [p, text] : overrides_) {
      if (path == p) return &text;
      if (path.size() > p.size() && path.compare(0, p.size(), p) == 0 &&
          (path[p.size()] == '.' || path[p.size()] == '['))
        return &text;
    }
    return nullptr;
  }
  /// Where the value at `path` came from: (file, line) or ("--set key=value", 0).
  std::pair<std::string, int> location(const YAML::Node& n, const std::string& path) const {
    if (const std::string* ov = override_for(path)) return {"--set " + *ov, 0};
    return {file_, n.IsDefined() && !n.Mark().is_null() ? n.Mark().line + 1 : 0};
  }
  /// The override that created `path` or a key below it, if any.
  const std::string* override_under(const std::string& path) const {
    if (const std::string* o = override_for(path)) return o;
    for (const auto& [p, text] : overrides_)
      if (p.size() > path.size() && p.compare(0, path.size(), path) == 0 && (p[path.size()] == '.' || p[path.size()] == '['))
        return &text;
    return nullptr;
  }
  void add_override_path(const std::string& path, const std::string& text) { overrides_[path] = text; }

  // ---- structure ----
  void expect_map(const YAML::Node& n, const std::string& path) const {
    if (!n.IsMap()) fail(n, path, path + ": expected a mapping (key: value lines), got " + describe(n));
  }
  void expect_seq(const YAML::Node& n, const std::string& path) const {
    if (!n.IsSequence()) fail(n, path, path + ": expected a list, got " + describe(n));
  }
  static std::string describe(const YAML::Node& n) {
    if (n.IsScalar()) return "'" + n.Scalar() + "'";
    return scalar_text(n);
  }
  static std::string child(const std::string& path, const std::string& key) {
    return path.empty() ? key : path + "." + key;
  }
  static std::string item(const std::string& path, std::size_t i) {
    return path + "[" + std::to_string(i) + "]";
  }

  /// Every key of map `n` must be one the case schema gives the mapping at `path`
  /// (io/case_schema_table.cpp), and appear once.
  void check_keys(const YAML::Node& n, const std::string& path) const {
    check_keys(n, path, schema::key_names(schema::strip_indices(path)));
  }
  /// The same for one form of a mapping whose keys depend on its form (walls by type, size
  /// distributions, a motion or a schedule phase, a nodal or a pressure load).
  void check_variant_keys(const YAML::Node& n, const std::string& path, const std::string& variant) const {
    check_keys(n, path, schema::key_names(schema::strip_indices(path), variant));
  }
  /// Every key of map `n` must be in `valid`, and appear once.
  void check_keys(const YAML::Node& n, const std::string& path,
                  const std::vector<std::string>& valid) const {
    expect_map(n, path);
    std::set<std::string> seen;
    for (auto it = n.begin(); it != n.end(); ++it) {
      const YAML::Node k = it->first;  // a copy: it-> returns a temporary proxy
      const std::string key = k.IsScalar() ? k.Scalar() : std::string("<non-scalar key>");
      const std::string where = path.empty() ? "at the top level" : "in " + path;
      if (std::find(valid.begin(), valid.end(), key) == valid.end()) {
        const std::string msg = "unknown key '" + key + "' " + where + " (valid: " + join(valid) + ")";
        // a key made by --set a.b.c=... is that override's mistake, not the case file's
        if (const std::string* ov = override_under(child(path, key))) throw InputError("--set " + *ov, 0, msg);
        fail(k, child(path, key), msg);
      }
      if (!seen.insert(key).second) fail(k, child(path, key), "duplicate key '" + key + "' " + where);
    }
  }

  void require(const YAML::Node& parent, const std::string& path, const std::string& key,
               const std::string& what = "") const {
    if (!parent[key])
      fail(parent, path, "missing required key '" + key + "' in " + (path.empty() ? "the case" : path) +
                             (what.empty() ? "" : " (" + what + ")"));
  }

  // ---- scalars ----
  double number(const YAML::Node& n, const std::string& path, const std::string& range_path = "") const {
    if (!n.IsScalar()) fail(n, path, path + ": expected a number, got " + describe(n));
    const std::string& s = n.Scalar();
    char* end = nullptr;
    errno = 0;
    double v = std::strtod(s.c_str(), &end);
    if (s.empty() || end != s.c_str() + s.size() || errno == ERANGE || !std::isfinite(v))
      fail(n, path, path + ": expected a number, got '" + s + "'");
    check_range(n, path, v, range_path);
    return v;
  }
  /// The physical range of the key (the table above); `key_path` replaces `path` for the lookup.
  void check_range(const YAML::Node& n, const std::string& path, double v, const std::string& key_path = "") const {
    const std::string m = range_problem(key_path.empty() ? path : key_path, v);
    if (!m.empty()) fail(n, path, path + ": " + m);
  }
  double positive(const YAML::Node& n, const std::string& path, const std::string& unit = "") const {
    double v = number(n, path);
    if (!(v > 0)) fail(n, path, path + ": must be positive" + unit + ", got " + n.Scalar());
    return v;
  }
  double non_negative(const YAML::Node& n, const std::string& path) const {
    double v = number(n, path);
    if (v < 0) fail(n, path, path + ": must be >= 0, got " + n.Scalar());
    return v;
  }
  std::int64_t integer(const YAML::Node& n, const std::string& path) const {
    if (!n.IsScalar()) fail(n, path, path + ": expected an integer, got " + describe(n));
    const std::string& s = n.Scalar();
    char* end = nullptr;
    errno = 0;
    long long v = std::strtoll(s.c_str(), &end, 10);
    if (!s.empty() && end == s.c_str() + s.size() && errno == 0) {
      check_range(n, path, static_cast<double>(v));
      return v;
    }
    // accept integral values written as floats, e.g. 1e5
    errno = 0;
    double d = std::strtod(s.c_str(), &end);
    if (!s.empty() && end == s.c_str() + s.size() && errno == 0 && std::isfinite(d) &&
        d == std::floor(d) && std::fabs(d) < 9.0e15) {
      check_range(n, path, d);
      return static_cast<std::int64_t>(d);
    }
    fail(n, path, path + ": expected an integer, got '" + s + "'");
  }
  std::int64_t positive_int(const YAML::Node& n, const std::string& path) const {
    std::int64_t v = integer(n, path);
    if (v <= 0) fail(n, path, path + ": must be a positive integer, got " + n.Scalar());
    return v;
  }
  std::int64_t non_negative_int(const YAML::Node& n, const std::string& path) const {
    std::int64_t v = integer(n, path);
    if (v < 0) fail(n, path, path + ": must be >= 0, got " + n.Scalar());
    return v;
  }
  bool boolean(const YAML::Node& n, const std::string& path) const {
    if (n.IsScalar() && n.Tag() != "!") {  // (a quoted 'true' is a string: tag "!")
      std::string s = n.Scalar();
      std::transform(s.begin(), s.end(), s.begin(), ::tolower);
      // only true and false (yaml-cpp's as<bool> would also take yes/no/on/off)
      if (s == "true") return true;
      if (s == "false") return false;
    }
    fail(n, path, path + ": expected true or false, got " + describe(n));
  }
  std::string string(const YAML::Node& n, const std::string& path) const {
    if (!n.IsScalar() || n.Scalar().empty())
      fail(n, path, path + ": expected a non-empty string, got " + describe(n));
    return n.Scalar();
  }
  /// A name (of the case, a material, a wall, a mesh, a surface, a box): it goes into file
  /// names, CSV headers and run.json, so printable UTF-8 only.
  std::string name(const YAML::Node& n, const std::string& path) const {
    std::string s = string(n, path);
    const std::string why = text_problem(s);
    if (!why.empty()) fail(n, path, path + ": " + why);
    return s;
  }
  Vec3 vec3(const YAML::Node& n, const std::string& path) const {
    if (!n.IsSequence() || n.size() != 3)
      fail(n, path, path + ": expected a list of 3 numbers [x, y, z], got " +
                        (n.IsSequence() ? "a list of " + std::to_string(n.size()) : describe(n)));
    return {number(n[0], item(path, 0)), number(n[1], item(path, 1)), number(n[2], item(path, 2))};
  }
  /// A positive number or the word "auto" (returns 0 for auto).
  double positive_or_auto(const YAML::Node& n, const std::string& path) const {
    if (n.IsScalar() && n.Scalar() == "auto") return 0;
    if (!n.IsScalar()) fail(n, path, path + ": expected a positive number or 'auto', got " + describe(n));
    char* end = nullptr;
    const std::string& s = n.Scalar();
    double v = std::strtod(s.c_str(), &end);
    if (s.empty() || end != s.c_str() + s.size() || !std::isfinite(v))
      fail(n, path, path + ": expected a positive number or 'auto', got '" + s + "'");
    if (!(v > 0)) fail(n, path, path + ": must be positive or 'auto', got " + s);
    check_range(n, path, v);
    return v;
  }

  std::string resolve(const std::string& p) const {
    fs::path q(p);
    if (q.is_absolute()) return q.string();
    return (dir_ / q).lexically_normal().string();
  }

  const std::string& file() const { return file_; }

 private:
  std::string file_;
  fs::path dir_;
  std::map<std::string, std::string> overrides_;  // normalised path -> override text
};

// ---------------------------------------------------------------- --set overrides

bool is_index(const std::string& s) {
  return !s.empty() && std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; });
}

/// The key path of an override split at the dots; an item selector `[name]` or `[3]` after a key
/// ("walls[top]") becomes its own part "[top]".
std::vector<std::string> override_parts(const std::string& text, const std::string& key) {
  std::vector<std::string> parts;
  std::stringstream ss(key);
  std::string p;
  while (std::getline(ss, p, '.')) {
    const auto open = p.find('[');
    if (open == std::string::npos) {
      parts.push_back(p);
      continue;
    }
    if (p.back() != ']' || p.find('[', open + 1) != std::string::npos || open + 2 >= p.size())
      throw InputError("--set " + text, 0, "'" + p + "': a list item is selected as key[name] or key[number]");
    if (open > 0) parts.push_back(p.substr(0, open));
    parts.push_back(p.substr(open));
  }
  if (key.back() == '.') parts.push_back("");
  for (const auto& q : parts)
    if (q.empty()) throw InputError("--set " + text, 0, "empty part in key path '" + key + "'");
  return parts;
}

/// The item of list `seq` named `name` (its `name:` key), or throws naming the names there are.
std::size_t item_by_name(const YAML::Node& seq, const std::string& name, const std::string& path,
                         const std::string& text) {
  std::vector<std::string> names;
  for (std::size_t k = 0; k < seq.size(); ++k) {
    const YAML::Node n = seq[k];
    if (!n.IsMap() || !n["name"] || !n["name"].IsScalar()) continue;
    if (n["name"].Scalar() == name) return k;
    names.push_back(n["name"].Scalar());
  }
  throw InputError("--set " + text, 0, "no item named '" + name + "' in " + path +
                                         (names.empty() ? " (its items have no names)" : " (names: " + join(names) + ")"));
}

/// Apply one "a.b.0.c=value" override to the tree (an item of a list by position, `walls.5`,
/// or by its name, `walls[top]`). Returns the normalised path ("a.b[0].c"); `warning` is set when
/// a list whose items have names is addressed by position (a wall added later moves the target).
std::string apply_override(YAML::Node& root, const std::string& text, std::string* warning = nullptr) {
  const auto eq = text.find('=');
  if (eq == std::string::npos || eq == 0)
    throw InputError("--set " + text, 0, "expected key.path=value");
  const std::string key = text.substr(0, eq);
  const std::string value = text.substr(eq + 1);
  std::vector<std::string> parts = override_parts(text, key);
  YAML::Node val;
  try {
    val = YAML::Load(value);
  } catch (const YAML::Exception& e) {
    throw InputError("--set " + text, 0, "cannot parse the value: " + e.msg);
  }
  if (!val.IsDefined() || val.IsNull()) val = YAML::Node(value);  // empty value: empty string

  YAML::Node cur = root;
  std::string path;
  for (std::size_t i = 0; i < parts.size(); ++i) {
    const std::string& p = parts[i];
    const bool last = i + 1 == parts.size();
    if (p.front() == '[' && !cur.IsSequence())
      throw InputError("--set " + text, 0, "'" + path + "' is not a list: " + p + " selects nothing");
    if (cur.IsSequence()) {
      std::string q = p;  // the item's number
      if (q.front() == '[') {  // [name] or [number]
        const std::string sel = q.substr(1, q.size() - 2);
        q = is_index(sel) ? sel : std::to_string(item_by_name(cur, sel, path, text));
      } else if (!is_index(q)) {
        throw InputError("--set " + text, 0, "'" + (path.empty() ? q : path) + "' is a list; select an item by name, " +
                                          path + "[name], or by number, got '" + q + "'");
      }
      if (q.size() > 9 || std::stoul(q) > cur.size() || (std::stoul(q) == cur.size() && !last))
        throw InputError("--set " + text, 0, "index " + q + " out of range in " +
                                          path + " (size " + std::to_string(cur.size()) + ")");
      const std::size_t k = std::stoul(q);
      if (warning && p.front() != '[' && k < cur.size() && cur[k].IsMap() && cur[k]["name"] && cur[k]["name"].IsScalar()) {
        const std::string name = cur[k]["name"].Scalar();
        *warning = "--set " + text + ": warning: " + path + "." + q + " is the item named '" + name +
                   "' by its position: write " + path + "[" + name + "] to keep naming it when the list changes";
      }
      path += "[" + q + "]";
      if (last) {
        if (k == cur.size()) cur.push_back(val);
        else cur[k] = val;
      } else {
        YAML::Node next = cur[k];
        cur.reset(next);
      }
    } else if (cur.IsMap() || cur.IsNull() || !cur.IsDefined()) {
      if (is_index(p) && cur.IsMap() && !cur[p])
        throw InputError("--set " + text, 0, "'" + path + "' is not a list; cannot index it with " + p);
      path += (path.empty() ? "" : ".") + p;
      if (last) {
        cur[p] = val;
      } else {
        if (!cur[p] || cur[p].IsNull()) cur[p] = YAML::Node(YAML::NodeType::Map);
        YAML::Node next = cur[p];
        cur.reset(next);
      }
    } else {
      throw InputError("--set " + text, 0, "'" + path + "' is a value, it has no key '" + p + "'");
    }
  }
  return path;
}

// ---------------------------------------------------------------- sections

std::uint8_t dof_bits(const Reader& R, const YAML::Node& n, const std::string& path, bool rotations) {
  R.expect_seq(n, path);
  static const std::vector<std::pair<std::string, std::uint8_t>> names = {
      {"x", kDofX}, {"y", kDofY}, {"z", kDofZ}, {"rx", kDofRX}, {"ry", kDofRY}, {"rz", kDofRZ}};
  std::uint8_t bits = 0;
  const std::size_t nvalid = rotations ? 6 : 3;
  for (std::size_t i = 0; i < n.size(); ++i) {
    const std::string s = R.string(n[i], Reader::item(path, i));
    bool ok = false;
    for (std::size_t k = 0; k < nvalid; ++k)
      if (names[k].first == s) { bits |= names[k].second; ok = true; }
    if (!ok) {
      std::vector<std::string> v;
      for (std::size_t k = 0; k < nvalid; ++k) v.push_back(names[k].first);
      R.fail(n[i], Reader::item(path, i), Reader::item(path, i) + ": unknown degree of freedom '" + s +
                                               "' (valid: " + join(v) + ")");
    }
  }
  return bits;
}

int material_index(const Reader& R, const CaseConfig& c, const YAML::Node& n, const std::string& path) {
  const std::string name = R.string(n, path);
  for (std::size_t i = 0; i < c.materials.size(); ++i)
    if (c.materials[i].name == name) return static_cast<int>(i);
  std::vector<std::string> v;
  for (const auto& m : c.materials) v.push_back(m.name);
  R.fail(n, path, path + ": unknown material '" + name + "' (valid: " + join(v) + ")");
}

void read_box(const Reader& R, const YAML::Node& n, const std::string& path, Vec3& lo, Vec3& hi) {
  R.check_keys(n, path);
  R.require(n, path, "min");
  R.require(n, path, "max");
  lo = R.vec3(n["min"], path + ".min");
  hi = R.vec3(n["max"], path + ".max");
  for (int k = 0; k < 3; ++k)
    if (!(lo[k] < hi[k]))
      R.fail(n["max"], path + ".max", path + ": min must be below max in every direction (" +
                                          std::string(1, "xyz"[k]) + ": min " + std::to_string(lo[k]) +
                                          ", max " + std::to_string(hi[k]) + ")");
}

bool inside(const Vec3& x, const Vec3& lo, const Vec3& hi) {
  return x.x >= lo.x && x.x <= hi.x && x.y >= lo.y && x.y <= hi.y && x.z >= lo.z && x.z <= hi.z;
}

void read_time(const Reader& R, const YAML::Node& n, CaseConfig& c) {
  const std::string P = "time";
  R.check_keys(n, P);
  if (n["dt"]) c.dt = R.positive_or_auto(n["dt"], P + ".dt");
  if (n["safety"]) {
    c.dt_safety = R.number(n["safety"], P + ".safety");
    if (!(c.dt_safety > 0 && c.dt_safety <= 1))
      R.fail(n["safety"], P + ".safety", P + ".safety: must be in (0, 1], got " + n["safety"].Scalar());
  }
  if (n["steps"] && n["duration"])
    R.fail(n["duration"], P + ".duration", "time: give either steps or duration, not both");
  if (!n["steps"] && !n["duration"] && !c.packing.present)
    R.fail(n, P, "missing required key 'steps' or 'duration' in time");
  if (n["steps"]) c.steps = R.positive_int(n["steps"], P + ".steps");
  if (n["duration"]) c.duration = R.positive(n["duration"], P + ".duration", " (s)");
  if (n["stop_unbalanced"]) c.stop_unbalanced = R.non_negative(n["stop_unbalanced"], P + ".stop_unbalanced");
  if (n["stop_kinetic_ratio"]) c.stop_kinetic_ratio = R.non_negative(n["stop_kinetic_ratio"], P + ".stop_kinetic_ratio");
}

/// A rolling law by name (`rolling_law` at the top, in materials and interactions).
RollingLaw read_rolling_law(const Reader& R, const YAML::Node& n, const std::string& path) {
  const std::string name = R.string(n, path);
  RollingLaw m = RollingLaw::kIncremental;
  if (!rolling_law_from_name(name, m))
    R.fail(n, path, path + ": unknown rolling law '" + name + "' (valid: " + rolling_law_names() + ")");
  return m;
}

void read_materials(const Reader& R, const YAML::Node& n, CaseConfig& c) {
  const std::string P = "materials";
  R.expect_seq(n, P);
  if (n.size() == 0) R.fail(n, P, "materials: the list is empty; define at least one material");
  for (std::size_t i = 0; i < n.size(); ++i) {
    const YAML::Node m = n[i];
    const std::string p = Reader::item(P, i);
    R.check_keys(m, p);
    R.require(m, p, "name");
    R.require(m, p, "young", "Young's modulus, Pa");
    R.require(m, p, "density", "kg/m^3");
    Material mat;
    mat.name = R.name(m["name"], p + ".name");
    for (const auto& o : c.materials)
      if (o.name == mat.name) R.fail(m["name"], p + ".name", p + ".name: duplicate material name '" + mat.name + "'");
    mat.young = R.positive(m["young"], p + ".young", " (Pa)");
    mat.density = R.positive(m["density"], p + ".density", " (kg/m^3)");
    if (m["kt_kn"]) mat.kt_kn = R.non_negative(m["kt_kn"], p + ".kt_kn");
    if (m["friction"]) mat.friction = R.non_negative(m["friction"], p + ".friction");
    if (m["rolling_stiffness"]) mat.rolling_stiffness = R.non_negative(m["rolling_stiffness"], p + ".rolling_stiffness");
    if (m["rolling_limit"]) mat.rolling_limit = R.non_negative(m["rolling_limit"], p + ".rolling_limit");
    mat.rolling_law = m["rolling_law"] ? read_rolling_law(R, m["rolling_law"], p + ".rolling_law") : c.rolling_law;
    if (m["poisson"]) {
      mat.poisson = R.number(m["poisson"], p + ".poisson");
      if (!(mat.poisson > -1 && mat.poisson < 0.5))
        R.fail(m["poisson"], p + ".poisson", p + ".poisson: must be in (-1, 0.5), got " + m["poisson"].Scalar());
    }
    c.materials.push_back(mat);
    c.material_at.push_back(R.location(m["friction"] ? m["friction"] : m, p + (m["friction"] ? ".friction" : "")));
  }
}

/// A contact model by name (`interactions[].model`, `contact_model`); unknown: an error listing the valid ones.
ContactModel read_contact_model(const Reader& R, const YAML::Node& n, const std::string& path) {
  const std::string name = R.string(n, path);
  ContactModel m = ContactModel::kLinear;
  if (!contact_model_from_name(name, m))
    R.fail(n, path, path + ": unknown contact model '" + name + "' (valid: " + contact_model_names() + ")");
  return m;
}

void read_interactions(const Reader& R, const YAML::Node& n, CaseConfig& c) {
  const std::string P = "interactions";
  R.expect_seq(n, P);
  for (std::size_t i = 0; i < n.size(); ++i) {
    const YAML::Node e = n[i];
    const std::string p = Reader::item(P, i);
    R.check_keys(e, p);
    R.require(e, p, "materials", "two material names");
    const YAML::Node mm = e["materials"];
    if (!mm.IsSequence() || mm.size() != 2)
      R.fail(mm, p + ".materials", p + ".materials: expected a list of two material names, got " +
                                       (mm.IsSequence() ? "a list of " + std::to_string(mm.size()) : Reader::describe(mm)));
    PairOverride o;
    o.a = material_index(R, c, mm[0], p + ".materials[0]");
    o.b = material_index(R, c, mm[1], p + ".materials[1]");
    if (e["friction"]) { o.has_friction = true; o.friction = R.non_negative(e["friction"], p + ".friction"); }
    if (e["kt_kn"]) { o.has_kt_kn = true; o.kt_kn = R.non_negative(e["kt_kn"], p + ".kt_kn"); }
    if (e["rolling_stiffness"]) { o.has_beta_r = true; o.beta_r = R.non_negative(e["rolling_stiffness"], p + ".rolling_stiffness"); }
    if (e["rolling_limit"]) { o.has_eta_r = true; o.eta_r = R.non_negative(e["rolling_limit"], p + ".rolling_limit"); }
    if (e["model"]) { o.has_model = true; o.model = read_contact_model(R, e["model"], p + ".model"); }
    if (e["rolling_law"]) { o.has_rolling_law = true; o.rolling_law = read_rolling_law(R, e["rolling_law"], p + ".rolling_law"); }
    if (!o.has_friction && !o.has_kt_kn && !o.has_beta_r && !o.has_eta_r && !o.has_model && !o.has_rolling_law)
      R.fail(e, p, p + ": give at least one of friction, kt_kn, rolling_stiffness, rolling_limit, model, rolling_law");
    for (std::size_t j = 0; j < c.interactions.size(); ++j) {
      const auto& q = c.interactions[j];
      if ((q.a == o.a && q.b == o.b) || (q.a == o.b && q.b == o.a))
        R.fail(e, p, p + ": duplicate pair (" + c.materials[o.a].name + ", " + c.materials[o.b].name +
                         ") already given in interactions[" + std::to_string(j) + "]");
    }
    c.interactions.push_back(o);
  }
}

/// Two materials of different rolling laws: their pair's law must be given in `interactions`
/// (as YADE has no law for a pair of two material types that no functor names).
void check_rolling_laws(const Reader& R, const YAML::Node& root, const CaseConfig& c) {
  const auto& m = c.materials;
  for (std::size_t a = 0; a < m.size(); ++a)
    for (std::size_t b = a + 1; b < m.size(); ++b) {
      if (m[a].rolling_law == m[b].rolling_law) continue;
      bool given = false;
      for (const auto& o : c.interactions)
        given |= o.has_rolling_law && ((o.a == static_cast<int>(a) && o.b == static_cast<int>(b)) ||
                                       (o.a == static_cast<int>(b) && o.b == static_cast<int>(a)));
      if (given) continue;
      const YAML::Node mb = root["materials"][b];
      const std::string p = Reader::item("materials", b);
      R.fail(mb["rolling_law"] ? mb["rolling_law"] : mb, p + ".rolling_law",
             p + ": material '" + m[b].name + "' has the " + rolling_law_name(m[b].rolling_law) +
                 " rolling law and '" + m[a].name + "' the " + rolling_law_name(m[a].rolling_law) +
                 "; give their pair's law in interactions (- {materials: [" + m[a].name + ", " + m[b].name +
                 "], rolling_law: total}) or the same law to both");
    }
}

/// size.distribution: sieve, a grading curve (mass % passing at each sieve size).
void read_sieve(const Reader& R, const YAML::Node& n, const std::string& P, SizeDistribution& s) {
  s.kind = SizeDistribution::kSieve;
  R.check_variant_keys(n, P, "sieve");
  R.require(n, P, "sizes", "sieve sizes, m, ascending");
  R.require(n, P, "passing", "mass % passing at each size");
  const YAML::Node sz = n["sizes"], pa = n["passing"];
  R.expect_seq(sz, P + ".sizes");
  R.expect_seq(pa, P + ".passing");
  if (sz.size() < 2) R.fail(sz, P + ".sizes", P + ".sizes: give at least two sieve sizes");
  if (pa.size() != sz.size())
    R.fail(pa, P + ".passing", P + ".passing: has " + std::to_string(pa.size()) + " values but sizes has " +
                                   std::to_string(sz.size()));
  for (std::size_t i = 0; i < sz.size(); ++i) {
    const std::string pi = Reader::item(P + ".sizes", i);
    const double d = R.positive(sz[i], pi, " (m)");
    if (i > 0 && !(d > s.sieve_d.back())) R.fail(sz[i], pi, P + ".sizes: must be strictly ascending");
    s.sieve_d.push_back(d);
  }
  for (std::size_t i = 0; i < pa.size(); ++i) {
    const std::string pi = Reader::item(P + ".passing", i);
    const double q = R.number(pa[i], pi);
    if (q < 0 || q > 100) R.fail(pa[i], pi, pi + ": mass % passing must be in [0, 100], got " + pa[i].Scalar());
    if (i > 0 && q < s.passing.back()) R.fail(pa[i], pi, P + ".passing: must be non-decreasing");
    s.passing.push_back(q);
  }
  if (s.passing.back() != 100) R.fail(pa, P + ".passing", P + ".passing: the last value must be 100 (all passes the largest sieve)");
  if (n["min"]) s.dmin = R.positive(n["min"], P + ".min", " (diameter, m)");
  if (n["max"]) s.dmax = R.positive(n["max"], P + ".max", " (diameter, m)");
  if (s.passing.front() > 0 && !(s.dmin > 0 && s.dmin < s.sieve_d.front()))
    R.fail(pa, P + ".passing", P + ".passing: " + pa[0].Scalar() +
                                   " % passes the smallest sieve; give min (the smallest diameter, below the "
                                   "smallest sieve) or start the curve at 0");
  const double lo = s.dmin > 0 ? s.dmin : s.sieve_d.front();
  const double hi = s.dmax > 0 ? std::min(s.dmax, s.sieve_d.back()) : s.sieve_d.back();
  if (!(lo < hi)) R.fail(n, P, P + ": the truncation [min, max] leaves no part of the curve");
  // some mass must lie in [lo, hi]
  double mass = 0;
  for (std::size_t k = 0; k <= s.sieve_d.size(); ++k) {
    const double a = k == 0 ? (s.dmin > 0 ? s.dmin : s.sieve_d[0]) : s.sieve_d[k - 1];
    const double b = k == s.sieve_d.size() ? a : s.sieve_d[k];
    const double f = k == 0 ? s.passing[0] : (k == s.sieve_d.size() ? 0 : s.passing[k] - s.passing[k - 1]);
    const double aa = std::max(a, lo), bb = std::min(b, hi);
    if (bb > aa) mass += f;
  }
  if (!(mass > 0)) R.fail(n, P, P + ": no mass of the curve lies within [min, max]");
}

void read_size(const Reader& R, const YAML::Node& n, const std::string& P, SizeDistribution& s) {
  R.expect_map(n, P);
  R.require(n, P, "distribution", "constant, uniform, normal or sieve");
  const std::string kind = R.string(n["distribution"], P + ".distribution");
  if (kind == "constant") {
    s.kind = SizeDistribution::kConstant;
    R.check_variant_keys(n, P, "constant");
    R.require(n, P, "d", "diameter, m");
    s.d = R.positive(n["d"], P + ".d", " (diameter, m)");
  } else if (kind == "uniform") {
    s.kind = SizeDistribution::kUniform;
    R.check_variant_keys(n, P, "uniform");
    R.require(n, P, "min", "smallest diameter, m");
    R.require(n, P, "max", "largest diameter, m");
    s.dmin = R.positive(n["min"], P + ".min", " (diameter, m)");
    s.dmax = R.positive(n["max"], P + ".max", " (diameter, m)");
    if (s.dmin > s.dmax) R.fail(n["max"], P + ".max", P + ": min must not exceed max");
  } else if (kind == "normal") {
    s.kind = SizeDistribution::kNormal;
    R.check_variant_keys(n, P, "normal");
    R.require(n, P, "mean", "mean diameter, m");
    R.require(n, P, "sd", "standard deviation, m");
    s.mean = R.positive(n["mean"], P + ".mean", " (diameter, m)");
    s.sd = R.non_negative(n["sd"], P + ".sd");
    if (n["min"]) s.dmin = R.positive(n["min"], P + ".min", " (diameter, m)");
    if (n["max"]) s.dmax = R.positive(n["max"], P + ".max", " (diameter, m)");
    if (s.dmin > 0 && s.dmax > 0 && s.dmin >= s.dmax) R.fail(n["max"], P + ".max", P + ": min must be below max");
    const double lo = s.dmin > 0 ? s.dmin : 0, hi = s.dmax > 0 ? s.dmax : s.mean + 10 * s.sd;
    if (s.sd == 0 && (s.mean < lo || (s.dmax > 0 && s.mean > s.dmax)))
      R.fail(n, P, P + ": with sd 0 the mean must lie within [min, max]");
    if (s.sd > 0 && (hi < s.mean - 5 * s.sd || lo > s.mean + 5 * s.sd))
      R.fail(n, P, P + ": the truncation [min, max] lies more than 5 sd from the mean; nothing to draw");
    if (s.sd > 0 && !(s.dmin > 0) && s.mean < 2 * s.sd)
      R.fail(n, P, P + ": mean < 2 sd draws many non-positive diameters; give min (a truncation)");
  } else if (kind == "sieve") {
    read_sieve(R, n, P, s);
  } else {
    R.fail(n["distribution"], P + ".distribution", P + ".distribution: unknown distribution '" + kind +
                                                       "' (valid: constant, uniform, normal, sieve)");
  }
  if (n["scale"]) s.scale = R.positive(n["scale"], P + ".scale");
}

/// An inline sphere: [x, y, z, r] or {id, x, r, v}.
ParticleSource::Sphere read_sphere(const Reader& R, const YAML::Node& n, const std::string& p,
                                   const CaseConfig& c) {
  ParticleSource::Sphere s;
  const YAML::Node* rnode = &n;
  YAML::Node rn;
  if (n.IsSequence()) {
    if (n.size() != 4)
      R.fail(n, p, p + ": expected [x, y, z, r] (4 numbers) or {id, x, r, v}, got a list of " + std::to_string(n.size()));
    s.x = {R.number(n[0], Reader::item(p, 0)), R.number(n[1], Reader::item(p, 1)), R.number(n[2], Reader::item(p, 2))};
    s.r = R.number(n[3], Reader::item(p, 3), "particles.inline.spheres.r");
    rn = n[3];
    rnode = &rn;
  } else if (n.IsMap()) {
    R.check_keys(n, p);
    R.require(n, p, "x", "centre, m");
    R.require(n, p, "r", "radius, m");
    if (n["id"]) {
      s.id = R.integer(n["id"], p + ".id");
      if (s.id < 0) R.fail(n["id"], p + ".id", p + ".id: must be >= 0, got " + n["id"].Scalar());
    }
    s.x = R.vec3(n["x"], p + ".x");
    s.r = R.number(n["r"], p + ".r");
    rn = n["r"];
    rnode = &rn;
    if (n["v"]) s.v = R.vec3(n["v"], p + ".v");
  } else {
    R.fail(n, p, p + ": expected [x, y, z, r] or {id, x, r, v}, got " + Reader::describe(n));
  }
  if (!(s.r > 0)) R.fail(*rnode, p, p + ": radius must be positive, got " + rnode->Scalar());
  if (!inside(s.x, c.domain_min, c.domain_max)) {
    std::ostringstream o;
    o << p << (s.id >= 0 ? " (id " + std::to_string(s.id) + ")" : std::string()) << ": centre (" << s.x.x
      << ", " << s.x.y << ", " << s.x.z << ") lies outside the domain [" << c.domain_min.x << ", "
      << c.domain_max.x << "] x [" << c.domain_min.y << ", " << c.domain_max.y << "] x [" << c.domain_min.z
      << ", " << c.domain_max.z << "]";
    R.fail(n, p, o.str());
  }
  return s;
}

/// particles[i].inline: spheres given in the case file.
void read_inline_source(const Reader& R, const YAML::Node& s, const std::string& q, const CaseConfig& c,
                        ParticleSource& src) {
  src.kind = ParticleSource::kInline;
  R.check_keys(s, q);
  R.require(s, q, "material");
  R.require(s, q, "spheres", "a list of [x, y, z, r]");
  src.material = material_index(R, c, s["material"], q + ".material");
  if (s["velocity"]) src.velocity = R.vec3(s["velocity"], q + ".velocity");
  const YAML::Node sp = s["spheres"];
  R.expect_seq(sp, q + ".spheres");
  if (sp.size() == 0) R.fail(sp, q + ".spheres", q + ".spheres: the list is empty");
  for (std::size_t k = 0; k < sp.size(); ++k) {
    ParticleSource::Sphere sph = read_sphere(R, sp[k], Reader::item(q + ".spheres", k), c);
    if (!sp[k].IsMap() || !sp[k]["v"]) sph.v = src.velocity;
    src.spheres.push_back(sph);
  }
}

/// particles[i].generate: random non-overlapping spheres in a box.
void read_generate_source(const Reader& R, const YAML::Node& g, const std::string& q, const CaseConfig& c,
                          ParticleSource& src) {
  src.kind = ParticleSource::kGenerate;
  R.check_keys(g, q);
  R.require(g, q, "material");
  R.require(g, q, "box", "{min: [x,y,z], max: [x,y,z]}");
  R.require(g, q, "size", "the size distribution");
  src.material = material_index(R, c, g["material"], q + ".material");
  read_box(R, g["box"], q + ".box", src.box_min, src.box_max);
  if (!inside(src.box_min, c.domain_min, c.domain_max) || !inside(src.box_max, c.domain_min, c.domain_max))
    R.fail(g["box"], q + ".box", q + ".box: must lie inside the domain");
  if (g["count"] && g["porosity"]) R.fail(g["porosity"], q + ".porosity", q + ": give either count or porosity, not both");
  if (!g["count"] && !g["porosity"]) R.fail(g, q, "missing required key 'count' or 'porosity' in " + q);
  if (g["count"]) src.count = R.positive_int(g["count"], q + ".count");
  if (g["porosity"]) {
    src.porosity = R.number(g["porosity"], q + ".porosity");
    if (!(src.porosity > 0 && src.porosity < 1))
      R.fail(g["porosity"], q + ".porosity", q + ".porosity: must be in (0, 1), got " + g["porosity"].Scalar());
  }
  if (g["seed"]) {
    const std::int64_t sd = R.integer(g["seed"], q + ".seed");
    if (sd < 0) R.fail(g["seed"], q + ".seed", q + ".seed: must be >= 0");
    src.seed = static_cast<std::uint64_t>(sd);
  }
  if (g["max_attempts"]) {
    const std::int64_t m = R.positive_int(g["max_attempts"], q + ".max_attempts");
    if (m > 100000000) R.fail(g["max_attempts"], q + ".max_attempts", q + ".max_attempts: at most 1e8");
    src.max_attempts = static_cast<int>(m);
  }
  if (g["placement"]) {
    const std::string pl = R.string(g["placement"], q + ".placement");
    if (pl == "cells") src.placement = ParticleSource::kCells;
    else if (pl != "sequential")
      R.fail(g["placement"], q + ".placement", q + ".placement: unknown placement '" + pl + "' (valid: sequential, cells)");
  }
  if (g["velocity"]) src.velocity = R.vec3(g["velocity"], q + ".velocity");
  read_size(R, g["size"], q + ".size", src.size);
}

/// particles[i].file: a sphere file.
void read_file_source(const Reader& R, const YAML::Node& f, const std::string& q, const CaseConfig& c,
                      ParticleSource& src) {
  src.kind = ParticleSource::kFile;
  R.check_keys(f, q);
  R.require(f, q, "path", "sphere file, relative to the case file");
  R.require(f, q, "material");
  src.path = R.resolve(R.string(f["path"], q + ".path"));
  src.material = material_index(R, c, f["material"], q + ".material");
  if (f["scale"]) src.scale = R.positive(f["scale"], q + ".scale");
  if (f["offset"]) src.offset = R.vec3(f["offset"], q + ".offset");
  if (f["velocity"]) src.velocity = R.vec3(f["velocity"], q + ".velocity");
  const std::string problem = input_file_problem(src.path);
  if (!problem.empty())
    R.fail(f["path"], q + ".path", problem.rfind("cannot read", 0) == 0
                                       ? q + ".path: cannot read sphere file '" + src.path + "'"
                                       : q + ".path: sphere file '" + src.path + "' " + problem);
}

void read_particles(const Reader& R, const YAML::Node& n, CaseConfig& c) {
  const std::string P = "particles";
  R.expect_seq(n, P);
  for (std::size_t i = 0; i < n.size(); ++i) {
    const YAML::Node e = n[i];
    const std::string p = Reader::item(P, i);
    R.check_keys(e, p);
    if (e.size() != 1) R.fail(e, p, p + ": each entry has exactly one of inline, generate, file");
    ParticleSource src;
    src.source_file = R.file();
    src.line = e.Mark().is_null() ? 0 : e.Mark().line + 1;
    if (e["inline"]) read_inline_source(R, e["inline"], p + ".inline", c, src);
    else if (e["generate"]) read_generate_source(R, e["generate"], p + ".generate", c, src);
    else if (e["file"]) read_file_source(R, e["file"], p + ".file", c, src);
    c.particles.push_back(std::move(src));
  }
}

/// A facet wall's automatic servo area (projected across the axis) must not vanish.
void check_auto_area(const Reader& R, const YAML::Node& n, const std::string& q, const WallConfig& w,
                     const ServoConfig& s) {
  if (w.kind != WallConfig::kFacets) return;
  double a = 0, total = 0;
  for (const auto& t : w.triangles) {
    const Vec3 c = cross(w.vertices[t[1]] - w.vertices[t[0]], w.vertices[t[2]] - w.vertices[t[0]]);
    a += 0.5 * std::fabs(dot(c, s.axis));
    total += 0.5 * norm(c);
  }
  if (!(a > 1e-9 * total))
    R.fail(n, q, q + ": the facets' area projected across the axis is zero; give 'area' (m^2)");
}

void read_servo(const Reader& R, const YAML::Node& f, const std::string& q, const WallConfig& w, ServoConfig& s) {
  R.check_keys(f, q);
  R.require(f, q, "stress", "target stress, Pa, compression positive");
  R.require(f, q, "max_velocity", "m/s");
  s.stress = R.number(f["stress"], q + ".stress");
  if (s.stress < 0)
    R.fail(f["stress"], q + ".stress", q + ".stress: must be >= 0 (Pa, compression positive), got " + f["stress"].Scalar());
  s.max_velocity = R.positive(f["max_velocity"], q + ".max_velocity", " (m/s)");
  if (f["gain"]) {
    s.gain = R.number(f["gain"], q + ".gain");
    if (!(s.gain > 0 && s.gain <= 1))
      R.fail(f["gain"], q + ".gain", q + ".gain: must be in (0, 1] (the stability limit of the servo), got " + f["gain"].Scalar());
  }
  if (f["stiffness"]) s.stiffness = R.positive_or_auto(f["stiffness"], q + ".stiffness");
  if (f["velocity"]) s.velocity = R.vec3(f["velocity"], q + ".velocity");
  if (f["axis"]) {
    s.axis = R.vec3(f["axis"], q + ".axis");
    const double l = norm(s.axis);
    if (!(l > 0)) R.fail(f["axis"], q + ".axis", q + ".axis: must be non-zero");
    s.axis *= 1.0 / l;
    s.has_axis = true;
  } else if (w.kind != WallConfig::kPlane) {
    R.fail(f, q, "missing required key 'axis' in " + q + " (the direction in which a box or facet wall compresses the specimen)");
  }
  if (!f["area"]) {
    if (w.kind == WallConfig::kPlane)
      R.fail(f, q, "missing required key 'area' in " + q + " (m^2, or {between: [[a, b], [c, d]]}; a plane has no area of its own)");
    check_auto_area(R, f, q, w, s);
    return;  // auto
  }
  const YAML::Node a = f["area"];
  const std::string qa = q + ".area";
  if (a.IsMap()) {
    R.check_keys(a, qa);
    const YAML::Node b = a["between"];
    if (!b.IsSequence() || b.size() != 2 || !b[0].IsSequence() || b[0].size() != 2 || !b[1].IsSequence() ||
        b[1].size() != 2)
      R.fail(b, qa + ".between", qa + ".between: expected two pairs of plane wall names [[a, b], [c, d]]");
    for (int k = 0; k < 4; ++k) s.area_walls[k] = R.string(b[k / 2][k % 2], qa + ".between");
    return;
  }
  if (a.IsScalar() && a.Scalar() == "auto") {
    if (w.kind == WallConfig::kPlane)
      R.fail(a, qa, qa + ": 'auto' needs a box or facet wall (a plane has no area of its own)");
    check_auto_area(R, a, qa, w, s);
    return;
  }
  s.area = R.positive(a, qa, " (m^2)");
}

void read_motion(const Reader& R, const YAML::Node& n, const std::string& P, WallMotion& m,
                 const WallConfig& w) {
  m.line = n.Mark().is_null() ? 0 : n.Mark().line + 1;
  if (n.IsScalar()) {
    if (n.Scalar() == "fixed") { m.kind = WallMotion::kFixed; return; }
    R.fail(n, P, P + ": expected 'fixed', {velocity: [vx, vy, vz]}, {free: {...}}, {servo: {...}} or a list of them, got '" +
                     n.Scalar() + "'");
  }
  R.check_variant_keys(n, P, "single");
  if (n.size() != 1) R.fail(n, P, P + ": give exactly one of velocity, free, servo");
  if (n["servo"]) {
    m.kind = WallMotion::kServo;
    read_servo(R, n["servo"], P + ".servo", w, m.servo);
    return;
  }
  if (n["velocity"]) {
    m.kind = WallMotion::kVelocity;
    m.velocity = R.vec3(n["velocity"], P + ".velocity");
    return;
  }
  const YAML::Node f = n["free"];
  const std::string q = P + ".free";
  m.kind = WallMotion::kFree;
  R.check_keys(f, q);
  R.require(f, q, "mass", "kg");
  m.mass = R.positive(f["mass"], q + ".mass", " (kg)");
  if (f["dofs"]) {
    m.free_dofs = dof_bits(R, f["dofs"], q + ".dofs", false);
    if (m.free_dofs == 0) R.fail(f["dofs"], q + ".dofs", q + ".dofs: give at least one of x, y, z");
  }
  if (f["gravity"]) m.gravity = R.boolean(f["gravity"], q + ".gravity");
  if (f["velocity"]) m.velocity = R.vec3(f["velocity"], q + ".velocity");
}

/// `after: {unbalanced, kinetic_ratio, servo, time, steps}` of a schedule's phase: the conditions
/// on which it starts (at least one of unbalanced, servo, time, steps).
void read_after(const Reader& R, const YAML::Node& n, const std::string& q, WallMotion& m) {
  R.expect_map(n, q);
  R.check_keys(n, q);
  m.after = true;
  if (n["unbalanced"]) m.after_unbalanced = R.positive(n["unbalanced"], q + ".unbalanced", "");
  if (n["kinetic_ratio"]) m.after_kinetic = R.non_negative(n["kinetic_ratio"], q + ".kinetic_ratio");
  if (n["servo"]) m.after_servo = R.positive(n["servo"], q + ".servo", "");
  if (n["time"]) m.after_time = R.positive(n["time"], q + ".time", " (s)");
  if (n["steps"]) m.after_steps = R.positive_int(n["steps"], q + ".steps");
  if (n["stage"]) {
    m.after_stage = R.name(n["stage"], q + ".stage");
    if (n["unbalanced"] || n["servo"] || n["time"] || n["steps"])
      R.fail(n["stage"], q + ".stage", q + ".stage: starts with the phase it names; give no other condition");
    return;
  }
  if (!n["unbalanced"] && !n["servo"] && !n["time"] && !n["steps"])
    R.fail(n, q, q + ": give at least one condition: unbalanced, servo, time, steps or stage");
}

/// Every `after: {stage: name}` names a phase of some wall (not its own), and phase names are unique.
void resolve_phase_stages(const Reader& R, const YAML::Node& walls, const CaseConfig& c) {
  std::map<std::string, std::string> where;  // phase name -> "walls[i].motion[k]"
  const auto node = [&](const WallConfig& w, std::size_t k) { return walls[static_cast<std::size_t>(w.node)]["motion"][k]; };
  const auto path = [](const WallConfig& w, std::size_t k) {
    return Reader::item(Reader::item("walls", static_cast<std::size_t>(w.node)) + ".motion", k);
  };
  std::set<int> seen_nodes;
  for (const WallConfig& w : c.walls) {
    if (!seen_nodes.insert(w.node).second) continue;  // (segments and faces share their entry)
    for (std::size_t k = 0; k < w.schedule.size(); ++k) {
      const std::string& nm = w.schedule[k].name;
      if (nm.empty()) continue;
      if (where.count(nm))
        R.fail(node(w, k)["name"], path(w, k) + ".name", path(w, k) + ".name: phase name '" + nm + "' is already used by " + where[nm]);
      where[nm] = path(w, k);
    }
  }
  for (const WallConfig& w : c.walls)
    for (std::size_t k = 0; k < w.schedule.size(); ++k) {
      const std::string& st = w.schedule[k].after_stage;
      if (st.empty()) continue;
      std::vector<std::string> names;
      for (const auto& [n, p] : where) names.push_back(n);
      if (!where.count(st))
        R.fail(node(w, k)["after"]["stage"], path(w, k) + ".after.stage",
               path(w, k) + ".after.stage: no motion phase is named '" + st + "'" +
                   (names.empty() ? " (give the phase to start with `name: " + st + "`)" : " (names: " + join(names) + ")"));
      if (st == w.schedule[k].name)
        R.fail(node(w, k)["after"]["stage"], path(w, k) + ".after.stage", path(w, k) + ".after.stage: names its own phase");
    }
}

/// `motion` as one motion or as a schedule: a list of {from_step: N, <one motion>} (N strictly
/// increasing; the first defaults to 0; before the first phase the wall is fixed), or phases that
/// start `after:` a condition (every later phase too).
void read_motion_or_schedule(const Reader& R, const YAML::Node& n, const std::string& P, WallConfig& w) {
  if (!n.IsSequence()) { read_motion(R, n, P, w.motion, w); return; }
  if (n.size() == 0) R.fail(n, P, P + ": the list of motion phases is empty");
  for (std::size_t k = 0; k < n.size(); ++k) {
    const std::string q = Reader::item(P, k);
    const YAML::Node e = n[k];
    WallMotion m;
    if (e.IsMap()) {
      R.check_variant_keys(e, q, "phase");
      std::size_t given = 0;
      for (auto it = e.begin(); it != e.end(); ++it) {
        const std::string key = it->first.Scalar();
        if (key == "from_step") { m.from_step = R.non_negative_int(it->second, q + ".from_step"); continue; }
        if (key == "after") { read_after(R, it->second, q + ".after", m); continue; }
        if (key == "name") { m.name = R.name(it->second, q + ".name"); continue; }
        if (key == "fixed" && !R.boolean(it->second, q + ".fixed"))
          R.fail(it->second, q + ".fixed", q + ".fixed: only 'fixed: true' is meaningful");
        ++given;
      }
      if (given != 1) R.fail(e, q, q + ": give exactly one of fixed: true, velocity, free, servo (and optionally from_step or after)");
      if (e["from_step"] && e["after"]) R.fail(e["after"], q + ".after", q + ": give from_step or after, not both");
      if (e["fixed"]) m.kind = WallMotion::kFixed;
      else {
        // Read the one motion key with its own node (keeps its line for errors).
        for (const char* key : {"velocity", "free", "servo"})
          if (e[key]) {
            YAML::Node one(YAML::NodeType::Map);
            one[key] = e[key];
            read_motion(R, one, q, m, w);
          }
      }
      m.line = e.Mark().is_null() ? 0 : e.Mark().line + 1;
    } else {
      read_motion(R, e, q, m, w);
    }
    if (k > 0 && w.schedule.back().after && !m.after)
      R.fail(e, q, q + ": follows a phase that starts `after:` a condition, so it must start `after:` one too "
                       "(its step is not known before the run)");
    if (k > 0 && !m.after && m.from_step <= w.schedule.back().from_step)
      R.fail(e, q + ".from_step", q + ".from_step: phases must start at strictly increasing steps (previous phase from step " +
                                      std::to_string(w.schedule.back().from_step) + ")");
    w.schedule.push_back(m);
  }
  w.motion = w.schedule.front();
}

/// Servo areas given as {between: [[a, b], [c, d]]}: the named walls must be planes.
void resolve_servo_areas(const Reader& R, const YAML::Node& n, CaseConfig& c) {
  for (std::size_t i = 0; i < c.walls.size(); ++i) {
    WallConfig& w = c.walls[i];
    std::vector<WallMotion*> ms{&w.motion};
    for (WallMotion& m : w.schedule) ms.push_back(&m);
    for (WallMotion* m : ms) {
      if (m->kind != WallMotion::kServo || m->servo.area_walls[0].empty()) continue;
      for (int k = 0; k < 4; ++k) {
        const std::string& name = m->servo.area_walls[k];
        int idx = -1;
        for (std::size_t j = 0; j < c.walls.size(); ++j)
          if (c.walls[j].name == name) idx = static_cast<int>(j);
        const std::string p = Reader::item("walls", static_cast<std::size_t>(w.node)) + ".motion";
        const YAML::Node mn = n[static_cast<std::size_t>(w.node)]["motion"];
        if (idx < 0) R.fail(mn, p, p + ": servo area: unknown wall '" + name + "'");
        if (c.walls[idx].kind != WallConfig::kPlane)
          R.fail(mn, p, p + ": servo area: wall '" + name + "' is not a plane (the gap is measured between planes)");
        m->servo.area_wall_index[k] = idx;
      }
    }
  }
}

/// `segments: [n1, n2]` of a servo box: the box cut across its servo axis (a coordinate
/// direction) into n1 x n2 equal boxes <name>_1 ... <name>_{n1 n2}, each its own servo with the
/// wall's motion (areas automatic: each segment's face). Numbered along the first of the two
/// cut directions first (x before y before z).
void split_into_segments(const Reader& R, const YAML::Node& n, const std::string& q, const WallConfig& w,
                         CaseConfig& c) {
  if (!n.IsSequence() || n.size() != 2) R.fail(n, q, q + ": expected [n1, n2] (segments along the two directions across the servo axis)");
  std::array<int, 2> cnt{};
  for (int k = 0; k < 2; ++k) {
    const std::int64_t v = R.integer(n[k], Reader::item(q, static_cast<std::size_t>(k)));
    if (v < 1 || v > 1000) R.fail(n[k], Reader::item(q, static_cast<std::size_t>(k)), q + ": each count must be in [1, 1000], got " + std::to_string(v));
    cnt[k] = static_cast<int>(v);
  }
  std::vector<const WallMotion*> ms{&w.motion};
  for (const WallMotion& m : w.schedule) ms.push_back(&m);
  int axis = -1;
  for (const WallMotion* m : ms) {
    if (m->kind != WallMotion::kServo) continue;
    if (m->servo.area > 0 || !m->servo.area_walls[0].empty())
      R.fail(n, q, q + ": a segmented wall's servo area is each segment's own face: remove 'area'");
    int a = -1;
    for (int d = 0; d < 3; ++d)
      if (std::fabs(m->servo.axis[d]) > 1 - 1e-12) a = d;
    if (a < 0 || (axis >= 0 && a != axis))
      R.fail(n, q, q + ": segments need a servo axis along x, y or z (the same in every phase)");
    axis = a;
  }
  if (axis < 0) R.fail(n, q, q + ": only a servo-controlled box can be split into segments (give motion: {servo: ...})");
  const int d1 = axis == 0 ? 1 : 0, d2 = axis == 2 ? 1 : 2;
  WallGroup g{w.name, static_cast<int>(c.walls.size()), cnt[0] * cnt[1]};
  for (int j = 0; j < cnt[1]; ++j)
    for (int i = 0; i < cnt[0]; ++i) {
      WallConfig s = w;
      s.name = w.name + "_" + std::to_string(j * cnt[0] + i + 1);
      const double h1 = (w.max[d1] - w.min[d1]) / cnt[0], h2 = (w.max[d2] - w.min[d2]) / cnt[1];
      s.min[d1] = w.min[d1] + i * h1;
      s.max[d1] = i + 1 == cnt[0] ? w.max[d1] : w.min[d1] + (i + 1) * h1;
      s.min[d2] = w.min[d2] + j * h2;
      s.max[d2] = j + 1 == cnt[1] ? w.max[d2] : w.min[d2] + (j + 1) * h2;
      for (const WallConfig& o : c.walls)
        if (o.name == s.name) R.fail(n, q, q + ": segment name '" + s.name + "' is already a wall's name");
      c.walls.push_back(std::move(s));
    }
  c.wall_groups.push_back(g);
}

/// `type: container`: the hollow box [min, max] the grains fill, read as its faces: fixed plane
/// walls <name>_xmin ... <name>_zmax with normals pointing in, less the faces listed in `open`.
void read_container(const Reader& R, const YAML::Node& e, const std::string& p, const WallConfig& w, CaseConfig& c) {
  static const char* const kFaces[6] = {"xmin", "xmax", "ymin", "ymax", "zmin", "zmax"};
  std::array<bool, 6> open{};
  if (e["open"]) {
    const std::string q = p + ".open";
    R.expect_seq(e["open"], q);
    for (std::size_t j = 0; j < e["open"].size(); ++j) {
      const std::string f = R.string(e["open"][j], Reader::item(q, j));
      int k = 0;
      while (k < 6 && f != kFaces[k]) ++k;
      if (k == 6) R.fail(e["open"][j], Reader::item(q, j), q + ": unknown face '" + f + "' (valid: xmin, xmax, ymin, ymax, zmin, zmax)");
      open[static_cast<std::size_t>(k)] = true;
    }
  }
  WallGroup g{w.name, static_cast<int>(c.walls.size()), 0, true};
  for (int k = 0; k < 6; ++k) {
    if (open[static_cast<std::size_t>(k)]) continue;
    WallConfig f = w;
    f.kind = WallConfig::kPlane;
    f.name = w.name + "_" + kFaces[k];
    const int d = k / 2;
    f.point = k % 2 ? w.max : w.min;
    f.normal = Vec3{};
    f.normal[d] = k % 2 ? -1.0 : 1.0;
    for (const WallConfig& o : c.walls)
      if (o.name == f.name) R.fail(e["name"], p + ".name", p + ": face name '" + f.name + "' is already a wall's name");
    c.walls.push_back(std::move(f));
    ++g.count;
  }
  if (g.count == 0) R.fail(e["open"], p + ".open", p + ".open: every face is open: the container has no wall");
  c.wall_groups.push_back(g);
}

/// A facet wall's vertices and triangles (0-based indices, no degenerate triangle).
void read_facet_wall(const Reader& R, const YAML::Node& e, const std::string& p, WallConfig& w) {
  R.require(e, p, "vertices", "[[x,y,z], ...]");
  R.require(e, p, "triangles", "[[i,j,k], ...], 0-based vertex indices");
  const YAML::Node vs = e["vertices"], ts = e["triangles"];
  R.expect_seq(vs, p + ".vertices");
  R.expect_seq(ts, p + ".triangles");
  for (std::size_t k = 0; k < vs.size(); ++k) w.vertices.push_back(R.vec3(vs[k], Reader::item(p + ".vertices", k)));
  if (ts.size() == 0) R.fail(ts, p + ".triangles", p + ".triangles: the list is empty");
  for (std::size_t k = 0; k < ts.size(); ++k) {
    const std::string q = Reader::item(p + ".triangles", k);
    const YAML::Node t = ts[k];
    if (!t.IsSequence() || t.size() != 3) R.fail(t, q, q + ": expected 3 vertex indices [i, j, k]");
    std::array<int, 3> tri{};
    for (int a = 0; a < 3; ++a) {
      const std::int64_t v = R.integer(t[a], Reader::item(q, a));
      if (v < 0 || v >= static_cast<std::int64_t>(w.vertices.size()))
        R.fail(t[a], Reader::item(q, a), q + ": vertex index " + std::to_string(v) + " out of range [0, " +
                                             std::to_string(w.vertices.size()) + ")");
      tri[a] = static_cast<int>(v);
    }
    const Vec3 nrm = cross(w.vertices[tri[1]] - w.vertices[tri[0]], w.vertices[tri[2]] - w.vertices[tri[0]]);
    double scale = std::max({norm2(w.vertices[tri[1]] - w.vertices[tri[0]]),
                             norm2(w.vertices[tri[2]] - w.vertices[tri[0]])});
    if (!(norm(nrm) > 1e-12 * scale)) R.fail(t, q, q + ": degenerate triangle (zero area)");
    w.triangles.push_back(tri);
  }
}

/// A wall's name must differ from every wall's and segmented wall's, and their segments'.
void check_wall_name(const Reader& R, const YAML::Node& node, const std::string& p, const std::string& name,
                     const CaseConfig& c) {
  for (int k = 0; k < static_cast<int>(c.wall_groups.size()); ++k) {
    const WallGroup& g = c.wall_groups[static_cast<std::size_t>(k)];
    for (int j = g.first; j < g.first + g.count; ++j)
      if (c.walls[static_cast<std::size_t>(j)].name == name)
        R.fail(node, p + ".name", p + ".name: '" + name + "' is the name of a segment of wall '" + g.name + "'");
  }
  for (const auto& o : c.walls)
    if (o.name == name) R.fail(node, p + ".name", p + ".name: duplicate wall name '" + name + "'");
  for (const auto& g : c.wall_groups)
    if (g.name == name) R.fail(node, p + ".name", p + ".name: duplicate wall name '" + name + "'");
}

std::vector<double> read_factors(const Reader& R, const YAML::Node& n, const std::string& P);

/// `bands: {axis, edges}`: the wall's force also summed per band of the grains' centres along axis.
void read_wall_bands(const Reader& R, const YAML::Node& n, const std::string& q, WallConfig& w) {
  R.expect_map(n, q);
  R.check_keys(n, q);
  R.require(n, q, "axis", "the direction along which the bands lie, e.g. [0, 0, 1]");
  R.require(n, q, "edges", "the band edges along the axis, m, strictly increasing");
  w.band_axis = R.vec3(n["axis"], q + ".axis");
  const double l = norm(w.band_axis);
  if (!(l > 0)) R.fail(n["axis"], q + ".axis", q + ".axis: must be non-zero");
  w.band_axis *= 1.0 / l;
  const YAML::Node es = n["edges"];
  w.band_edges = read_factors(R, es, q + ".edges");
  if (w.band_edges.size() < 2) R.fail(es, q + ".edges", q + ".edges: give at least two edges (one band)");
  if (w.band_edges.size() > 10001) R.fail(es, q + ".edges", q + ".edges: at most 10000 bands");
  for (std::size_t k = 1; k < w.band_edges.size(); ++k)
    if (!(w.band_edges[k] > w.band_edges[k - 1]))
      R.fail(es[k], Reader::item(q + ".edges", k), Reader::item(q + ".edges", k) + ": the edges must increase strictly (" +
                                                        short_num(w.band_edges[k]) + " after " + short_num(w.band_edges[k - 1]) + ")");
}

void read_walls(const Reader& R, const YAML::Node& n, CaseConfig& c) {
  const std::string P = "walls";
  R.expect_seq(n, P);
  for (std::size_t i = 0; i < n.size(); ++i) {
    const YAML::Node e = n[i];
    const std::string p = Reader::item(P, i);
    R.expect_map(e, p);
    R.require(e, p, "type", "plane, box, container or facets");
    const std::string type = R.string(e["type"], p + ".type");
    WallConfig w;
    w.line = e.Mark().is_null() ? 0 : e.Mark().line + 1;
    if (type == "plane") {
      w.kind = WallConfig::kPlane;
      R.check_variant_keys(e, p, "plane");
    } else if (type == "box") {
      w.kind = WallConfig::kBox;
      R.check_variant_keys(e, p, "box");
    } else if (type == "container") {
      w.kind = WallConfig::kBox;  // (read as its faces below)
      R.check_variant_keys(e, p, "container");
    } else if (type == "facets") {
      w.kind = WallConfig::kFacets;
      R.check_variant_keys(e, p, "facets");
    } else {
      R.fail(e["type"], p + ".type", p + ".type: unknown wall type '" + type + "' (valid: plane, box, container, facets)");
    }
    R.require(e, p, "name");
    R.require(e, p, "material");
    w.name = R.name(e["name"], p + ".name");
    check_wall_name(R, e["name"], p, w.name, c);
    w.material = material_index(R, c, e["material"], p + ".material");
    if (w.kind == WallConfig::kPlane) {
      R.require(e, p, "point", "a point on the plane, m");
      R.require(e, p, "normal", "pointing to the particles' side");
      w.point = R.vec3(e["point"], p + ".point");
      w.normal = R.vec3(e["normal"], p + ".normal");
      const double l = norm(w.normal);
      if (!(l > 0)) R.fail(e["normal"], p + ".normal", p + ".normal: must be non-zero");
      w.normal *= 1.0 / l;
    } else if (w.kind == WallConfig::kBox) {
      R.require(e, p, "min");
      R.require(e, p, "max");
      w.min = R.vec3(e["min"], p + ".min");
      w.max = R.vec3(e["max"], p + ".max");
      for (int k = 0; k < 3; ++k)
        if (!(w.min[k] < w.max[k])) R.fail(e["max"], p + ".max", p + ": min must be below max in every direction");
    } else {
      read_facet_wall(R, e, p, w);
    }
    if (e["motion"]) read_motion_or_schedule(R, e["motion"], p + ".motion", w);
    if (e["bands"]) read_wall_bands(R, e["bands"], p + ".bands", w);
    w.node = static_cast<int>(i);
    if (type == "container") {
      read_container(R, e, p, w, c);
      continue;
    }
    if (e["segments"]) {
      split_into_segments(R, e["segments"], p + ".segments", w, c);
      continue;
    }
    c.walls.push_back(std::move(w));
  }
  resolve_servo_areas(R, n, c);
  resolve_phase_stages(R, n, c);
}

void read_constraints(const Reader& R, const YAML::Node& n, CaseConfig& c) {
  const std::string P = "constraints";
  R.expect_seq(n, P);
  for (std::size_t i = 0; i < n.size(); ++i) {
    const YAML::Node e = n[i];
    const std::string p = Reader::item(P, i);
    R.check_keys(e, p);
    ConstraintConfig k;
    k.line = e.Mark().is_null() ? 0 : e.Mark().line + 1;
    if (e["ids"] && e["region"]) R.fail(e, p, p + ": give either ids or region, not both");
    if (!e["ids"] && !e["region"]) R.fail(e, p, "missing required key 'ids' or 'region' in " + p);
    if (e["ids"]) {
      R.expect_seq(e["ids"], p + ".ids");
      for (std::size_t j = 0; j < e["ids"].size(); ++j) k.ids.push_back(R.integer(e["ids"][j], Reader::item(p + ".ids", j)));
    } else {
      k.has_region = true;
      read_box(R, e["region"], p + ".region", k.region_min, k.region_max);
    }
    const bool fixed = e["fixed"] && R.boolean(e["fixed"], p + ".fixed");
    if (fixed && e["block"]) R.fail(e["block"], p + ".block", p + ": give either fixed: true or block, not both");
    if (fixed && e["velocity"])
      R.fail(e["velocity"], p + ".velocity", p + ": fixed: true means zero velocity; use block: [x, y, z] with velocity");
    if (fixed) k.blocked = kDofAll;
    else if (e["block"]) k.blocked = dof_bits(R, e["block"], p + ".block", true);
    else R.fail(e, p, "missing required key 'fixed' or 'block' in " + p);
    if (k.blocked == 0) R.fail(e, p, p + ": no degree of freedom blocked");
    if (e["velocity"]) {
      k.has_velocity = true;
      k.velocity = R.vec3(e["velocity"], p + ".velocity");
    }
    c.constraints.push_back(std::move(k));
  }
}

void read_output(const Reader& R, const YAML::Node& n, CaseConfig& c) {
  const std::string P = "output";
  R.check_keys(n, P);
  if (n["dir"]) {
    c.out_dir = R.string(n["dir"], P + ".dir");
    std::tie(c.out_dir_file, c.out_dir_line) = R.location(n["dir"], P + ".dir");
  }
  if (n["snapshot_every"]) c.snapshot_every = R.non_negative_int(n["snapshot_every"], P + ".snapshot_every");
  if (n["history_every"]) c.history_every = R.positive_int(n["history_every"], P + ".history_every");
  if (n["checkpoint_every"]) c.checkpoint_every = R.non_negative_int(n["checkpoint_every"], P + ".checkpoint_every");
}


// ---------------------------------------------------------------- fem
int fem_mesh_index(const Reader& R, const CaseConfig& c, const YAML::Node& n, const std::string& path) {
  const std::string name = R.string(n, path);
  std::vector<std::string> names;
  for (std::size_t i = 0; i < c.fem.meshes.size(); ++i) {
    if (c.fem.meshes[i].name == name) return static_cast<int>(i);
    names.push_back(c.fem.meshes[i].name);
  }
  R.fail(n, path, path + ": unknown mesh '" + name + "' (valid: " + join(names) + ")");
}

std::array<int, 3> int3(const Reader& R, const YAML::Node& n, const std::string& path) {
  if (!n.IsSequence() || n.size() != 3) R.fail(n, path, path + ": expected a list of 3 positive integers");
  std::array<int, 3> v{};
  for (int i = 0; i < 3; ++i) v[i] = static_cast<int>(R.positive_int(n[i], Reader::item(path, i)));
  return v;
}

void read_fem_materials(const Reader& R, const YAML::Node& n, FeConfig& f) {
  const std::string P = "fem.materials";
  R.expect_seq(n, P);
  if (n.size() == 0) R.fail(n, P, P + ": the list is empty");
  for (std::size_t i = 0; i < n.size(); ++i) {
    const YAML::Node e = n[i];
    const std::string p = Reader::item(P, i);
    R.check_keys(e, p);
    FeMaterialConfig m;
    m.line = e.Mark().is_null() ? 0 : e.Mark().line + 1;
    R.require(e, p, "name");
    m.name = R.name(e["name"], p + ".name");
    for (const auto& o : f.materials)
      if (o.name == m.name) R.fail(e["name"], p + ".name", p + ".name: duplicate FE material name '" + m.name + "'");
    std::string model = "elastic";
    if (e["model"]) model = R.string(e["model"], p + ".model");
    if (model == "mohr_coulomb") m.mohr_coulomb = true;
    else if (model != "elastic")
      R.fail(e["model"], p + ".model", p + ".model: unknown model '" + model + "' (valid: elastic, mohr_coulomb)");
    R.require(e, p, "young", "Pa");
    m.young = R.positive(e["young"], p + ".young", " (Pa)");
    if (e["poisson"]) {
      m.poisson = R.number(e["poisson"], p + ".poisson");
      if (!(m.poisson > -1 && m.poisson < 0.5)) R.fail(e["poisson"], p + ".poisson", p + ".poisson: must be in (-1, 0.5), got " + e["poisson"].Scalar());
    }
    R.require(e, p, "density", "kg/m^3");
    m.density = R.positive(e["density"], p + ".density", " (kg/m^3)");
    if (e["unit_weight"]) m.unit_weight = R.non_negative(e["unit_weight"], p + ".unit_weight");
    if (e["hourglass"]) m.hourglass = R.non_negative(e["hourglass"], p + ".hourglass");
    if (e["thickness"]) m.thickness = R.positive(e["thickness"], p + ".thickness", " (m)");
    if (e["nlgeom"]) m.nlgeom = R.boolean(e["nlgeom"], p + ".nlgeom");
    if (m.nlgeom && m.mohr_coulomb)
      R.fail(e["nlgeom"], p + ".nlgeom", p + ".nlgeom: only for model: elastic (a total Lagrangian Mohr-Coulomb is not built)");
    if (m.mohr_coulomb) {
      R.require(e, p, "friction_angle", "degrees");
      if (e["cohesion"]) m.cohesion = R.non_negative(e["cohesion"], p + ".cohesion");
      m.friction_deg = R.non_negative(e["friction_angle"], p + ".friction_angle");
      if (m.friction_deg >= 90) R.fail(e["friction_angle"], p + ".friction_angle", p + ".friction_angle: must be below 90 degrees");
      if (e["dilation_angle"]) m.dilation_deg = R.non_negative(e["dilation_angle"], p + ".dilation_angle");
      if (m.dilation_deg > m.friction_deg)
        R.fail(e["dilation_angle"], p + ".dilation_angle", p + ".dilation_angle: must not exceed the friction angle");
    } else {
      for (const char* k : {"cohesion", "friction_angle", "dilation_angle"})
        if (e[k]) R.fail(e[k], p + "." + k, p + "." + k + ": only for model: mohr_coulomb");
    }
    f.materials.push_back(m);
  }
}

/// A mesh's `element` key (default the mesh kind's), checked against the element table.
void read_element_name(const Reader& R, const YAML::Node& g, const std::string& q, FeMeshConfig& m) {
  if (!g["element"]) return;
  m.element = R.string(g["element"], q + ".element");
  bool known = false;
  for (const auto& t : fem::kElementTraits) known = known || m.element == t.name;
  if (!known)
    R.fail(g["element"], q + ".element",
           q + ".element: unknown element '" + m.element + "' (valid: " + fem::element_type_names() + ")");
}

/// fem.meshes[].block: a structured block of bricks.
void read_mesh_block(const Reader& R, const YAML::Node& g, const std::string& q, FeMeshConfig& m) {
  R.check_keys(g, q);
  m.kind = FeMeshConfig::kBlock;
  R.require(g, q, "min"); R.require(g, q, "max"); R.require(g, q, "divisions");
  m.min = R.vec3(g["min"], q + ".min");
  m.max = R.vec3(g["max"], q + ".max");
  m.divisions = int3(R, g["divisions"], q + ".divisions");
  read_element_name(R, g, q, m);
  if (m.element != "hex8" && m.element != "hex8i" && m.element != "hex8r" && m.element != "shell4")
    R.fail(g["element"], q + ".element", q + ".element: blocks are meshed with hex8, hex8i, hex8r or shell4");
  if (m.element == "shell4") {
    // a plate: flat in exactly one direction, one element through it
    int flat = 0;
    for (int d = 0; d < 3; ++d) {
      if (m.min[d] == m.max[d]) {
        ++flat;
        m.plate_axis = d;
      } else if (!(m.min[d] < m.max[d])) {
        R.fail(g["max"], q + ".max", q + ": min must not be above max");
      }
    }
    if (flat != 1)
      R.fail(g["max"], q + ".max", q + ": a shell4 block is a plate: min and max equal in exactly one direction (its plane)");
    if (m.divisions[m.plate_axis] != 1)
      R.fail(g["divisions"], q + ".divisions", q + ".divisions: a plate has 1 division across its plane (" +
                                                   std::string(1, "xyz"[m.plate_axis]) + ")");
    if (g["void"]) R.fail(g["void"], q + ".void", q + ".void: a plate has no void");
    return;
  }
  for (int d = 0; d < 3; ++d)
    if (!(m.min[d] < m.max[d])) R.fail(g["max"], q + ".max", q + ": min must be below max in every direction");
  if (g["void"]) {
    m.has_void = true;
    read_box(R, g["void"], q + ".void", m.void_min, m.void_max);
  }
}

/// fem.meshes[].geogrid: a generated biaxial geogrid.
void read_mesh_geogrid(const Reader& R, const YAML::Node& g, const std::string& q, FeMeshConfig& m) {
  R.check_keys(g, q);
  m.kind = FeMeshConfig::kGeogrid;
  for (const char* k : {"length", "width", "longitudinal_ribs", "transverse_ribs", "rib_width", "thickness"})
    R.require(g, q, k);
  m.length = R.positive(g["length"], q + ".length", " (m)");
  m.width = R.positive(g["width"], q + ".width", " (m)");
  m.longitudinal_ribs = static_cast<int>(R.positive_int(g["longitudinal_ribs"], q + ".longitudinal_ribs"));
  m.transverse_ribs = static_cast<int>(R.positive_int(g["transverse_ribs"], q + ".transverse_ribs"));
  m.rib_width = R.positive(g["rib_width"], q + ".rib_width", " (m)");
  m.thickness = R.positive(g["thickness"], q + ".thickness", " (m)");
  if (g["junction_thickness"]) m.junction_thickness = R.non_negative(g["junction_thickness"], q + ".junction_thickness");
  if (g["clamp_length"]) m.clamp_length = R.non_negative(g["clamp_length"], q + ".clamp_length");
  if (g["clamp_gap"]) m.clamp_gap = R.non_negative(g["clamp_gap"], q + ".clamp_gap");
  if (g["side_overhang"]) m.side_overhang = R.non_negative(g["side_overhang"], q + ".side_overhang");
  if (g["origin"]) m.origin = R.vec3(g["origin"], q + ".origin");
  if (g["elements_per_rib_width"]) m.elements_per_rib_width = static_cast<int>(R.positive_int(g["elements_per_rib_width"], q + ".elements_per_rib_width"));
  if (g["elements_through_thickness"]) m.elements_through_thickness = static_cast<int>(R.positive_int(g["elements_through_thickness"], q + ".elements_through_thickness"));
  if (g["max_element_length"]) m.max_element_length = R.non_negative(g["max_element_length"], q + ".max_element_length");
  read_element_name(R, g, q, m);
  if (m.element != "hex8" && m.element != "hex8i")
    R.fail(g["element"], q + ".element", q + ".element: geogrids are meshed with hex8 or hex8i");
}

/// fem.meshes[].thesis: the thesis's text formats.
void read_mesh_thesis(const Reader& R, const YAML::Node& g, const std::string& q, FeMeshConfig& m) {
  R.check_keys(g, q);
  m.kind = FeMeshConfig::kThesis;
  R.require(g, q, "nodes"); R.require(g, q, "elements");
  m.nodes_file = R.resolve(R.string(g["nodes"], q + ".nodes"));
  m.elements_file = R.resolve(R.string(g["elements"], q + ".elements"));
  read_element_name(R, g, q, m);
  if (g["dim"]) {
    m.dim = static_cast<int>(R.integer(g["dim"], q + ".dim"));
    if (m.dim != 2 && m.dim != 3) R.fail(g["dim"], q + ".dim", q + ".dim: must be 2 or 3");
  }
  if ((m.element == "quad4") != (m.dim == 2) && !(m.element == "shell4" && m.dim == 3))
    R.fail(g, q, q + ": quad4 elements go with dim: 2, bricks with dim: 3");
  for (const std::string* file : {&m.nodes_file, &m.elements_file}) {
    const std::string problem = input_file_problem(*file);
    if (!problem.empty())
      R.fail(g, q, problem.rfind("cannot read", 0) == 0 ? q + ": cannot read mesh file '" + *file + "'"
                                                        : q + ": mesh file '" + *file + "' " + problem);
  }
}

/// fem.meshes[].cylinder: a pipe of shell4 elements.
void read_mesh_cylinder(const Reader& R, const YAML::Node& g, const std::string& q, FeMeshConfig& m) {
  R.check_keys(g, q);
  m.kind = FeMeshConfig::kCylinder;
  m.element = "shell4";
  R.require(g, q, "radius"); R.require(g, q, "length"); R.require(g, q, "divisions");
  if (g["base"]) m.base = R.vec3(g["base"], q + ".base");
  m.radius = R.positive(g["radius"], q + ".radius", " (m)");
  m.length = R.positive(g["length"], q + ".length", " (m)");
  const YAML::Node dv = g["divisions"];
  if (!dv.IsSequence() || dv.size() != 2) R.fail(dv, q + ".divisions", q + ".divisions: expected [around, along]");
  m.cyl_divisions = {static_cast<int>(R.positive_int(dv[0], q + ".divisions[0]")),
                     static_cast<int>(R.positive_int(dv[1], q + ".divisions[1]"))};
  if (m.cyl_divisions[0] < 3) R.fail(dv, q + ".divisions", q + ".divisions: at least 3 elements around");
  if (g["axis"]) {
    const std::string a = R.string(g["axis"], q + ".axis");
    if (a != "x" && a != "y" && a != "z") R.fail(g["axis"], q + ".axis", q + ".axis: must be x, y or z, got '" + a + "'");
    m.cyl_axis = a[0] - 'x';
  }
}

/// fem.meshes[].gmsh: a Gmsh file.
void read_mesh_gmsh(const Reader& R, const YAML::Node& e, const std::string& p, FeMeshConfig& m) {
  m.kind = FeMeshConfig::kGmsh;
  m.gmsh_file = R.resolve(R.string(e["gmsh"], p + ".gmsh"));
  const std::string problem = input_file_problem(m.gmsh_file);
  if (!problem.empty())
    R.fail(e["gmsh"], p + ".gmsh", problem.rfind("cannot read", 0) == 0
                                       ? p + ".gmsh: cannot read mesh file '" + m.gmsh_file + "'"
                                       : p + ".gmsh: mesh file '" + m.gmsh_file + "' " + problem);
}

void read_fem_meshes(const Reader& R, const YAML::Node& n, FeConfig& f) {
  const std::string P = "fem.meshes";
  R.expect_seq(n, P);
  if (n.size() == 0) R.fail(n, P, P + ": the list is empty");
  for (std::size_t i = 0; i < n.size(); ++i) {
    const YAML::Node e = n[i];
    const std::string p = Reader::item(P, i);
    R.check_keys(e, p);
    FeMeshConfig m;
    m.line = e.Mark().is_null() ? 0 : e.Mark().line + 1;
    R.require(e, p, "name");
    m.name = R.name(e["name"], p + ".name");
    for (const auto& o : f.meshes)
      if (o.name == m.name) R.fail(e["name"], p + ".name", p + ".name: duplicate mesh name '" + m.name + "'");
    R.require(e, p, "material");
    {
      const std::string name = R.string(e["material"], p + ".material");
      std::vector<std::string> names;
      for (std::size_t k = 0; k < f.materials.size(); ++k) {
        if (f.materials[k].name == name) m.material = static_cast<int>(k);
        names.push_back(f.materials[k].name);
      }
      if (m.material < 0)
        R.fail(e["material"], p + ".material", p + ".material: unknown FE material '" + name + "' (valid: " + join(names) + ")");
    }
    int kinds = 0;
    for (const char* k : {"block", "geogrid", "thesis", "gmsh", "cylinder"}) kinds += e[k] ? 1 : 0;
    if (kinds != 1) R.fail(e, p, p + ": give exactly one of block, geogrid, thesis, gmsh, cylinder");
    if (e["block"]) read_mesh_block(R, e["block"], p + ".block", m);
    else if (e["geogrid"]) read_mesh_geogrid(R, e["geogrid"], p + ".geogrid", m);
    else if (e["thesis"]) read_mesh_thesis(R, e["thesis"], p + ".thesis", m);
    else if (e["cylinder"]) read_mesh_cylinder(R, e["cylinder"], p + ".cylinder", m);
    else read_mesh_gmsh(R, e, p, m);
    if ((m.element == "shell4" || m.element == "hex8r") && f.materials[m.material].nlgeom)
      R.fail(e["material"], p + ".material",
             p + ": fem.materials '" + f.materials[m.material].name + "' has nlgeom: true, which " + m.element +
                 " elements do not support (hex8, hex8i, hex20 and quad4 do)");
    if (m.element == "hex8i" && f.materials[m.material].mohr_coulomb)
      R.fail(e["material"], p + ".material",
             p + ": fem.materials '" + f.materials[m.material].name +
                 "' is mohr_coulomb; hex8i elements are elastic only (use hex8, hex8r or hex20)");
    if (m.element == "shell4" && !(f.materials[m.material].thickness > 0))
      R.fail(e["material"], p + ".material",
             p + ": shell4 elements need a thickness: give fem.materials '" + f.materials[m.material].name +
                 "' a thickness (m)");
    f.meshes.push_back(m);
  }
}

void read_fem_nodal(const Reader& R, const CaseConfig& c, const YAML::Node& n, const std::string& P,
                    std::vector<FeNodalConfig>& out, int kind /* 0 restraint, 1 load, 2 displacement */) {
  R.expect_seq(n, P);
  for (std::size_t i = 0; i < n.size(); ++i) {
    const YAML::Node e = n[i];
    const std::string p = Reader::item(P, i);
    const char* value_key = kind == 0 ? "fixed" : (kind == 1 ? "total" : "value");
    if (kind == 1 && e.IsMap() && e["pressure"]) {
      R.check_variant_keys(e, p, "pressure");
      FeNodalConfig b;
      b.line = e.Mark().is_null() ? 0 : e.Mark().line + 1;
      R.require(e, p, "mesh");
      b.mesh = fem_mesh_index(R, c, e["mesh"], p + ".mesh");
      b.is_pressure = true;
      b.pressure = R.number(e["pressure"], p + ".pressure");
      out.push_back(b);
      continue;
    }
    if (kind == 1) R.check_variant_keys(e, p, "nodal");
    else R.check_keys(e, p);
    FeNodalConfig b;
    b.line = e.Mark().is_null() ? 0 : e.Mark().line + 1;
    R.require(e, p, "mesh");
    b.mesh = fem_mesh_index(R, c, e["mesh"], p + ".mesh");
    if ((e["node_set"] ? 1 : 0) + (e["file"] ? 1 : 0) + (e["region"] ? 1 : 0) > 1)
      R.fail(e, p, p + ": give one of node_set, region or file");
    if (e["file"]) {
      b.file = R.resolve(R.string(e["file"], p + ".file"));
      const std::string problem = input_file_problem(b.file);
      if (!problem.empty())
        R.fail(e["file"], p + ".file", problem.rfind("cannot read", 0) == 0 ? p + ".file: cannot read '" + b.file + "'"
                                                                           : p + ".file: '" + b.file + "' " + problem);
      if (e[value_key]) R.fail(e[value_key], p + "." + value_key, p + ": the values come from the file; remove '" + value_key + "'");
    } else {
      if (!e["node_set"] && !e["region"]) R.fail(e, p, "missing required key 'node_set', 'region' or 'file' in " + p);
      if (e["node_set"]) b.node_set = R.string(e["node_set"], p + ".node_set");
      else {
        b.has_region = true;
        read_box(R, e["region"], p + ".region", b.region_min, b.region_max);
      }
      R.require(e, p, value_key);
      if (kind == 0) {
        const std::uint8_t bits = dof_bits(R, e["fixed"], p + ".fixed", true);
        for (int d = 0; d < 3; ++d) {
          b.fixed[d] = bits & (1u << d);
          b.fixed_rot[d] = bits & (8u << d);
        }
      } else {
        b.value = R.vec3(e[value_key], p + "." + value_key);
      }
    }
    out.push_back(b);
  }
}

std::vector<double> read_factors(const Reader& R, const YAML::Node& n, const std::string& P) {
  R.expect_seq(n, P);
  if (n.size() == 0) R.fail(n, P, P + ": the list is empty");
  std::vector<double> v;
  for (std::size_t i = 0; i < n.size(); ++i) v.push_back(R.number(n[i], Reader::item(P, i)));
  return v;
}

/// fem's solver settings (solver, damping, safety, ... gravity).
void read_fem_solver(const Reader& R, const YAML::Node& n, const std::string& P, FeConfig& f) {
  if (n["solver"]) {
    const std::string s = R.string(n["solver"], P + ".solver");
    if (s == "static") f.static_solver = true;
    else if (s != "relaxation") R.fail(n["solver"], P + ".solver", P + ".solver: unknown solver '" + s + "' (valid: relaxation, static)");
  }
  if (n["damping"]) {
    const double d = R.positive_or_auto(n["damping"], P + ".damping");
    f.damping = d > 0 ? d : -1;
  }
  if (n["safety"]) {
    f.safety = R.positive(n["safety"], P + ".safety");
    if (f.safety > 1) R.fail(n["safety"], P + ".safety", P + ".safety: must be in (0, 1]");
  }
  if (n["mass_scaling"]) {
    f.mass_scaling = R.positive_or_auto(n["mass_scaling"], P + ".mass_scaling");
    f.mass_scaling_auto = f.mass_scaling == 0;
    if (f.mass_scaling_auto) f.mass_scaling = 1;  // (the model is built unscaled; the coupled set-up scales it)
    if (f.mass_scaling < 1)
      R.fail(n["mass_scaling"], P + ".mass_scaling", P + ".mass_scaling: must be at least 1 (it multiplies the densities), got " +
                                                         n["mass_scaling"].Scalar());
  }
  if (n["tolerance"]) f.tolerance = R.positive(n["tolerance"], P + ".tolerance");
  if (n["max_steps"]) f.max_steps = R.positive_int(n["max_steps"], P + ".max_steps");
  if (n["check_every"]) f.check_every = static_cast<int>(R.positive_int(n["check_every"], P + ".check_every"));
  if (n["gravity"]) f.gravity = R.boolean(n["gravity"], P + ".gravity");
  if (n["distribute"]) f.distribute = R.boolean(n["distribute"], P + ".distribute");
}

/// A static solve needs restraints, and every direction held somewhere.
void check_static_solver(const Reader& R, const YAML::Node& n, const std::string& P, const FeConfig& f) {
  if (f.static_solver && f.restraints.empty() && f.displacements.empty())
    R.fail(n["solver"], P + ".solver", P + ".solver: static needs restraints (fem.restraints or fem.displacements); "
                                          "an unrestrained structure has a singular stiffness matrix");
  if (f.static_solver && f.displacements.empty() && !f.restraints.empty()) {
    // every direction must be held somewhere (restraint files are read later: then trust them)
    bool from_file = false;
    std::array<bool, 3> held{false, false, false};
    for (const FeNodalConfig& b : f.restraints) {
      from_file = from_file || !b.file.empty();
      for (int d = 0; d < 3; ++d) held[d] = held[d] || b.fixed[d];
    }
    bool planar = true;
    for (const FeMeshConfig& m : f.meshes) planar = planar && m.kind == FeMeshConfig::kThesis && m.dim == 2;
    for (int d = 0; d < (planar ? 2 : 3) && !from_file; ++d)
      if (!held[d])
        R.fail(n["restraints"], P + ".restraints", P + ".restraints: no restraint holds the " + std::string(1, "xyz"[d]) +
                                                        " direction; a static solve needs every direction restrained "
                                                        "somewhere (the stiffness matrix is singular otherwise)");
  }
}

void read_fem_removals(const Reader& R, const YAML::Node& n, const std::string& Q, const CaseConfig& c, FeConfig& f) {
  R.expect_seq(n, Q);
  for (std::size_t i = 0; i < n.size(); ++i) {
    const YAML::Node e = n[i];
    const std::string q = Reader::item(Q, i);
    R.check_keys(e, q);
    FeRemovalConfig r;
    r.line = e.Mark().is_null() ? 0 : e.Mark().line + 1;
    R.require(e, q, "mesh"); R.require(e, q, "element_set"); R.require(e, q, "at_hold");
    r.mesh = fem_mesh_index(R, c, e["mesh"], q + ".mesh");
    r.element_set = R.string(e["element_set"], q + ".element_set");
    r.at_hold = static_cast<int>(R.non_negative_int(e["at_hold"], q + ".at_hold"));
    f.removals.push_back(r);
  }
}

void read_fem_ties(const Reader& R, const YAML::Node& n, const std::string& Q, const CaseConfig& c, FeConfig& f) {
  R.expect_seq(n, Q);
  for (std::size_t i = 0; i < n.size(); ++i) {
    const YAML::Node e = n[i];
    const std::string q = Reader::item(Q, i);
    R.check_keys(e, q);
    FeTieConfig t;
    t.line = e.Mark().is_null() ? 0 : e.Mark().line + 1;
    R.require(e, q, "mesh"); R.require(e, q, "to");
    t.mesh = fem_mesh_index(R, c, e["mesh"], q + ".mesh");
    t.to = fem_mesh_index(R, c, e["to"], q + ".to");
    if (t.to == t.mesh) R.fail(e["to"], q + ".to", q + ".to: a mesh is not tied to itself");
    for (const FeTieConfig& o : f.ties)
      if (o.mesh == t.mesh)
        R.fail(e["mesh"], q + ".mesh", q + ".mesh: mesh '" + f.meshes[t.mesh].name + "' is already tied (one tie per mesh)");
    if (e["node_set"]) t.node_set = R.string(e["node_set"], q + ".node_set");
    if (e["tolerance"]) t.tolerance = R.positive(e["tolerance"], q + ".tolerance", " (m)");
    f.ties.push_back(t);
  }
}

void read_fem(const Reader& R, const YAML::Node& n, CaseConfig& c) {
  const std::string P = "fem";
  R.check_keys(n, P);
  FeConfig& f = c.fem;
  f.present = true;
  f.line = n.Mark().is_null() ? 0 : n.Mark().line + 1;
  read_fem_solver(R, n, P, f);
  R.require(n, P, "materials", "a list of FE materials");
  read_fem_materials(R, n["materials"], f);
  for (std::size_t k = 0; k < f.materials.size() && f.static_solver; ++k)
    if (f.materials[k].nlgeom)
      R.fail(n["materials"][k]["nlgeom"], Reader::item(P + ".materials", k) + ".nlgeom",
             "fem.solver: static is for linear elastic materials; material '" + f.materials[k].name +
                 "' has nlgeom: true (use solver: relaxation)");
  R.require(n, P, "meshes", "a list of meshes");
  read_fem_meshes(R, n["meshes"], f);
  if (n["restraints"]) read_fem_nodal(R, c, n["restraints"], P + ".restraints", f.restraints, 0);
  if (n["loads"]) read_fem_nodal(R, c, n["loads"], P + ".loads", f.loads, 1);
  if (n["displacements"]) read_fem_nodal(R, c, n["displacements"], P + ".displacements", f.displacements, 2);
  if (n["load_steps"]) f.load_steps = read_factors(R, n["load_steps"], P + ".load_steps");
  if (n["displacement_steps"]) f.displacement_steps = read_factors(R, n["displacement_steps"], P + ".displacement_steps");
  if (!f.load_steps.empty() && !f.displacement_steps.empty() && f.load_steps.size() != f.displacement_steps.size())
    R.fail(n["displacement_steps"], P + ".displacement_steps",
           P + ": load_steps and displacement_steps must have the same length (one entry per hold)");
  check_static_solver(R, n, P, f);
  if (n["remove"]) read_fem_removals(R, n["remove"], P + ".remove", c, f);
  if (n["ties"]) read_fem_ties(R, n["ties"], P + ".ties", c, f);
}

// ---------------------------------------------------------------- coupling
void read_coupling(const Reader& R, const YAML::Node& n, CaseConfig& c) {
  const std::string P = "coupling";
  R.check_keys(n, P);
  CouplingConfig& k = c.coupling;
  k.present = true;
  k.line = n.Mark().is_null() ? 0 : n.Mark().line + 1;
  R.require(n, P, "material", "the DEM material of the interface triangles");
  k.material = material_index(R, c, n["material"], P + ".material");
  R.require(n, P, "surfaces", "a list of FE surfaces: mesh, and face_set or element_set");
  const YAML::Node sl = n["surfaces"];
  R.expect_seq(sl, P + ".surfaces");
  if (sl.size() == 0) R.fail(sl, P + ".surfaces", P + ".surfaces: the list is empty; give at least one surface");
  for (std::size_t i = 0; i < sl.size(); ++i) {
    const YAML::Node e = sl[i];
    const std::string p = Reader::item(P + ".surfaces", i);
    R.check_keys(e, p);
    CouplingSurfaceConfig sc;
    sc.line = e.Mark().is_null() ? 0 : e.Mark().line + 1;
    R.require(e, p, "mesh", "an fem mesh name");
    sc.mesh = fem_mesh_index(R, c, e["mesh"], p + ".mesh");
    if (e["face_set"] && e["element_set"]) R.fail(e, p, p + ": give face_set or element_set, not both");
    if (e["face_set"]) sc.face_set = R.string(e["face_set"], p + ".face_set");
    if (e["element_set"]) sc.element_set = R.string(e["element_set"], p + ".element_set");
    if (e["material"]) sc.material = material_index(R, c, e["material"], p + ".material");
    sc.name = e["name"] ? R.name(e["name"], p + ".name")
                        : (!sc.face_set.empty() ? sc.face_set
                                                : (!sc.element_set.empty() ? sc.element_set : c.fem.meshes[sc.mesh].name));
    for (const CouplingSurfaceConfig& o : k.surfaces)
      if (o.name == sc.name)
        R.fail(e, p, p + ": surface name '" + sc.name + "' is used twice (give each surface its own name:)");
    k.surfaces.push_back(sc);
  }
  if (n["subcycle"]) {
    const std::int64_t v = R.non_negative_int(n["subcycle"], P + ".subcycle");
    if (v > 1000000) R.fail(n["subcycle"], P + ".subcycle", P + ".subcycle: must be at most 1000000, got " + n["subcycle"].Scalar());
    k.subcycle = static_cast<int>(v);
  }
  if (n["rigid_steps"]) k.rigid_steps = R.non_negative_int(n["rigid_steps"], P + ".rigid_steps");
  if (n["tolerance"]) k.tolerance = R.positive(n["tolerance"], P + ".tolerance");
  if (n["ramp_steps"]) k.ramp_steps = R.non_negative_int(n["ramp_steps"], P + ".ramp_steps");
  if (n["kinetic_ratio"]) k.kinetic_ratio = R.positive(n["kinetic_ratio"], P + ".kinetic_ratio", "");
  if (n["grain_resultant"]) k.grain_resultant = R.positive(n["grain_resultant"], P + ".grain_resultant", "");
  if (n["creep"]) k.creep = R.positive(n["creep"], P + ".creep", " (m)");
  if (n["creep_damping"]) {
    k.creep_damping = R.positive(n["creep_damping"], P + ".creep_damping", "");
    if (!(k.creep > 0))
      R.fail(n["creep_damping"], P + ".creep_damping",
             P + ".creep_damping: scales the FE damping to the creep the holds allow, and needs " + P + ".creep (m)");
    if (!(c.fem.damping > 0))
      R.fail(n["creep_damping"], P + ".creep_damping",
             P + ".creep_damping: needs a fixed fem.damping (1/s: the damping before the first check and the largest "
                 "it may become), not `auto`");
  }
}

// ---------------------------------------------------------------- measure
void read_measure(const Reader& R, const YAML::Node& n, CaseConfig& c) {
  const std::string P = "measure";
  R.check_keys(n, P);
  MeasureConfig& m = c.measure;
  m.present = true;
  m.line = n.Mark().is_null() ? 0 : n.Mark().line + 1;
  R.require(n, P, "every", "steps between measurements");
  m.every = R.positive_int(n["every"], P + ".every");
  auto inside_domain = [&](const YAML::Node& e, const std::string& p, const Vec3& lo, const Vec3& hi) {
    for (int k = 0; k < 3; ++k)
      if (hi[k] <= c.domain_min[k] || lo[k] >= c.domain_max[k])
        R.fail(e, p, p + ": the box lies outside the domain in " + std::string(1, "xyz"[k]));
  };
  if (n["boxes"]) {
    const YAML::Node bl = n["boxes"];
    R.expect_seq(bl, P + ".boxes");
    std::set<std::string> names;
    for (std::size_t i = 0; i < bl.size(); ++i) {
      const YAML::Node e = bl[i];
      const std::string p = Reader::item(P + ".boxes", i);
      R.check_keys(e, p);
      MeasureBoxConfig b;
      b.line = e.Mark().is_null() ? 0 : e.Mark().line + 1;
      b.name = e["name"] ? R.name(e["name"], p + ".name") : "box" + std::to_string(i);
      if (!names.insert(b.name).second) R.fail(e["name"], p + ".name", p + ".name: duplicate box name '" + b.name + "'");
      R.require(e, p, "min");
      R.require(e, p, "max");
      b.min = R.vec3(e["min"], p + ".min");
      b.max = R.vec3(e["max"], p + ".max");
      for (int k = 0; k < 3; ++k)
        if (!(b.min[k] < b.max[k]))
          R.fail(e["max"], p + ".max", p + ": min must be below max in every direction (" + std::string(1, "xyz"[k]) + ")");
      inside_domain(e, p, b.min, b.max);
      m.boxes.push_back(b);
    }
  }
  if (n["grid"]) {
    const YAML::Node g = n["grid"];
    const std::string p = P + ".grid";
    R.check_keys(g, p);
    R.require(g, p, "min");
    R.require(g, p, "max");
    R.require(g, p, "divisions", "[nx, ny, nz]");
    m.grid_min = R.vec3(g["min"], p + ".min");
    m.grid_max = R.vec3(g["max"], p + ".max");
    for (int k = 0; k < 3; ++k)
      if (!(m.grid_min[k] < m.grid_max[k]))
        R.fail(g["max"], p + ".max", p + ": min must be below max in every direction (" + std::string(1, "xyz"[k]) + ")");
    inside_domain(g, p, m.grid_min, m.grid_max);
    const YAML::Node d = g["divisions"];
    if (!d.IsSequence() || d.size() != 3)
      R.fail(d, p + ".divisions", p + ".divisions: expected a list of 3 positive integers [nx, ny, nz], got " + Reader::describe(d));
    std::int64_t cells = 1;
    for (int k = 0; k < 3; ++k) {
      const std::int64_t v = R.positive_int(d[k], Reader::item(p + ".divisions", k));
      if (v > 100000) R.fail(d[k], Reader::item(p + ".divisions", k), Reader::item(p + ".divisions", k) + ": at most 100000");
      m.grid_divisions[k] = static_cast<int>(v);
      cells *= v;
    }
    if (cells > 10000000) R.fail(d, p + ".divisions", p + ".divisions: " + std::to_string(cells) + " cells; at most 10000000");
    m.has_grid = true;
  }
  if (n["roses"]) {
    const YAML::Node rl = n["roses"];
    R.expect_seq(rl, P + ".roses");
    for (std::size_t i = 0; i < rl.size(); ++i) {
      const YAML::Node e = rl[i];
      const std::string p = Reader::item(P + ".roses", i);
      R.check_keys(e, p);
      R.require(e, p, "plane", "xy, xz or yz");
      MeasureRoseConfig r;
      r.plane = R.string(e["plane"], p + ".plane");
      if (r.plane == "xy") { r.axes[0] = 0; r.axes[1] = 1; }
      else if (r.plane == "xz") { r.axes[0] = 0; r.axes[1] = 2; }
      else if (r.plane == "yz") { r.axes[0] = 1; r.axes[1] = 2; }
      else R.fail(e["plane"], p + ".plane", p + ".plane: unknown plane '" + r.plane + "' (valid: xy, xz, yz)");
      if (e["bins"]) {
        const std::int64_t b = R.positive_int(e["bins"], p + ".bins");
        if (b > 3600) R.fail(e["bins"], p + ".bins", p + ".bins: at most 3600, got " + e["bins"].Scalar());
        r.bins = static_cast<int>(b);
      }
      m.roses.push_back(r);
    }
  }
  if (n["force_network"]) m.force_network = R.boolean(n["force_network"], P + ".force_network");
  if (n["particle_displacements"])
    m.particle_displacements = R.boolean(n["particle_displacements"], P + ".particle_displacements");
  if (n["displacement_from"]) m.displacement_from = R.non_negative_int(n["displacement_from"], P + ".displacement_from");
  if (m.boxes.empty() && !m.has_grid && m.roses.empty() && !m.force_network && !m.particle_displacements)
    R.fail(n, P, P + ": nothing to measure; give boxes, grid, roses, force_network or particle_displacements");
}

// ---------------------------------------------------------------- lab
int wall_index(const Reader& R, const CaseConfig& c, const YAML::Node& n, const std::string& path) {
  const std::string name = R.string(n, path);
  std::vector<std::string> names;
  for (std::size_t j = 0; j < c.walls.size(); ++j) {
    if (c.walls[j].name == name) return static_cast<int>(j);
    names.push_back(c.walls[j].name);
  }
  for (const WallGroup& g : c.wall_groups)
    if (g.name == name)
      R.fail(n, path, path + ": wall '" + name + "' is " + (g.container ? "a container with faces " : "split into segments ") +
                          "(" + c.walls[g.first].name + " ... " + c.walls[g.first + g.count - 1].name + "): name one of them");
  R.fail(n, path, path + ": unknown wall '" + name + "' (valid: " + join(names) + ")");
}

/// A wall's name, or the name of a segmented wall (all its segments).
std::vector<int> wall_indices(const Reader& R, const CaseConfig& c, const YAML::Node& n, const std::string& path) {
  const std::string name = R.string(n, path);
  for (const WallGroup& g : c.wall_groups)
    if (g.name == name) {
      std::vector<int> r;
      for (int k = 0; k < g.count; ++k) r.push_back(g.first + k);
      return r;
    }
  return {wall_index(R, c, n, path)};
}

bool ever_servo(const WallConfig& w) {
  if (w.motion.kind == WallMotion::kServo) return true;
  for (const WallMotion& m : w.schedule)
    if (m.kind == WallMotion::kServo) return true;
  return false;
}

void read_lab(const Reader& R, const YAML::Node& n, CaseConfig& c) {
  const std::string P = "lab";
  R.check_keys(n, P);
  if (n.size() != 1) R.fail(n, P, P + ": give exactly one of direct_shear, triaxial");
  LabConfig& L = c.lab;
  L.line = n.Mark().is_null() ? 0 : n.Mark().line + 1;
  if (n["direct_shear"]) {
    const YAML::Node d = n["direct_shear"];
    const std::string q = P + ".direct_shear";
    L.kind = LabConfig::kDirectShear;
    R.check_keys(d, q);
    R.require(d, q, "shear_walls", "the walls of the moving half, their x-forces make the shear stress");
    R.require(d, q, "normal_wall", "the servo plate on top");
    const YAML::Node sw = d["shear_walls"];
    R.expect_seq(sw, q + ".shear_walls");
    if (sw.size() == 0) R.fail(sw, q + ".shear_walls", q + ".shear_walls: the list is empty");
    for (std::size_t k = 0; k < sw.size(); ++k) L.shear_walls.push_back(wall_index(R, c, sw[k], Reader::item(q + ".shear_walls", k)));
    L.normal_wall = wall_index(R, c, d["normal_wall"], q + ".normal_wall");
    if (!ever_servo(c.walls[L.normal_wall]))
      R.fail(d["normal_wall"], q + ".normal_wall", q + ".normal_wall: wall '" + c.walls[L.normal_wall].name +
                                                     "' is not servo-controlled");
    if (d["direction"]) {
      L.direction = R.vec3(d["direction"], q + ".direction");
      const double l = norm(L.direction);
      if (!(l > 0)) R.fail(d["direction"], q + ".direction", q + ".direction: must be non-zero");
      L.direction *= 1.0 / l;
    }
    if (d["area"]) L.area = R.positive(d["area"], q + ".area", " (m^2)");
    return;
  }
  const YAML::Node t = n["triaxial"];
  const std::string q = P + ".triaxial";
  L.kind = LabConfig::kTriaxial;
  R.check_keys(t, q);
  R.require(t, q, "walls", "six plane walls [xmin, xmax, ymin, ymax, bottom, top]");
  const YAML::Node ws = t["walls"];
  if (!ws.IsSequence() || ws.size() != 6)
    R.fail(ws, q + ".walls", q + ".walls: expected six plane wall names [xmin, xmax, ymin, ymax, bottom, top]");
  for (int k = 0; k < 6; ++k) {
    L.box[k] = wall_index(R, c, ws[k], Reader::item(q + ".walls", k));
    for (int j = 0; j < k; ++j)
      if (L.box[j] == L.box[k])
        R.fail(ws[k], Reader::item(q + ".walls", k), Reader::item(q + ".walls", k) + ": wall '" + c.walls[L.box[k]].name +
                                                         "' is listed twice (also " + Reader::item(q + ".walls", j) +
                                                         "); give six different walls");
    if (c.walls[L.box[k]].kind != WallConfig::kPlane)
      R.fail(ws[k], Reader::item(q + ".walls", k), Reader::item(q + ".walls", k) + ": wall '" + c.walls[L.box[k]].name +
                                                       "' is not a plane");
  }
}


/// `packing` (docs/case-format.md#packing): specimen preparation before the run.
/// `holds`: the servo walls' target stresses per hold and what ends a hold (after the walls).
void read_holds(const Reader& R, const YAML::Node& n, CaseConfig& c) {
  const std::string P = "holds";
  HoldsConfig& h = c.holds;
  R.check_keys(n, P);
  h.present = true;
  h.line = n.Mark().is_null() ? 0 : n.Mark().line + 1;
  R.require(n, P, "walls", "a list of {wall: NAME, stress: [Pa per hold]}");
  const YAML::Node ws = n["walls"];
  R.expect_seq(ws, P + ".walls");
  if (ws.size() == 0) R.fail(ws, P + ".walls", P + ".walls: the list is empty");
  for (std::size_t i = 0; i < ws.size(); ++i) {
    const std::string q = Reader::item(P + ".walls", i);
    const YAML::Node w = ws[i];
    R.expect_map(w, q);
    R.check_keys(w, P + ".walls");
    R.require(w, q, "wall", "the name of a servo wall (or of a segmented one: all its segments), or of a fixed wall "
                            "moved by `displacement`");
    if (w["stress"] && w["displacement"]) R.fail(w["displacement"], q, q + ": give either stress or displacement, not both");
    if (!w["stress"] && !w["displacement"])
      R.fail(w, q, "missing required key 'stress' (Pa per hold, a servo wall) or 'displacement' (m per hold, a fixed "
                   "wall) in " + q);
    HoldsConfig::Wall held;
    const bool moved = static_cast<bool>(w["displacement"]);
    const char* key = moved ? "displacement" : "stress";
    std::vector<double>& targets = moved ? held.displacement : held.stress;
    targets = read_factors(R, w[key], q + "." + key);
    if (moved) {
      for (const char* k : {"axis", "velocity"})
        if (!w[k]) R.fail(w, q, "missing required key '" + std::string(k) + "' in " + q + " (a wall held by displacement)");
      held.axis = R.vec3(w["axis"], q + ".axis");
      const double l = norm(held.axis);
      if (!(l > 0)) R.fail(w["axis"], q + ".axis", q + ".axis: must be non-zero");
      held.axis *= 1.0 / l;
      held.velocity = R.positive(w["velocity"], q + ".velocity", " (m/s)");
    } else {
      for (const char* k : {"axis", "velocity"})
        if (w[k]) R.fail(w[k], q + "." + k, q + "." + k + ": only for a wall held by displacement (a servo wall "
                                                          "moves along its servo axis)");
      for (std::size_t k = 0; k < targets.size(); ++k)
        if (!(targets[k] > 0))
          R.fail(w["stress"][k], Reader::item(q + ".stress", k), Reader::item(q + ".stress", k) + ": must be > 0 (Pa, compression)");
    }
    if (h.count == 0) h.count = targets.size();
    if (targets.size() != h.count)
      R.fail(w[key], q + "." + key, q + "." + key + ": " + std::to_string(targets.size()) + " holds, the first wall has " +
                                        std::to_string(h.count) + " (one target per hold for every wall)");
    for (int k : wall_indices(R, c, w["wall"], q + ".wall")) {
      const WallConfig& wc = c.walls[k];
      if (moved && (wc.motion.kind != WallMotion::kFixed || !wc.schedule.empty()))
        R.fail(w["wall"], q + ".wall", q + ".wall: wall '" + wc.name + "' is not a fixed wall (a displacement hold "
                                           "moves it: give it no motion and no schedule)");
      if (!moved && (wc.motion.kind != WallMotion::kServo || !wc.schedule.empty()))
        R.fail(w["wall"], q + ".wall", q + ".wall: wall '" + wc.name + "' is not a servo wall (holds set a servo's "
                                           "target: give it motion: {servo: ...}, without a schedule)");
      for (const HoldsConfig::Wall& o : h.walls)
        if (o.wall == k) R.fail(w["wall"], q + ".wall", q + ".wall: wall '" + wc.name + "' is listed twice");
      held.wall = k;
      h.walls.push_back(held);
    }
  }
  if (n["tolerance"]) h.tolerance = R.positive(n["tolerance"], P + ".tolerance");
  if (n["check_every"]) h.check_every = R.positive_int(n["check_every"], P + ".check_every");
  if (n["min_steps"]) h.min_steps = R.non_negative_int(n["min_steps"], P + ".min_steps");
  if (n["max_steps"]) h.max_steps = R.positive_int(n["max_steps"], P + ".max_steps");
  if (n["creep"]) h.creep = R.non_negative(n["creep"], P + ".creep");
  if (n["stop"]) {
    const YAML::Node s = n["stop"];
    const std::string q = P + ".stop";
    R.expect_map(s, q);
    R.check_keys(s, q);
    R.require(s, q, "wall", "the wall whose displacement ends the run");
    R.require(s, q, "displacement", "m, along the wall's servo axis");
    h.stop_wall = wall_index(R, c, s["wall"], q + ".wall");
    if (c.walls[h.stop_wall].motion.kind != WallMotion::kServo)
      R.fail(s["wall"], q + ".wall", q + ".wall: wall '" + c.walls[h.stop_wall].name + "' is not a servo wall (its axis "
                                         "gives the direction of the displacement)");
    h.stop_displacement = R.positive(s["displacement"], q + ".displacement", " (m)");
  }
}

/// packing.shaking: the walls that shake, amplitude, frequency, cycles, direction.
void read_packing_shaking(const Reader& R, const YAML::Node& n, const CaseConfig& c, PackingConfig& k) {
  const std::string P = "packing";
  const YAML::Node s = n["shaking"];
  const std::string q = P + ".shaking";
  R.check_keys(s, q);
  R.require(s, q, "walls", "names of the walls that shake, e.g. [xmin, xmax]");
  R.require(s, q, "amplitude", "m");
  R.require(s, q, "frequency", "Hz");
  const YAML::Node w = s["walls"];
  R.expect_seq(w, q + ".walls");
  if (w.size() == 0) R.fail(w, q + ".walls", q + ".walls: the list is empty");
  for (std::size_t i = 0; i < w.size(); ++i) {
    k.shake_walls.push_back(wall_index(R, c, w[i], Reader::item(q + ".walls", i)));
  }
  k.shake_amplitude = R.positive(s["amplitude"], q + ".amplitude", " (m)");
  k.shake_frequency = R.positive(s["frequency"], q + ".frequency", " (Hz)");
  k.shake_cycles = 3;
  if (s["cycles"]) k.shake_cycles = R.positive(s["cycles"], q + ".cycles");
  if (s["direction"]) {
    const Vec3 d = R.vec3(s["direction"], q + ".direction");
    if (!(norm(d) > 0)) R.fail(s["direction"], q + ".direction", q + ".direction: must not be zero");
    k.shake_direction = (1.0 / norm(d)) * d;
  }
}

/// packing.settle: when a layer counts as settled.
void read_packing_settle(const Reader& R, const YAML::Node& n, PackingConfig& k) {
  const std::string P = "packing";
  const YAML::Node s = n["settle"];
  const std::string q = P + ".settle";
  R.check_keys(s, q);
  if (s["criterion"]) {
    const std::string v = R.string(s["criterion"], q + ".criterion");
    if (v == "auto") k.settle_criterion = PackingConfig::kAuto;
    else if (v == "unbalanced") k.settle_criterion = PackingConfig::kUnbalanced;
    else if (v == "porosity") k.settle_criterion = PackingConfig::kPorosity;
    else R.fail(s["criterion"], q + ".criterion", q + ".criterion: '" + v + "' is not one of auto, unbalanced, porosity");
  }
  if (s["porosity_change"]) k.settle_porosity_change = R.positive(s["porosity_change"], q + ".porosity_change");
  if (s["window"]) k.settle_window = R.positive_int(s["window"], q + ".window");
  if (s["kinetic_ratio"]) k.settle_kinetic_ratio = R.positive(s["kinetic_ratio"], q + ".kinetic_ratio");
  if (s["unbalanced"]) k.settle_unbalanced = R.positive(s["unbalanced"], q + ".unbalanced");
  if (s["kinetic"]) k.settle_kinetic = R.non_negative(s["kinetic"], q + ".kinetic");
  if (s["min_steps"]) k.settle_min_steps = R.non_negative_int(s["min_steps"], q + ".min_steps");
  if (s["max_steps"]) k.settle_max_steps = R.positive_int(s["max_steps"], q + ".max_steps");
  if (s["check_every"]) k.check_every = R.positive_int(s["check_every"], q + ".check_every");
}

/// packing.expansion (method expansion only).
void read_packing_expansion(const Reader& R, const YAML::Node& n, PackingConfig& k) {
  const std::string P = "packing";
  const YAML::Node s = n["expansion"];
  const std::string q = P + ".expansion";
  if (k.method != PackingConfig::kExpansion)
    R.fail(s, q, q + ": only with method: expansion");
  R.check_keys(s, q);
  if (s["stages"]) {
    const std::int64_t st = R.positive_int(s["stages"], q + ".stages");
    if (st > 100000) R.fail(s["stages"], q + ".stages", q + ".stages: at most 100000");
    k.expansion_stages = static_cast<int>(st);
  }
  if (s["stage_steps"]) k.stage_steps = R.positive_int(s["stage_steps"], q + ".stage_steps");
}

/// packing.place_on_surface: plane walls, and servo boxes with their axis along x, y or z.
void read_place_on_surface(const Reader& R, const YAML::Node& n, const CaseConfig& c, PackingConfig& k) {
  const std::string P = "packing";
  const std::string q = P + ".place_on_surface";
  const YAML::Node w = n["place_on_surface"];
  R.expect_seq(w, q);
  for (std::size_t i = 0; i < w.size(); ++i) {
    const std::string qi = Reader::item(q, i);
    for (const int idx : wall_indices(R, c, w[i], qi)) {
      const WallConfig& wc = c.walls[static_cast<std::size_t>(idx)];
      // a box moves along the axis of its first servo phase, which must be x, y or z
      const WallMotion* servo = wc.motion.kind == WallMotion::kServo ? &wc.motion : nullptr;
      for (const WallMotion& m : wc.schedule)
        if (!servo && m.kind == WallMotion::kServo) servo = &m;
      bool along = false;
      for (int d = 0; servo && d < 3; ++d) along = along || std::fabs(servo->servo.axis[d]) > 1 - 1e-12;
      if (wc.kind == WallConfig::kFacets || (wc.kind == WallConfig::kBox && !along))
        R.fail(w[i], qi, qi + ": wall '" + wc.name + "' is neither a plane nor a servo-controlled box with its axis along x, y or z (a plane moves along its normal, a box along its servo axis)");
      k.surface_walls.push_back(idx);
    }
  }
}

/// The box must hold the largest grain, the layers be thick enough, and the loose clouds fit below
/// the domain's top and below any box wall waiting over the container.
void check_packing_room(const Reader& R, const YAML::Node& n, const CaseConfig& c, const PackingConfig& k) {
  const std::string P = "packing";
  // the box must be wider and taller than the largest particle
  SizeDistribution s = k.size;
  double dmax = s.kind == SizeDistribution::kConstant ? s.d
                : s.kind == SizeDistribution::kUniform ? s.dmax
                : s.kind == SizeDistribution::kNormal ? (s.dmax > 0 ? s.dmax : s.mean + 5 * s.sd)
                : (s.dmax > 0 ? std::min(s.dmax, s.sieve_d.back()) : s.sieve_d.back());
  dmax *= s.scale;
  const Vec3 L = k.box_max - k.box_min;
  for (int d = 0; d < 3; ++d)
    if (L[d] < 4 * dmax)
      R.fail(n["box"], P + ".box", P + ".box: the " + std::string(1, "xyz"[d]) + " size must be at least 4 largest "
                                   "diameters (" + std::to_string(4 * dmax) + " m)");
  if (k.method == PackingConfig::kLayers && L.z / k.layers < 2 * dmax)
    R.fail(n["layers"] ? n["layers"] : n, P + ".layers", P + ".layers: each layer must be at least 2 largest diameters thick");
  if (k.surcharge.present && k.surcharge.thickness < dmax)
    R.fail(n["surcharge"]["thickness"], P + ".surcharge.thickness",
           P + ".surcharge.thickness: " + std::to_string(k.surcharge.thickness) + " m is less than the largest grain diameter (" +
               std::to_string(dmax) + " m)");
  if (k.method == PackingConfig::kLayers) {
    // the highest cloud (the last layer's, on a specimen at the target porosity) must fit
    const double h = L.z / k.layers;
    const double top = k.box_min.z + (k.layers - 1) * h + (1 - k.porosity) * h / k.cloud_fraction;
    if (top > c.domain_max.z) {
      std::ostringstream m;
      m << "packing: the loose clouds (solid fraction cloud_fraction " << k.cloud_fraction << ") reach up to z = " << top
        << " m, above the domain's top " << c.domain_max.z << " m: raise domain.max z to at least " << top
        << ", use more layers or a larger cloud_fraction";
      R.fail(n, P, m.str());
    }
    // ... and below a box wall waiting over the container (a footing for place_on_surface)
    for (const WallConfig& w : c.walls)
      if (w.kind == WallConfig::kBox && w.min.z >= k.box_max.z && w.min.z < top && w.min.x < k.box_max.x &&
          w.max.x > k.box_min.x && w.min.y < k.box_max.y && w.max.y > k.box_min.y) {
        std::ostringstream m;
        m << "packing: the loose clouds (solid fraction cloud_fraction " << k.cloud_fraction << ") reach up to z = "
          << top << " m, above wall '" << w.name << "' at z = " << w.min.z << " m: raise wall '" << w.name
          << "' to at least " << top << ", use more layers or a larger cloud_fraction";
        R.fail(n, P, m.str());
      }
  }
}

void read_packing_method(const Reader& R, const YAML::Node& n, PackingConfig& k) {
  const std::string P = "packing";
  const std::string m = R.string(n["method"], P + ".method");
  if (m == "layers") k.method = PackingConfig::kLayers;
  else if (m == "expansion") k.method = PackingConfig::kExpansion;
  else R.fail(n["method"], P + ".method", P + ".method: unknown method '" + m + "' (valid: layers, expansion)");
}

/// packing.exclude: cylinders kept free of particles.
void read_packing_exclude(const Reader& R, const YAML::Node& n, PackingConfig& k) {
  const std::string P = "packing";
  const YAML::Node xs = n["exclude"];
  R.expect_seq(xs, P + ".exclude");
  for (std::size_t i = 0; i < xs.size(); ++i) {
    const std::string q = Reader::item(P + ".exclude", i);
    R.check_keys(xs[i], q);
    for (const char* key : {"point", "axis", "radius"}) R.require(xs[i], q, key);
    PackingConfig::Cylinder cy;
    cy.point = R.vec3(xs[i]["point"], q + ".point");
    cy.axis = R.vec3(xs[i]["axis"], q + ".axis");
    const double l = norm(cy.axis);
    if (!(l > 0)) R.fail(xs[i]["axis"], q + ".axis", q + ".axis: must be non-zero");
    cy.axis *= 1.0 / l;
    cy.radius = R.positive(xs[i]["radius"], q + ".radius", " (m)");
    k.exclude.push_back(cy);
  }
}

/// packing.insert_structure_after_layer and packing.structures: when the meshes join the packing.
void read_packing_structures(const Reader& R, const YAML::Node& n, const CaseConfig& c, PackingConfig& k) {
  const std::string P = "packing";
  if (n["insert_structure_after_layer"]) {
    const std::int64_t a = R.positive_int(n["insert_structure_after_layer"], P + ".insert_structure_after_layer");
    if (a >= k.layers)
      R.fail(n["insert_structure_after_layer"], P + ".insert_structure_after_layer",
             P + ".insert_structure_after_layer: must be below layers (" + std::to_string(k.layers) + ")");
    k.insert_structure_after_layer = static_cast<int>(a);
  }
  if (n["structures"]) {
    const YAML::Node xs = n["structures"];
    R.expect_seq(xs, P + ".structures");
    if (!c.fem.present)
      R.fail(xs, P + ".structures", P + ".structures: needs a coupled case (fem and coupling): a structure is a mesh's "
                                        "interface surface");
    for (std::size_t i = 0; i < xs.size(); ++i) {
      const std::string q = Reader::item(P + ".structures", i);
      R.check_keys(xs[i], q);
      for (const char* key : {"mesh", "after_layer"}) R.require(xs[i], q, key);
      PackingConfig::StructureJoin j;
      j.mesh = fem_mesh_index(R, c, xs[i]["mesh"], q + ".mesh");
      for (const PackingConfig::StructureJoin& o : k.structures)
        if (o.mesh == j.mesh)
          R.fail(xs[i]["mesh"], q + ".mesh", q + ".mesh: mesh '" + c.fem.meshes[j.mesh].name + "' is listed twice");
      const std::int64_t a = R.non_negative_int(xs[i]["after_layer"], q + ".after_layer");
      if (a >= k.layers)
        R.fail(xs[i]["after_layer"], q + ".after_layer",
               q + ".after_layer: must be below layers (" + std::to_string(k.layers) + ")");
      j.after_layer = static_cast<int>(a);
      j.line = xs[i].Mark().is_null() ? 0 : xs[i].Mark().line + 1;
      k.structures.push_back(j);
    }
  }
}

/// packing.surcharge: a layer of dense grains rained on the finished specimen.
void read_packing_surcharge(const Reader& R, const YAML::Node& n, const CaseConfig& c, PackingConfig& k) {
  const std::string P = "packing";
  const YAML::Node u = n["surcharge"];
  const std::string q = P + ".surcharge";
  R.check_keys(u, q);
  for (const char* key : {"material", "thickness"}) R.require(u, q, key);
  k.surcharge.present = true;
  k.surcharge.material = material_index(R, c, u["material"], q + ".material");
  k.surcharge.thickness = R.positive(u["thickness"], q + ".thickness", " (m)");
  k.surcharge.line = u.Mark().is_null() ? 0 : u.Mark().line + 1;
}

void read_packing(const Reader& R, const YAML::Node& n, CaseConfig& c) {
  const std::string P = "packing";
  PackingConfig& k = c.packing;
  R.check_keys(n, P);
  k.present = true;
  k.line = n.Mark().is_null() ? 0 : n.Mark().line + 1;
  if (n["method"]) read_packing_method(R, n, k);
  R.require(n, P, "material");
  R.require(n, P, "box", "{min: [x,y,z], max: [x,y,z]}, the specimen's container, m");
  R.require(n, P, "size", "the size distribution");
  k.material = material_index(R, c, n["material"], P + ".material");
  read_box(R, n["box"], P + ".box", k.box_min, k.box_max);
  if (!inside(k.box_min, c.domain_min, c.domain_max) || !inside(k.box_max, c.domain_min, c.domain_max))
    R.fail(n["box"], P + ".box", P + ".box: must lie inside the domain");
  if (n["layers"]) {
    const std::int64_t L = R.positive_int(n["layers"], P + ".layers");
    if (L > 1000) R.fail(n["layers"], P + ".layers", P + ".layers: at most 1000");
    k.layers = static_cast<int>(L);
  }
  if (n["porosity"]) {
    k.porosity = R.number(n["porosity"], P + ".porosity");
    if (!(k.porosity >= 0.2 && k.porosity < 0.9))
      R.fail(n["porosity"], P + ".porosity", P + ".porosity: must be in [0.2, 0.9) (random packings of spheres: "
                                             "0.36 densest ... 0.45 loose), got " + n["porosity"].Scalar());
  }
  read_size(R, n["size"], P + ".size", k.size);
  if (n["seed"]) {
    const std::int64_t sd = R.integer(n["seed"], P + ".seed");
    if (sd < 0) R.fail(n["seed"], P + ".seed", P + ".seed: must be >= 0");
    k.seed = static_cast<std::uint64_t>(sd);
  }
  if (n["friction"]) k.friction = R.non_negative(n["friction"], P + ".friction");
  if (n["wall_friction"]) {
    const std::string v = R.string(n["wall_friction"], P + ".wall_friction");
    if (v != "packing" && v != "case")
      R.fail(n["wall_friction"], P + ".wall_friction", P + ".wall_friction: unknown value '" + v + "' (valid: packing, case)");
    k.wall_friction_case = v == "case";
  }
  if (n["cloud_fraction"]) {
    k.cloud_fraction = R.number(n["cloud_fraction"], P + ".cloud_fraction");
    if (!(k.cloud_fraction > 0 && k.cloud_fraction <= 0.3))
      R.fail(n["cloud_fraction"], P + ".cloud_fraction", P + ".cloud_fraction: must be in (0, 0.3] (random placement "
                                                         "cannot reach denser clouds), got " + n["cloud_fraction"].Scalar());
  }
  if (k.cloud_fraction >= 1 - k.porosity)
    R.fail(n["cloud_fraction"] ? n["cloud_fraction"] : n["porosity"], P + ".cloud_fraction",
           P + ": cloud_fraction must be below the target solid fraction 1 - porosity");
  if (n["max_attempts"]) {
    const std::int64_t m = R.positive_int(n["max_attempts"], P + ".max_attempts");
    if (m > 100000000) R.fail(n["max_attempts"], P + ".max_attempts", P + ".max_attempts: at most 1e8");
    k.max_attempts = static_cast<int>(m);
  }
  if (n["placement"]) {
    const std::string pl = R.string(n["placement"], P + ".placement");
    if (pl == "cells") k.placement = ParticleSource::kCells;
    else if (pl != "sequential")
      R.fail(n["placement"], P + ".placement", P + ".placement: unknown placement '" + pl + "' (valid: sequential, cells)");
  }
  if (n["shaking"]) read_packing_shaking(R, n, c, k);
  if (n["exclude"]) read_packing_exclude(R, n, k);
  if (n["settle"]) read_packing_settle(R, n, k);
  if (n["expansion"]) read_packing_expansion(R, n, k);
  // (layers has a default, 1: another value is the user's, and expansion packs the box at once)
  if (k.method == PackingConfig::kExpansion && k.layers != 1)
    R.fail(n["layers"], P + ".layers", P + ".layers: only with method: layers (expansion fills and compacts the "
                                       "whole box at once; remove layers, or use method: layers)");
  if (n["final_steps"]) k.final_steps = R.non_negative_int(n["final_steps"], P + ".final_steps");
  if (n["report"]) {
    const YAML::Node s = n["report"];
    const std::string q = P + ".report";
    R.check_keys(s, q);
    if (s["margin"]) k.margin = R.positive(s["margin"], q + ".margin", " (m)");
    if (s["top_margin"]) k.top_margin = R.positive(s["top_margin"], q + ".top_margin", " (m)");
  }
  if (n["level"]) k.level = R.boolean(n["level"], P + ".level");
  read_packing_structures(R, n, c, k);
  if (n["surcharge"]) read_packing_surcharge(R, n, c, k);
  if (n["save"]) {
    k.save = R.resolve(R.string(n["save"], P + ".save"));
    std::tie(k.save_file, k.save_line) = R.location(n["save"], P + ".save");
  }
  if (n["place_on_surface"]) read_place_on_surface(R, n, c, k);
  check_packing_room(R, n, c, k);
}

// ---------------------------------------------------------------- the resolved case
//
// case.yaml (what a run writes) is the case with --set applied and the defaults of the schema
// filled in: in every mapping the case gives, each key it leaves out gets its default, when the
// schema's default is one plain value (`0.2`, `[0, 0, 0]`, `auto`, a word of the key's list).
// Mappings the case leaves out stay out (their presence can change what the case does), and so
// do defaults that depend on other keys.

/// The default of `k` as a YAML value to write, if it has one that can be written.
std::optional<YAML::Node> default_value(const schema::Key& k) {
  if (k.conditional) return std::nullopt;  // depends on other keys (the table says which)
  const std::string& d = k.def;
  if (d.size() < 3 || d.front() != '`' || d.back() != '`' || d.find('`', 1) != d.size() - 1) return std::nullopt;
  YAML::Node v;
  try {
    v = YAML::Load(d.substr(1, d.size() - 2));
  } catch (const YAML::Exception&) {
    return std::nullopt;
  }
  using schema::Type;
  switch (k.type) {
    case Type::kNumber:
    case Type::kInteger: {
      if (!v.IsScalar() || v.Scalar().empty()) return std::nullopt;
      char* end = nullptr;
      std::strtod(v.Scalar().c_str(), &end);
      return *end == '\0' ? std::optional<YAML::Node>(v) : std::nullopt;
    }
    case Type::kBool: return v.IsScalar() && (v.Scalar() == "true" || v.Scalar() == "false") ? std::optional<YAML::Node>(v) : std::nullopt;
    case Type::kEnum:
      return v.IsScalar() && std::find(k.values.begin(), k.values.end(), v.Scalar()) != k.values.end() ? std::optional<YAML::Node>(v) : std::nullopt;
    case Type::kAny: return v.IsScalar() && (v.Scalar() == "auto" || v.Scalar() == "fixed") ? std::optional<YAML::Node>(v) : std::nullopt;
    case Type::kVec3:
    case Type::kNumbers:
      if (!v.IsSequence() || (k.type == Type::kVec3 && v.size() != 3)) return std::nullopt;
      v.SetStyle(YAML::EmitterStyle::Flow);
      return v;
    default: return std::nullopt;
  }
}

/// Fill the defaults into the mapping `n` of section `path`, and into the mappings below it.
void fill_defaults(YAML::Node n, const std::string& path) {
  const schema::Section* sec = schema::find_section(path);
  if (!sec) return;
  if (n.IsSequence()) {  // a list of this section's mappings (or a motion schedule)
    for (std::size_t i = 0; i < n.size(); ++i) fill_defaults(n[i], path);
    return;
  }
  if (!n.IsMap()) return;
  const YAML::Node& cn = n;  // look up through a const node: a non-const operator[] adds the key
  // the keys of this mapping's form: all, the variant its key selects, none for forms told apart by shape
  std::vector<std::string> allowed = schema::key_names(path);
  if (!sec->variants.empty()) {
    allowed.clear();
    if (!sec->variant_key.empty() && cn[sec->variant_key] && cn[sec->variant_key].IsScalar())
      for (const auto& [value, keys] : sec->variants)
        if (value == cn[sec->variant_key].Scalar()) allowed = keys;
  }
  for (const schema::Key& k : sec->keys) {
    if (cn[k.name]) {
      if (!k.section.empty()) fill_defaults(n[k.name], k.section);
      continue;
    }
    if (std::find(allowed.begin(), allowed.end(), k.name) == allowed.end()) continue;
    if (const std::optional<YAML::Node> v = default_value(k)) n[k.name] = *v;
  }
}

/// The schema's defaults filled into a case before it is read: the values a run uses for the
/// keys a case leaves out are the table's (io/case_schema_table.cpp), the ones
/// docs/case-format.md and case.yaml show; the reader's own initial values are not reached for
/// them. The nodes filled in carry no line; a default is never an error.
void fill_case_defaults(YAML::Node root) {
  if (!root.IsMap()) return;
  const YAML::Node& croot = root;  // (a const lookup does not add the key)
  // a pure FE case takes none of the particle keys (read_tree): fill only its own sections
  const bool fe_only = croot["fem"] && !croot["particles"] && !croot["restart"] && !croot["packing"];
  if (fe_only) {
    for (const char* k : {"fem", "output"})
      if (croot[k]) fill_defaults(root[k], k);
  } else {
    fill_defaults(root, "");
  }
}

// ---------------------------------------------------------------- resource limits
//
// Sizes estimated from the keys before anything is allocated: more than kMaxItems particles or
// elements, or an estimate above the machine's physical memory, is an input error naming the key.
constexpr double kMaxItems = 2147483647.0;       // 2^31 - 1
constexpr double kBytesPerParticle = 1024;       // state, contacts, neighbour lists, ghosts (generous)
constexpr double kBytesPerElement = 4096;        // nodes, Gauss-point state, PETSc vectors (generous)

double physical_memory() {
  const long pages = ::sysconf(_SC_PHYS_PAGES), page = ::sysconf(_SC_PAGESIZE);
  return pages > 0 && page > 0 ? static_cast<double>(pages) * static_cast<double>(page) : 0;
}

/// A typical diameter of a distribution (for counting particles in a volume).
double typical_diameter(const SizeDistribution& s) {
  double d = s.d;
  if (s.kind == SizeDistribution::kUniform) d = 0.5 * (s.dmin + s.dmax);
  else if (s.kind == SizeDistribution::kNormal) d = s.mean;
  else if (s.kind == SizeDistribution::kSieve) {
    d = s.sieve_d.back();
    for (std::size_t k = 0; k < s.sieve_d.size(); ++k)
      if (s.passing[k] >= 50) { d = s.sieve_d[k]; break; }
    if (s.dmin > 0) d = std::max(d, s.dmin);
  }
  return d * s.scale;
}

void check_size(const Reader& R, const YAML::Node& n, const std::string& key, double count, const char* what,
                double bytes_each) {
  const double mem = physical_memory();
  std::ostringstream o;
  if (count > kMaxItems) {
    o << key << ": about " << count << " " << what << "; at most " << static_cast<long long>(kMaxItems);
    R.fail(n, key, o.str());
  }
  if (mem > 0 && count * bytes_each > mem) {
    o << key << ": about " << count << " " << what << " need about " << count * bytes_each / 1e9
      << " GB, more than this machine's " << mem / 1e9 << " GB of memory";
    R.fail(n, key, o.str());
  }
}

void check_resources(const Reader& R, const YAML::Node& root, const CaseConfig& c) {
  double particles = 0;
  const YAML::Node pl = root["particles"];
  for (std::size_t i = 0; i < c.particles.size(); ++i) {
    const ParticleSource& s = c.particles[i];
    const std::string p = Reader::item("particles", i) + ".generate";
    if (s.kind == ParticleSource::kInline) particles += static_cast<double>(s.spheres.size());
    if (s.kind != ParticleSource::kGenerate) continue;
    const YAML::Node g = pl[i]["generate"];
    if (s.count > 0) {
      particles += static_cast<double>(s.count);
      check_size(R, g["count"], p + ".count", particles, "particles", kBytesPerParticle);
    } else {
      const Vec3 L = s.box_max - s.box_min;
      const double d = typical_diameter(s.size);
      const double n = (1 - s.porosity) * L.x * L.y * L.z / (M_PI / 6 * d * d * d);
      particles += n;
      check_size(R, g["porosity"], p + ".porosity", particles, "particles (box volume, porosity and size)",
                 kBytesPerParticle);
    }
  }
  if (c.packing.present) {
    const PackingConfig& k = c.packing;
    const Vec3 L = k.box_max - k.box_min;
    const double d = typical_diameter(k.size);
    particles += (1 - k.porosity) * L.x * L.y * L.z / (M_PI / 6 * d * d * d);
    check_size(R, root["packing"]["box"], "packing.box", particles, "particles (box volume, porosity and size)",
               kBytesPerParticle);
  }
  if (!c.fem.present) return;
  double elements = 0;
  const YAML::Node ml = root["fem"]["meshes"];
  for (std::size_t i = 0; i < c.fem.meshes.size(); ++i) {
    const FeMeshConfig& m = c.fem.meshes[i];
    const std::string p = Reader::item("fem.meshes", i);
    if (m.kind == FeMeshConfig::kBlock) {
      elements += static_cast<double>(m.divisions[0]) * m.divisions[1] * m.divisions[2];
      check_size(R, ml[i]["block"]["divisions"], p + ".block.divisions", elements, "elements", kBytesPerElement);
    } else if (m.kind == FeMeshConfig::kCylinder) {
      elements += static_cast<double>(m.cyl_divisions[0]) * m.cyl_divisions[1];
      check_size(R, ml[i]["cylinder"]["divisions"], p + ".cylinder.divisions", elements, "elements", kBytesPerElement);
    } else if (m.kind == FeMeshConfig::kGeogrid) {
      // ribs x (elements across a rib) x (elements along a rib, at most one per rib width) x thickness
      const double along = m.length / std::max(1e-12, m.max_element_length > 0 ? std::min(m.max_element_length, m.rib_width) : m.rib_width);
      const double across = m.width / std::max(1e-12, m.rib_width);
      const double e = (static_cast<double>(m.longitudinal_ribs) * along + static_cast<double>(m.transverse_ribs) * across) *
                       m.elements_per_rib_width * m.elements_through_thickness;
      elements += e;
      check_size(R, ml[i]["geogrid"], p + ".geogrid", elements, "elements", kBytesPerElement);
    }
  }
}


void read_progress(const Reader& R, const YAML::Node& root, CaseConfig& c) {
  R.check_keys(root["progress"], "progress");
  if (root["progress"]["interval"]) c.progress_interval = R.positive(root["progress"]["interval"], "progress.interval", " (s)");
}

/// The rest of a pure FE case (fem and no particles): the DEM keys are refused.
void read_fe_only(const Reader& R, const YAML::Node& root, CaseConfig& c) {
  for (const char* k : {"domain", "time", "materials", "interactions", "walls", "constraints", "neighbor", "damping",
                        "decomposition", "coupling", "measure", "lab", "contact_model", "rolling_law", "holds"})
    if (root[k]) R.fail(root[k], k, std::string(k) + ": only for cases with particles (this case has fem and no particles)");
  if (root["output"]) read_output(R, root["output"], c);
  if (c.out_dir.empty()) c.out_dir = "out/" + c.name;
  if (root["progress"]) read_progress(R, root, c);
  check_resources(R, root, c);
}

void read_restart(const Reader& R, const YAML::Node& root, CaseConfig& c) {
  R.check_keys(root["restart"], "restart");
  R.require(root["restart"], "restart", "from", "checkpoint file");
  c.restart_from = R.resolve(R.string(root["restart"]["from"], "restart.from"));
  std::tie(c.restart_file, c.restart_line) = R.location(root["restart"]["from"], "restart.from");
}

void read_case_holds(const Reader& R, const YAML::Node& root, CaseConfig& c) {
  if (!root["walls"]) R.fail(root["holds"], "holds", "holds: the case has no walls");
  read_holds(R, root["holds"], c);
  // a coupled case's FE holds are the same holds: one factor per hold, or none
  for (const auto& [key, v] : {std::pair<const char*, const std::vector<double>*>{"load_steps", &c.fem.load_steps},
                               {"displacement_steps", &c.fem.displacement_steps}})
    if (!v->empty() && v->size() != c.holds.count)
      R.fail(root["fem"][key], std::string("fem.") + key,
             std::string("fem.") + key + ": " + std::to_string(v->size()) + " holds, holds.walls " +
                 std::to_string(c.holds.count) + " (the FE factors and the walls' targets are one list of holds)");
  if (c.stop_unbalanced > 0)
    R.fail(root["time"]["stop_unbalanced"], "time.stop_unbalanced",
           "time.stop_unbalanced: not with holds (the holds end the run: holds.tolerance)");
}

/// `after:` conditions are decided by the particle run (app/driver.cpp): refused in coupled cases,
/// whose stages are their holds.
void refuse_phase_conditions(const Reader& R, const YAML::Node& root, const CaseConfig& c) {
  for (const WallConfig& w : c.walls)
    for (std::size_t k = 0; k < w.schedule.size(); ++k)
      if (w.schedule[k].after) {
        const std::string q = Reader::item(Reader::item("walls", static_cast<std::size_t>(w.node)) + ".motion", k);
        R.fail(root["walls"][static_cast<std::size_t>(w.node)]["motion"][k]["after"], q + ".after",
               q + ".after: a phase that starts on a condition is for particle runs; a coupled case's stages are its "
                   "holds (fem.load_steps, holds)");
      }
}

void read_case_packing(const Reader& R, const YAML::Node& root, CaseConfig& c) {
  read_packing(R, root["packing"], c);
  if (!c.restart_from.empty()) R.fail(root["packing"], "packing", "packing: not with restart (a restart continues a packed run)");
  if (c.packing.insert_structure_after_layer > 0 && !root["fem"])
    R.fail(root["packing"]["insert_structure_after_layer"], "packing.insert_structure_after_layer",
           "packing.insert_structure_after_layer: needs a coupled case (fem and coupling): the structure is its "
           "interface surface");
}

// Particles and finite elements together are a coupled case: both or neither with `coupling`.
void check_coupled(const Reader& R, const YAML::Node& root) {
  if (root["coupling"] && !root["fem"])
    R.fail(root["coupling"], "coupling", "coupling: needs finite elements; this case has no fem section");
  if (root["fem"] && !root["coupling"])
    R.fail(root["fem"], "fem", "fem: a case with both particles and finite elements needs a coupling section "
                               "(interface material and surfaces, docs/case-format.md#coupling)");
}

CaseConfig read_tree(const Reader& R, const YAML::Node& root, const std::string& file) {
  CaseConfig c;
  c.file = file;
  if (!root.IsDefined() || root.IsNull()) throw InputError(file, 0, "the case file is empty");
  R.check_keys(root, "");
  c.name = fs::path(file).stem().string();
  if (root["name"]) {
    c.name = R.name(root["name"], "name");  // (it goes into file names and run.json)
  }
  // A case with finite elements and no particles (a pure FE case) needs no domain, time,
  // materials or particles; the DEM keys are required as soon as particles are given.
  const bool fe_only = root["fem"] && !root["particles"] && !root["restart"] && !root["packing"];
  if (root["fem"]) read_fem(R, root["fem"], c);
  if (c.fem.mass_scaling_auto && !root["coupling"])
    R.fail(root["fem"]["mass_scaling"], "fem.mass_scaling",
           "fem.mass_scaling: `auto` matches the FE step to the DEM's and needs a coupled case (fem and coupling); "
           "give a number");
  if (root["gravity"]) c.gravity = R.vec3(root["gravity"], "gravity");
  if (fe_only) {
    read_fe_only(R, root, c);
    return c;
  }
  R.require(root, "", "domain", "{min: [x,y,z], max: [x,y,z]}, m");
  read_box(R, root["domain"], "domain", c.domain_min, c.domain_max);
  if (root["packing"]) c.packing.present = true;  // the full section is read below, after the walls
  if (root["time"] || !root["packing"]) {
    R.require(root, "", "time", "dt, steps or duration");
    read_time(R, root["time"], c);
  }
  if (root["damping"]) {
    c.damping = R.number(root["damping"], "damping");
    if (!(c.damping >= 0 && c.damping < 1)) R.fail(root["damping"], "damping", "damping: must be in [0, 1), got " + root["damping"].Scalar());
  }
  if (root["neighbor"]) {
    R.check_keys(root["neighbor"], "neighbor");
    if (root["neighbor"]["skin"]) c.skin = R.positive_or_auto(root["neighbor"]["skin"], "neighbor.skin");
  }
  if (root["decomposition"]) {
    R.check_keys(root["decomposition"], "decomposition");
    const YAML::Node g = root["decomposition"]["grid"];
    if (g && !(g.IsScalar() && g.Scalar() == "auto")) {
      const std::string q = "decomposition.grid";
      if (!g.IsSequence() || g.size() != 3)
        R.fail(g, q, q + ": expected 'auto' or [px, py, pz] (the ranks along x, y and z), got " + Reader::describe(g));
      for (int k = 0; k < 3; ++k) {
        const std::int64_t v = R.integer(g[k], Reader::item(q, static_cast<std::size_t>(k)));
        if (v < 1 || v > 100000)
          R.fail(g[k], Reader::item(q, static_cast<std::size_t>(k)), q + ": each count must be in [1, 100000], got " + std::to_string(v));
        c.grid[k] = static_cast<int>(v);
      }
      c.grid_at = R.location(g, q);
    }
  }
  R.require(root, "", "materials", "a list of materials");
  if (root["rolling_law"]) c.rolling_law = read_rolling_law(R, root["rolling_law"], "rolling_law");
  read_materials(R, root["materials"], c);
  if (root["interactions"]) read_interactions(R, root["interactions"], c);
  check_rolling_laws(R, root, c);
  if (root["contact_model"]) c.contact_model = read_contact_model(R, root["contact_model"], "contact_model");
  if (root["restart"]) read_restart(R, root, c);
  if (root["particles"]) read_particles(R, root["particles"], c);
  else if (c.restart_from.empty() && !root["packing"])
    R.require(root, "", "particles", "required unless restart.from or packing is given");
  if (c.restart_from.empty() && c.particles.empty() && (root["particles"] || !root["packing"]))
    R.fail(root["particles"], "particles", "particles: the list is empty; give at least one source");
  if (root["walls"]) read_walls(R, root["walls"], c);
  if (root["lab"]) read_lab(R, root["lab"], c);
  if (root["holds"]) read_case_holds(R, root, c);
  if (root["packing"]) read_case_packing(R, root, c);
  check_coupled(R, root);
  if (root["fem"]) refuse_phase_conditions(R, root, c);
  if (root["coupling"]) read_coupling(R, root["coupling"], c);
  if (root["constraints"]) read_constraints(R, root["constraints"], c);
  if (root["output"]) read_output(R, root["output"], c);
  if (c.out_dir.empty()) c.out_dir = "out/" + c.name;
  if (root["progress"]) read_progress(R, root, c);
  if (root["measure"]) read_measure(R, root["measure"], c);
  check_resources(R, root, c);
  return c;
}

}  // namespace

CaseConfig read_case(const std::string& path, const std::vector<std::string>& overrides) {
  // stat before opening: a FIFO would block the open, /dev/zero would never end.
  const std::string problem = input_file_problem(path);
  if (!problem.empty()) {
    if (problem == "is a directory") throw InputError(path, 0, "'" + path + "' is a directory, not a case file");
    if (problem.rfind("cannot read", 0) == 0)
      throw InputError(path, 0, "cannot read the case file '" + path + "' (missing or not readable)");
    throw InputError(path, 0, "the case file '" + path + "' " + problem);
  }
  constexpr std::uintmax_t kMaxCaseBytes = 64u << 20;  // a case file is a few kB; refuse > 64 MB
  std::error_code ec;
  const std::uintmax_t bytes = fs::file_size(path, ec);
  if (!ec && bytes > kMaxCaseBytes)
    throw InputError(path, 0, "the case file is " + std::to_string(bytes) + " bytes; at most 64 MB (" +
                                  std::to_string(kMaxCaseBytes) + " bytes)");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, 0, "cannot read the case file '" + path + "' (missing or not readable)");
  std::string text;
  {
    std::vector<char> chunk(1 << 16);
    while (in && text.size() <= kMaxCaseBytes) {
      in.read(chunk.data(), static_cast<std::streamsize>(chunk.size()));
      text.append(chunk.data(), static_cast<std::size_t>(in.gcount()));
    }
    if (text.size() > kMaxCaseBytes) throw InputError(path, 0, "the case file is larger than 64 MB");
    if (in.bad()) throw InputError(path, 0, "read error in the case file");
  }
  std::stringstream buf(text);
  YAML::Node root;
  try {
    root = YAML::Load(buf.str());
  } catch (const YAML::Exception& e) {
    throw InputError(path, e.mark.is_null() ? 0 : e.mark.line + 1, "YAML syntax error: " + e.msg);
  }
  Reader R(path, fs::path(path).parent_path());
  std::vector<std::string> override_warnings;
  if (!overrides.empty()) {
    if (!root.IsDefined() || root.IsNull()) root = YAML::Node(YAML::NodeType::Map);
    if (!root.IsMap()) throw InputError(path, 1, "the case file must be a mapping of keys (name:, domain:, ...)");
    for (const auto& o : overrides) {
      try {
        std::string warning;
        R.add_override_path(apply_override(root, o, &warning), o);
        if (!warning.empty()) override_warnings.push_back(warning);
      } catch (const InputError&) {
        throw;
      } catch (const std::exception& e) {
        throw InputError("--set " + o, 0, std::string("cannot apply the override: ") + e.what());
      }
    }
  }
  try {
    fill_case_defaults(root);
    CaseConfig c = read_tree(R, root, path);
    c.overrides = overrides;
    c.warnings = override_warnings;
    YAML::Node resolved = YAML::Clone(root);
    if (!root["name"]) resolved["name"] = c.name;  // the file's stem: the resolved file has another
    c.resolved_yaml = YAML::Dump(resolved);
    return c;
  } catch (const InputError&) {
    throw;
  } catch (const YAML::Exception& e) {
    // should not happen (all access is checked), but never let a yaml-cpp error escape
    throw InputError(path, e.mark.is_null() ? 0 : e.mark.line + 1, "invalid case: " + e.msg);
  } catch (const std::bad_alloc&) {
    throw InputError(path, 0, "invalid case: out of memory while reading it");
  } catch (const std::exception& e) {
    throw InputError(path, 0, std::string("invalid case: ") + e.what());
  }
}

namespace {

/// "" if `dir` is (or can be made) a directory this process can write in, else why not. A
/// directory made by the check is removed again (nothing is left behind by a refused run).
std::string dir_problem(const fs::path& dir) {
  std::error_code ec;
  fs::path first_missing;
  for (fs::path a = dir; !a.empty(); a = a.parent_path()) {
    const fs::file_status st = fs::status(a, ec);
    if (fs::exists(st)) {
      if (!fs::is_directory(st))
        return "'" + a.string() + "' " + (a == dir ? "exists and is not a directory" : "is a file, not a directory");
      break;
    }
    first_missing = a;
    if (a == a.parent_path()) break;
  }
  if (!first_missing.empty()) {
    fs::create_directories(dir, ec);
    if (ec) return "cannot create '" + dir.string() + "': " + ec.message();
  }
  const fs::path probe = dir / (".fdem_write_test." + std::to_string(::getpid()));
  std::string problem;
  {
    std::ofstream f(probe, std::ios::trunc);
    if (!f) problem = "cannot write in '" + dir.string() + "': " + std::strerror(errno);
    else {
      f << "x";
      f.flush();
      if (!f) problem = "cannot write in '" + dir.string() + "' (file system full?)";
    }
  }
  fs::remove(probe, ec);
  if (!first_missing.empty()) fs::remove_all(first_missing, ec);
  return problem;
}

}  // namespace

void check_output_paths(const CaseConfig& c, bool out_from_flag) {
  const std::string out_problem = dir_problem(fs::path(c.out_dir));
  if (!out_problem.empty()) {
    if (out_from_flag) throw InputError("--out " + c.out_dir, 0, "unusable output directory: " + out_problem);
    if (!c.out_dir_file.empty())
      throw InputError(c.out_dir_file, c.out_dir_line, "output.dir: unusable output directory: " + out_problem);
    throw InputError(c.file, 0, "the default output directory '" + c.out_dir + "' is unusable (give --out DIR): " + out_problem);
  }
  // The files a run writes (and renames into place: the checkpoints): a directory of that name
  // would be found only when the first one is written, after the run has computed.
  for (const char* name : {"checkpoint.h5", "fe_checkpoint.h5", "run.json", "case.yaml", "history.csv", "walls.csv",
                           "holds.csv", "lab.csv", "removed.csv", "interface.csv", "measure.csv", "packing.json",
                           "specimen.h5", "specimen.txt", "particles.xdmf", "fe.xdmf", "force_network.xdmf"}) {
    const fs::path f = fs::path(c.out_dir) / name;
    std::error_code ec;
    const fs::file_status st = fs::status(f, ec);  // (a link to a file is fine)
    if (!fs::exists(st) || fs::is_regular_file(st)) continue;
    const std::string what = "'" + f.string() + "' exists and is not a file (" +
                             (fs::is_directory(st) ? "a directory" : "not a regular file") +
                             "): the run writes " + name + " there; remove it or give another output directory";
    if (out_from_flag) throw InputError("--out " + c.out_dir, 0, "unusable output directory: " + what);
    if (!c.out_dir_file.empty()) throw InputError(c.out_dir_file, c.out_dir_line, "output.dir: unusable output directory: " + what);
    throw InputError(c.file, 0, "the default output directory '" + c.out_dir + "' is unusable (give --out DIR): " + what);
  }
  if (c.packing.present && !c.packing.save.empty()) {
    const fs::path p(c.packing.save);
    std::error_code ec;
    std::string problem;
    if (fs::is_directory(p, ec)) problem = "'" + p.string() + "' is a directory";
    else {
      fs::path parent = p.parent_path();
      if (parent.empty()) parent = ".";
      problem = dir_problem(parent);
      if (problem.empty() && fs::exists(p, ec) && ::access(p.c_str(), W_OK) != 0)
        problem = "cannot overwrite '" + p.string() + "': " + std::strerror(errno);
    }
    if (!problem.empty())
      throw InputError(c.packing.save_file.empty() ? c.file : c.packing.save_file, c.packing.save_line,
                       "packing.save: unusable path: " + problem);
  }
}

}  // namespace fdem
