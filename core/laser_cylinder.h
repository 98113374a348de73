#pragma once
// The stretch of a ray that lies inside a laser's beam: a laser lights only the half-cylinder of
// its radius in front of its disc, so the segment connections to it (laser chords) sample only
// there. Camera paths that wait for a collision inside a thin beam find its light by chance.
#include <algorithm>
#include <cmath>

#include "core/lights.h"
#include "core/narrow_interval.h"
#include "core/vec3.h"

namespace femto {

/// Narrows [lo, hi] along `ray` (unit direction) to the points inside the beam of laser `l`:
/// distance from the axis (l.position, unit l.direction) at most l.radius, and in front of the
/// disc (along the axis from l.position >= 0). Returns false when none of [lo, hi] is inside.
/// The result is widened by a relative 1e-9 against rounding (LightSet::sample decides exactly
/// which points are lit).
inline bool laser_chord(const Light& l, const Ray& ray, double& lo, double& hi) {
  if (!(hi > lo)) return false;
  const Vec3& a = l.direction;
  const Vec3 v = ray.o - l.position;
  const double va = dot(v, a), da = dot(ray.d, a);
  // Front half-space: va + s da >= 0.
  double s0 = lo, s1 = hi;
  if (da > 0) {
    s0 = std::max(s0, -va / da);
  } else if (da < 0) {
    s1 = std::min(s1, -va / da);
  } else if (va < 0) {
    return false;
  }
  // Cylinder: |w + s e|^2 <= r^2 with w, e the parts of v and ray.d across the axis.
  const Vec3 w = v - a * va, e = ray.d - a * da;
  const double A = dot(e, e), B = dot(w, e), C = dot(w, w) - l.radius * l.radius;
  if (A < 1e-24) {  // along the axis: inside everywhere or nowhere
    if (C > 0) return false;
  } else {
    const double disc = B * B - A * C;
    if (!(disc >= 0)) return false;
    const double sq = std::sqrt(disc);
    // Roots without cancellation.
    const double q = -(B + (B >= 0 ? sq : -sq));
    double r1 = q / A, r2 = q != 0 ? C / q : r1;
    if (r1 > r2) std::swap(r1, r2);
    s0 = std::max(s0, r1);
    s1 = std::min(s1, r2);
  }
  return narrow_interval(s0, s1, l.radius, lo, hi);
}

}  // namespace femto
