#pragma once
// What BSDF sampling returns, and which quantity a path carries (Veach thesis, ch. 5).
#include "core/spectrum.h"
#include "core/vec3.h"

namespace femto {

/// Radiance: camera paths, f(wo, wi) scatters radiance arriving along wi into wo.
/// Importance: light paths carrying flux; f is the adjoint,
/// f_importance(wo, wi) = f_radiance(wi, wo).
enum class TransportMode { Radiance, Importance };

struct BsdfSample {
  Vec3 wi;             ///< sampled direction, local frame, unit
  RGB weight;          ///< f(wo,wi) |cos wi| / pdf; delta lobes: throughput / pick probability
  double pdf = 0;      ///< solid-angle density; delta lobes: the discrete pick probability
  bool delta = false;  ///< sampled lobe is a Dirac delta
  bool transmitted = false;  ///< wi lies on the other side of the surface than wo
};

/// Whether a and b are both > 0 or both < 0 (compares signs: the product underflows to 0 at
/// grazing angles).
inline bool same_sign(double a, double b) {
  return (a > 0.0 && b > 0.0) || (a < 0.0 && b < 0.0);
}

/// Whether a and b lie strictly on the same side of the surface (z = 0 belongs to neither).
inline bool same_side(const Vec3& a, const Vec3& b) {
  return same_sign(a.z, b.z);
}

/// Whether a and b lie strictly on opposite sides of the surface.
inline bool opposite_sides(const Vec3& a, const Vec3& b) {
  return same_sign(a.z, -b.z);
}

/// w mirrored through the surface plane: how two-sided BSDFs move wo's side to z > 0.
inline Vec3 mirror_z(const Vec3& w) {
  return {w.x, w.y, -w.z};
}

}  // namespace femto
