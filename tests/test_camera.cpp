// Camera geometry that light tracing relies on.
#include <catch2/catch.hpp>

#include <cmath>

#include "core/camera.h"
#include "core/rng.h"

using namespace femto;

namespace {
CameraDesc perspective_camera() {
  CameraDesc d;
  d.type = CameraDesc::Type::Perspective;
  d.position = {10, 20, 300};
  d.look_at = {-5, 0, 0};
  d.fov_deg = 40;
  d.width = 64;
  d.height = 48;
  return d;
}
}  // namespace

// Catches: a side plane with the wrong sign or the wrong half-width (light tracing's sensor
// connections would then sample points the film cannot see, or miss points it sees, and the
// MIS weights of its collision splats would no longer sum to one).
TEST_CASE("the camera's frustum interval holds the ray points that project onto the film",
          "[camera]") {
  const Camera cam(perspective_camera());
  Rng rng(17, 1);
  int inside = 0, outside = 0;
  for (int k = 0; k < 4000; ++k) {
    const Vec3 o(rng.uniform() * 600 - 300, rng.uniform() * 600 - 300, rng.uniform() * 800 - 300);
    const double z = 2 * rng.uniform() - 1, phi = 6.283185307179586 * rng.uniform();
    const double r = std::sqrt(1 - z * z);
    const Vec3 d(r * std::cos(phi), r * std::sin(phi), z);
    double s0 = 0, s1 = 1000;
    const bool any = cam.frustum_interval(o, d, s0, s1);
    for (int j = 0; j < 50; ++j) {
      const double s = 1000 * (j + 0.5) / 50;
      double fx, fy, dist, W;
      Vec3 w;
      const bool sees = cam.connect_to(o + d * s, fx, fy, w, dist, W);
      const double margin = 1e-6 * (1 + std::abs(s));
      if (any && s > s0 + margin && s < s1 - margin) {
        CHECK(sees);
        ++inside;
      } else if (!any || s < s0 - margin || s > s1 + margin) {
        CHECK_FALSE(sees);
        ++outside;
      }
    }
  }
  // Both cases were exercised.
  CHECK(inside > 10000);
  CHECK(outside > 10000);

  CameraDesc ortho = perspective_camera();
  ortho.type = CameraDesc::Type::Orthographic;
  ortho.ortho_width = 100;
  double s0 = 0, s1 = 1000;
  CHECK_FALSE(Camera(ortho).frustum_interval({0, 0, 0}, {0, 0, -1}, s0, s1));
}
