#include "io/run_info.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <system_error>

namespace fdem {

namespace {

std::string num(double v) {
  if (!std::isfinite(v)) return "null";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

}  // namespace

std::string json_string(const std::string& s) {
  std::string o = "\"";
  for (unsigned char c : s) {
    switch (c) {
      case '"': o += "\\\""; break;
      case '\\': o += "\\\\"; break;
      case '\b': o += "\\b"; break;
      case '\f': o += "\\f"; break;
      case '\n': o += "\\n"; break;
      case '\r': o += "\\r"; break;
      case '\t': o += "\\t"; break;
      default:
        if (c < 0x20) {
          char buf[8];
          std::snprintf(buf, sizeof buf, "\\u%04x", c);
          o += buf;
        } else {
          o += static_cast<char>(c);  // UTF-8 passes through
        }
    }
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
