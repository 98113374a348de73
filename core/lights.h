#pragma once
// Pulsed light sources: point, spot, collimated laser beam, and emissive shapes (area lights).
#include <vector>

#include "core/scene_desc.h"
#include "core/spectrum.h"
#include "core/vec3.h"

namespace femto {

/// A light sample seen from a receiving point x.
struct LightSample {
  Vec3 p;           ///< point on the light
  Vec3 wi;          ///< unit direction from x towards p
  double dist = 0;  ///< |p - x|, mm
  RGB Li;           ///< radiance (area lights) or irradiance normal to wi (delta lights)
  double pdf = 0;   ///< solid-angle pdf of wi (area lights); 1 for delta lights
  bool is_delta = false;
};

/// A ray leaving a light, for light paths and photons.
struct LightEmission {
  Ray ray;              ///< origin on the light, unit direction of travel
  Vec3 n;               ///< area lights: unit normal at the origin
  RGB beta;             ///< flux weight: emitted intensity or radiance x cos / (pdf_pos pdf_dir)
  RGB Le_over_pdf_pos;  ///< area lights: emitted radiance / area pdf of the origin
  bool area = false;
};

struct Light {
  enum class Type { Point, Spot, Laser, AreaMesh, AreaSphere };
  Type type = Type::Point;
  Vec3 position, direction;
  RGB intensity, power, emission;
  double cos_cone = 0, cos_falloff = 1, radius = 0;
  int shape = -1;               ///< area lights: the emitting shape
  std::vector<double> tri_cdf;  ///< area meshes: CDF over triangle areas
  double area = 0;              ///< area lights: total area, mm^2
  PulseDesc pulse;
};

/// A spot's smooth falloff at cosine cos_t from its axis: 0 outside the cone, 1 inside the
/// falloff start.
double spot_falloff(const Light& l, double cos_t);

/// Point and spot lights: a single emitting point, the target of segment connections.
inline bool is_point_like(const Light& l) {
  return l.type == Light::Type::Point || l.type == Light::Type::Spot;
}

class LightSet {
 public:
  LightSet(const SceneDesc& scene);

  int count() const { return static_cast<int>(lights_.size()); }
  const Light& light(int i) const { return lights_[static_cast<size_t>(i)]; }
  /// Picks a light with probability proportional to its power; returns -1 if none.
  int pick(double u, double& pmf) const;
  double pmf(int i) const { return pmf_[static_cast<size_t>(i)]; }
  /// Samples light i as seen from x. False when it cannot reach x (outside a cone or beam).
  bool sample(int i, const Vec3& x, double u1, double u2, LightSample& ls) const;
  /// Samples a ray leaving light i (position and direction from u1..u4). False if the light
  /// emits nothing.
  bool sample_emission(int i, double u1, double u2, double u3, double u4, LightEmission& e) const;
  /// Light index of an emissive shape, or -1.
  int light_of_shape(int shape) const {
    return shape >= 0 && shape < static_cast<int>(shape_light_.size())
               ? shape_light_[static_cast<size_t>(shape)]
               : -1;
  }
  /// Solid-angle pdf with which sample() would produce direction x->p on area light i
  /// (p with unit normal n on the light), not including the pick pmf.
  double pdf_area(int i, const Vec3& x, const Vec3& p, const Vec3& n) const;
  /// Smallest emission offset and largest pulse std over all lights (for path cut-off).
  double min_offset_ps() const { return min_offset_; }
  double max_sigma_ps() const { return max_sigma_; }

 private:
  const SceneDesc* scene_;
  std::vector<Light> lights_;
  std::vector<double> cdf_, pmf_;
  std::vector<int> shape_light_;
  double min_offset_ = 0, max_sigma_ = 0;
};

}  // namespace femto
