#pragma once
// Small helpers shared by the element kernels and the Mohr-Coulomb return map (internal).
namespace fdem::fem::detail {

/// Isotropic elastic compliance: strain (Voigt, engineering shear) of a stress (Voigt).
inline void elastic_compliance(double young, double poisson, const double* s, double* e) {
  const double G = young / (2 * (1 + poisson));
  e[0] = (s[0] - poisson * (s[1] + s[2])) / young;
  e[1] = (s[1] - poisson * (s[0] + s[2])) / young;
  e[2] = (s[2] - poisson * (s[0] + s[1])) / young;
  e[3] = s[3] / G;
  e[4] = s[4] / G;
  e[5] = s[5] / G;
}

}  // namespace fdem::fem::detail
