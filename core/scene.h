#pragma once
// The renderable scene built from a SceneDesc: geometry, lights, camera and the media of every
// region (the space outside all shapes, and each closed shape's interior).
#include <memory>
#include <vector>

#include "core/camera.h"
#include "core/geometry.h"
#include "core/lights.h"
#include "core/scene_desc.h"
#include "media/grid_medium.h"
#include "media/medium.h"

namespace femto {

class Scene {
 public:
  explicit Scene(SceneDesc desc);
  Scene(const Scene&) = delete;
  Scene& operator=(const Scene&) = delete;

  const SceneDesc& desc() const { return desc_; }
  const Geometry& geometry() const { return geometry_; }
  const LightSet& lights() const { return lights_; }
  const Camera& camera() const { return camera_; }

  /// Media of all regions; index global_medium() is the space outside all shapes (vacuum by
  /// default). A dielectric shape without a named medium gets a clear medium of its own eta.
  const std::vector<Medium>& media() const { return media_; }
  int global_medium() const { return outside_; }
  /// Medium entered when a ray crosses shape i against its normal.
  int inside_medium(int shape) const { return inside_[static_cast<size_t>(shape)]; }
  /// Whether shape i bounds a medium (a named medium inside, or a refracting surface). Other
  /// shapes have the same medium on both sides, which outside_medium only names when no medium
  /// boundary crosses them.
  bool bounds_medium(int shape) const { return bounds_[static_cast<size_t>(shape)] != 0; }
  /// Medium entered when a ray crosses shape i along its normal: the inside of the innermost
  /// shape around it (media nest), else the global medium.
  int outside_medium(int shape) const { return outside_of_[static_cast<size_t>(shape)]; }
  /// Medium on the far side of shape i from a ray travelling along d.
  int medium_beyond(int shape, const Vec3& d, const Vec3& ng) const {
    return dot(d, ng) < 0 ? inside_medium(shape) : outside_medium(shape);
  }
  /// Medium the camera sits in (the innermost closed medium shape around it).
  int camera_medium() const { return camera_medium_; }
  /// Medium at point p: the inside of the innermost closed medium shape holding it strictly,
  /// else the global medium.
  int medium_at(const Vec3& p) const;
  /// Whether any shape is an index-matched boundary (shadow rays must then walk through them).
  bool has_null_boundaries() const { return has_null_boundaries_; }
  /// Offset used to leave a surface without hitting it again, mm.
  double ray_epsilon() const { return ray_eps_; }

 private:
  SceneDesc desc_;
  Geometry geometry_;
  LightSet lights_;
  Camera camera_;
  std::vector<Medium> media_;
  std::vector<std::unique_ptr<GridMedium>> grids_;
  std::vector<int> inside_;
  std::vector<char> bounds_;
  std::vector<int> outside_of_;
  std::vector<int> enclosing_;  // enclosing_shapes(desc_)
  int outside_ = 0;
  int camera_medium_ = 0;
  double ray_eps_ = 1e-5;
  bool has_null_boundaries_ = false;
};

}  // namespace femto
