#pragma once
// A distance on [a, b] with density proportional to exp(-lambda (s - a)), lambda >= 0 (uniform at
// lambda = 0; b may be infinite when lambda > 0):
//   pdf(s) = lambda exp(-lambda (s - a)) / (1 - exp(-lambda (b - a))).
// Laser chords use it with the decay of both transmittances along the chord, which a homogeneous
// medium makes exact.
#include <cmath>
#include <limits>

namespace femto {

class IntervalExponential {
 public:
  IntervalExponential(double a, double b, double lambda) : a_(a), lambda_(lambda) {
    const double len = b - a;
    valid_ = std::isfinite(a) && len > 0 && lambda >= 0 && (lambda > 0 || std::isfinite(len));
    if (!valid_) return;
    // Below ~1e-8 of decay across the interval the uniform density is exact to 1e-8.
    if (!(lambda * len > 1e-8)) {
      uniform_ = true;
      len_ = len;
      return;
    }
    mass_ = -std::expm1(-lambda * len);  // 1 - exp(-lambda len), accurate for small products
  }

  bool valid() const { return valid_; }

  /// Inverse CDF; u in [0, 1).
  double sample(double u) const {
    if (uniform_) return a_ + u * len_;
    return a_ - std::log1p(-u * mass_) / lambda_;
  }

  double pdf(double s) const {
    if (uniform_) return 1.0 / len_;
    return lambda_ * std::exp(-lambda_ * (s - a_)) / mass_;
  }

 private:
  double a_ = 0, lambda_ = 0, len_ = 0, mass_ = 1;
  bool valid_ = false, uniform_ = false;
};

}  // namespace femto
