// Ray queries: the closed-form exit from boxes and spheres that nothing else touches must give
// what Embree gives, and must stand aside when another shape lies inside.
#include <catch2/catch.hpp>

#include <cmath>

#include "core/geometry.h"
#include "core/rng.h"
#include "core/sampling.h"
#include "core/scene_loader.h"

using namespace femto;

namespace {

/// Random rays from inside [lo, hi] (and some from outside it) against both geometries.
void compare(const SceneDesc& d, const Vec3& lo, const Vec3& hi, int* fast_hits_of_box) {
  const Geometry fast(d, true), embree(d, false);
  Rng rng = Rng::for_sample(7, 0, 0);
  int mismatches = 0;
  for (int i = 0; i < 20000; ++i) {
    // A tenth of the origins lie outside the region, where the shortcut must not apply.
    const double grow = i % 10 == 0 ? 1.5 : 1.0;
    const Vec3 c = (lo + hi) * 0.5, half = (hi - lo) * (0.5 * grow);
    const Vec3 o(c.x + half.x * (2 * rng.uniform() - 1), c.y + half.y * (2 * rng.uniform() - 1),
                 c.z + half.z * (2 * rng.uniform() - 1));
    const Vec3 w = sample_uniform_sphere(rng.uniform(), rng.uniform());
    const double s_max = i % 3 == 0 ? 5.0 + 40.0 * rng.uniform() : 1e30;
    SurfaceHit a, b;
    const bool ha = fast.intersect({o, w}, 0.0, s_max, a);
    const bool hb = embree.intersect({o, w}, 0.0, s_max, b);
    const bool oa = fast.occluded({o, w}, 0.0, s_max), ob = embree.occluded({o, w}, 0.0, s_max);
    // Embree works in float: hits agree to float precision; a hit within that of s_max may be
    // found by one and not the other.
    const double tol = 1e-5 * (1.0 + (ha ? a.s : 0.0) + length(o));
    if (ha != hb || oa != ob) {
      if (std::abs((ha ? a.s : b.s) - s_max) > tol) ++mismatches;
      continue;
    }
    if (!ha) continue;
    if (a.shape != b.shape || std::abs(a.s - b.s) > tol || length(a.ng - b.ng) > 1e-6) {
      INFO("ray " << i << ": shape " << a.shape << " vs " << b.shape << ", s " << a.s << " vs "
                  << b.s);
      ++mismatches;
    }
    if (a.shape == 0 && fast_hits_of_box) ++*fast_hits_of_box;
  }
  CHECK(mismatches == 0);
}

}  // namespace

// Catches: a wrong exit face, normal, distance or triangle index in the closed-form exit, an
// exit found for origins outside the cell, or a hit beyond s_max reported.
TEST_CASE("closed-form exits from empty boxes and spheres match Embree", "[geometry]") {
  const SceneDesc d = load_scene_string(R"({
    "camera": { "type": "perspective", "position": [0, 0, 100], "look_at": [0, 0, 0], "resolution": [4, 4] },
    "time": { "t_start": 0, "bin_width": 10, "bins": 4 },
    "shapes": [
      { "type": "box", "min": [-10, -7, -5], "max": [12, 9, 6], "material": { "type": "diffuse", "albedo": 0.5 } },
      { "type": "sphere", "center": [40, 0, 0], "radius": 8, "material": { "type": "diffuse", "albedo": 0.5 } },
      { "type": "quad", "corner": [-50, -20, -50], "edge1": [100, 0, 0], "edge2": [0, 0, 100], "material": { "type": "diffuse", "albedo": 0.5 } }
    ],
    "lights": [ { "type": "point", "position": [0, 50, 0], "intensity": 1 } ]
  })",
                                        "geometry test", ".");
  int box_hits = 0;
  compare(d, {-10, -7, -5}, {12, 9, 6}, &box_hits);
  CHECK(box_hits > 10000);
  compare(d, {32, -8, -8}, {48, 8, 8}, nullptr);
}

// Catches: the shortcut applied to a box with something inside (rays from inside must then hit
// the inner sphere, as Embree finds) or to one touching another shape.
TEST_CASE("closed-form exits stand aside for boxes that hold or touch other shapes",
          "[geometry]") {
  const SceneDesc d = load_scene_string(R"({
    "camera": { "type": "perspective", "position": [0, 0, 100], "look_at": [0, 0, 0], "resolution": [4, 4] },
    "time": { "t_start": 0, "bin_width": 10, "bins": 4 },
    "shapes": [
      { "type": "box", "min": [-10, -10, -10], "max": [10, 10, 10], "material": { "type": "diffuse", "albedo": 0.5 } },
      { "type": "sphere", "center": [2, 1, 0], "radius": 4, "material": { "type": "diffuse", "albedo": 0.5 } },
      { "type": "box", "min": [20, -10, -10], "max": [30, 10, 10], "material": { "type": "diffuse", "albedo": 0.5 } },
      { "type": "quad", "corner": [15, -10, -20], "edge1": [20, 0, 0], "edge2": [0, 0, 40], "material": { "type": "diffuse", "albedo": 0.5 } }
    ],
    "lights": [ { "type": "point", "position": [0, 50, 0], "intensity": 1 } ]
  })",
                                        "geometry test", ".");
  compare(d, {-10, -10, -10}, {10, 10, 10}, nullptr);
  compare(d, {20, -10, -10}, {30, 10, 10}, nullptr);
}
