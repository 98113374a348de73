#pragma once
// Pulse spreading at a detector: mean arrival time, rms width and peak time of a TPSF and its
// distance from a Gaussian pulse of the same mean and width, each with a 95% interval from the
// jackknife over the run's batches, and flags where Monte Carlo noise decides the value
// (docs/tissue.md, "Pulse spreading").
#include <vector>

#include "core/time_axis.h"

namespace femto::tissue {

struct PulseStat {
  double value = 0, se = 0, ci_lo = 0, ci_hi = 0;  ///< ps
};

struct PulseStats {
  bool defined = false;  ///< the TPSF has signal in the window
  PulseStat mean, rms, peak;
  /// Total-variation distance (0 to 1, no unit) between the TPSF's gate masses and those of a
  /// Gaussian pulse with its mean and rms width, both normalised over the window: 0 for a
  /// Gaussian pulse; a diffusive TPSF's long tail keeps it well above 0 (value, se and the
  /// interval in the PulseStat's fields, which for it carry no unit).
  PulseStat gaussian_distance;
  /// The distance that Monte Carlo noise alone would give (the expected |noise| summed over the
  /// gates, as femto diffusion's noise floor).
  double gaussian_noise = 0;
  /// The peak gate does not stand out from its larger neighbour by 2 standard errors, or its 95%
  /// interval is wider than +-1 gate: the peak time is decided by noise.
  bool peak_noise_limited = false;
  /// The jackknife error of the mean or the width is more than 10% of the width: too few photons
  /// for the shape.
  bool width_noise_limited = false;
  /// The noise floor is at least half the Gaussian distance: noise, not the pulse, decides it.
  bool gaussian_noise_limited = false;
};

/// `batches` holds B TPSFs of the same detector (each a per-batch estimate, any unit), gate
/// averages over `axis`. Moments use the gate centres with Sheppard's correction for the width
/// (- bin^2 / 12); the peak is a parabola through the largest gate and its neighbours; the
/// Gaussian pulse of the distance has that mean and width and is integrated over the gates.
PulseStats pulse_stats(const TimeAxis& axis, const std::vector<std::vector<double>>& batches);

}  // namespace femto::tissue
