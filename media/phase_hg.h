#pragma once
// Henyey–Greenstein phase function over the angle between propagation directions.
#include <cmath>

#include "core/constants.h"
#include "core/sincos_2pi.h"
#include "core/vec3.h"

namespace femto {

/// p(cos_theta) for HG with asymmetry g; cos_theta is the cosine between the incident propagation
/// direction and the scattered propagation direction. Integrates to 1 over the sphere.
/// Valid for |g| < 1; |g| < 1e-3 is treated as isotropic, exactly as hg_sample_cos samples it.
inline double hg_eval(double cos_theta, double g) {
  if (std::abs(g) < 1e-3) return kInv4Pi;
  const double denom = 1.0 + g * g - 2.0 * g * cos_theta;
  return kInv4Pi * (1.0 - g * g) / (denom * std::sqrt(denom));
}

/// Inverse-CDF sample of cos_theta for HG from u in [0,1).
inline double hg_sample_cos(double u, double g) {
  if (std::abs(g) < 1e-3) return 1.0 - 2.0 * u;
  const double sq = (1.0 - g * g) / (1.0 - g + 2.0 * g * u);
  const double c = (1.0 + g * g - sq * sq) / (2.0 * g);
  return c < -1.0 ? -1.0 : (c > 1.0 ? 1.0 : c);  // comparisons inline; std::fmin/fmax are calls
}

/// hg_sample_cos with the constants of one g worked out once (random walks draw millions of
/// cosines per medium): one division per draw instead of two, off the walk's critical path.
struct HgCosSampler {
  double one_minus_g2 = 1, one_minus_g = 1, two_g = 0, one_plus_g2 = 1, inv_two_g = 0;
  bool isotropic = true;
  static HgCosSampler of(double g) {
    HgCosSampler h;
    h.isotropic = std::abs(g) < 1e-3;  // as hg_sample_cos
    h.one_minus_g2 = 1.0 - g * g, h.one_minus_g = 1.0 - g, h.two_g = 2.0 * g;
    h.one_plus_g2 = 1.0 + g * g, h.inv_two_g = h.isotropic ? 0.0 : 1.0 / (2.0 * g);
    return h;
  }
  double operator()(double u) const {
    if (isotropic) return 1.0 - 2.0 * u;
    const double sq = one_minus_g2 / (one_minus_g + two_g * u);
    const double c = (one_plus_g2 - sq * sq) * inv_two_g;
    return c < -1.0 ? -1.0 : (c > 1.0 ? 1.0 : c);
  }
};

struct PhaseSample {
  Vec3 dir;      ///< new propagation direction
  double value;  ///< phase function value (= pdf for HG)
};

/// The direction at polar cosine cos_t and azimuth 2 pi u2 around the propagation direction `d`.
inline Vec3 direction_around(const Vec3& d, double cos_t, double u2) {
  const double sin2_t = 1.0 - cos_t * cos_t;
  const double sin_t = std::sqrt(sin2_t > 0.0 ? sin2_t : 0.0);
  const SinCos phi = sincos_2pi(u2);
  const Frame f(d);
  const Vec3 dir = f.to_world({sin_t * phi.cos, sin_t * phi.sin, cos_t});
  // |dir| is 1 to a few ulp (an orthonormal frame of a unit d): one Newton step of 1/sqrt at 1
  // makes it 1 to rounding without a square root or a division, and keeps d from drifting.
  return dir * (1.5 - 0.5 * dot(dir, dir));
}

/// Samples a new propagation direction around the current propagation direction `d` (photon
/// walks: no phase value needed). Not renormalised: the frame passes d's length error on scaled
/// by a factor of mean at most 1, so chained walks stay within tens of ulp of unit length
/// (tests/test_samplers.cpp), and the Newton step would sit on the walk's critical path.
inline Vec3 hg_sample_direction(const Vec3& d, const HgCosSampler& hg, double u1, double u2) {
  const double cos_t = hg(u1);
  const double sin2_t = 1.0 - cos_t * cos_t;
  const double sin_t = std::sqrt(sin2_t > 0.0 ? sin2_t : 0.0);
  const SinCos phi = sincos_2pi(u2);
  const Frame f(d);
  return f.to_world({sin_t * phi.cos, sin_t * phi.sin, cos_t});
}

/// Samples a new propagation direction around `d`, with the phase function's value there.
inline PhaseSample hg_sample(const Vec3& d, double g, double u1, double u2) {
  const double cos_t = hg_sample_cos(u1, g);
  return {direction_around(d, cos_t, u2), hg_eval(cos_t, g)};
}

}  // namespace femto
