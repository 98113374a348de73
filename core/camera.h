#pragma once
// Pinhole perspective and orthographic cameras. Pixel (0,0) is the top-left corner.
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

  int width() const { return desc_.width; }
  int height() const { return desc_.height; }

 private:
  CameraDesc desc_;
  Vec3 forward_, right_, up_;
  double half_w_ = 1, half_h_ = 1;
};

}  // namespace femto
