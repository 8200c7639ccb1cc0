#include "dem/material.hpp"

#include <algorithm>

namespace fdem {

MaterialTable::MaterialTable(std::vector<Material> mats, const std::vector<PairOverride>& overrides)
    : mats_(std::move(mats)) {
  const std::size_t n = mats_.size();
  pairs_.resize(n * n);
  for (std::size_t a = 0; a < n; ++a)
    for (std::size_t b = 0; b < n; ++b) {
      PairParams p;
      p.kt_kn = 0.5 * (mats_[a].kt_kn + mats_[b].kt_kn);
      p.friction = std::min(mats_[a].friction, mats_[b].friction);
      p.beta_r = 0.5 * (mats_[a].rolling_stiffness + mats_[b].rolling_stiffness);
      p.eta_r = 0.5 * (mats_[a].rolling_limit + mats_[b].rolling_limit);
      pairs_[a * n + b] = p;
    }
  for (const auto& o : overrides) {
    for (int k = 0; k < 2; ++k) {
      PairParams& p = k == 0 ? pairs_[o.a * n + o.b] : pairs_[o.b * n + o.a];
      if (o.has_friction) p.friction = o.friction;
      if (o.has_kt_kn) p.kt_kn = o.kt_kn;
      if (o.has_beta_r) p.beta_r = o.beta_r;
      if (o.has_eta_r) p.eta_r = o.eta_r;
    }
  }
}

int MaterialTable::find(const std::string& name) const {
  for (std::size_t i = 0; i < mats_.size(); ++i)
    if (mats_[i].name == name) return static_cast<int>(i);
  return -1;
}

}  // namespace fdem
