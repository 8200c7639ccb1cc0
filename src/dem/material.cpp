#include "dem/material.hpp"

#include <algorithm>

namespace fdem {

namespace {

/// The explicit name -> model table (the order of the enum).
struct ModelName {
  ContactModel model;
  const char* name;
};
constexpr ModelName kModelNames[] = {{ContactModel::kLinear, "linear"},
                                     {ContactModel::kHertzMindlin, "hertz_mindlin"}};

struct RollingName {
  RollingLaw law;
  const char* name;
};
constexpr RollingName kRollingNames[] = {{RollingLaw::kIncremental, "incremental"}, {RollingLaw::kTotal, "total"}};

}  // namespace

const char* rolling_law_name(RollingLaw m) {
  for (const RollingName& q : kRollingNames)
    if (q.law == m) return q.name;
  return "?";
}

bool rolling_law_from_name(const std::string& name, RollingLaw& out) {
  for (const RollingName& q : kRollingNames)
    if (name == q.name) { out = q.law; return true; }
  return false;
}

std::string rolling_law_names() {
  std::string s;
  for (const RollingName& q : kRollingNames) s += (s.empty() ? "" : ", ") + std::string(q.name);
  return s;
}

const char* contact_model_name(ContactModel m) {
  for (const ModelName& q : kModelNames)
    if (q.model == m) return q.name;
  return "?";
}

bool contact_model_from_name(const std::string& name, ContactModel& out) {
  for (const ModelName& q : kModelNames)
    if (name == q.name) { out = q.model; return true; }
  return false;
}

std::string contact_model_names() {
  std::string s;
  for (const ModelName& q : kModelNames) s += (s.empty() ? "" : ", ") + std::string(q.name);
  return s;
}

MaterialTable::MaterialTable(std::vector<Material> mats, const std::vector<PairOverride>& overrides,
                             ContactModel model)
    : mats_(std::move(mats)) {
  const std::size_t n = mats_.size();
  pairs_.resize(n * n);
  for (std::size_t a = 0; a < n; ++a)
    for (std::size_t b = 0; b < n; ++b) {
      PairParams p;
      p.kt_kn = 0.5 * (mats_[a].kt_kn + mats_[b].kt_kn);
      p.friction = std::min(mats_[a].friction, mats_[b].friction);
      // A pair of two materials of the total law is a pair of YADE's NormalInelasticity engine:
      // its Ip2 functor gives every pair one beta_r (an attribute of the functor, not of a
      // material) and eta_r = 1, so a material without rolling values (a wall, a grid) takes the
      // grains' (the larger of the two), not the mean. Two materials of different laws: the
      // incremental law unless `interactions` gives the pair one (the case reader requires it).
      const bool total = mats_[a].rolling_law == RollingLaw::kTotal && mats_[b].rolling_law == RollingLaw::kTotal;
      p.rolling = total ? RollingLaw::kTotal : RollingLaw::kIncremental;
      if (total) {
        p.beta_r = std::max(mats_[a].rolling_stiffness, mats_[b].rolling_stiffness);
        p.eta_r = std::max(mats_[a].rolling_limit, mats_[b].rolling_limit);
      } else {
        p.beta_r = 0.5 * (mats_[a].rolling_stiffness + mats_[b].rolling_stiffness);
        p.eta_r = 0.5 * (mats_[a].rolling_limit + mats_[b].rolling_limit);
      }
      p.model = model;
      const Material& ma = mats_[a];
      const Material& mb = mats_[b];
      p.e_star = 1.0 / ((1 - ma.poisson * ma.poisson) / ma.young + (1 - mb.poisson * mb.poisson) / mb.young);
      p.g_star = 1.0 / (2 * (2 - ma.poisson) * (1 + ma.poisson) / ma.young +
                        2 * (2 - mb.poisson) * (1 + mb.poisson) / mb.young);
      pairs_[a * n + b] = p;
    }
  for (const auto& o : overrides) {
    for (int k = 0; k < 2; ++k) {
      PairParams& p = k == 0 ? pairs_[o.a * n + o.b] : pairs_[o.b * n + o.a];
      if (o.has_friction) p.friction = o.friction;
      if (o.has_kt_kn) p.kt_kn = o.kt_kn;
      if (o.has_beta_r) p.beta_r = o.beta_r;
      if (o.has_eta_r) p.eta_r = o.eta_r;
      if (o.has_model) p.model = o.model;
      if (o.has_rolling_law) {
        p.rolling = o.rolling_law;
        const std::size_t ia = static_cast<std::size_t>(o.a), ib = static_cast<std::size_t>(o.b);
        const bool total = o.rolling_law == RollingLaw::kTotal;
        if (!o.has_beta_r)
          p.beta_r = total ? std::max(mats_[ia].rolling_stiffness, mats_[ib].rolling_stiffness)
                           : 0.5 * (mats_[ia].rolling_stiffness + mats_[ib].rolling_stiffness);
        if (!o.has_eta_r)
          p.eta_r = total ? std::max(mats_[ia].rolling_limit, mats_[ib].rolling_limit)
                          : 0.5 * (mats_[ia].rolling_limit + mats_[ib].rolling_limit);
      }
    }
  }
  for (const PairParams& p : pairs_) {
    any_hertz_ |= p.model == ContactModel::kHertzMindlin;
    any_rolling_ |= p.beta_r > 0.0;
  }
}

int MaterialTable::find(const std::string& name) const {
  for (std::size_t i = 0; i < mats_.size(); ++i)
    if (mats_[i].name == name) return static_cast<int>(i);
  return -1;
}

}  // namespace fdem
