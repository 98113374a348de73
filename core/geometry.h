#pragma once
// Ray–surface intersection for all shapes of a scene, backed by Embree. Embree's headers stay in
// geometry.cpp so the rest of femto compiles without them.
#include <memory>

#include "core/scene_desc.h"
#include "core/vec3.h"

namespace femto {

struct SurfaceHit {
  double s = 0.0;     ///< distance along the ray, mm
  Vec3 p;             ///< hit point
  Vec3 ng;            ///< unit geometric normal: front side of quads, outside of closed shapes
  int shape = -1;     ///< index into SceneDesc::shapes
  int prim = -1;      ///< triangle index within the shape (0 for spheres)
};

class Geometry {
 public:
  /// closed_form_cells: rays that start inside a box or sphere that nothing else touches find
  /// their exit in closed form instead of in Embree, and in scenes made only of such shapes a ray
  /// that misses every shape's bounds skips Embree (false only to test these shortcuts).
  explicit Geometry(const SceneDesc& scene, bool closed_form_cells = true);
  ~Geometry();
  Geometry(const Geometry&) = delete;
  Geometry& operator=(const Geometry&) = delete;

  /// Closest hit with s in (s_min, s_max); thread-safe.
  bool intersect(const Ray& ray, double s_min, double s_max, SurfaceHit& hit) const;
  /// Whether any surface lies at s in (s_min, s_max); cheaper than intersect. Thread-safe.
  bool occluded(const Ray& ray, double s_min, double s_max) const;
  /// Bounds of all shapes (empty scene: a unit box at the origin).
  Vec3 bounds_min() const;
  Vec3 bounds_max() const;

 private:
  void find_empty_cells(const SceneDesc& desc);
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace femto
