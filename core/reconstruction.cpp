#include "core/reconstruction.h"

#include <algorithm>

namespace femto {

double kth_nearest_distance(const std::vector<double>& sorted_times, double t, int k) {
  const size_t n = sorted_times.size();
  if (n == 0) return -1.0;
  const size_t steps = std::min(n, static_cast<size_t>(std::max(k, 1)));
  // Merge outwards from t's insertion point, taking the nearer neighbour each step.
  size_t hi = static_cast<size_t>(std::lower_bound(sorted_times.begin(), sorted_times.end(), t) -
                                  sorted_times.begin());
  size_t lo = hi;  // candidates: sorted_times[lo - 1] on the left, sorted_times[hi] on the right
  double d = 0.0;
  for (size_t i = 0; i < steps; ++i) {
    const double dl = lo > 0 ? t - sorted_times[lo - 1] : -1.0;
    const double dr = hi < n ? sorted_times[hi] - t : -1.0;
    if (dr < 0.0 || (dl >= 0.0 && dl <= dr)) {
      d = dl;
      --lo;
    } else {
      d = dr;
      ++hi;
    }
  }
  return d;
}

}  // namespace femto
