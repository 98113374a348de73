// Which integrator renders a scene, and the photon-mapping defaults that depend on the scene.
#include <algorithm>
#include <cmath>

#include "core/constants.h"
#include "core/medium_nesting.h"
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
    case IntegratorKind::Beams:
      return "beams";
    case IntegratorKind::Hybrid:
      return "hybrid";
  }
  return "?";
}

namespace {
bool scatters(const MediumDesc& m) {
  return m.type == MediumDesc::Type::Vdb || m.medium.sigma_s > 0;
}

// The medium around the camera scatters: light tracing alone would splat points next to the
// pinhole with weight 1 / d^2 (the hybrid's camera ball takes them instead).
bool camera_in_scattering_medium(const SceneDesc& scene) {
  const int shape = innermost_shape_at(scene, enclosing_shapes(scene), scene.camera.position);
  const int m =
      shape >= 0 ? scene.shapes[static_cast<size_t>(shape)].interior_medium : scene.global_medium;
  return m >= 0 && scatters(scene.media[static_cast<size_t>(m)]);
}
}  // namespace

bool has_scattering_medium(const SceneDesc& scene) {
  return std::any_of(scene.media.begin(), scene.media.end(), scatters);
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
  // A laser lights only its beam and its spots: camera paths reach the beam by segment connections
  // (laser chords), but the light scattered off it, and what a spot lights, only by chance (a
  // relay wall's spot in a non-line-of-sight scene: never).
  const bool scattering = has_scattering_medium(scene);
  const bool laser_lights =
      std::any_of(scene.lights.begin(), scene.lights.end(),
                  [](const LightDesc& l) { return l.type == LightDesc::Type::Laser; }) &&
      (scattering || std::any_of(scene.shapes.begin(), scene.shapes.end(), [](const ShapeDesc& s) {
         return s.material.type == MaterialDesc::Type::Diffuse;
       }));
  if (!delta_light || (!non_diffuse && !laser_lights)) {
    why =
        "auto: no caustics to gather (needs a point, spot or laser light and a non-diffuse "
        "surface, or a laser lighting a diffuse surface or a scattering medium)";
    return IntegratorKind::Path;
  }
  if (scene.reconstruction.type == TemporalFilter::Kind::Kernel) {
    why =
        "auto: the scene has caustics or a laser, but the kernel film works with camera paths "
        "only";
    return IntegratorKind::Path;
  }
  // Every surface specular (glass, mirrors, index-matched boundaries): no photon has a surface to
  // land on, and camera paths meet the media before any non-specular surface, so beams gather
  // all of the medium light; the hybrid would leave most of it to camera paths scattering their
  // way to the light's first segments (4-11x worse at equal time on such scenes,
  // docs/PERFORMANCE.md).
  const bool all_specular =
      std::all_of(scene.shapes.begin(), scene.shapes.end(), [](const ShapeDesc& s) {
        return s.material.type == MaterialDesc::Type::None || s.material.is_specular();
      });
  if (!non_diffuse && !(scattering && all_specular)) {
    // Light tracing reaches everything here (no specular surface hides what the camera sees) and
    // finds the beam, its spots and what they light where camera paths find them by chance:
    // 1.4x lower summed variance per unit time than the hybrid on a 0.5 mm beam in fog and 5x
    // in a non-line-of-sight scene (docs/PERFORMANCE.md, "Lasers in fog").
    if (!camera_in_scattering_medium(scene)) {
      why =
          "auto: a laser lighting diffuse surfaces or a scattering medium, and no specular "
          "surface, so light tracing finds all light";
      return IntegratorKind::Light;
    }
    // With the camera in the fog the hybrid keeps the points next to the pinhole for camera
    // paths (the camera ball).
    why =
        "auto: a laser lighting a scattering medium around the camera, so light tracing gives its "
        "beam, its spots and the light they throw, camera paths the light next to the camera";
    return IntegratorKind::Hybrid;
  }
  if (!scattering) {
    // Light tracing gives the caustic seen directly exactly, photons the rest: 6x (steady) and
    // 129x (transient) lower error than photons alone at equal time on a floor caustic seen
    // directly (docs/PERFORMANCE.md, "Without fog"; what is seen through glass not measured).
    why =
        "auto: delta lights and non-diffuse surfaces, so caustics come from light tracing where "
        "the camera sees them directly and from photons elsewhere";
    return IntegratorKind::Hybrid;
  }
  if (all_specular) {
    why =
        "auto: delta lights and a scattering medium behind specular surfaces only, so photon "
        "beams gather all light scattered in the media";
    return IntegratorKind::Beams;
  }
  why =
      "auto: delta lights, non-diffuse surfaces and a scattering medium, so caustics come from "
      "light tracing on the surfaces the camera sees directly, photons on other surfaces and "
      "photon beams in media";
  return IntegratorKind::Hybrid;
}

int64_t default_beam_paths_per_pass(int64_t pixels) {
  // Half a light path per pixel keeps a pass's beams in proportion to its camera samples at every
  // resolution (at 64 x 48, 20000 beam paths per pass made the hybrid's error 2-5x larger at
  // equal time: docs/PERFORMANCE.md); the cap is the full-size renders' long-standing value.
  return std::clamp<int64_t>(pixels / 2, 1000, 20000);
}

int64_t default_caustic_beam_paths_per_pass(int64_t pixels) {
  // The hybrid's caustic beams are gathered along every camera segment in a medium, and a pass's
  // other parts (camera paths, light paths) decide most of its variance: in the default scene
  // 20000 paths per pass took half of each pass and lowered no error, and 3072 still cost a fifth
  // of a pass of the through-glass scene against 500 at the same error (docs/PERFORMANCE.md).
  return std::clamp<int64_t>(pixels / 128, 500, 20000);
}

int64_t default_hybrid_photons_per_pass(int64_t pixels) {
  // In the hybrid, 200000 photons per pass took a third of each pass in the default scene and
  // lowered no error: its caustic's noise is the camera's pixel sampling of the sharp focus; so
  // did 49152 after the other parts of a pass became cheaper (10000 still gave the same errors).
  return std::clamp<int64_t>(pixels / 2, 10000, 200000);
}

int64_t default_hybrid_light_paths_per_pass(int64_t pixels) {
  // A light path's sensor connections along its medium rays cost about as much as the rest of
  // it: a quarter of a path per pixel then keeps the pass's time, with 1.26x the efficiency in
  // the fog under a glass sphere and the same on the floor caustic (docs/PERFORMANCE.md).
  return std::max<int64_t>(1, pixels / 4);
}

int64_t hybrid_light_paths_per_pass(const RenderOptions& opt, int64_t pixels) {
  if (opt.light_paths <= 0) return default_hybrid_light_paths_per_pass(pixels);
  const int64_t passes = std::max(1, opt.spp);
  return std::max<int64_t>(1, (opt.light_paths + passes / 2) / passes);  // nearest, at least 1
}

double pixel_footprint_mm(const CameraDesc& cam) {
  if (cam.type == CameraDesc::Type::Orthographic) return cam.ortho_width / cam.width;
  const double distance = length(cam.look_at - cam.position);
  const double half = std::tan(0.5 * cam.fov_deg * kPi / 180.0);
  return distance * 2.0 * half / cam.height;
}

PhotonDesc progressive_settings(const Scene& scene, IntegratorKind kind, PhotonDesc p) {
  const bool caustic = kind == IntegratorKind::Hybrid;
  const bool beams = kind == IntegratorKind::Beams || caustic;
  const double extent = length(scene.geometry().bounds_max() - scene.geometry().bounds_min());
  const double diag = extent > 0 ? extent : 1.0;
  const int64_t pixels = static_cast<int64_t>(scene.camera().width()) * scene.camera().height();
  if (p.per_pass <= 0)
    p.per_pass = caustic ? default_caustic_beam_paths_per_pass(pixels)
                 : beams ? default_beam_paths_per_pass(pixels)
                         : 200000;
  // Caustic beams are focused light: a kernel of 1% of the diagonal blurred the default scene's
  // volumetric caustic over 3 pixels, which at 32 passes was most of its error.
  const double footprint = pixel_footprint_mm(scene.desc().camera);
  if (p.radius <= 0)
    p.radius = caustic && footprint > 0 ? std::min(0.01 * diag, footprint)
               : beams                  ? 0.01 * diag
                                        : 0.005 * diag;
  if (p.bandwidth_ps <= 0) p.bandwidth_ps = scene.desc().time.bin_width_ps;
  // Photons: bias R^2 + T^2 with R^2 T shrinking balances at beta_t = 1/3 and the MSE is best at
  // alpha = 4/7; beams: bias R^2 + T^2 with R T shrinking balances at 1/2, best alpha 2/3.
  if (p.alpha <= 0) p.alpha = beams ? 2.0 / 3.0 : 4.0 / 7.0;
  if (p.beta_t < 0) p.beta_t = beams ? 0.5 : 1.0 / 3.0;
  return p;
}

}  // namespace femto
