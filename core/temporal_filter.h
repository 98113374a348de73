#pragma once
// Temporal reconstruction: how one time-stamped contribution is spread over the film's time bins.
// The histogram puts it in one bin; the kernel film spreads it with a compact kernel K_T of
// bandwidth T (core/temporal_kernel.h). Either way the deposit is integrated exactly over every
// bin it overlaps, so its energy is kept bin by bin, and a light's Gaussian pulse is integrated
// exactly as well.
#include <algorithm>
#include <cmath>
#include <limits>

#include "core/spectrum.h"
#include "core/temporal_kernel.h"
#include "core/time_axis.h"

namespace femto {

/// Energy of one deposit that fell before, inside and after the window.
struct DepositSplit {
  double before = 0.0;
  double inside = 0.0;
  double after = 0.0;
  int first_bin = 0, last_bin = -1;  ///< the bins written (none when last_bin < first_bin)
};

class TemporalFilter {
 public:
  enum class Kind { Histogram, Kernel };

  TemporalFilter() = default;
  TemporalFilter(const TimeAxis& axis, Kind kind, TemporalKernel kernel = TemporalKernel::Perlin)
      : axis_(axis), kind_(kind), kernel_(kernel) {}

  const TimeAxis& axis() const { return axis_; }
  Kind kind() const { return kind_; }
  TemporalKernel kernel() const { return kernel_; }

  /// Adds `value` arriving at t_ps, smeared by a Gaussian of std sigma_ps (0 = delta), into the
  /// pixel's bin buffer `bins` (bins x 3 doubles). Returns the fractions outside the window.
  /// A kernel filter with bandwidth T > 0 spreads a delta arrival by K_T; a Gaussian arrival gets
  /// the Gaussian whose variance is the pulse's plus the kernel's (exact in energy and variance,
  /// not in shape; the bias still vanishes as T -> 0). T <= 0 deposits like the histogram.
  /// `floor_ps`: the pixel's onset (no light before it); kernel mass that would fall before
  /// min(floor, t) is reflected back above it, which keeps the deposit's energy and removes
  /// the kernel's spill ahead of a causal onset. -inf: none.
  DepositSplit deposit(double t_ps, double sigma_ps, const RGB& value, double* bins,
                       double bandwidth_ps = 0.0,
                       double floor_ps = -std::numeric_limits<double>::infinity()) const {
    if (kind_ == Kind::Kernel && bandwidth_ps > 0.0) {
      if (sigma_ps <= 0.0)
        return deposit_kernel(t_ps, bandwidth_ps, std::fmin(floor_ps, t_ps), value, bins);
      sigma_ps =
          std::sqrt(sigma_ps * sigma_ps + kernel_variance(kernel_) * bandwidth_ps * bandwidth_ps);
    }
    return deposit_histogram(t_ps, sigma_ps, value, bins);
  }

  static double gaussian_cdf(double z) { return 0.5 * std::erfc(-z * 0.70710678118654752440); }

 private:
  DepositSplit deposit_histogram(double t_ps, double sigma_ps, const RGB& value,
                                 double* bins) const {
    DepositSplit split;
    if (sigma_ps <= 0.0) {
      const int i = axis_.bin_of(t_ps);
      if (i >= 0) {
        add(bins, i, value, 1.0);
        split.inside = 1.0;
        split.first_bin = split.last_bin = i;
      } else if (t_ps < axis_.t_start_ps) {
        split.before = 1.0;
      } else {
        split.after = 1.0;
      }
      return split;
    }
    // Exact integral of the Gaussian over each overlapped bin (CDF differences), +-8 sigma.
    const double t0 = axis_.t_start_ps, w = axis_.bin_width_ps, t_end = axis_.t_end_ps();
    split.before = gaussian_cdf((t0 - t_ps) / sigma_ps);
    split.after = 1.0 - gaussian_cdf((t_end - t_ps) / sigma_ps);
    const double lo = std::fmax(t0, t_ps - 8.0 * sigma_ps);
    const double hi = std::fmin(t_end, t_ps + 8.0 * sigma_ps);
    if (lo >= hi) return split;
    int i = static_cast<int>((lo - t0) / w);
    const int i_end = std::min(axis_.bins - 1, static_cast<int>((hi - t0) / w));
    split.first_bin = i, split.last_bin = i_end;
    double cdf_prev = gaussian_cdf((t0 + i * w - t_ps) / sigma_ps);
    for (; i <= i_end; ++i) {
      const double cdf_next = gaussian_cdf((t0 + (i + 1) * w - t_ps) / sigma_ps);
      const double f = cdf_next - cdf_prev;
      cdf_prev = cdf_next;
      if (f > 0.0) add(bins, i, value, f);
      split.inside += f;
    }
    return split;
  }

  /// K_T(. - t) integrated over each bin of [t - T, t + T] by kernel CDF differences; with a
  /// floor tf <= t inside the support, the reflected kernel K_T(. - t) + K_T(2 tf - . - t) on
  /// [tf, inf), whose CDF is F((x - t) / T) - F((2 tf - x - t) / T).
  DepositSplit deposit_kernel(double t_ps, double T, double tf, const RGB& value,
                              double* bins) const {
    const double t0 = axis_.t_start_ps, w = axis_.bin_width_ps, t_end = axis_.t_end_ps();
    const bool reflect = t_ps - T < tf;
    auto G = [&](double x) {
      if (!reflect) return kernel_cdf(kernel_, (x - t_ps) / T);
      return x <= tf ? 0.0
                     : kernel_cdf(kernel_, (x - t_ps) / T) -
                           kernel_cdf(kernel_, (2.0 * tf - x - t_ps) / T);
    };
    DepositSplit split;
    split.before = G(t0);
    split.after = 1.0 - G(t_end);
    const double lo = std::fmax(t0, reflect ? tf : t_ps - T), hi = std::fmin(t_end, t_ps + T);
    if (lo >= hi) return split;
    int i = static_cast<int>((lo - t0) / w);
    const int i_end = std::min(axis_.bins - 1, static_cast<int>((hi - t0) / w));
    split.first_bin = i, split.last_bin = i_end;
    double cdf_prev = G(t0 + i * w);
    for (; i <= i_end; ++i) {
      const double cdf_next = G(t0 + (i + 1) * w);
      const double f = cdf_next - cdf_prev;
      cdf_prev = cdf_next;
      if (f > 0.0) add(bins, i, value, f);
      split.inside += f;
    }
    return split;
  }

  static void add(double* bins, int i, const RGB& v, double f) {
    double* b = bins + 3 * i;
    b[0] += v.r * f;
    b[1] += v.g * f;
    b[2] += v.b * f;
  }

  TimeAxis axis_;
  Kind kind_ = Kind::Histogram;
  TemporalKernel kernel_ = TemporalKernel::Perlin;
};

}  // namespace femto
