#include "io/run_info.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <system_error>

namespace fdem {

std::string json_number(double v, int digits) {
  if (!std::isfinite(v)) return "null";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*g", digits, v);
  return buf;
}

std::string json_array(const std::vector<double>& v, int digits) {
  std::string s = "[";
  for (std::size_t i = 0; i < v.size(); ++i) s += (i ? ", " : "") + json_number(v[i], digits);
  return s + "]";
}

namespace {
std::string num(double v) { return json_number(v, 17); }
}  // namespace

std::string json_string(const std::string& s) {
  // Valid JSON for any bytes: quotes, backslashes and control characters escaped, well-formed
  // UTF-8 passed through, every byte of an invalid UTF-8 sequence written as \ufffd.
  std::string o = "\"";
  const std::size_t n = s.size();
  for (std::size_t i = 0; i < n;) {
    const unsigned char c = static_cast<unsigned char>(s[i]);
    switch (c) {
      case '"': o += "\\\""; ++i; continue;
      case '\\': o += "\\\\"; ++i; continue;
      case '\b': o += "\\b"; ++i; continue;
      case '\f': o += "\\f"; ++i; continue;
      case '\n': o += "\\n"; ++i; continue;
      case '\r': o += "\\r"; ++i; continue;
      case '\t': o += "\\t"; ++i; continue;
      default: break;
    }
    if (c < 0x20 || c == 0x7f) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\u%04x", c);
      o += buf;
      ++i;
      continue;
    }
    if (c < 0x80) { o += static_cast<char>(c); ++i; continue; }
    // Multi-byte UTF-8: length from the lead byte; reject overlong forms, surrogates, > U+10FFFF.
    std::size_t len = 0;
    unsigned cp = 0;
    if (c >= 0xc2 && c <= 0xdf) { len = 2; cp = c & 0x1f; }
    else if (c >= 0xe0 && c <= 0xef) { len = 3; cp = c & 0x0f; }
    else if (c >= 0xf0 && c <= 0xf4) { len = 4; cp = c & 0x07; }
    bool ok = len > 0 && i + len <= n;
    for (std::size_t k = 1; ok && k < len; ++k) {
      const unsigned char d = static_cast<unsigned char>(s[i + k]);
      if ((d & 0xc0) != 0x80) ok = false;
      else cp = (cp << 6) | (d & 0x3f);
    }
    if (ok && ((len == 3 && (cp < 0x800 || (cp >= 0xd800 && cp <= 0xdfff))) || (len == 4 && (cp < 0x10000 || cp > 0x10ffff))))
      ok = false;
    if (!ok) { o += "\\ufffd"; ++i; continue; }
    o.append(s, i, len);
    i += len;
  }
  return o + "\"";
}

std::string run_json(const RunInfo& r) {
  std::ostringstream o;
  o << "{\n"
    << "  \"version\": " << json_string(r.version) << ",\n"
    << "  \"case\": " << json_string(r.case_name) << ",\n"
    << "  \"case_file\": " << json_string(r.case_file) << ",\n"
    << "  \"overrides\": [" << [&] {
         std::string o;
         for (const std::string& x : r.overrides) o += (o.empty() ? "" : ", ") + json_string(x);
         return o;
       }() << "],\n"
    << (r.specimen.empty() ? std::string() : "  \"specimen\": " + json_string(r.specimen) + ",\n")
    << "  \"status\": " << json_string(r.status) << ",\n"
    << (r.message.empty() ? std::string() : "  \"message\": " + json_string(r.message) + ",\n")
    << "  \"ranks\": " << r.ranks << ",\n"
    << "  \"dt\": " << num(r.dt) << ",\n"
    << "  \"steps\": " << r.steps << ",\n"
    << "  \"start_step\": " << r.start_step << ",\n"
    << "  \"simulated_time\": " << num(r.simulated_time) << ",\n"
    << "  \"wall_time_s\": " << num(r.wall_time) << ",\n"
    << "  \"particles\": {\n"
    << "    \"initial\": " << r.particles_initial << ",\n"
    << "    \"final\": " << r.particles_final << ",\n"
    << "    \"removed\": " << r.particles_removed << "\n"
    << "  },\n"
    << "  \"particle_steps_per_second\": " << num(r.particle_steps_per_second) << ",\n"
    << "  \"element_updates_per_second\": " << num(r.element_updates_per_second) << ",\n"
    << "  \"neighbour_rebuilds\": " << r.rebuilds << ",\n"
    << "  \"comm_bytes_max_rank\": " << r.comm_bytes << ",\n"
    << "  \"timings\": {";
  for (std::size_t i = 0; i < r.timings.size(); ++i) {
    o << (i ? ",\n" : "\n") << "    " << json_string(r.timings[i].first) << ": "
      << num(r.timings[i].second);
  }
  o << (r.timings.empty() ? "}" : "\n  }");
  if (!r.coupling.empty()) {
    o << ",\n  \"coupling\": {";
    for (std::size_t i = 0; i < r.coupling.size(); ++i)
      o << (i ? ",\n" : "\n") << "    " << json_string(r.coupling[i].first) << ": " << num(r.coupling[i].second);
    o << "\n  }";
  }
  if (!r.ranks_detail.empty()) {
    o << ",\n  \"decomposition\": {\"grid\": [" << r.grid[0] << ", " << r.grid[1] << ", " << r.grid[2]
      << "], \"ranks\": [";
    for (std::size_t i = 0; i < r.ranks_detail.size(); ++i) {
      const RankRecord& q = r.ranks_detail[i];
      o << (i ? ",\n" : "\n") << "    {\"owned\": " << q.owned << ", \"ghosts\": " << q.ghosts
        << ", \"bytes_sent\": " << q.bytes << ", \"messages\": " << q.messages
        << ", \"peak_rss_mb\": " << num(q.peak_rss_mb) << "}";
    }
    o << "\n  ]}";
  }
  if (!r.fe_ranks.empty()) {
    o << ",\n  \"fe_partition\": {\"ranks\": [";
    for (std::size_t i = 0; i < r.fe_ranks.size(); ++i) {
      const FeRankRecord& q = r.fe_ranks[i];
      o << (i ? ",\n" : "\n") << "    {\"elements\": " << q.elements << ", \"nodes\": " << q.nodes
        << ", \"mesh_nodes\": " << q.mesh_nodes << ", \"peak_rss_mb\": " << num(q.peak_rss_mb) << "}";
    }
    o << "\n  ]}";
  }
  if (!r.pairs.empty()) {
    o << ",\n  \"pairs\": [";
    for (std::size_t i = 0; i < r.pairs.size(); ++i) {
      const PairRecord& q = r.pairs[i];
      o << (i ? ",\n" : "\n") << "    {\"materials\": [" << json_string(q.a) << ", " << json_string(q.b)
        << "], \"touch\": " << json_string(q.touch) << ", \"friction\": " << num(q.friction)
        << ", \"friction_from\": " << json_string(q.friction_from) << ", \"kt_kn\": " << num(q.kt_kn)
        << ", \"rolling_stiffness\": " << num(q.beta_r) << ", \"rolling_limit\": " << num(q.eta_r)
        << ", \"rolling_law\": " << json_string(q.rolling_law);
      if (q.model != "linear") o << ", \"model\": " << json_string(q.model);
      o << "}";
    }
    o << "\n  ]";
  }
  o << "\n}\n";
  return o.str();
}

void write_run_json(const std::string& path, const RunInfo& info) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream f(tmp, std::ios::trunc);
    if (!f) throw std::runtime_error(tmp + ": cannot open for writing");
    f << run_json(info);
    f.flush();
    if (!f) throw std::runtime_error(tmp + ": write failed");
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) throw std::runtime_error(path + ": cannot rename " + tmp + ": " + ec.message());
}

}  // namespace fdem
