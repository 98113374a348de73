#pragma once
// Compact temporal smoothing kernels for density estimation in time (seed 000 Sec. 4):
// K_T(t) = k(|t| / T) / T on [-T, T], normalised to integrate to one, with closed-form CDFs so a
// deposit can be integrated exactly over every film bin it overlaps (energy kept bin by bin).
#include <algorithm>
#include <cmath>

namespace femto {

enum class TemporalKernel {
  Perlin,        ///< 1 - (6u^5 - 15u^4 + 10u^3): Perlin's smootherstep turned into a bump (C2 at |u| = 1)
  Epanechnikov,  ///< 3/4 (1 - u^2)
};

/// k(u) for u in [-1, 1] (0 outside); integrates to one over [-1, 1].
inline double kernel_value(TemporalKernel k, double u) {
  const double a = std::abs(u);
  if (a >= 1.0) return 0.0;
  if (k == TemporalKernel::Epanechnikov) return 0.75 * (1.0 - a * a);
  return 1.0 - a * a * a * (10.0 + a * (-15.0 + 6.0 * a));
}

/// Integral of k from -1 to u.
inline double kernel_cdf(TemporalKernel k, double u) {
  if (u <= -1.0) return 0.0;
  if (u >= 1.0) return 1.0;
  const double a = std::abs(u);
  // Integral of k over [0, a]; the kernel is even, so F(u) = 1/2 + sign(u) G(|u|).
  const double G = k == TemporalKernel::Epanechnikov
                       ? 0.75 * (a - a * a * a / 3.0)
                       : a - a * a * a * a * (2.5 + a * (-3.0 + a));
  return u >= 0 ? 0.5 + G : 0.5 - G;
}

/// Weight of bin [b0, b1) for a deposit at time t with bandwidth T: the integral of K_T(. - t).
inline double kernel_bin_weight(TemporalKernel k, double t, double T, double b0, double b1) {
  return kernel_cdf(k, (b1 - t) / T) - kernel_cdf(k, (b0 - t) / T);
}

/// Variance of k on [-1, 1]: the kernel K_T has variance kernel_variance(k) * T^2.
inline double kernel_variance(TemporalKernel k) {
  return k == TemporalKernel::Epanechnikov ? 1.0 / 5.0 : 5.0 / 42.0;
}

/// Progressive bandwidth schedule of seed 000 Sec. 4 / Supp. B: T_{j+1} = T_j (j + alpha) / (j + 1)
/// after pass j (j = 1, 2, ...), alpha in (0, 1); alpha = 4/5 gives AMSE O(n^-4/5).
inline double next_bandwidth(double T_j, int j, double alpha) {
  return T_j * (static_cast<double>(j) + alpha) / (static_cast<double>(j) + 1.0);
}

}  // namespace femto
