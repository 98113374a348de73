#pragma once
// Exact track-length tallies over radial shells and time bins: every straight segment of a
// photon's path adds, to each (shell, bin) cell, the time it spends there weighted by its
// energy, and per bin the time integrals of energy, r^2 and r^4. Nothing is sampled: the
// estimators are unbiased and their only noise is that of the paths themselves.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

#include "core/diffusion/transport.h"
#include "core/time_axis.h"

namespace femto::diffusion {

/// Radial shells [i dr, (i + 1) dr), i < shells, around the source at the origin, and a time axis.
struct Grid {
  TimeAxis time;
  int shells = 1;
  double dr = 1;  ///< mm

  double r_max() const { return shells * dr; }
  double shell_volume(int i) const;  ///< mm^3
  double shell_center(int i) const { return (i + 0.5) * dr; }
};

/// Per-bin quantities tallied next to the (shell, bin) cells.
enum class Quantity { Energy, R2, R4, Unscattered, Single };
constexpr int kQuantities = 5;

/// Where each per-photon integral lives in a tally vector: one block per bin, first the per-bin
/// quantities (integral over the bin of w, w r^2, w r^4: ps, mm^2 ps, mm^4 ps, and of w
/// restricted to unscattered and to singly scattered light), then the bin's cells (time
/// integral of the weight in each shell, ps). A photon leaving a bin updates one block.
struct TallyLayout {
  int shells = 1, bins = 1;
  size_t stride() const { return static_cast<size_t>(shells) + kQuantities; }
  size_t slot(Quantity q, int bin) const {
    return static_cast<size_t>(bin) * stride() + static_cast<size_t>(q);
  }
  size_t cell(int shell, int bin) const {
    return static_cast<size_t>(bin) * stride() + kQuantities + static_cast<size_t>(shell);
  }
  size_t size() const { return stride() * static_cast<size_t>(bins); }
};

/// Sums over photons of the per-photon integrals and of their squares (for per-photon variance).
/// Entry i's sum and sum of squares sit side by side (at 2i and 2i + 1): adding a photon's value
/// and its square is one 16-byte update.
struct TallySums {
  std::vector<double> sums;
  uint64_t photons = 0, segments = 0;
  void reset(size_t n);  ///< n entries, all zero
  size_t size() const { return sums.size() / 2; }
  double& sum(size_t i) { return sums[2 * i]; }
  double sum(size_t i) const { return sums[2 * i]; }
  double sum2(size_t i) const { return sums[2 * i + 1]; }
  /// Elementwise sum; calling it in a fixed order makes the rounding independent of threads.
  void add(const TallySums& other);
};

/// Accumulates one photon at a time. A photon's segments must come in time order (as a walk
/// makes them): each bin is then visited in one stretch, and its entries are final (added to
/// the sums with their squares) when the photon moves on to the next bin.
class PhotonTally {
 public:
  explicit PhotonTally(const Grid& grid);
  const TallyLayout& layout() const { return layout_; }
  /// Adds the part of the segment inside the time window; bins the photon has left go to `into`
  /// (the same for all of a photon's segments and its end_photon).
  void add(const Segment& s, TallySums& into);
  /// Adds the rest of this photon's integrals and their squares to `into`; the next photon starts.
  void end_photon(TallySums& into);

 private:
  template <bool kWeighted>
  void sweep(const Segment& s, double tau_lo, double tau_hi, int j, TallySums& into);
  void finish_bin(TallySums& into);

  Grid grid_;
  TallyLayout layout_;
  // The current bin, while the photon may still add to it: its per-bin integrals and its shells
  // (the radius is continuous, so the shells touched in one bin are the range [i_lo_, i_hi_]).
  // shell_[shells] collects the time spent beyond the last shell, so that pieces need no test;
  // it is never added to the sums.
  int bin_ = -1;
  double q_[kQuantities] = {0, 0, 0, 0, 0};
  bool low_order_ = false;  ///< q_ of unscattered or singly scattered light may be non-zero
  std::vector<double> shell_;
  int i_lo_ = std::numeric_limits<int>::max(), i_hi_ = -1;
  uint64_t segments_ = 0;
};

/// J[n] = integral over s in [0, h] of exp(-k s) s^n, n = 0..4, for k >= 0 and h >= 0: a power
/// series when k h < 2, the closed-form recurrence otherwise (relative error ~1e-15).
void exp_moments(double k, double h, double J[5]);

}  // namespace femto::diffusion
