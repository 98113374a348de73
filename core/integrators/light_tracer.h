#pragma once
// Transient light tracing: light sub-paths (core/transport/light_walk.h) whose every non-delta
// vertex is connected to the sensor and splatted into the pixel it projects to, at the path's
// time plus the connection's (camera time) or without it (unwarp time). Emitting surfaces are
// connected too; delta lights seen directly are not (as for camera paths, they cover no pixel
// area). Specular surfaces seen by the camera need camera paths.
#include <cstdint>
#include <vector>

#include "core/integrators/camera_ball.h"
#include "core/scene.h"
#include "core/transport/light_walk.h"

namespace femto {

/// One contribution of a light path to one pixel.
struct Splat {
  uint32_t pixel = 0;  ///< y * width + x
  double t_ps = 0;
  double sigma_ps = 0;  ///< pulse std
  RGB value;            ///< mean radiance added to the pixel times the number of light paths
};

class LightTracer {
 public:
  /// Which vertices are splatted. MediumIndirect: medium vertices whose light sub-path has
  /// scattered (off a diffuse surface or in a medium) or met a surface before, light -> X+ -> M
  /// -> sensor, diffuse surface vertices reached from a medium scattering or a diffuse surface
  /// through specular ones, light -> X* M S* -> D and light -> X* D S+ -> D, the light's own
  /// caustic, light -> (S|G)+ -> D, what it lights through diffuse bounces alone, light ->
  /// (S|G)+ -> D D* -> D, a delta light's caustic on a glossy surface, light -> S (S|G)* -> G,
  /// and a laser's beam and spots, laser -> M and laser -> D|G;
  /// the hybrid integrator's camera paths leave exactly those paths out (docs/ARCHITECTURE.md,
  /// "Path-space partition"; the last they cannot reach at all).
  enum class Vertices { All, MediumIndirect };
  LightTracer(const Scene& scene, int max_depth, double t_cut_ps,
              Vertices vertices = Vertices::All);
  /// Leaves the medium points inside `ball` (MediumIndirect, perspective camera) to camera
  /// paths: they are not splatted, and the ray pieces that pass within ball.reach go to
  /// trace's `ball_beams` instead (core/integrators/camera_ball.h).
  void set_camera_ball(const CameraBall& ball) { ball_ = ball; }
  /// Pixels of a medium ray's image (its streak on the film) per sensor connection along it:
  /// a ray whose streak spans L pixels gets min(kMaxRayConnections, 1 + floor(L / px))
  /// connections, stratified on the equiangular distribution. Large values: one per ray.
  void set_streak_pixels(double px) { streak_pixels_ = px; }
  static constexpr double kStreakPixels = 32.0;
  static constexpr int kMaxRayConnections = 4;
  /// Traces one light path and appends its sensor splats to `out` (and, with a camera ball, the
  /// beams through it to `ball_beams`).
  void trace(Rng& rng, std::vector<Splat>& out, PathStats& stats,
             std::vector<Beam>* ball_beams = nullptr) const;

 private:
  /// Splat of the connection x -> sensor from medium m leaving along a known side (x already
  /// offset).
  void splat(const Vec3& x, int m, const Vec3& w, double dist, const RGB& value, double t_ps,
             double sigma_ps, double fx, double fy, std::vector<Splat>& out,
             PathStats& stats) const;

  const Scene& scene_;
  MediumTracker tracker_;
  int max_depth_;
  double t_cut_;
  bool unwarp_;
  Vertices vertices_;
  /// Perspective camera: each medium ray piece the splatted vertices may lie on is also connected
  /// to the sensor at distances sampled equiangularly towards the pinhole (one or more, by the
  /// length of its streak), by MIS with the collisions (the splat weighs 1 / dist^2, which
  /// collisions alone sample poorly).
  bool sensor_rays_;
  double streak_pixels_ = kStreakPixels;
  CameraBall ball_;
};

}  // namespace femto
