#pragma once
// Isotropic GGX (Trowbridge–Reitz) microfacet distribution with Smith masking-shadowing, and
// sampling of its visible normals (Heitz 2018, "Sampling the GGX distribution of visible normals").
// Local frame: macro normal +z; microfacet normals m have m.z > 0.
#include <algorithm>
#include <cmath>
#include <limits>

#include "core/constants.h"
#include "core/sincos_2pi.h"
#include "core/vec3.h"

namespace femto {

struct Ggx {
  double alpha = 0.1;  ///< roughness: the slope scale of the distribution (> 0)

  /// D(m): microfacet normals per steradian, normalised so that integral of D(m) m.z dm = 1.
  /// D = 1 / (pi alpha^2 cos^4 (1 + tan^2 / alpha^2)^2), written in the components of unit m.
  double D(const Vec3& m) const {
    if (!(m.z > 0.0)) return 0.0;
    const double a2 = alpha * alpha;
    const double t = m.z * m.z + (m.x * m.x + m.y * m.y) / a2;  // >= min(1, 1 / a2) for unit m
    return 1.0 / (kPi * a2 * t * t);
  }

  /// Smith Lambda(w) = (sqrt(1 + alpha^2 tan^2) - 1) / 2; depends on |tan theta| only, so it is
  /// the same from either side of the surface. Infinite at grazing incidence.
  double lambda(const Vec3& w) const {
    const double z2 = w.z * w.z;
    if (!(z2 > 0.0)) return std::numeric_limits<double>::infinity();
    const double x = alpha * alpha * (w.x * w.x + w.y * w.y) / z2;  // alpha^2 tan^2
    const double root = std::sqrt(1.0 + x);
    // The second form avoids cancellation for small x; the first stays finite for x = inf.
    return x > 1.0 ? 0.5 * (root - 1.0) : 0.5 * x / (root + 1.0);
  }

  /// Smith masking: the fraction of microfacets facing w that w sees unoccluded.
  double G1(const Vec3& w) const { return 1.0 / (1.0 + lambda(w)); }

  /// Smith height-correlated masking-shadowing, 1 / (1 + Lambda(wo) + Lambda(wi)); used for
  /// reflection and transmission alike (symmetric in wo, wi, and <= G1 of either).
  double G(const Vec3& wo, const Vec3& wi) const { return 1.0 / (1.0 + lambda(wo) + lambda(wi)); }

  /// Density of the normals visible from w (w.z > 0): D_w(m) = G1(w) max(0, w.m) D(m) / w.z.
  double D_visible(const Vec3& w, const Vec3& m) const {
    if (!(w.z > 0.0)) return 0.0;
    return G1(w) * std::max(0.0, dot(w, m)) * D(m) / w.z;
  }

  /// A normal drawn from D_visible(w, .) for unit w with w.z > 0; the result may have m.z = 0
  /// in degenerate cases, where D(m) = 0 tells the caller to give up.
  Vec3 sample_visible(const Vec3& w, double u1, double u2) const {
    // Stretch to the configuration where the microsurface is a hemisphere (alpha = 1).
    const Vec3 wh = normalize(Vec3(alpha * w.x, alpha * w.y, w.z));
    // Basis (t1, t2, wh) with t1 horizontal.
    const double len2 = wh.x * wh.x + wh.y * wh.y;
    const Vec3 t1 = len2 > 0.0 ? Vec3(-wh.y, wh.x, 0.0) / std::sqrt(len2) : Vec3(1.0, 0.0, 0.0);
    const Vec3 t2 = cross(wh, t1);
    // A uniform point on the unit disc, squeezed into the hemisphere's projection seen from wh:
    // a full half-disc plus the part of the other half scaled by wh.z.
    const double r = std::sqrt(u1);
    const SinCos phi = sincos_2pi(u2);
    const double p1 = r * phi.cos;
    const double s = 0.5 * (1.0 + wh.z);
    const double p2 = (1.0 - s) * std::sqrt(std::max(0.0, 1.0 - p1 * p1)) + s * r * phi.sin;
    // Lift onto the hemisphere, then unstretch the normal.
    const double p3 = std::sqrt(std::max(0.0, 1.0 - p1 * p1 - p2 * p2));
    const Vec3 nh = t1 * p1 + t2 * p2 + wh * p3;
    return normalize(Vec3(alpha * nh.x, alpha * nh.y, std::max(0.0, nh.z)));
  }
};

}  // namespace femto
