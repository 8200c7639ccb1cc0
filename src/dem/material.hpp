#pragma once
// DEM materials and the pair table (DESIGN.md 4.1).
//
// A material carries Young's modulus E (Pa), density (kg/m^3), the tangential/normal stiffness
// ratio alpha = K_T/K_N, the friction coefficient tan(phi_mu), the rolling stiffness factor
// beta_r and the rolling moment limit factor eta_r.  The per-pair parameters used by the contact
// law are resolved once at set-up into a dense table indexed by (material a, material b), so the
// per-contact loop does a table lookup and no string or virtual work.
#include <string>
#include <vector>

namespace fdem {

struct Material {
  std::string name;
  double young = 0;          // E, Pa
  double density = 0;        // rho, kg/m^3
  double kt_kn = 0.25;       // alpha = K_T / K_N
  double friction = 0.5;     // tan(phi_mu), Coulomb coefficient
  double rolling_stiffness = 0;  // beta_r (0: no rolling resistance)
  double rolling_limit = 0;      // eta_r
};

/// Pair parameters for the contact law, symmetric in (a, b).
struct PairParams {
  double kt_kn = 0.25;   // alpha of the pair (mean of the two materials unless overridden)
  double friction = 0.5; // tan(phi) of the pair (min of the two unless overridden, as YADE does)
  double beta_r = 0;     // rolling stiffness factor (mean unless overridden)
  double eta_r = 0;      // rolling limit factor (mean unless overridden)
};

/// An explicit override for one pair of materials (case file key `interactions`).
struct PairOverride {
  int a = -1, b = -1;
  bool has_friction = false, has_kt_kn = false, has_beta_r = false, has_eta_r = false;
  double friction = 0, kt_kn = 0, beta_r = 0, eta_r = 0;
};

class MaterialTable {
 public:
  MaterialTable() = default;
  explicit MaterialTable(std::vector<Material> mats, const std::vector<PairOverride>& overrides = {});
  int size() const { return static_cast<int>(mats_.size()); }
  const Material& operator[](int i) const { return mats_[i]; }
  /// Index of a material by name, -1 if there is none.
  int find(const std::string& name) const;
  const PairParams& pair(int a, int b) const { return pairs_[a * mats_.size() + b]; }
  const std::vector<Material>& all() const { return mats_; }

 private:
  std::vector<Material> mats_;
  std::vector<PairParams> pairs_;
};

}  // namespace fdem
