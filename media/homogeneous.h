#pragma once
// A homogeneous participating medium. Coefficients in 1/mm; eta sets the speed of light inside.

namespace femto {

struct HomogeneousMedium {
  double sigma_a = 0.0;  ///< absorption coefficient, 1/mm
  double sigma_s = 0.0;  ///< scattering coefficient, 1/mm
  double g = 0.0;        ///< Henyey–Greenstein asymmetry, |g| < 1
  double eta = 1.0;      ///< refractive index (phase velocity c / eta)

  double sigma_t() const { return sigma_a + sigma_s; }
  double albedo() const { const double st = sigma_t(); return st > 0 ? sigma_s / st : 0.0; }
  bool scatters() const { return sigma_s > 0.0; }
};

}  // namespace femto
