#include "core/reconstruction.h"

#include <algorithm>

namespace femto {

double kth_nearest_distance(const std::vector<double>& sorted_times, double t, int k) {
  const size_t n = sorted_times.size();
  if (n == 0) return -1.0;
  const size_t m = std::min(n, static_cast<size_t>(std::max(k, 1)));
  // The m nearest arrivals are a run [l, l + m) of the sorted times around t's insertion point
  // i (l <= i <= l + m); its reach is max(t - x_l, x_{l+m-1} - t): the left part falls and the
  // right part grows with l, so the best run sits where they cross (binary search, O(log m)).
  const size_t i = static_cast<size_t>(std::lower_bound(sorted_times.begin(), sorted_times.end(), t) -
                                       sorted_times.begin());
  size_t lo = i >= m ? i - m : 0, hi = std::min(i, n - m);
  auto reach = [&](size_t l) { return std::max(t - sorted_times[l], sorted_times[l + m - 1] - t); };
  while (lo < hi) {  // first l whose right part reaches at least its left part
    const size_t mid = lo + (hi - lo) / 2;
    if (sorted_times[mid + m - 1] - t >= t - sorted_times[mid])
      hi = mid;
    else
      lo = mid + 1;
  }
  double d = reach(lo);
  if (lo > 0 && lo - 1 + m <= n && lo - 1 >= (i >= m ? i - m : 0)) d = std::min(d, reach(lo - 1));
  return std::max(d, 0.0);
}

}  // namespace femto
