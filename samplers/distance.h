#pragma once
// Mean-free-path distance sampling in a homogeneous medium: p(s) = sigma_t exp(-sigma_t s).
#include <cmath>
#include <limits>

namespace femto {

/// Inverse CDF of the unit exponential, -log(1 - u), u in [0,1). For the 53-bit uniforms of
/// Rng (multiples of 2^-53) 1 - u is exact, so log is as accurate as log1p and ~3x cheaper.
inline double unit_exponential(double u) { return -std::log(1.0 - u); }

/// Inverse CDF of the exponential distribution; u in [0,1). Returns +inf when sigma_t == 0.
inline double sample_exponential(double sigma_t, double u) {
  if (!(sigma_t > 0.0)) return std::numeric_limits<double>::infinity();
  return unit_exponential(u) / sigma_t;
}

/// Density of sample_exponential at s >= 0.
inline double exponential_pdf(double sigma_t, double s) {
  if (s < 0.0 || sigma_t <= 0.0) return 0.0;
  return sigma_t * std::exp(-sigma_t * s);
}

/// Probability that the sampled distance exceeds s (the transmittance).
inline double exponential_survival(double sigma_t, double s) {
  if (s <= 0.0 || sigma_t <= 0.0) return 1.0;  // also avoids 0 * inf
  return std::exp(-sigma_t * s);
}

}  // namespace femto
