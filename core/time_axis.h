#pragma once
// The sensor's time axis: `bins` bins of width `bin_width_ps` starting at `t_start_ps`.
#include <cmath>
#include <cstdint>

#include "core/constants.h"

namespace femto {

struct TimeAxis {
  double t_start_ps = 0.0;
  double bin_width_ps = 1.0;
  int bins = 1;

  double t_end_ps() const { return t_start_ps + bin_width_ps * bins; }
  /// Vacuum optical path length (mm) equivalent of a time (ps): OPL = c t.
  static double opl_of_time(double t_ps) { return t_ps * kSpeedOfLight; }
  static double time_of_opl(double opl_mm) { return opl_mm / kSpeedOfLight; }
  double bin_center_ps(int i) const { return t_start_ps + (i + 0.5) * bin_width_ps; }
  double bin_start_ps(int i) const { return t_start_ps + i * bin_width_ps; }
  /// Bin index of time t, or -1 when t lies outside [t_start, t_end).
  int bin_of(double t_ps) const {
    const double u = (t_ps - t_start_ps) / bin_width_ps;
    if (!(u >= 0.0) || u >= bins) return -1;
    const int i = static_cast<int>(u);
    return i < bins ? i : bins - 1;
  }
};

/// Whether the time of the last segment (scene to sensor) is part of the recorded time.
enum class TimeMode { Camera, Unwarp };

}  // namespace femto
