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

/// Rays from make_ray(i, rng, o, w, s_max) against both geometries: the same hits (to float
/// precision), shapes and normals; returns how many of the shortcut's hits were on shape 0.
template <class MakeRay>
int compare_rays(const SceneDesc& d, int n, MakeRay make_ray) {
  const Geometry fast(d, true), embree(d, false);
  Rng rng = Rng::for_sample(7, 0, 0);
  int mismatches = 0, hits_of_0 = 0;
  for (int i = 0; i < n; ++i) {
    Vec3 o, w;
    double s_max;
    make_ray(i, rng, o, w, s_max);
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
    if (a.shape == 0) ++hits_of_0;
  }
  CHECK(mismatches == 0);
  return hits_of_0;
}

/// Random rays from inside [lo, hi] (and some from outside it) against both geometries.
void compare(const SceneDesc& d, const Vec3& lo, const Vec3& hi, int* fast_hits_of_box) {
  const int hits = compare_rays(d, 20000, [&](int i, Rng& rng, Vec3& o, Vec3& w, double& s_max) {
    // A tenth of the origins lie outside the region, where the shortcut must not apply.
    const double grow = i % 10 == 0 ? 1.5 : 1.0;
    const Vec3 c = (lo + hi) * 0.5, half = (hi - lo) * (0.5 * grow);
    o = Vec3(c.x + half.x * (2 * rng.uniform() - 1), c.y + half.y * (2 * rng.uniform() - 1),
             c.z + half.z * (2 * rng.uniform() - 1));
    w = sample_uniform_sphere(rng.uniform(), rng.uniform());
    s_max = i % 3 == 0 ? 5.0 + 40.0 * rng.uniform() : 1e30;
  });
  if (fast_hits_of_box) *fast_hits_of_box = hits;
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

// Catches: the bounds test (scenes of separate boxes and spheres only, as here: a fog box, a lamp
// housing and a plate) skipping Embree for a ray that does meet a shape: padding too thin for
// Embree's float vertices and rays (grazing an edge of a box whose coordinates reach 2000 mm), a
// slab test wrong for rays parallel to a face, or the shortcut taken past s_max's side. The rays
// are the tracer's: legs leaving a face of the fog box by the ray epsilon (2e-6 of the extent)
// towards a lamp or anywhere, rays aimed within 1e-3 mm of the box's edges and corners, and rays
// along the axes.
TEST_CASE("rays that miss every shape's bounds skip Embree and agree with it", "[geometry]") {
  const SceneDesc d = load_scene_string(R"({
    "camera": { "type": "perspective", "position": [0, 0, 50], "look_at": [0, 0, -1000], "resolution": [4, 4] },
    "time": { "t_start": 0, "bin_width": 10, "bins": 4 },
    "media": { "fog": { "type": "homogeneous", "sigma_a": 0.001, "sigma_s": 0.003 } },
    "shapes": [
      { "type": "box", "min": [-20, -20, -2000], "max": [20, 20, 0], "medium": "fog" },
      { "type": "sphere", "center": [0, 25, 40], "radius": 3, "material": { "type": "diffuse", "albedo": 0.5 } },
      { "type": "box", "min": [-30, -30, 60], "max": [30, 30, 62], "material": { "type": "diffuse", "albedo": 0.5 } }
    ],
    "lights": [ { "type": "point", "position": [0, 15, 30], "intensity": 1 } ]
  })",
                                        "bounds test", ".");
  const Vec3 lo(-20, -20, -2000), hi(20, 20, 0);
  const double eps = 2e-6 * 2000.0;
  auto on_box = [&](Rng& rng, Vec3& n) {  // a point on a random face, and its outward normal
    const int face = static_cast<int>(rng.uniform() * 6.0);
    Vec3 p(lo.x + (hi.x - lo.x) * rng.uniform(), lo.y + (hi.y - lo.y) * rng.uniform(),
           lo.z + (hi.z - lo.z) * rng.uniform());
    const double side = face % 2 ? 1.0 : 0.0;
    const double sign = face % 2 ? 1.0 : -1.0;
    n = Vec3(face / 2 == 0 ? sign : 0.0, face / 2 == 1 ? sign : 0.0, face / 2 == 2 ? sign : 0.0);
    if (face / 2 == 0) p.x = lo.x + side * (hi.x - lo.x);
    if (face / 2 == 1) p.y = lo.y + side * (hi.y - lo.y);
    if (face / 2 == 2) p.z = lo.z + side * (hi.z - lo.z);
    return p;
  };
  compare_rays(d, 60000, [&](int i, Rng& rng, Vec3& o, Vec3& w, double& s_max) {
    s_max = i % 4 == 0 ? 1.0 + 3000.0 * rng.uniform() : 1e30;
    switch (i % 3) {
      case 0: {  // a leg leaving a face (the tracer's step past a boundary), to the lamp or
                 // anywhere
        Vec3 n;
        const Vec3 p = on_box(rng, n);
        w = i % 2 ? normalize(Vec3(0, 15, 30) - p)
                  : sample_uniform_sphere(rng.uniform(), rng.uniform());
        if (dot(w, n) < 0) w = -w;  // inward legs start inside, where the closed-form exit rules
        o = p + w * eps;
        break;
      }
      case 1: {  // from around the scene, aimed within 1e-3 mm of an edge or corner
        o = Vec3(-300 + 600 * rng.uniform(), -300 + 600 * rng.uniform(),
                 -2300 + 2600 * rng.uniform());
        Vec3 t(rng.uniform() < 0.5 ? lo.x : hi.x, rng.uniform() < 0.5 ? lo.y : hi.y,
               lo.z + (hi.z - lo.z) *
                          (rng.uniform() < 0.3 ? std::floor(2 * rng.uniform()) : rng.uniform()));
        t = t + sample_uniform_sphere(rng.uniform(), rng.uniform()) * (1e-3 * rng.uniform());
        w = normalize(t - o);
        break;
      }
      default: {  // along an axis, beside or across the box
        const int axis = static_cast<int>(rng.uniform() * 3.0);
        o = Vec3(-40 + 80 * rng.uniform(), -40 + 80 * rng.uniform(), -2100 + 2200 * rng.uniform());
        w = Vec3(axis == 0, axis == 1, axis == 2) * (rng.uniform() < 0.5 ? 1.0 : -1.0);
        break;
      }
    }
  });
}
