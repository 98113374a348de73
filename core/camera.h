#pragma once
// Pinhole perspective and orthographic cameras. Pixel (0,0) is the top-left corner.
#include <algorithm>
#include <cmath>

#include "core/constants.h"
#include "core/scene_desc.h"
#include "core/vec3.h"

namespace femto {

class Camera {
 public:
  explicit Camera(const CameraDesc& d) : desc_(d) {
    forward_ = normalize(d.look_at - d.position);
    right_ = normalize(cross(forward_, d.up));
    up_ = cross(right_, forward_);
    const double aspect = static_cast<double>(d.width) / d.height;
    if (d.type == CameraDesc::Type::Perspective) {
      half_h_ = std::tan(0.5 * d.fov_deg * kPi / 180.0);
      half_w_ = half_h_ * aspect;
    } else {
      half_w_ = 0.5 * d.ortho_width;
      half_h_ = half_w_ / aspect;
    }
  }

  /// Ray through film position (fx, fy) in pixels (continuous; x right, y down).
  Ray generate_ray(double fx, double fy) const {
    const double sx = (2.0 * fx / desc_.width - 1.0) * half_w_;
    const double sy = (1.0 - 2.0 * fy / desc_.height) * half_h_;
    if (desc_.type == CameraDesc::Type::Perspective)
      return {desc_.position, normalize(forward_ + right_ * sx + up_ * sy)};
    return {desc_.position + right_ * sx + up_ * sy, forward_};
  }

  /// Connection of a world point x to the sensor (light tracing): film position (fx, fy) in
  /// pixels, unit direction from x to the sensor, its length, and the importance W of one pixel
  /// such that a light vertex adds beta f |cos_x| Tr W to that pixel's mean radiance. With the
  /// film as the plane at unit distance and A_pix its area per pixel: perspective W =
  /// 1 / (A_pix cos^3(theta) dist^2), orthographic W = 1 / A_pix (dist = depth along the axis).
  /// False when x is behind the sensor or projects outside the film.
  bool connect_to(const Vec3& x, double& fx, double& fy, Vec3& w_to_sensor, double& dist,
                  double& W) const {
    const bool persp = desc_.type == CameraDesc::Type::Perspective;
    const Vec3 v = x - desc_.position;
    const double z = dot(v, forward_);
    if (!(z > 0)) return false;
    const double sx = persp ? dot(v, right_) / z : dot(v, right_);
    const double sy = persp ? dot(v, up_) / z : dot(v, up_);
    fx = (sx / half_w_ + 1.0) * 0.5 * desc_.width;
    fy = (1.0 - sy / half_h_) * 0.5 * desc_.height;
    if (!(fx >= 0 && fx < desc_.width && fy >= 0 && fy < desc_.height)) return false;
    const double a_pix =
        4.0 * half_w_ * half_h_ / (static_cast<double>(desc_.width) * desc_.height);
    if (persp) {
      dist = length(v);
      w_to_sensor = -v / dist;
      const double cos_t = z / dist;
      W = 1.0 / (a_pix * cos_t * cos_t * cos_t * dist * dist);
    } else {
      dist = z;
      w_to_sensor = -forward_;
      W = 1.0 / a_pix;
    }
    return true;
  }

  /// Film position (fx, fy) in pixels of a world point in front of the sensor, inside the film
  /// or not; false behind it.
  bool raster(const Vec3& x, double& fx, double& fy) const {
    const bool persp = desc_.type == CameraDesc::Type::Perspective;
    const Vec3 v = x - desc_.position;
    const double z = dot(v, forward_);
    if (!(z > 0)) return false;
    fx = ((persp ? dot(v, right_) / z : dot(v, right_)) / half_w_ + 1.0) * 0.5 * desc_.width;
    fy = (1.0 - (persp ? dot(v, up_) / z : dot(v, up_)) / half_h_) * 0.5 * desc_.height;
    return true;
  }

  /// The part [s0, s1] of the ray o + s d, s in [s0, s1] on entry, that a perspective camera's
  /// film sees (between its four side planes); false if none, or for an orthographic camera.
  bool frustum_interval(const Vec3& o, const Vec3& d, double& s0, double& s1) const {
    if (desc_.type != CameraDesc::Type::Perspective) return false;
    const Vec3 v = o - desc_.position;
    const double z0 = dot(v, forward_), zd = dot(d, forward_);
    // Each side plane keeps a + b s >= 0.
    const double a[4] = {half_w_ * z0 - dot(v, right_), half_w_ * z0 + dot(v, right_),
                         half_h_ * z0 - dot(v, up_), half_h_ * z0 + dot(v, up_)};
    const double b[4] = {half_w_ * zd - dot(d, right_), half_w_ * zd + dot(d, right_),
                         half_h_ * zd - dot(d, up_), half_h_ * zd + dot(d, up_)};
    for (int k = 0; k < 4; ++k) {
      if (b[k] == 0) {
        if (a[k] < 0) return false;
      } else if (b[k] > 0) {
        s0 = std::max(s0, -a[k] / b[k]);
      } else {
        s1 = std::min(s1, -a[k] / b[k]);
      }
    }
    return s0 < s1;
  }

  const Vec3& position() const { return desc_.position; }
  bool perspective() const { return desc_.type == CameraDesc::Type::Perspective; }
  int width() const { return desc_.width; }
  int height() const { return desc_.height; }

 private:
  CameraDesc desc_;
  Vec3 forward_, right_, up_;
  double half_w_ = 1, half_h_ = 1;
};

}  // namespace femto
