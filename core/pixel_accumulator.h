#pragma once
// One pixel's running sums over its samples, and the per-sample state of the kernel film.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <vector>

#include "core/reconstruction.h"
#include "core/spectrum.h"
#include "core/temporal_filter.h"

namespace femto {

struct PixelAccumulator {
  std::vector<double> bins;  ///< T x 3
  RGB before, after;         ///< energy that arrived before / after the window

  // Kernel film (core/reconstruction.h): bandwidth of an arrival at t = scale * base(t), base =
  // `fixed_ps` when > 0, else the distance to the k-th nearest first-pass arrival (at most cap).
  bool kernel = false;
  double scale = 1.0;  ///< r_j / r_P (adaptive) or r_j (fixed) for the current sample
  double fixed_ps = 0.0;
  int knn = 40;
  double cap_ps = 0.0;       ///< widest useful kernel (the window length)
  double fallback_ps = 0.0;  ///< base when the first pass had no arrival
  double floor_ps =
      -std::numeric_limits<double>::infinity();  ///< onset: earliest first-pass arrival
  /// First pass of a k-NN kernel film: deposits wait here until the bandwidth is known.
  struct Held {
    double t_ps, sigma_ps;
    RGB value;
    int sample;
  };
  bool hold = false;
  int sample = 0;             ///< index of the sample being traced (recorded in Held)
  std::vector<Held> held;     ///< capacity kept between pixels: no allocation once warm
  std::vector<double> times;  ///< first-pass arrival times, sorted

  /// The bins add_now has written since the last reset (none when touched_last < touched_first).
  int touched_first = std::numeric_limits<int>::max(), touched_last = -1;

  void reset(int n_bins) {
    bins.assign(static_cast<size_t>(n_bins) * 3, 0.0);
    reset_state();
  }
  /// As reset, but zeroes only the bins written since the last reset: for one sample's
  /// accumulator whose bins are written by add and add_now only.
  void reset_touched(int n_bins) {
    if (bins.size() != static_cast<size_t>(n_bins) * 3) {
      reset(n_bins);
      return;
    }
    if (touched_last >= touched_first)
      std::fill(bins.begin() + 3 * touched_first, bins.begin() + 3 * (touched_last + 1), 0.0);
    reset_state();
  }
  void reset_state() {
    touched_first = std::numeric_limits<int>::max(), touched_last = -1;
    before = after = RGB(0.0);
    kernel = hold = false;
    scale = 1.0;
    floor_ps = -std::numeric_limits<double>::infinity();
    held.clear();
    times.clear();
  }

  double bandwidth_at(double t_ps) const {
    if (!kernel) return 0.0;
    if (fixed_ps > 0.0) return scale * fixed_ps;
    const double d = kth_nearest_distance(times, t_ps, knn);
    return scale * (d < 0.0 ? fallback_ps : std::fmin(d, cap_ps));
  }

  /// Deposits through `filter` with the current bandwidth, or holds the deposit.
  void add(const TemporalFilter& filter, double t_ps, double sigma_ps, const RGB& value) {
    if (hold) {
      held.push_back({t_ps, sigma_ps, value, sample});
      return;
    }
    add_now(filter, t_ps, sigma_ps, value, bandwidth_at(t_ps));
  }
  void add_now(const TemporalFilter& filter, double t_ps, double sigma_ps, const RGB& value,
               double T) {
    const DepositSplit split = filter.deposit(t_ps, sigma_ps, value, bins.data(), T, floor_ps);
    if (split.last_bin >= split.first_bin) {
      touched_first = std::min(touched_first, split.first_bin);
      touched_last = std::max(touched_last, split.last_bin);
    }
    if (split.before > 0) before += value * split.before;
    if (split.after > 0) after += value * split.after;
  }
};

}  // namespace femto
