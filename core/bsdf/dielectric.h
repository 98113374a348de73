#pragma once
// Smooth dielectric interface: Fresnel-weighted choice of specular reflection or refraction
// (both Dirac deltas). z > 0 is outside (relative index 1), z < 0 inside (index eta).
#include <cmath>

#include "core/bsdf/bsdf_sample.h"
#include "core/bsdf/fresnel.h"

namespace femto {

struct SmoothDielectric {
  double eta = 1.5;  ///< index inside / index outside

  /// Reflection with probability F, else refraction. Throughput / pick probability is 1 for
  /// reflection; for refraction 1 in Importance mode and (eta_wo / eta_wi)^2 in Radiance mode,
  /// since radiance / eta^2 is what is conserved across the interface.
  bool sample(const Vec3& wo, double u_lobe, TransportMode mode, BsdfSample& s) const {
    const double cos_o = wo.z;
    if (cos_o == 0.0 || !std::isfinite(cos_o)) return false;
    const double sign = cos_o > 0.0 ? 1.0 : -1.0;
    const double eta_t = cos_o > 0.0 ? eta : 1.0 / eta;  // index of wi's side / index of wo's side
    const Fresnel fr = fresnel_dielectric(std::abs(cos_o), eta_t);
    s.delta = true;
    if (u_lobe < fr.R) {
      s.wi = Vec3(-wo.x, -wo.y, wo.z);
      s.pdf = fr.R;
      s.weight = RGB(1.0);
      s.transmitted = false;
    } else {
      s.wi = refract(wo, Vec3(0.0, 0.0, sign), std::abs(cos_o), fr.cos_t, eta_t);
      s.pdf = fr.T;
      s.weight = RGB(mode == TransportMode::Radiance ? 1.0 / (eta_t * eta_t) : 1.0);
      s.transmitted = true;
    }
    return s.pdf > 0.0;
  }
};

}  // namespace femto
