#pragma once
// Angular time sampling (seed 000 Sec. 5.3, Supp. D.3): from a vertex x with a target p at
// distance l = |p - x|, a segment of length r in direction w (angle theta from p - x, phi
// uniform) ends at a vertex whose connection to p has length
//   d(theta) = |x + r w - p| = sqrt(r^2 + l^2 - 2 r l cos theta),  d in [|l - r|, l + r],
// and the time eta (r + d) / c. theta is chosen so that d is uniform on a range [d_a, d_b]
// (the whole range, or the part inside a time window):
//   d dd = r l sin theta dtheta  =>  p(theta) = r l sin theta / ((d_b - d_a) d),
//   p(w) = p(theta) / (2 pi sin theta) = r l / (2 pi (d_b - d_a) d) per steradian.
// Over the whole range d_b - d_a = 2 min(r, l): p(theta) = max(r, l) sin theta / (2 d) and
// p(w) = max(r, l) / (4 pi d); seed 000 eq. 16 has r in place of max(r, l), right only for r >= l.
// Inverse CDF: d = d_a + u (d_b - d_a), then
//   1 - cos theta = (d^2 - (l - r)^2) / (2 r l) = e (e + 2 |l - r|) / (2 r l),  e = d - |l - r|,
// kept in terms of 1 - cos theta so that small angles and tiny r stay accurate. For the whole
// range: 1 - cos theta = 2 u (M - m + m u) / M with m = min(r, l), M = max(r, l).
// r == l: d -> 0 towards the target; p(w) ~ 1 / d is integrable and p(theta) stays finite.
// r -> 0 (or l -> 0): d no longer depends on theta and the directions tend to the uniform
// sphere (p(w) -> 1 / (4 pi)); with r l == 0 exactly that is what is returned, the time range
// then being the single value eta (r + l) / c.
#include <algorithm>
#include <cmath>

#include "core/constants.h"
#include "core/sincos_2pi.h"
#include "core/vec3.h"

namespace femto {

class AngularTimeSampler {
 public:
  /// The sampled range of d as offsets e = d - |l - r| in [e_a, e_b] (whole range: [0, 2 m]).
  struct Window {
    bool valid = false;  ///< false: the time window misses [eta (r + |l - r|), eta (r + l + r)] / c
    double e_a = 0, e_b = 0;
  };

  /// Segment length r >= 0, distance to the target l >= 0, homogeneous index eta.
  AngularTimeSampler(double r, double l, double eta)
      : r_(r), l_(l), eta_(eta), gap_(std::abs(l - r)), full_(2.0 * std::min(r, l)) {}

  bool degenerate() const { return !(r_ * l_ > 0); }  ///< r l == 0: uniform sphere

  /// Connection length d for a given 1 - cos theta (stable near theta = 0).
  double d_of(double one_minus_cos) const {
    return std::sqrt(gap_ * gap_ + 2.0 * r_ * l_ * std::max(0.0, one_minus_cos));
  }
  /// Time eta (r + d) / c of the connection x -> x + r w -> p, ps.
  double time(double one_minus_cos) const {
    return eta_ * (r_ + d_of(one_minus_cos)) / kSpeedOfLight;
  }
  double t_min() const { return eta_ * (r_ + gap_) / kSpeedOfLight; }          ///< theta = 0
  double t_max() const { return eta_ * (r_ + gap_ + full_) / kSpeedOfLight; }  ///< theta = pi

  /// The whole range of d.
  Window full() const { return {true, 0.0, full_}; }

  /// The part of the range whose time lies in (t_a, t_b), ps.
  Window window(double t_a, double t_b) const {
    Window w;
    if (degenerate()) {  // a single time: all directions or none
      const double t = t_min();
      w.valid = t >= t_a && t <= t_b;
      return w;
    }
    const double e_lo = kSpeedOfLight * t_a / eta_ - r_ - gap_;
    const double e_hi = kSpeedOfLight * t_b / eta_ - r_ - gap_;
    w.e_a = std::max(0.0, e_lo);
    w.e_b = std::min(full_, e_hi);
    if (e_lo <= 0) w.e_a = 0.0;  // exact ends when the window covers them
    if (e_hi >= full_) w.e_b = full_;
    w.valid = w.e_b > w.e_a;
    return w;
  }

  /// Inverse CDF: 1 - cos theta for u in [0, 1) (0 = towards the target).
  double sample_one_minus_cos(const Window& w, double u) const {
    if (degenerate()) return 2.0 * u;  // uniform sphere
    const double e = w.e_a + u * (w.e_b - w.e_a);
    return std::clamp(e * (e + 2.0 * gap_) / (2.0 * r_ * l_), 0.0, 2.0);
  }

  /// Unit direction: theta from sample_one_minus_cos(u1) around to_target (unit), phi = 2 pi u2.
  Vec3 sample_direction(const Vec3& to_target, const Window& w, double u1, double u2) const {
    const double omc = sample_one_minus_cos(w, u1);
    const double cos_t = 1.0 - omc, sin_t = std::sqrt(std::max(0.0, omc * (2.0 - omc)));
    const SinCos phi = sincos_2pi(u2);
    const Frame f(to_target);
    return f.to_world({sin_t * phi.cos, sin_t * phi.sin, cos_t});
  }

  /// Density of cos theta (per unit cos theta).
  double pdf_cos(const Window& w, double one_minus_cos) const {
    if (!w.valid) return 0.0;
    if (degenerate()) return 0.5;
    const double d = d_of(one_minus_cos);
    const double e = 2.0 * r_ * l_ * std::max(0.0, one_minus_cos) / (d + gap_);  // d - gap, stable
    if (e < w.e_a || e > w.e_b) return 0.0;
    return r_ * l_ / ((w.e_b - w.e_a) * d);
  }

  /// Density per steradian of the direction.
  double pdf_solid_angle(const Window& w, double one_minus_cos) const {
    return pdf_cos(w, one_minus_cos) / (2.0 * kPi);
  }

  /// Density of theta in [0, pi] (finite also at theta = 0 when r == l).
  double pdf_theta(const Window& w, double theta) const {
    const double half = std::sin(0.5 * theta), omc = 2.0 * half * half;
    if (!degenerate() && d_of(omc) == 0.0) {  // r == l, theta = 0: sin(theta) / d -> 1 / sqrt(r l)
      return w.valid && w.e_a == 0.0 ? std::sqrt(r_ * l_) / (w.e_b - w.e_a) : 0.0;
    }
    return pdf_cos(w, omc) * std::sin(theta);
  }

  /// 1 - cos of the angle between unit vectors a and b, without cancellation at small angles.
  static double one_minus_cos(const Vec3& a, const Vec3& b) { return 0.5 * length_squared(a - b); }

 private:
  double r_, l_, eta_;
  double gap_;   ///< |l - r|, the shortest d
  double full_;  ///< 2 min(r, l), the width of the range of d
};

}  // namespace femto
