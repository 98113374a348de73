#pragma once
// How the film turns time-stamped path contributions into time bins: the histogram, or the
// progressive kernel density estimate of seed 000 Sec. 4 / Supp. B. Sample j of a pixel
// (j = 1, 2, ...) deposits with a bandwidth proportional to r_j, r_{j+1} = r_j (j + alpha) / (j +
// 1); the pixel value is the plain average over its samples, consistent because r_j -> 0. The
// bandwidth of an arrival at time t is either fixed (T_1 r_j) or adaptive: the distance from t
// to the k-th nearest arrival of the pixel's first pass, times r_j / r_P (P = first-pass size), so
// a sharp peak keeps a narrow kernel while a diffuse tail gets a wide one.
#include <cstddef>
#include <vector>

#include "core/temporal_filter.h"
#include "core/temporal_kernel.h"

namespace femto {

struct ReconstructionDesc {
  TemporalFilter::Kind type = TemporalFilter::Kind::Histogram;
  TemporalKernel kernel = TemporalKernel::Perlin;
  double alpha = 0.8;  ///< bandwidth shrinking exponent in (0, 1]; 1 keeps T fixed (biased)
  int knn = 40;        ///< k of the k-nearest-arrival bandwidth
  /// Samples per pixel whose arrival times set the bandwidth (several k).
  int first_pass_spp = 160;
  /// User-given T_1 > 0 for every arrival; 0 = k-nearest-arrival bandwidth.
  double bandwidth_ps = 0.0;
  /// Reflect kernel mass that would precede the pixel's earliest first-pass arrival (its onset).
  bool onset_reflection = true;
};

/// Ratio T_j / T_1 = prod_{i=1}^{j-1} (i + alpha) / (i + 1), updated one sample at a time.
class BandwidthSchedule {
 public:
  explicit BandwidthSchedule(double alpha) : alpha_(alpha) {}
  int j() const { return j_; }
  double ratio() const { return ratio_; }
  /// Moves from sample j to sample j + 1.
  void advance() {
    ratio_ *= (j_ + alpha_) / (j_ + 1.0);
    ++j_;
  }
  /// T_j / T_1 for a given j (loops j - 1 times).
  static double ratio_at(double alpha, int j) {
    BandwidthSchedule s(alpha);
    while (s.j() < j) s.advance();
    return s.ratio();
  }

 private:
  double alpha_;
  int j_ = 1;
  double ratio_ = 1.0;
};

/// Distance (ps) from t to the k-th nearest of the sorted arrival times (to the farthest when
/// there are fewer than k); -1 when there are none.
double kth_nearest_distance(const std::vector<double>& sorted_times, double t, int k);

}  // namespace femto
