#pragma once
// Line-to-point time sampling (seed 000 Sec. 5.2, Supp. D.2): a vertex y = x + s w on a ray is
// connected to a target p, and s is chosen so that the time of the two-segment connection
//   T(s) = eta (s + |x + s w - p|) / c
// is uniform over a window. With l = p - x, Delta = l.w, the optical length of the connection is
//   L(s) = s + sqrt(s^2 - 2 s Delta + |l|^2) = s + sqrt((s - Delta)^2 + h^2),
// h^2 = |l|^2 - Delta^2 (h: distance of p from the line), L increasing in s
// (dL/ds = 1 + (s - Delta) / |y - p| >= 0), with inverse (square L - s and solve for s)
//   s(L) = (L^2 - |l|^2) / (2 (L - Delta)),  L >= |l|.
// L uniform on [L_a, L_b] gives pdf(s) = (dL/ds) / (L_b - L_a) per unit distance (eta / c cancels
// between dT/ds and the time window). h -> 0 with the target ahead (Delta > 0): every
// s in [0, Delta] has L = |l| (the vertex lies between x and p), so dL/ds = 0 there and the
// sampler never returns such s; beyond Delta, L = 2 s - Delta.
#include <algorithm>
#include <cmath>
#include <limits>

#include "core/constants.h"
#include "core/vec3.h"

namespace femto {

class LineToPointSampler {
 public:
  /// The connection window in optical length (L = c T / eta) and the matching distances.
  struct Window {
    bool valid = false;       ///< false: no s in [s_min, s_max] reaches a time inside (t_a, t_b)
    double L_a = 0, L_b = 0;  ///< mm
    double s_a = 0, s_b = 0;  ///< mm along the ray
  };

  /// Ray x + s w (w unit length) and target p, homogeneous index eta along the connection.
  LineToPointSampler(const Vec3& x, const Vec3& w, const Vec3& p, double eta) : eta_(eta) {
    const Vec3 l = p - x;
    delta_ = dot(l, w);
    l_len_ = length(l);
    h_ = length(cross(l, w));
    // |l| - Delta without cancellation when p lies close to the ray ahead of x.
    l_minus_delta_ = delta_ > 0 ? h_ * h_ / (l_len_ + delta_) : l_len_ - delta_;
  }

  double eta() const { return eta_; }

  /// Optical length s + |x + s w - p| of the connection through the vertex at s, mm.
  double opl(double s) const {
    if (!std::isfinite(s)) return std::numeric_limits<double>::infinity();
    const double e = s - delta_;
    return s + std::sqrt(e * e + h_ * h_);
  }

  /// Connection time of the vertex at s, ps.
  double time(double s) const { return eta_ * opl(s) / kSpeedOfLight; }

  /// dL/ds = 1 + (s - Delta) / |y - p|, written without cancellation for s < Delta.
  double dopl_ds(double s) const {
    const double e = s - delta_, d = std::sqrt(e * e + h_ * h_);
    if (!(d > 0)) return 1.0;  // the kink at y = p (h = 0): a single point
    return e >= 0 ? 1.0 + e / d : h_ * h_ / (d * (d - e));
  }

  /// Distance whose connection has optical length L >= |l| (the inverse of opl).
  double s_of_opl(double L) const {
    const double above = L - l_len_;  // >= 0 for reachable L
    const double den = 2.0 * (above + l_minus_delta_);
    if (!(den > 0)) return std::max(0.0, delta_);  // L == |l| on the ray: s = Delta
    return above * (L + l_len_) / den;
  }

  /// Window of connection times (t_a, t_b) in ps, intersected with what s in [s_min, s_max]
  /// reaches; s_max may be +inf.
  Window window(double t_a, double t_b, double s_min, double s_max) const {
    Window win;
    const double L_lo = opl(s_min), L_hi = opl(s_max);
    win.L_a = std::max(kSpeedOfLight * t_a / eta_, L_lo);
    win.L_b = std::min(kSpeedOfLight * t_b / eta_, L_hi);
    if (!(win.L_b > win.L_a) || !std::isfinite(win.L_b)) return win;
    win.s_a = win.L_a == L_lo ? s_min : std::clamp(s_of_opl(win.L_a), s_min, s_max);
    win.s_b = win.L_b == L_hi ? s_max : std::clamp(s_of_opl(win.L_b), s_min, s_max);
    win.valid = true;
    return win;
  }

  /// Inverse CDF: L uniform on [L_a, L_b], mapped back to s; u in [0, 1).
  double sample(const Window& win, double u) const {
    const double L = win.L_a + u * (win.L_b - win.L_a);
    return std::clamp(s_of_opl(L), win.s_a, win.s_b);
  }

  /// Density per unit distance: (dL/ds) / (L_b - L_a) on [s_a, s_b].
  double pdf(const Window& win, double s) const {
    if (!win.valid || s < win.s_a || s > win.s_b) return 0.0;
    return dopl_ds(s) / (win.L_b - win.L_a);
  }

  /// P(sample <= s) = (L(s) - L_a) / (L_b - L_a).
  double cdf(const Window& win, double s) const {
    if (s <= win.s_a) return 0.0;
    if (s >= win.s_b) return 1.0;
    return std::clamp((opl(s) - win.L_a) / (win.L_b - win.L_a), 0.0, 1.0);
  }

 private:
  double eta_;
  double delta_ = 0, l_len_ = 0, h_ = 0, l_minus_delta_ = 0;
};

}  // namespace femto
