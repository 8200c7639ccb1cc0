// Lookups in the case schema and what is made from it: the markdown key tables of
// docs/case-format.md and the JSON Schema of `fdem schema`. The table itself:
// io/case_schema_table.cpp.
#include "io/case_schema.hpp"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <sstream>
#include <stdexcept>

#include "io/run_info.hpp"  // json_string, json_number

namespace fdem::schema {
namespace {

const std::map<std::string, const Section*>& section_index() {
  static const std::map<std::string, const Section*> index = [] {
    std::map<std::string, const Section*> m;
    for (const Section& s : sections()) m[s.path] = &s;
    return m;
  }();
  return index;
}

std::string join(const std::vector<std::string>& v, const char* sep) {
  std::string s;
  for (std::size_t i = 0; i < v.size(); ++i) s += (i ? sep : "") + v[i];
  return s;
}

/// %g without the exponent's '+' and leading zeros: 1e+12 -> 1e12, 1e-06 -> 1e-6.
std::string num_text(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  std::string s = buf;
  const auto e = s.find('e');
  if (e == std::string::npos) return s;
  std::string exp = s.substr(e + 1);
  const bool neg = exp[0] == '-';
  if (exp[0] == '+' || exp[0] == '-') exp.erase(0, 1);
  while (exp.size() > 1 && exp[0] == '0') exp.erase(0, 1);
  return s.substr(0, e) + "e" + (neg ? "-" : "") + exp;
}

/// The variants of section `s` that allow key `k` ("" when all do or the section has none).
std::string variants_of(const Section& s, const std::string& k) {
  if (s.variants.empty()) return "";
  std::vector<std::string> in;
  for (const auto& [value, keys] : s.variants)
    if (std::find(keys.begin(), keys.end(), k) != keys.end()) in.push_back(value);
  if (in.size() == s.variants.size()) return "";
  return join(in, ", ");
}

std::string type_text(const Key& k) {
  if (!k.type_text.empty()) return k.type_text;
  switch (k.type) {
    case Type::kNumber: return "number";
    case Type::kInteger: return "integer";
    case Type::kBool: return "`true` \\| `false`";
    case Type::kString: return "string";
    case Type::kEnum: {
      std::vector<std::string> w;
      for (const auto& v : k.values) w.push_back("`" + v + "`");
      return join(w, " \\| ");
    }
    case Type::kVec3: return "`[x, y, z]`";
    case Type::kNumbers: return "list of numbers";
    case Type::kStrings: return "list of names";
    case Type::kMap: return "mapping";
    case Type::kList: return "list";
    case Type::kAny: return "";
  }
  return "";
}

/// The allowed magnitude as the docs' Ranges table writes it.
std::string allowed_text(const Range& r) {
  const std::string lo = num_text(r.lo), hi = num_text(r.hi);
  if (r.lo <= 1e-300) return "−" + hi + " … " + hi;
  if (r.sign == '+') return lo + " … " + hi;
  if (r.sign == '0') return "0, or " + lo + " … " + hi;
  return "0, or ±(" + lo + " … " + hi + ")";
}

// ---- JSON Schema ----

/// Markdown to plain text for a description: drop backticks and bold marks, unescape \|.
std::string plain(const std::string& md) {
  std::string s;
  for (std::size_t i = 0; i < md.size(); ++i) {
    if (md[i] == '`') continue;
    if (md[i] == '*' && i + 1 < md.size() && md[i + 1] == '*') { ++i; continue; }
    if (md[i] == '\\' && i + 1 < md.size() && md[i + 1] == '|') continue;
    s += md[i];
  }
  return s;
}

std::string description(const Key& k) {
  std::string d = plain(k.help);
  std::vector<std::string> extra;
  if (!k.units.empty() && k.units != "–") extra.push_back("units: " + k.units);
  if (!k.def.empty()) extra.push_back("default: " + plain(k.def));
  if (!extra.empty()) d += (d.empty() ? "" : " ") + std::string("(") + join(extra, "; ") + ")";
  return d;
}

std::string ref(const std::string& section) { return "{\"$ref\": \"#/definitions/" + (section.empty() ? std::string("top") : section) + "\"}"; }

/// The bounds of one number of a key with a range: |v| <= hi, and v >= 0 unless any sign.
std::string number_bounds(const Key& k) {
  if (!k.range.defined()) return "";
  std::string s;
  if (k.range.sign == '~') s += ", \"minimum\": " + json_number(-k.range.hi);
  else if (k.range.sign == '+') s += ", \"exclusiveMinimum\": 0";
  else s += ", \"minimum\": 0";
  s += ", \"maximum\": " + json_number(k.range.hi);
  return s;
}

std::string value_schema(const Key& k) {
  const std::string num = std::string("{\"type\": \"number\"") + number_bounds(k) + "}";
  switch (k.type) {
    case Type::kNumber: return num;
    case Type::kInteger: return std::string("{\"type\": \"integer\"") + number_bounds(k) + "}";
    case Type::kBool: return "{\"type\": \"boolean\"}";
    case Type::kString: return "{\"type\": \"string\", \"minLength\": 1}";
    case Type::kEnum: {
      std::vector<std::string> w;
      for (const auto& v : k.values) w.push_back(json_string(v));
      return "{\"enum\": [" + join(w, ", ") + "]}";
    }
    case Type::kVec3: return "{\"type\": \"array\", \"items\": " + num + ", \"minItems\": 3, \"maxItems\": 3}";
    case Type::kNumbers: return "{\"type\": \"array\", \"items\": " + num + "}";
    case Type::kStrings: return "{\"type\": \"array\", \"items\": {\"type\": \"string\", \"minLength\": 1}}";
    case Type::kMap: return ref(k.section);
    case Type::kList: return "{\"type\": \"array\", \"items\": " + ref(k.section) + "}";
    case Type::kAny:
      // several forms: when it is a mapping, it is the section's
      if (!k.section.empty()) return "{\"anyOf\": [{\"not\": {\"type\": \"object\"}}, " + ref(k.section) + "]}";
      return "{}";
  }
  return "{}";
}

/// `value_schema` with the description merged in.
std::string property_schema(const Key& k) {
  std::string v = value_schema(k);
  const std::string d = "\"description\": " + json_string(description(k)) +
                        ", \"markdownDescription\": " + json_string(k.help);
  if (v == "{}") return "{" + d + "}";
  if (v.rfind("{\"$ref\"", 0) == 0) return "{\"allOf\": [" + v + "], " + d + "}";  // draft-07 ignores siblings of $ref
  return v.substr(0, v.size() - 1) + ", " + d + "}";
}

std::string section_schema(const Section& s, const std::string& indent) {
  std::ostringstream o;
  o << "{\"type\": \"object\", \"additionalProperties\": false,\n" << indent << " \"properties\": {";
  for (std::size_t i = 0; i < s.keys.size(); ++i)
    o << (i ? "," : "") << "\n" << indent << "  " << json_string(s.keys[i].name) << ": " << property_schema(s.keys[i]);
  o << "}";
  std::vector<std::string> required;
  for (const Key& k : s.keys)
    if (k.def == "**required**" && variants_of(s, k.name).empty()) required.push_back(json_string(k.name));
  if (!required.empty()) o << ",\n" << indent << " \"required\": [" << join(required, ", ") << "]";
  if (!s.variants.empty()) {
    o << ",\n" << indent << " \"allOf\": [";
    for (std::size_t i = 0; i < s.variants.size(); ++i) {
      std::vector<std::string> names;
      for (const auto& n : s.variants[i].second) names.push_back(json_string(n));
      o << (i ? "," : "") << "\n" << indent << "  {\"if\": {\"properties\": {" << json_string(s.variant_key)
        << ": {\"const\": " << json_string(s.variants[i].first) << "}}, \"required\": [" << json_string(s.variant_key)
        << "]}, \"then\": {\"propertyNames\": {\"enum\": [" << join(names, ", ") << "]}}}";
    }
    o << "]";
  }
  o << "}";
  return o.str();
}

}  // namespace

std::string strip_indices(const std::string& path) {
  std::string k;
  for (std::size_t i = 0; i < path.size(); ++i) {
    if (path[i] == '[') {
      while (i < path.size() && path[i] != ']') ++i;
      continue;
    }
    k += path[i];
  }
  return k;
}

const Section* find_section(const std::string& path) {
  const auto& index = section_index();
  const auto it = index.find(path);
  return it == index.end() ? nullptr : it->second;
}

const Key* find_key(const std::string& path) {
  const auto dot = path.rfind('.');
  const Section* s = find_section(dot == std::string::npos ? "" : path.substr(0, dot));
  if (!s) return nullptr;
  const std::string name = dot == std::string::npos ? path : path.substr(dot + 1);
  for (const Key& k : s->keys)
    if (k.name == name) return &k;
  return nullptr;
}

std::vector<std::string> key_names(const std::string& path, const std::string& variant) {
  const Section* s = find_section(path);
  if (!s) throw std::logic_error("case schema: no section '" + path + "'");
  if (!variant.empty()) {
    for (const auto& [value, keys] : s->variants)
      if (value == variant) return keys;
    throw std::logic_error("case schema: section '" + path + "' has no variant '" + variant + "'");
  }
  std::vector<std::string> names;
  for (const Key& k : s->keys) names.push_back(k.name);
  return names;
}

std::string markdown_table(const std::string& path) {
  const Section* s = find_section(path);
  if (!s) throw std::logic_error("case schema: no section '" + path + "'");
  std::ostringstream o;
  o << "| key | type | units | default | meaning |\n|---|---|---|---|---|\n";
  for (const Key& k : s->keys) {
    const std::string v = variants_of(*s, k.name);
    o << "| `" << k.name << "`" << (v.empty() ? "" : " (" + v + ")") << " | " << type_text(k) << " | " << k.units
      << " | " << k.def << " | " << k.help << " |\n";
  }
  return o.str();
}

std::string markdown_ranges() {
  std::ostringstream o;
  o << "| key | allowed | unit |\n|---|---|---|\n";
  for (const Section& s : sections())
    for (const Key& k : s.keys) {
      if (!k.range.defined()) continue;
      const std::string unit = k.range_unit.empty() ? k.units : k.range_unit;
      o << "| `" << (s.path.empty() ? k.name : s.path + "." + k.name) << "` | " << allowed_text(k.range) << " | "
        << (unit == "–" ? "" : unit) << " |\n";
    }
  return o.str();
}

std::string json_schema() {
  std::ostringstream o;
  o << "{\n \"$schema\": \"http://json-schema.org/draft-07/schema#\",\n"
       " \"$id\": \"https://fdem.invalid/case.schema.json\",\n"
       " \"title\": \"fdem case file\",\n"
       " \"description\": \"A case of fdem, the coupled finite-discrete element code (docs/case-format.md). "
       "Generated by `fdem schema`.\",\n"
       " \"allOf\": [{\"$ref\": \"#/definitions/top\"}],\n"
       " \"definitions\": {";
  bool first = true;
  for (const Section& s : sections()) {
    o << (first ? "" : ",") << "\n  " << json_string(s.path.empty() ? "top" : s.path) << ": " << section_schema(s, "   ");
    first = false;
  }
  o << "\n }\n}\n";
  return o.str();
}

std::string regenerate_docs(const std::string& text) {
  std::istringstream in(text);
  std::ostringstream out;
  std::string line;
  int n = 0;
  const std::string open = "<!-- schema: ", close = "<!-- /schema -->";
  while (std::getline(in, line)) {
    ++n;
    out << line << "\n";
    if (line.rfind(open, 0) != 0) continue;
    const auto end = line.find(" -->");
    if (end == std::string::npos) throw std::runtime_error("line " + std::to_string(n) + ": expected '<!-- schema: PATH -->'");
    // one path, or several whose tables are the same (the boxes {min, max}): one table
    const std::string paths = line.substr(open.size(), end - open.size());
    std::istringstream words(paths);
    std::string table, path;
    while (words >> path) {
      if (path != "ranges" && path != "top" && !find_section(path))
        throw std::runtime_error("line " + std::to_string(n) + ": no section '" + path + "' in the case schema");
      const std::string t = path == "ranges" ? markdown_ranges() : markdown_table(path == "top" ? "" : path);
      if (!table.empty() && t != table)
        throw std::runtime_error("line " + std::to_string(n) + ": the sections '" + paths + "' have different tables");
      table = t;
    }
    const int start = n;
    bool closed = false;
    while (std::getline(in, line)) {
      ++n;
      if (line == close) { closed = true; break; }
    }
    if (!closed) throw std::runtime_error("line " + std::to_string(start) + ": '" + open + paths + " -->' without '" + close + "'");
    out << table << close << "\n";
  }
  return out.str();
}

}  // namespace fdem::schema
