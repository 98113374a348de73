#pragma once
// Warps from the unit square to directions and points, each with its pdf.
#include <cmath>

#include "core/constants.h"
#include "core/sincos_2pi.h"
#include "core/vec3.h"

namespace femto {

/// Cosine-weighted direction in the local frame (z up); pdf = cos(theta) / pi per steradian.
inline Vec3 sample_cosine_hemisphere(double u1, double u2) {
  const double r = std::sqrt(u1);
  const SinCos phi = sincos_2pi(u2);
  return {r * phi.cos, r * phi.sin, std::sqrt(1.0 - u1)};  // 1 - u1 >= 0 in floating point too
}
inline double cosine_hemisphere_pdf(double cos_theta) {
  return cos_theta > 0.0 ? cos_theta * kInvPi : 0.0;
}

/// Uniform direction on the unit sphere; pdf = 1 / (4 pi).
inline Vec3 sample_uniform_sphere(double u1, double u2) {
  const double z = 1.0 - 2.0 * u1;
  const double r = 2.0 * std::sqrt(u1 * (1.0 - u1));  // sqrt(1 - z^2), without its cancellation
  const SinCos phi = sincos_2pi(u2);
  return {r * phi.cos, r * phi.sin, z};
}

/// Uniform point on a disc of radius 1; pdf = 1 / pi per unit area.
inline void sample_uniform_disc(double u1, double u2, double& x, double& y) {
  const double r = std::sqrt(u1);
  const SinCos phi = sincos_2pi(u2);
  x = r * phi.cos;
  y = r * phi.sin;
}

/// Barycentrics (b1, b2) of a uniform point on a triangle; pdf = 1 / area.
inline void sample_uniform_triangle(double u1, double u2, double& b1, double& b2) {
  const double su = std::sqrt(u1);
  b1 = 1.0 - su;
  b2 = u2 * su;
}

/// Power heuristic (beta = 2) weight of a strategy with pdf a against one with pdf b.
inline double power_heuristic(double a, double b) {
  const double a2 = a * a, b2 = b * b;
  return a2 + b2 > 0.0 ? a2 / (a2 + b2) : 0.0;
}

}  // namespace femto
