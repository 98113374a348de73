#pragma once
// Where segment connections pay (connection_sampling "auto"). Next-event estimation at the
// path's collisions has, per unit time, the lowest error on typical pixels (femto-bench-sampling),
// but near a point light its 1/r^2 gives fireflies; an equiangular connection removes them at the
// cost of a shadow ray. So a segment adds a connection only when the light's direct term along
// it has a peak much narrower than the spread of the collisions that sample it: peak width w =
// the light's distance from the line (foot on the segment), from the start (foot behind) or from
// the end (foot beyond); spread = min(segment length, mean free path), the mean free path at the
// light in a voxel medium (the collisions that sample the peak are those near it; at the
// segment's start where the light sits in empty space). Under mean-free-path
// distances a point light's connection and the collisions then share the light by the balance
// heuristic: the connection's vertices crowd the peak, the collisions keep the frames far from
// it (where equiangular vertices are sparse), so neither loses where the other is better.
// Spot lights always use connections, alone: their cone lights only a short stretch of a
// segment, which collisions rarely hit, while equiangular sampling spreads over the light's
// angles and so over the cone. The choice depends only on the segment and the light, never on a
// sampled distance, so the estimators split the light between them without bias.
// Where a time rule below also holds for a segment, its pair takes the segment instead (measured:
// adding the equiangular vertex to it cost the fog corridors 13-16% of their efficiency).
// Second rule, for the frames a camera segment reaches late: when its reachable part spans 3 to
// 16 mean free paths and the light lies behind its start (a source beside the camera: the light
// term falls from the start on and covers all the segment's frames), collisions leave the late
// frames almost empty. Such a segment keeps its collisions and adds one line-to-point connection
// (uniform in time), the two weighted by the balance heuristic.
// Third rule, for media less than a mean free path across (a bank of thin fog) lit only by
// lights outside every scattering medium: a segment there whose reachable part has optical depth
// between 0.05 and 1 gets the same pair, whatever side the light is on. Fewer than 1 - 1/e of such
// segments hold a collision, while the connection puts a vertex on every one, spread over the
// window, and with the light outside the medium its term along the segment has no 1/r^2 peak.
// Measured (femto-bench-sampling, docs/PERFORMANCE.md): with the light inside the medium the extra
// shadow rays cost more than they save (thin fog box and room), as they do on the rare thin
// segments of an optically thick medium (tissue) and on segments thinner than 0.05 (the narrow
// corridor's crossings, 0.02-0.04 deep: a shadow ray on each).
#include <cmath>
#include <limits>

#include "core/lights.h"
#include "core/vec3.h"
#include "media/medium.h"

namespace femto {

/// Segments whose peak is narrower than this fraction of the collision spread use a connection
/// instead of the collisions (distance sampling other than mean free path: `mis + auto`).
constexpr double kConnectionPeakFraction = 0.1;
/// ... and under mean-free-path distances, where the connection and the collisions share the
/// light by MIS, so that a wider reach costs shadow rays but no variance, on segments spanning a
/// mean free path: collisions' relative second moment of the light's peak is about
/// 1 / (2 pi sigma_t h) at distance h from the light, above 1 once h < 0.16 mean free paths.
/// 0.2 measured best of 0.1-0.4; shorter segments keep 0.1 of their length (0.2 of it cost the
/// thin fog room 4-10% on typical pixels: a shadow ray on many segments that hold no collision).
constexpr double kNearPairFraction = 0.2;

/// The extinction that sets how far the collisions of a segment starting at o spread: the local
/// value, or in a voxel medium where o lies in empty space (a camera outside a cloud), the grid's
/// mean.
inline double spread_sigma_t(const Medium& med, const Vec3& o) {
  if (med.type != Medium::Type::Grid) return med.homogeneous.sigma_t();
  const double local = med.grid->sigma_t_at(o);
  return local > 0 ? local : med.grid->mean_sigma_t();
}

/// Whether the segment o + s d, s in [0, s_full), in a medium with extinction sigma_t (at p or o)
/// gathers the direct light of the point light at p by segment connections; `fraction` of the
/// spread when that is the mean free path, kConnectionPeakFraction of the segment's length else.
inline bool connect_segment_to(const Vec3& o, const Vec3& d, double s_full, double sigma_t,
                               const Vec3& p, double fraction = kConnectionPeakFraction) {
  // spread = min(s_full, 1 / sigma_t); compared squared and without a division (every segment
  // asks).
  const bool mfp_spread = sigma_t * s_full >= 1.0;  // false for a clear medium (also 0 x inf)
  // A clear, endless segment has no collisions to lean on.
  if (!mfp_spread && !(s_full < std::numeric_limits<double>::infinity())) return true;
  const Vec3 l = p - o;
  const double delta = dot(l, d);
  double w2;  // the light's squared distance from the segment
  if (delta <= 0.0)
    w2 = length_squared(l);
  else if (delta >= s_full)
    w2 = length_squared(p - (o + d * s_full));
  else
    w2 = std::fmax(length_squared(l) - delta * delta, 0.0);
  const double k2 = fraction * fraction;
  constexpr double k2_len = kConnectionPeakFraction * kConnectionPeakFraction;
  return mfp_spread ? w2 * sigma_t * sigma_t < k2 : w2 < k2_len * s_full * s_full;
}

/// Whether no segment inside the box [lo, hi] can connect to the point light at p under
/// connect_segment_to, wherever it starts and however long it is: its spread is at most the
/// box's diagonal and, where the extinction is sigma_t everywhere (homogeneous; 0: unknown), at
/// most the mean free path, and the light's distance from the segment at least its distance from
/// the box (1% of slack for rounding). A light outside a dense medium (a source in front of
/// tissue) is far: then the rule need not be asked on the medium's many short segments.
inline bool box_far_from_light(const Vec3& lo, const Vec3& hi, double sigma_t, const Vec3& p) {
  double spread = length(hi - lo);
  if (sigma_t > 0) spread = std::fmin(spread, 1.0 / sigma_t);
  const double k = 1.01 * std::fmax(kConnectionPeakFraction, kNearPairFraction) * spread;
  const Vec3 gap = vmax(vmax(lo - p, p - hi), Vec3(0.0));
  return length_squared(gap) >= k * k;
}

/// Optical depth of a camera segment's reachable part beyond which auto adds a line-to-point
/// connection: collisions put a fraction exp(-tau) of their density at depth tau, so the frames
/// that look there get few vertices, while line-to-point sampling is uniform in time.
constexpr double kStarvedDepth = 3.0;
/// ... and up to which it does: the connection gathers light scattered once along the segment,
/// which falls as exp(-2 tau) with depth. Where the window reaches more than 16 mean free paths
/// into a medium (tissue: 200), most connections land where that light is below 1e-14 of the
/// first frames' and multiply scattered light fills the frames: a shadow ray per path for nothing
/// (4-7% of the tissue scene's time in femto-bench-sampling).
constexpr double kStarvedMaxDepth = 16.0;

/// Whether a camera segment of length s_surf, with extinction sigma_t (spread_sigma_t) and
/// `budget` mm of light travel left in the window, spans so many mean free paths that its later
/// frames starve under collision sampling, yet few enough for its single scattering to count.
inline bool starved_segment(double s_surf, double budget, double sigma_t) {
  const double tau = sigma_t * std::fmin(s_surf, budget);
  return tau >= kStarvedDepth && tau < kStarvedMaxDepth;
}

/// Optical depths of a segment's reachable part between which auto adds a line-to-point
/// connection under the third rule: below kThinDepth most such segments hold no collision; below
/// kThinMinDepth a segment gathers too little light to pay for a shadow ray of its own (0.05
/// measured better than 0.1 and 0 in both fog corridors). A medium thinner than kThinDepth across
/// its bounding box is one where such segments are the rule.
constexpr double kThinDepth = 1.0, kThinMinDepth = 0.05;

/// Whether a segment of length s_surf, with extinction sigma_t (spread_sigma_t) and `budget` mm
/// of light travel left in the window, is optically thin enough for the third rule.
inline bool thin_segment(double s_surf, double budget, double sigma_t) {
  const double tau = sigma_t * std::fmin(s_surf, budget);
  return tau >= kThinMinDepth && tau < kThinDepth;
}

/// Whether the point light p lies behind the start o of a segment along d: then its direct term
/// along the segment falls from the start on and spans all of the segment's frames (a source
/// beside the camera), instead of peaking at the light's foot.
inline bool lights_from_start(const Vec3& o, const Vec3& d, const Vec3& p) {
  return dot(p - o, d) <= 0.0;
}

/// The auto rule for one light: spot lights always connect (their cone), point lights by
/// connect_segment_to. Both the segment estimate and the collision vertices ask this.
inline bool auto_connects(const Light& light, const Vec3& o, const Vec3& d, double s_full,
                          double sigma_t, double fraction = kConnectionPeakFraction) {
  return light.type == Light::Type::Spot ||
         connect_segment_to(o, d, s_full, sigma_t, light.position, fraction);
}

}  // namespace femto
