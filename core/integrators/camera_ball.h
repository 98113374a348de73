#pragma once
// The ball around a perspective camera's pinhole inside a scattering medium, where the hybrid
// integrator's light tracing hands medium scattering over to camera paths. A light-path vertex
// at distance d from the pinhole reaches the sensor with weight 1 / d^2, and a light ray piece
// passing at distance h with theta / h: the variance of light tracing there has no bound (one
// sample 1.25 mm from the pinhole outweighed a pixel's mean 12000 times). Inside the ball the
// camera's own segment gathers the light pieces that pass through it as beams with their exact
// transmittance, so that light tracing splats only points at least `radius` from the pinhole
// (docs/ARCHITECTURE.md, "Path-space partition"). The gather's 1-D kernel widens along the camera
// ray, R(s) = max(slope s, r_min): a fixed radius blurs in angle by R / s, which next to the
// pinhole smeared a caustic passing the camera over much of the image; this one blurs by at most
// `slope` (one pixel at first) beyond s = r_min / slope, and weighs at most 1 / (2 r_min sin).
#include <algorithm>

#include "core/integrators/photon_beams.h"
#include "core/scene.h"
#include "core/transport/light_walk.h"

namespace femto {

struct CameraBall {
  Vec3 centre;
  double radius = 0;  ///< mm; 0: no ball (light tracing splats everything)
  double slope = 0;   ///< first pass's gather radius per mm along the camera ray (radians)
  double r_min = 0;   ///< first pass's smallest gather radius, mm
  double reach = 0;   ///< radius + the widest gather radius: light pieces farther away are not kept
  /// The widest gather radius at the ball's edge when the kernel has shrunk by `ratio`.
  double widest(double ratio) const { return std::max(r_min, slope * radius) * ratio; }
  bool active() const { return radius > 0; }
};

/// Distance from p to the nearest surface of the scene (spheres and triangles; infinite if none).
double nearest_surface_distance(const SceneDesc& desc, const Vec3& p);

/// The hybrid's ball, for a perspective camera in a medium that interacts (otherwise none):
/// `requested_mm` > 0 (checked to hold no surface when the options are read), 0 for none, or by
/// default min(1% of the scene's bounding-box diagonal, half the distance to the nearest surface),
/// so that the ball holds no surface and lies in the camera's medium. The gather kernel starts at a
/// slope of one pixel's angle (as the caustic beams: one pixel at the look_at distance) and
/// r_min = slope radius / 4.
CameraBall camera_ball(const Scene& scene, double requested_mm);

/// The part of the light ray piece `piece` (LightVertex::Kind::Ray, cut at `length`) within
/// ball.reach of the pinhole, as a beam that starts where that part starts and carries the
/// piece's flux times the transmittance to there (its time advanced by the optical path over
/// c). False if the piece passes farther away.
bool camera_ball_beam(const MediumTracker& tracker, const CameraBall& ball,
                      const LightVertex& piece, double length, Beam& out);

}  // namespace femto
