#include "core/integrators/camera_ball.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/constants.h"
#include "core/medium_nesting.h"
#include "core/render.h"

namespace femto {

double nearest_surface_distance(const SceneDesc& desc, const Vec3& p) {
  double best = std::numeric_limits<double>::infinity();
  for (const ShapeDesc& sh : desc.shapes) {
    if (sh.type == ShapeDesc::Type::Sphere) {
      best = std::min(best, std::abs(length(p - sh.center) - sh.radius));
      continue;
    }
    best = std::min(best, distance_to_triangles(sh, p));
  }
  return best;
}

CameraBall camera_ball(const Scene& scene, double requested_mm) {
  CameraBall ball;
  const Camera& cam = scene.camera();
  if (!cam.perspective()) return ball;
  const Medium& med = scene.media()[static_cast<size_t>(scene.camera_medium())];
  if (!med.interacts()) return ball;
  const double extent = length(scene.geometry().bounds_max() - scene.geometry().bounds_min());
  const double r = requested_mm >= 0
                       ? requested_mm
                       : std::min(0.01 * (extent > 0 ? extent : 1.0),
                                  0.5 * nearest_surface_distance(scene.desc(), cam.position()));
  if (!(r > 0) || !std::isfinite(r)) return ball;
  ball.centre = cam.position();
  ball.radius = r;
  const CameraDesc& cd = scene.desc().camera;
  const double look = length(cd.look_at - cd.position);
  const double pixel_angle = look > 0 ? pixel_footprint_mm(cd) / look : 0.0;
  ball.slope = pixel_angle > 0 ? pixel_angle : 1e-3;
  ball.r_min = ball.slope * r / 4.0;
  ball.reach = r + ball.widest(1.0);
  return ball;
}

bool camera_ball_beam(const MediumTracker& tracker, const CameraBall& ball,
                      const LightVertex& piece, double length_cut, Beam& out) {
  const Vec3 l = ball.centre - piece.p;
  const double foot = dot(l, piece.d), h = length(cross(l, piece.d));
  if (!(h < ball.reach)) return false;
  const double half = std::sqrt((ball.reach - h) * (ball.reach + h));
  const double v0 = std::max(0.0, foot - half), v1 = std::min(length_cut, foot + half);
  if (!(v1 > v0)) return false;
  double tau = 0, opl = 0;
  if (v0 > 0) tracker.segment_integrals(piece.medium, {piece.p, piece.d}, v0, tau, opl);
  out = {piece.p + piece.d * v0,           piece.d,        v1 - v0, piece.beta * std::exp(-tau),
         piece.t_ps + opl / kSpeedOfLight, piece.sigma_ps, piece.g, piece.medium};
  return true;
}

}  // namespace femto
