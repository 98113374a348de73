#pragma once
// The stretch of a ray that lies inside a spot light's cone: a spot lights nothing outside it,
// so segment connections sample only there (samplers spread over the whole segment would put
// most of their points in the dark when the cone is narrow seen from the segment).
#include <algorithm>
#include <cmath>

#include "core/lights.h"
#include "core/narrow_interval.h"
#include "core/vec3.h"

namespace femto {

/// Narrows [lo, hi] along `ray` (unit direction) to the points inside the cone of spot `l`
/// (apex l.position, axis l.direction, cosine l.cos_cone). Returns false when none of [lo, hi]
/// is inside. Where the cone is not convex (half-angle of 90 degrees or more) or the line runs
/// along its surface, [lo, hi] is left as it is: a wider range only costs samples, a narrower
/// one would lose light. The result is widened by a relative 1e-9 against rounding.
inline bool spot_cone_interval(const Light& l, const Ray& ray, double& lo, double& hi) {
  if (!(hi > lo)) return false;
  const double c = l.cos_cone;
  if (!(c > 0)) return true;
  const Vec3& a = l.direction;
  const Vec3 v = ray.o - l.position;
  const double va = dot(v, a), da = dot(ray.d, a), c2 = c * c;
  // Inside both nappes: q(s) = A s^2 + B s + C >= 0; the spot's own nappe: va + s da >= 0.
  const double A = da * da - c2, B = 2.0 * (va * da - c2 * dot(v, ray.d)),
               C = va * va - c2 * dot(v, v);
  if (std::abs(A) < 1e-12) return true;  // along the surface: keep the whole range
  const double disc = B * B - 4.0 * A * C;
  if (!(disc >= 0)) return A > 0;  // A < 0: q < 0 everywhere, nothing inside
  const double sq = std::sqrt(disc);
  // Roots without cancellation.
  const double qq = -0.5 * (B + (B >= 0 ? sq : -sq));
  double r1 = qq / A, r2 = qq != 0 ? C / qq : r1;
  if (r1 > r2) std::swap(r1, r2);
  double s0, s1;
  if (A < 0) {  // inside between the roots, one nappe only (it holds no apex crossing)
    s0 = r1;
    s1 = r2;
    if (!(va + 0.5 * (r1 + r2) * da >= 0)) return false;  // the mirror nappe
  } else if (da > 0) {  // steeper than the cone, heading along the axis: the far part
    s0 = r2;
    s1 = hi;
  } else {  // heading against the axis: the near part
    s0 = lo;
    s1 = r1;
  }
  return narrow_interval(s0, s1, (hi - lo), lo, hi);
}

}  // namespace femto
