// Which integrator renders a scene, and the photon-mapping defaults that depend on the scene.
#include <algorithm>
#include <cmath>

#include "core/render.h"

namespace femto {

const char* integrator_name(IntegratorKind kind) {
  switch (kind) {
    case IntegratorKind::Auto:
      return "auto";
    case IntegratorKind::Path:
      return "path";
    case IntegratorKind::Light:
      return "light";
    case IntegratorKind::Photons:
      return "photons";
  }
  return "?";
}

IntegratorKind resolve_integrator(const SceneDesc& scene, IntegratorKind kind, std::string& why) {
  if (kind != IntegratorKind::Auto) {
    why = "chosen";
    return kind;
  }
  const bool delta_light = !scene.lights.empty();  // point, spot and laser lights are all deltas
  const bool non_diffuse =
      std::any_of(scene.shapes.begin(), scene.shapes.end(), [](const ShapeDesc& s) {
        return s.material.type != MaterialDesc::Type::None &&
               s.material.type != MaterialDesc::Type::Diffuse;
      });
  if (!delta_light || !non_diffuse) {
    why =
        "auto: no caustics to gather (needs a point, spot or laser light and a non-diffuse "
        "surface)";
    return IntegratorKind::Path;
  }
  if (scene.reconstruction.type == TemporalFilter::Kind::Kernel) {
    why = "auto: the scene has caustics, but the kernel film works with camera paths only";
    return IntegratorKind::Path;
  }
  why = "auto: delta lights and non-diffuse surfaces, so caustics come from photons";
  return IntegratorKind::Photons;
}

double default_photon_radius(const Scene& scene) {
  const double diag = length(scene.geometry().bounds_max() - scene.geometry().bounds_min());
  return 0.005 * (diag > 0 ? diag : 1.0);
}

double default_photon_bandwidth(const SceneDesc& scene) {
  return scene.time.bin_width_ps;
}

}  // namespace femto
