#include "app/pairs.hpp"

#include <algorithm>
#include <cstdio>

namespace fdem {
namespace {

std::string num(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.6g", v);
  return b;
}

std::vector<int> grain_materials(const CaseConfig& c) {
  std::vector<int> g;
  for (const ParticleSource& s : c.particles)
    if (s.material >= 0) g.push_back(s.material);
  if (c.packing.present && c.packing.material >= 0) g.push_back(c.packing.material);
  if (c.packing.present && c.packing.surcharge.present) g.push_back(c.packing.surcharge.material);
  if (g.empty())  // a restart (or a case without particle sources): any material may be a grain's
    for (int m = 0; m < static_cast<int>(c.materials.size()); ++m) g.push_back(m);
  std::sort(g.begin(), g.end());
  g.erase(std::unique(g.begin(), g.end()), g.end());
  return g;
}

}  // namespace

std::vector<ContactPair> contact_pairs(const CaseConfig& c) {
  const MaterialTable table(c.materials, c.interactions, c.contact_model);
  auto make = [&](int g, int o, std::string touch) {
    ContactPair q;
    q.grain = g;
    q.other = o;
    q.touch = std::move(touch);
    q.p = table.pair(g, o);
    for (const PairOverride& ov : c.interactions)
      if ((ov.a == g && ov.b == o) || (ov.a == o && ov.b == g)) {
        q.friction_set = ov.has_friction;
        q.kt_kn_set = ov.has_kt_kn;
        q.beta_r_set = ov.has_beta_r;
        q.eta_r_set = ov.has_eta_r;
        q.model_set = ov.has_model;
        q.rolling_set = ov.has_rolling_law;
      }
    return q;
  };
  std::vector<ContactPair> out;
  const std::vector<int> grains = grain_materials(c);
  for (std::size_t i = 0; i < grains.size(); ++i)
    for (std::size_t j = i; j < grains.size(); ++j) out.push_back(make(grains[i], grains[j], "grain-grain"));
  std::vector<int> wall_mats;
  for (const WallConfig& w : c.walls)
    if (w.material >= 0) wall_mats.push_back(w.material);
  std::sort(wall_mats.begin(), wall_mats.end());
  wall_mats.erase(std::unique(wall_mats.begin(), wall_mats.end()), wall_mats.end());
  for (int m : wall_mats) {
    std::string names;
    for (const WallConfig& w : c.walls)
      if (w.material == m) names += (names.empty() ? "" : ", ") + w.name;
    for (int g : grains) out.push_back(make(g, m, "grain-wall (" + names + ")"));
  }
  if (c.coupling.present && c.coupling.material >= 0) {
    const std::vector<int> ims = c.coupling.interface_materials();
    for (int m : ims) {
      std::string names;  // the surfaces of this material (with several materials)
      for (std::size_t i = 0; i < c.coupling.surfaces.size(); ++i)
        if (c.coupling.surface_material(i) == m) names += (names.empty() ? "" : ", ") + c.coupling.surfaces[i].name;
      const bool one = ims.size() == 1;
      for (int g : grains) out.push_back(make(g, m, one ? "grain-interface" : "grain-interface (" + names + ")"));
    }
  }
  return out;
}

std::vector<std::string> pair_table_lines(const CaseConfig& c) {
  std::vector<std::string> lines;
  const std::vector<ContactPair> pairs = contact_pairs(c);
  std::size_t wname = 9;
  for (const ContactPair& q : pairs)
    wname = std::max(wname, c.materials[q.grain].name.size() + c.materials[q.other].name.size() + 3);
  char b[512];
  std::snprintf(b, sizeof b, "%-*s  %-9s  %-9s  %-7s  %-7s  %-12s  %-14s  %s", static_cast<int>(wname),
                "materials", "friction", "K_T/K_N", "beta_r", "eta_r", "rolling", "model", "touch");
  lines.emplace_back(b);
  auto cell = [](double v, bool set) { return num(v) + (set ? "*" : ""); };
  for (const ContactPair& q : pairs) {
    const std::string names = c.materials[q.grain].name + " - " + c.materials[q.other].name;
    const std::string model = std::string(contact_model_name(q.p.model)) + (q.model_set ? "*" : "");
    const std::string rolling = std::string(rolling_law_name(q.p.rolling)) + (q.rolling_set ? "*" : "");
    std::snprintf(b, sizeof b, "%-*s  %-9s  %-9s  %-7s  %-7s  %-12s  %-14s  %s", static_cast<int>(wname),
                  names.c_str(), cell(q.p.friction, q.friction_set).c_str(), cell(q.p.kt_kn, q.kt_kn_set).c_str(),
                  cell(q.p.beta_r, q.beta_r_set).c_str(), cell(q.p.eta_r, q.eta_r_set).c_str(), rolling.c_str(),
                  model.c_str(), q.touch.c_str());
    lines.emplace_back(b);
  }
  return lines;
}

std::vector<PairRecord> pair_records(const CaseConfig& c) {
  std::vector<PairRecord> out;
  for (const ContactPair& q : contact_pairs(c)) {
    PairRecord r;
    r.a = c.materials[q.grain].name;
    r.b = c.materials[q.other].name;
    r.touch = q.touch;
    r.friction = q.p.friction;
    r.kt_kn = q.p.kt_kn;
    r.beta_r = q.p.beta_r;
    r.eta_r = q.p.eta_r;
    r.model = contact_model_name(q.p.model);
    r.rolling_law = rolling_law_name(q.p.rolling);
    r.friction_from = q.friction_set ? "interactions" : "smaller of the two";
    out.push_back(r);
  }
  return out;
}

std::vector<std::string> pair_warnings(const CaseConfig& c) {
  std::vector<std::string> out;
  const std::vector<ContactPair> pairs = contact_pairs(c);
  for (int m = 0; m < static_cast<int>(c.materials.size()); ++m) {
    const Material& mat = c.materials[m];
    const std::string where = m < static_cast<int>(c.material_at.size())
                                  ? (c.material_at[m].second > 0 ? c.material_at[m].first + ":" +
                                                                       std::to_string(c.material_at[m].second)
                                                                 : c.material_at[m].first)
                                  : c.file;
    bool touched = false, used = false;
    std::vector<const ContactPair*> undercut;
    for (const ContactPair& q : pairs) {
      if (q.grain != m && q.other != m) continue;
      touched = true;
      if (!q.friction_set && q.p.friction == mat.friction) used = true;
      else if (!q.friction_set) undercut.push_back(&q);
    }
    if (!touched) {
      out.push_back(where + ": warning: material '" + mat.name +
                    "' is used by no particle, wall or interface: its parameters have no effect");
      continue;
    }
    if (used || undercut.empty()) continue;  // (every pair overridden: the case says what it wants)
    std::string msg = where + ": warning: the friction " + num(mat.friction) + " of material '" + mat.name +
                      "' is used by no contact:";
    std::string fix;
    for (const ContactPair* q : undercut) {
      const std::string& a = c.materials[q->grain].name;
      const std::string& b = c.materials[q->other].name;
      msg += " " + a + " - " + b + " takes " + num(q->p.friction) + ",";
      fix += "\n    - {materials: [" + a + ", " + b + "], friction: " + num(mat.friction) + "}";
    }
    msg += " the smaller friction of the two (the rule of YADE's FrictMat). To apply " + num(mat.friction) +
           ", add to the case:\n  interactions:" + fix;
    out.push_back(msg);
  }
  return out;
}

}  // namespace fdem
