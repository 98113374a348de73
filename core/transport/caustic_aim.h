#pragma once
// Emission aimed at the non-diffuse shapes, for the light paths that count only while they meet
// mirrors, glass or rough metal first: photons (stored at the first diffuse vertex after such a
// chain) and the hybrid's caustic beams. Such a path stores nothing if its first straight flight
// meets a diffuse surface, scatters in a medium or leaves the scene, so from a point or spot light
// its direction is drawn from cones around the bounding spheres of the non-diffuse shapes (a
// mixture, chosen in proportion to their solid angles) and weighted by intensity / pdf. Unbiased:
// no direction outside every cone can start a caustic chain. docs/ARCHITECTURE.md, "Aimed caustic
// paths".
#include <vector>

#include "core/lights.h"
#include "core/scene_desc.h"
#include "core/vec3.h"

namespace femto {

class CausticAim {
 public:
  /// A cone of directions from a light that holds a shape's bounding sphere.
  struct Cone {
    Vec3 axis;               ///< unit, light -> sphere centre
    double cos_max = 1;      ///< cosine of the half-angle
    double one_minus = 0;    ///< 1 - cos_max, without cancellation
    double sin2_max = 0;     ///< sin^2 of the half-angle
    double solid_angle = 0;  ///< 2 pi (1 - cos_max), sr
  };

  CausticAim() = default;  ///< aims nothing
  CausticAim(const SceneDesc& desc, const LightSet& lights);

  /// Whether light i's caustic paths are aimed (a point or spot light outside every bounding
  /// sphere whose cones cover at most half of its emission's solid angle).
  bool aims(int light) const {
    return light >= 0 && light < static_cast<int>(per_light_.size()) &&
           per_light_[static_cast<size_t>(light)].aimed;
  }
  /// Draws a ray leaving light i within its cones: u_cone picks the cone, u1 and u2 the direction
  /// in it. e.beta = intensity x falloff / pdf. False when the direction carries no light (outside
  /// a spot's cone). Only for lights that aims().
  bool sample_emission(const Light& l, int i, double u_cone, double u1, double u2,
                       LightEmission& e) const;
  /// Solid-angle pdf of unit direction d from light i (0 outside every cone).
  double pdf(int i, const Vec3& d) const;
  /// Light i's cones (empty when not aimed).
  const std::vector<Cone>& cones(int i) const { return per_light_[static_cast<size_t>(i)].cones; }
  /// The cones' summed solid angle over the light's emission solid angle (4 pi for a point light,
  /// the cone for a spot); 1 when not aimed. The expected share of paths that now reach a
  /// non-diffuse shape grows by up to 1 / this.
  double solid_angle_ratio(int i) const { return per_light_[static_cast<size_t>(i)].ratio; }
  /// Whether any light is aimed.
  bool any() const;
  /// The paths' expected share of plain emission that aimed emission keeps: each light's
  /// solid_angle_ratio (1 if not aimed) weighted by its pick pmf. Plain emission stored about as
  /// many photons and beams from N paths as aimed emission does from share x N.
  double path_share(const LightSet& lights) const;

 private:
  struct PerLight {
    bool aimed = false;
    double ratio = 1;
    std::vector<Cone> cones;
    std::vector<double> cdf;  ///< over cones, by solid angle; last = 1
    double total = 0;         ///< summed solid angle
  };
  std::vector<PerLight> per_light_;
};

}  // namespace femto
