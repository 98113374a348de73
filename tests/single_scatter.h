#pragma once
// Single scattering along one camera ray: the ray x(s) = (0, 0, s) in a homogeneous medium, lit
// by a point light at (0, h, z0), seen in camera time t(s) = eta (s + r(s)) / c with
// r = sqrt((s - z0)^2 + h^2). Its time-resolved radiance is a 1-D integral over s. Shared by the
// tests and the benchmarks that need an exact time-resolved answer.
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
  double z0 = 0.0;  ///< the light's position along the ray (> 0: ahead of the camera)
  TimeAxis axis;

  double sigma_t() const { return sigma_a + sigma_s; }
  /// First light: the vertex at s = 0.
  double onset_ps() const { return eta * std::sqrt(z0 * z0 + h * h) / kSpeedOfLight; }
  /// Radiance per unit distance contributed by the vertex at s.
  double density(double s) const {
    const double st = sigma_t();
    const double r = std::sqrt((s - z0) * (s - z0) + h * h);
    const double cos_t = -(s - z0) / r;  // light travels (x - L) / r, then -z towards the camera
    return sigma_s * std::exp(-st * s) * hg_eval(cos_t, g) * I * std::exp(-st * r) / (r * r);
  }
  double time_of(double s) const {
    return eta * (s + std::sqrt((s - z0) * (s - z0) + h * h)) / kSpeedOfLight;
  }
  /// Inverse of time_of: s + sqrt((s - z0)^2 + h^2) = tau  <=>
  /// s = (tau^2 - z0^2 - h^2) / (2 (tau - z0)), for tau >= sqrt(z0^2 + h^2) (the onset).
  double s_of_time(double t) const {
    const double tau = std::max(t * kSpeedOfLight / eta, std::sqrt(z0 * z0 + h * h));
    return (tau * tau - z0 * z0 - h * h) / (2.0 * (tau - z0));
  }
  /// Integral of density over [s0, s1] to ~1e-11 relative: pieces of at most 4 mm so the adaptive
  /// rule sees the 1/r^2 peak, each with a tolerance relative to its own size (late bins are
  /// many orders of magnitude dimmer than early ones).
  double integral(double s0, double s1) const {
    if (!(s1 > s0)) return 0.0;
    const int pieces = std::max(1, static_cast<int>(std::ceil((s1 - s0) / 4.0)));
    double sum = 0.0;
    for (int k = 0; k < pieces; ++k) {
      const double a = s0 + (s1 - s0) * k / pieces, b = s0 + (s1 - s0) * (k + 1) / pieces;
      const double scale = (b - a) * std::max({density(a), density(0.5 * (a + b)), density(b)});
      sum += stats::adaptive_simpson([&](double s) { return density(s); }, a, b,
                                     1e-11 * scale + 1e-300);
    }
    return sum;
  }
  /// Exact bin-integrated radiance of bin i.
  double bin(int i) const {
    return integral(s_of_time(axis.bin_start_ps(i)), s_of_time(axis.bin_start_ps(i + 1)));
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
    l.position = {0, h, z0};
    l.intensity = RGB(I);
    d.lights.push_back(l);
    return d;
  }
};

}  // namespace femto::test
