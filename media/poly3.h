#pragma once
// Cubic polynomials in a local ray parameter. A trilinearly interpolated field restricted to a
// straight segment inside one cell is a product of three linear functions, hence a cubic, so
// optical depth and optical path length over a cell are integrated exactly.
#include <cmath>

namespace femto {

struct Poly3 {
  double c[4] = {0, 0, 0, 0};  ///< c0 + c1 t + c2 t^2 + c3 t^3

  static Poly3 constant(double v) {
    Poly3 p;
    p.c[0] = v;
    return p;
  }
  /// (a0 + a1 t)(b0 + b1 t)(d0 + d1 t)
  static Poly3 product_of_linears(double a0, double a1, double b0, double b1, double d0, double d1) {
    Poly3 p;
    p.c[0] = a0 * b0 * d0;
    p.c[1] = a1 * b0 * d0 + a0 * b1 * d0 + a0 * b0 * d1;
    p.c[2] = a1 * b1 * d0 + a1 * b0 * d1 + a0 * b1 * d1;
    p.c[3] = a1 * b1 * d1;
    return p;
  }
  Poly3& operator+=(const Poly3& o) {
    for (int i = 0; i < 4; ++i) c[i] += o.c[i];
    return *this;
  }
  Poly3 operator*(double s) const {
    Poly3 p;
    for (int i = 0; i < 4; ++i) p.c[i] = c[i] * s;
    return p;
  }
  bool is_constant() const { return c[1] == 0 && c[2] == 0 && c[3] == 0; }
  double operator()(double t) const { return c[0] + t * (c[1] + t * (c[2] + t * c[3])); }
  /// Integral from 0 to t (t finite). Constant pieces (homogeneous media, nearest-neighbour
  /// voxels) skip the division by 3 of the general form, which gives the same value for them.
  double integral(double t) const {
    if (is_constant()) return t * c[0];
    return t * (c[0] + t * (c[1] / 2 + t * (c[2] / 3 + t * c[3] / 4)));
  }
};

/// Smallest t in [0, t_max] with p.integral(t) = target, for p >= 0 on [0, t_max] and
/// 0 <= target <= p.integral(t_max). Newton steps safeguarded by bisection.
inline double invert_integral(const Poly3& p, double target, double t_max) {
  if (p.is_constant()) {
    if (!(p.c[0] > 0)) return t_max;
    const double t = target / p.c[0];
    return t < t_max ? t : t_max;  // std::fmin is a library call; neither value is NaN here
  }
  double lo = 0, hi = t_max;
  double t = 0.5 * (lo + hi);
  for (int it = 0; it < 100; ++it) {
    const double F = p.integral(t) - target;
    if (F > 0) hi = t; else lo = t;
    const double f = p(t);
    double next = f > 0 ? t - F / f : 0.5 * (lo + hi);
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    if (std::abs(next - t) <= 1e-15 * (1 + t_max) || hi - lo <= 1e-15 * (1 + t_max)) return next;
    t = next;
  }
  return t;
}

}  // namespace femto
