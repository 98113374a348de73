#pragma once
// Single scattering along one camera ray: the ray x(s) = (0, 0, s) in a homogeneous medium, lit
// by a point light at (0, h, 0), seen in camera time t(s) = eta (s + r(s)) / c with
// r = sqrt(s^2 + h^2). Its time-resolved radiance is a 1-D integral over s.
#include <algorithm>
#include <cmath>

#include "core/constants.h"
#include "core/time_axis.h"
#include "media/phase_hg.h"
#include "samplers/stats.h"
#include "scene_builders.h"

namespace femto::test {

struct SingleScatterSetup {
  double sigma_a = 0.01, sigma_s = 0.05, g = 0.4, eta = 1.2, h = 30.0, I = 1000.0;
  TimeAxis axis;

  /// Radiance per unit distance contributed by the vertex at s.
  double density(double s) const {
    const double st = sigma_a + sigma_s;
    const double r = std::sqrt(s * s + h * h);
    const double cos_t = -s / r;  // light travels (x - L) / r, then -z towards the camera
    return sigma_s * std::exp(-st * s) * hg_eval(cos_t, g) * I * std::exp(-st * r) / (r * r);
  }
  double time_of(double s) const { return eta * (s + std::sqrt(s * s + h * h)) / kSpeedOfLight; }
  /// Inverse of time_of: s + sqrt(s^2 + h^2) = tau  <=>  s = (tau^2 - h^2) / (2 tau).
  double s_of_time(double t) const {
    const double tau = std::max(t * kSpeedOfLight / eta, h);
    return (tau * tau - h * h) / (2.0 * tau);
  }
  /// Exact bin-integrated radiance of bin i.
  double bin(int i) const {
    const double s0 = s_of_time(axis.bin_start_ps(i)), s1 = s_of_time(axis.bin_start_ps(i + 1));
    if (s1 <= s0) return 0.0;
    return stats::adaptive_simpson([&](double s) { return density(s); }, s0, s1, 1e-12);
  }
  /// The scene: a 1 x 1 orthographic pixel looking down +z (render with max_depth 1).
  SceneDesc scene() const {
    SceneDesc d;
    d.source = "single scattering";
    d.camera = ortho_camera({0, 0, 0}, {0, 0, 1}, 1e-4, 1, 1);
    d.time = axis;
    d.media.push_back(medium("m", sigma_a, sigma_s, g, eta));
    d.global_medium = 0;
    LightDesc l;
    l.position = {0, h, 0};
    l.intensity = RGB(I);
    d.lights.push_back(l);
    return d;
  }
};

}  // namespace femto::test
