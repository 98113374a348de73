#pragma once
// Pulse spreading at a detector: mean arrival time, rms width and peak time of a TPSF, each with
// a 95% interval from the jackknife over the run's batches, and flags where Monte Carlo noise
// decides the value (docs/tissue.md, "Pulse spreading").
#include <vector>

#include "core/time_axis.h"

namespace femto::tissue {

struct PulseStat {
  double value = 0, se = 0, ci_lo = 0, ci_hi = 0;  ///< ps
};

struct PulseStats {
  bool defined = false;  ///< the TPSF has signal in the window
  PulseStat mean, rms, peak;
  /// The peak gate does not stand out from its larger neighbour by 2 standard errors, or its 95%
  /// interval is wider than +-1 gate: the peak time is decided by noise.
  bool peak_noise_limited = false;
  /// The jackknife error of the mean or the width is more than 10% of the width: too few photons
  /// for the shape.
  bool width_noise_limited = false;
};

/// `batches` holds B TPSFs of the same detector (each a per-batch estimate, any unit), gate
/// averages over `axis`. Moments use the gate centres with Sheppard's correction for the width
/// (- bin^2 / 12); the peak is a parabola through the largest gate and its neighbours.
PulseStats pulse_stats(const TimeAxis& axis, const std::vector<std::vector<double>>& batches);

}  // namespace femto::tissue
