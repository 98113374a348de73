#pragma once
// Narrowing a ray's [lo, hi] to a computed stretch [s0, s1] (a spot's cone, a laser's beam),
// widened against rounding: a wider range only costs samples, a narrower one would lose light.
#include <algorithm>
#include <cmath>

namespace femto {

/// Sets [lo, hi] to [s0, s1] widened by 1e-9 (|s0| + |s1| + scale) and clipped to [lo, hi];
/// false (and [lo, hi] unchanged) when nothing is left.
inline bool narrow_interval(double s0, double s1, double scale, double& lo, double& hi) {
  const double pad = 1e-9 * (std::abs(s0) + std::abs(s1) + scale);
  const double n0 = std::max(lo, s0 - pad), n1 = std::min(hi, s1 + pad);
  if (!(n1 > n0)) return false;
  lo = n0;
  hi = n1;
  return true;
}

}  // namespace femto
