#pragma once
// DEM materials and the pair table (DESIGN.md 4.1).
//
// A material carries Young's modulus E (Pa), Poisson's ratio nu (used by the Hertz-Mindlin model
// only), density (kg/m^3), the tangential/normal stiffness ratio alpha = K_T/K_N (linear model only), the friction coefficient tan(phi_mu), the rolling stiffness factor
// beta_r, the rolling moment limit factor eta_r and the rolling law.  The per-pair parameters used by the contact
// law are resolved once at set-up into a dense table indexed by (material a, material b), so the
// per-contact loop does a table lookup and no string or virtual work.
#include <string>
#include <vector>

namespace fdem {

/// The contact models (the table of formulas is normal_law() in dem/contact_law.hpp):
///  - kLinear: the thesis's linear spring, K_N = springs 2 E r in series, K_T = alpha K_N;
///  - kHertzMindlin: Hertz's normal force with Mindlin's no-slip tangential stiffness.
enum class ContactModel { kLinear, kHertzMindlin };

/// The rolling-resistance laws (the formulas are in contact_force(), dem/contact_law.hpp):
///  - kIncremental: the stored rolling rotation is capped with the moment (elastic-perfectly
///    plastic, twist excluded): YADE 2023's Law2_ScGeom6D_CohFrictPhys_CohesionMoment (CohFrictMat);
///  - kTotal: the thesis's eqs 3-7/3-8 and the engine its scripts ran (YADE's
///    Law2_ScGeom6D_NormalInelasticityPhys_NormalInelasticity): the moment is K_r times the total
///    relative rotation since the contact formed (twist included), only the moment is capped.
enum class RollingLaw { kIncremental, kTotal };

const char* rolling_law_name(RollingLaw m);
bool rolling_law_from_name(const std::string& name, RollingLaw& out);
std::string rolling_law_names();

/// The case-file name of a model ("linear", "hertz_mindlin").
const char* contact_model_name(ContactModel m);
/// The model of a case-file name; false if there is none of that name.
bool contact_model_from_name(const std::string& name, ContactModel& out);
/// The valid names, for error messages: "linear, hertz_mindlin".
std::string contact_model_names();

struct Material {
  std::string name;
  double young = 0;          // E, Pa
  double poisson = 0.25;     // nu, Poisson's ratio (Hertz-Mindlin pairs only)
  double density = 0;        // rho, kg/m^3
  double kt_kn = 0.25;       // alpha = K_T / K_N
  double friction = 0.5;     // tan(phi_mu), Coulomb coefficient
  double rolling_stiffness = 0;  // beta_r (0: no rolling resistance)
  double rolling_limit = 0;      // eta_r
  RollingLaw rolling_law = RollingLaw::kIncremental;  // the law of this material's pairs
};

/// Pair parameters for the contact law, symmetric in (a, b).
struct PairParams {
  double kt_kn = 0.25;   // alpha of the pair (mean of the two materials unless overridden)
  double friction = 0.5; // tan(phi) of the pair (min of the two unless overridden, as YADE does)
  double beta_r = 0;     // rolling stiffness factor (mean unless overridden)
  double eta_r = 0;      // rolling limit factor (mean unless overridden)
  ContactModel model = ContactModel::kLinear;  // the case's contact_model unless overridden
  RollingLaw rolling = RollingLaw::kIncremental;  // the two materials' law unless overridden
  // Hertz-Mindlin effective moduli of the two materials (set for every pair, used by Hertz pairs):
  // 1/E* = (1-nu_a^2)/E_a + (1-nu_b^2)/E_b, 1/G* = 2(2-nu_a)(1+nu_a)/E_a + 2(2-nu_b)(1+nu_b)/E_b.
  double e_star = 0;     // E*, Pa
  double g_star = 0;     // G*, Pa
};

/// An explicit override for one pair of materials (case file key `interactions`).
struct PairOverride {
  int a = -1, b = -1;
  bool has_friction = false, has_kt_kn = false, has_beta_r = false, has_eta_r = false, has_model = false,
       has_rolling_law = false;
  double friction = 0, kt_kn = 0, beta_r = 0, eta_r = 0;
  ContactModel model = ContactModel::kLinear;
  RollingLaw rolling_law = RollingLaw::kIncremental;
};

class MaterialTable {
 public:
  MaterialTable() = default;
  /// `model`: the contact model of every pair that no override gives one.
  explicit MaterialTable(std::vector<Material> mats, const std::vector<PairOverride>& overrides = {},
                         ContactModel model = ContactModel::kLinear);
  int size() const { return static_cast<int>(mats_.size()); }
  const Material& operator[](int i) const { return mats_[i]; }
  /// Index of a material by name, -1 if there is none.
  int find(const std::string& name) const;
  const PairParams& pair(int a, int b) const { return pairs_[a * mats_.size() + b]; }
  const std::vector<Material>& all() const { return mats_; }
  /// Whether any pair uses the Hertz-Mindlin model (time-step estimates then take its bound too).
  bool any_hertz() const { return any_hertz_; }
  /// Whether any pair has rolling resistance (beta_r > 0): else no contact ever accumulates a
  /// rolling rotation, and the engine keeps none.
  bool any_rolling() const { return any_rolling_; }

 private:
  std::vector<Material> mats_;
  std::vector<PairParams> pairs_;
  bool any_hertz_ = false, any_rolling_ = false;
};

}  // namespace fdem
