#pragma once
// Lambertian reflection, two-sided: f = albedo / pi on wo's side of the surface.
#include <cmath>

#include "core/bsdf/bsdf_sample.h"
#include "core/constants.h"
#include "core/sampling.h"

namespace femto {

struct Diffuse {
  RGB albedo{0.5};

  RGB f(const Vec3& wo, const Vec3& wi) const {
    return same_side(wo, wi) ? albedo * kInvPi : RGB();
  }

  /// Cosine-weighted hemisphere on wo's side.
  double pdf(const Vec3& wo, const Vec3& wi) const {
    return same_side(wo, wi) ? std::abs(wi.z) * kInvPi : 0.0;
  }

  bool sample(const Vec3& wo, double u1, double u2, BsdfSample& s) const {
    if (wo.z == 0.0 || !std::isfinite(wo.z)) return false;  // no side to reflect into
    Vec3 wi = sample_cosine_hemisphere(u1, u2);
    if (!(wi.z > 0.0)) return false;  // u1 = 1 lands on the horizon
    if (wo.z < 0.0) wi = mirror_z(wi);
    s.wi = wi;
    s.pdf = std::abs(wi.z) * kInvPi;
    s.weight = albedo;  // (albedo / pi) |cos| / (|cos| / pi)
    s.delta = false;
    s.transmitted = false;
    return true;
  }
};

}  // namespace femto
