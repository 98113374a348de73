#pragma once
// Equiangular sampling (Kulla & Fajardo 2012) of a distance s in [s_a, s_b] along a ray o + s w
// towards a point p: the angle subtended at p is uniform, so
//   pdf(s) = h / ((theta_b - theta_a) (h^2 + (s - Delta)^2)),
// with Delta = (p - o).w, h = distance of p from the line and theta = atan((s - Delta) / h).
//
// Everything is written with x = s - Delta and the endpoint offsets a = s_a - Delta,
// b = s_b - Delta; the subtended angle is atan2(h (b - a), a b + h^2), which stays accurate when
// h -> 0 (the difference of two angles near pi/2 would not).
// h -> 0: if the target is off the segment (a b > 0) the density tends to
// a b / ((b - a) x^2), which is used once h <= 1e-8 min(|a|, |b|) (relative difference below
// (h / a)^2 = 1e-16). If h == 0 and the segment reaches the target (a b <= 0) the density would
// be a delta (and 1 / x^2 is not integrable there): the sampler reports valid() == false.
#include <algorithm>
#include <cmath>

#include "core/vec3.h"

namespace femto {

class EquiangularSampler {
 public:
  /// No segment: valid() is false.
  EquiangularSampler() = default;
  /// w must be unit length; [s_a, s_b] finite with s_a < s_b, otherwise valid() is false.
  EquiangularSampler(const Vec3& o, const Vec3& w, const Vec3& p, double s_a, double s_b)
      : s_a_(s_a), s_b_(s_b) {
    const Vec3 l = p - o;
    delta_ = dot(l, w);
    h_ = length(cross(l, w));  // |l| sin(angle), no cancellation for small h
    a_ = s_a - delta_;
    b_ = s_b - delta_;
    if (!(std::isfinite(s_a) && std::isfinite(s_b) && s_b > s_a && std::isfinite(h_))) return;
    const double near = std::min(std::abs(a_), std::abs(b_));
    if (a_ * b_ > 0 && h_ <= 1e-8 * near) {
      limit_ = true;
      valid_ = true;
      return;
    }
    if (!(h_ > 0)) return;  // target on the segment: no integrable density
    theta_ = std::atan2(h_ * (b_ - a_), a_ * b_ + h_ * h_);
    valid_ = theta_ > 0;
  }

  bool valid() const { return valid_; }
  double delta() const { return delta_; }  ///< foot of the perpendicular from p, along the ray
  double h() const { return h_; }          ///< distance of p from the line
  double theta() const { return theta_; }  ///< angle subtended at p (0 in the h -> 0 limit)

  /// Inverse CDF; u in [0, 1). Rotates the direction p -> o + s_a w by u * theta and intersects
  /// it with the line (tan-addition form, exact at u = 0 and u = 1).
  double sample(double u) const {
    double x;
    if (limit_) {
      x = a_ * b_ / (b_ - u * (b_ - a_));  // inverse of the 1 / x^2 CDF
    } else {
      const double phi = u * theta_, c = std::cos(phi), s = std::sin(phi);
      x = h_ * (a_ * c + h_ * s) / (h_ * c - a_ * s);
    }
    return std::clamp(delta_ + x, s_a_, s_b_);
  }

  /// Density per unit distance at s (0 outside [s_a, s_b]).
  double pdf(double s) const {
    if (!valid_ || s < s_a_ || s > s_b_) return 0.0;
    const double x = s - delta_;
    if (limit_) return a_ * b_ / ((b_ - a_) * x * x);
    return (h_ / theta_) / (h_ * h_ + x * x);
  }

  /// P(sample <= s).
  double cdf(double s) const {
    if (s <= s_a_) return 0.0;
    if (s >= s_b_) return 1.0;
    const double x = s - delta_;
    if (limit_) return b_ * (x - a_) / ((b_ - a_) * x);
    return std::atan2(h_ * (x - a_), a_ * x + h_ * h_) / theta_;
  }

 private:
  double s_a_ = 0, s_b_ = 0;
  double delta_ = 0, h_ = 0, a_ = 0, b_ = 0, theta_ = 0;
  bool limit_ = false, valid_ = false;
};

}  // namespace femto
