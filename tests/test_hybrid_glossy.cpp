// The hybrid against light tracing where the camera sees a glossy surface (rough metal): a spot's
// caustic on the metal itself, which only light tracing reaches, and a caustic on a diffuse wall
// seen in the metal, which the camera paths take from the photons at the wall.
#include <catch2/catch.hpp>

#include "agreement.h"
#include "core/scene_loader.h"
#include "hybrid_scenes.h"

using namespace femto;
using namespace femto::test;

namespace {

/// 24 hybrid renders of `passes` passes against 24 light-tracing renders of `light_paths` paths,
/// the cells that see the glass sphere of radius 12 at `sphere` left out.
void hybrid_matches_light_tracing(const Scene& scene, const Vec3& sphere, uint64_t seed_light,
                                  uint64_t seed_hybrid, int64_t light_paths, int passes,
                                  int min_cells, double resolution) {
  const PhotonDesc pd = progressive(2000, 0.8, 1.0);
  const auto lt = cells(batches(scene, IntegratorKind::Light, light_paths, 24, seed_light), 4, 2);
  const auto hy = cells(batches(scene, IntegratorKind::Hybrid, passes, 24, seed_hybrid, pd), 4, 2);
  require_agreement(hy, lt, min_cells, resolution, cells_seeing_sphere(scene, sphere, 12.5, 4, 2));
}

}  // namespace

// Catches: a delta light's caustic on a glossy surface the camera sees (light -> glass -> rough
// metal -> camera) missing from the hybrid. Camera paths cannot reach the spot from the metal (a
// shadow ray does not pass smooth glass) and photons are stored on diffuse surfaces only, so the
// hybrid's light paths splat it. Without that splat the hybrid rendered this scene black (max |z|
// 539); as built max |z| 1.4 over 10 cells.
TEST_CASE("hybrid agrees with light tracing on a caustic on rough metal seen directly",
          "[hybrid][statistical]") {
  const SceneDesc d = load_scene_string(R"({
    "camera": { "type": "perspective", "position": [60, 50, 60], "look_at": [0, 5, 0], "fov": 25,
                "resolution": [32, 24] },
    "time": { "t_start": 550, "bin_width": 50, "bins": 6 },
    "shapes": [
      { "type": "quad", "corner": [-60, 0, 60], "edge1": [120, 0, 0], "edge2": [0, 0, -120],
        "material": { "type": "rough_conductor", "reflectance": 0.9, "roughness": 0.5 } },
      { "type": "sphere", "center": [0, 40, 0], "radius": 12, "material": { "type": "dielectric", "eta": 1.5 } }
    ],
    "lights": [ { "type": "spot", "position": [0, 90, 0], "look_at": [0, 40, 0], "intensity": 3000,
                  "cone_angle": 12, "falloff_start": 10 } ]
  })",
                                        "a caustic on rough metal", ".");
  hybrid_matches_light_tracing(Scene(d), {0, 40, 0}, 2000, 2100, 20000, 16, 8, 0.03);
}

// Catches: the photons' weight in the hybrid. The camera's first vertex is rough metal, so the
// caustic the glass focuses onto the diffuse wall (light -> glass -> wall -> metal -> camera) is
// the photons', gathered where camera paths reach the wall after the metal; light tracing
// connects the metal to the camera. The wall seen directly is light tracing's in both. Measured:
// max |z| 75 with no photon gathers, 18 with photons at twice their weight; as built 2.7 over 18
// cells.
TEST_CASE("hybrid agrees with light tracing on a wall's caustic seen in rough metal",
          "[hybrid][statistical]") {
  const SceneDesc d = load_scene_string(R"({
    "camera": { "type": "perspective", "position": [-50, 40, 50], "look_at": [10, 5, 5], "fov": 45,
                "resolution": [32, 24] },
    "time": { "t_start": 500, "bin_width": 100, "bins": 8 },
    "shapes": [
      { "type": "quad", "corner": [-60, 0, 60], "edge1": [120, 0, 0], "edge2": [0, 0, -120],
        "material": { "type": "rough_conductor", "reflectance": 0.9, "roughness": 0.2 } },
      { "type": "quad", "corner": [40, 0, 60], "edge1": [0, 0, -120], "edge2": [0, 80, 0],
        "material": { "type": "diffuse", "albedo": 0.8 } },
      { "type": "sphere", "center": [-10, 30, 0], "radius": 12, "material": { "type": "dielectric", "eta": 1.5 } }
    ],
    "lights": [ { "type": "spot", "position": [-70, 30, 0], "look_at": [-10, 30, 0], "intensity": 3000,
                  "cone_angle": 10, "falloff_start": 8 } ]
  })",
                                        "a wall's caustic seen in rough metal", ".");
  hybrid_matches_light_tracing(Scene(d), {-10, 30, 0}, 2200, 2300, 20000, 16, 8, 0.03);
}
