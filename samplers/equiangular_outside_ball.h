#pragma once
// Equiangular sampling of s in [s_a, s_b] along o + s w towards p, leaving out the points within
// distance r of p: pdf(s) = 1 / (M (h^2 + (s - Delta)^2)) on what is left (one interval, or two
// around the chord the line cuts through the ball), M its total angle over h. Each interval is an
// EquiangularSampler; one is picked in proportion to its mass theta_k / h (in the h -> 0 limit,
// the integral of 1 / x^2, (b - a) / (a b)). Light tracing uses it to leave the points next to the
// pinhole, whose sensor weight 1 / dist^2 has no bounded variance, to camera paths.
#include <cmath>

#include "samplers/equiangular.h"

namespace femto {

class EquiangularOutsideBall {
 public:
  /// w unit; [s_a, s_b] finite; r >= 0 (0: plain equiangular sampling).
  EquiangularOutsideBall(const Vec3& o, const Vec3& w, const Vec3& p, double s_a, double s_b,
                         double r) {
    const Vec3 l = p - o;
    const double delta = dot(l, w), h = length(cross(l, w));
    double c0 = s_b, c1 = s_b;  // the chord [c0, c1] inside the ball, clipped to the segment
    if (r > h) {
      const double half = std::sqrt((r - h) * (r + h));
      c0 = std::fmax(s_a, delta - half);
      c1 = std::fmin(s_b, delta + half);
      if (!(c1 > c0)) c0 = c1 = s_b;  // the chord misses the segment
    }
    part_[0] = EquiangularSampler(o, w, p, s_a, c0);
    part_[1] = EquiangularSampler(o, w, p, c1, s_b);
    for (int k = 0; k < 2; ++k) mass_[k] = part_[k].valid() ? mass(part_[k], h) : 0.0;
    total_ = mass_[0] + mass_[1];
    valid_ = total_ > 0 && std::isfinite(total_);
  }

  bool valid() const { return valid_; }

  /// u in [0, 1).
  double sample(double u) const {
    const double pick = u * total_;
    if (pick < mass_[0] || !(mass_[1] > 0)) return part_[0].sample(std::fmin(pick / mass_[0], 1.0));
    return part_[1].sample(std::fmin((pick - mass_[0]) / mass_[1], 1.0));
  }

  /// Density per unit distance at s (0 inside the ball and outside [s_a, s_b]).
  double pdf(double s) const {
    if (!valid_) return 0.0;
    for (int k = 0; k < 2; ++k) {
      const double p = mass_[k] > 0 ? part_[k].pdf(s) : 0.0;
      if (p > 0) return p * (mass_[k] / total_);
    }
    return 0.0;
  }

 private:
  /// The integral of 1 / (h^2 + x^2) over the sampler's interval.
  static double mass(const EquiangularSampler& eq, double h) {
    if (eq.theta() > 0) return eq.theta() / h;
    // h -> 0 limit: the sampler's density is a b / ((b - a) x^2), so its mass is 1 / pdf x^2.
    const double x = eq.sample(0.5) - eq.delta();
    return 1.0 / (eq.pdf(eq.delta() + x) * x * x);
  }
  EquiangularSampler part_[2] = {EquiangularSampler(Vec3(), Vec3(0, 0, 1), Vec3(), 0, 0),
                                 EquiangularSampler(Vec3(), Vec3(0, 0, 1), Vec3(), 0, 0)};
  double mass_[2] = {0, 0};
  double total_ = 0;
  bool valid_ = false;
};

}  // namespace femto
