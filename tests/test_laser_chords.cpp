// Laser chords (core/integrators/laser_chords.cpp): camera segments crossing a laser's beam take
// its scattered light at a point of the crossing. And the hybrid's share of a laser's light for
// light tracing: its beam and its spots seen directly, and what the spots light through diffuse
// bounces alone.
#include <catch2/catch.hpp>

#include <cmath>

#include "agreement.h"
#include "core/constants.h"
#include "core/laser_cylinder.h"
#include "core/rng.h"
#include "core/scene_loader.h"
#include "media/phase_hg.h"
#include "scene_builders.h"

using namespace femto;
using namespace femto::test;

namespace {
// Inside the beam by its definition: in front of the disc, within the radius of the axis.
bool in_beam(const Light& l, const Vec3& x) {
  const Vec3 v = x - l.position;
  const double along = dot(v, l.direction);
  return along >= 0 && length_squared(v - l.direction * along) <= l.radius * l.radius;
}
}  // namespace

// Catches: a chord that misses part of the beam (a root of the wrong sign, the half-cylinder
// behind the disc kept or the front one cut) or takes points outside it (which would cost only
// samples, but says the quadratic is wrong), for rays at every angle including along the axis.
TEST_CASE("laser_chord is the stretch of a ray inside the beam", "[lights][laser]") {
  Rng rng(7, 3);
  int crossing = 0;
  for (int k = 0; k < 4000; ++k) {
    Light l;
    l.type = Light::Type::Laser;
    l.position = {rng.uniform() * 20 - 10, rng.uniform() * 20 - 10, rng.uniform() * 20 - 10};
    l.direction = normalize(Vec3(rng.uniform() - 0.5, rng.uniform() - 0.5, rng.uniform() - 0.5));
    l.radius = 0.2 + 3.0 * rng.uniform();
    Ray ray;
    ray.o = {rng.uniform() * 20 - 10, rng.uniform() * 20 - 10, rng.uniform() * 20 - 10};
    // Every eighth ray along the axis, forwards or backwards, inside the beam or not.
    ray.d = k % 8 == 0
                ? l.direction * (k % 16 == 0 ? 1.0 : -1.0)
                : normalize(l.position + l.direction * (10 * rng.uniform()) +
                            Vec3(rng.uniform() - 0.5, rng.uniform() - 0.5, rng.uniform() - 0.5) *
                                (4 * l.radius) -
                            ray.o);
    if (k % 8 == 0) ray.o = l.position + Frame(l.direction).s * (1.5 * l.radius * rng.uniform());
    double lo = 0, hi = 40;
    const bool any = laser_chord(l, ray, lo, hi);
    crossing += any;
    const int n = 2000;
    int wrong = 0;
    for (int i = 0; i <= n; ++i) {
      const double s = 40.0 * i / n;
      const bool in_chord = any && s >= lo && s <= hi;
      const double margin = 1e-6 * (1 + s);
      // Points within rounding of the beam's surface may go either way.
      const bool near_edge = in_beam(l, ray.at(s + margin)) != in_beam(l, ray.at(s - margin));
      wrong += !near_edge && in_beam(l, ray.at(s)) != in_chord;
    }
    INFO("ray " << k << ": chord [" << lo << ", " << hi << "], any " << any);
    REQUIRE(wrong == 0);
  }
  CHECK(crossing > 1000);  // the rays were aimed near the beam: most cross it
}

// Catches: a wrong irradiance or attenuation on the chord, a wrong phase angle for an oblique
// crossing (the scattering angle is between the beam and the way to the camera), and a chord
// density that is not the decay of both transmittances along the chord (exp(-sigma_t (1 + cos)
// s) with cos between the camera ray and the beam). With that density every camera path's value
// is the answer itself, so the batches differ only by the film's float32 rounding: uniform
// sampling of the chord gave a standard error of 7e-4 of the mean here, the camera's
// transmittance alone 3e-4, and 1 - cos for 1 + cos 6e-4.
TEST_CASE("an oblique laser chord gives the exact single scattering", "[tracer][analytic][laser]") {
  const double sigma_a = 0.02, sigma_s = 0.08, g = 0.6, R = 1.0, P = 50.0;
  const double theta = 40.0 * kPi / 180.0, X = 15.0, Z0 = 12.0;
  const Vec3 d(std::cos(theta), 0, std::sin(theta));
  const Vec3 cross(X, 0, 0);  // where the camera ray meets the beam's axis
  SceneDesc desc;
  desc.source = "oblique laser";
  desc.camera = ortho_camera(cross - d * Z0, cross, 1e-4, 1, 1);
  desc.time.t_start_ps = 0;
  desc.time.bin_width_ps = 10;
  desc.time.bins = 20;
  desc.media.push_back(medium("m", sigma_a, sigma_s, g, 1.0));
  desc.global_medium = 0;
  desc.lights.push_back(laser_along_x(R, P));
  const auto films = render_batches(desc, 4000, 16, /*max_depth=*/1);
  std::vector<double> totals;
  for (const auto& f : films) totals.push_back(f.total_steady().r);
  const MeanSE m = mean_se(totals);
  // The ray o + s d is within R of the x axis for |z(s)| <= R: s in Z0 -+ R / sin(theta). On it
  // the beam has run x(s) = X + (s - Z0) cos(theta).
  const double st = sigma_a + sigma_s, half = R / std::sin(theta), k = st * (1 + std::cos(theta));
  const double s0 = Z0 - half, s1 = Z0 + half;
  const double integral =
      std::exp(-st * (X - Z0 * std::cos(theta))) * (std::exp(-k * s0) - std::exp(-k * s1)) / k;
  const double expected = sigma_s * hg_eval(-std::cos(theta), g) * P / (kPi * R * R) * integral;
  INFO("MC " << m.mean << " +- " << m.se << " expected " << expected);
  CHECK(std::abs(m.mean - expected) < 1e-5 * expected);
  CHECK(m.se < 1e-6 * expected);
}

namespace {
// A laser crossing fog above a diffuse floor, hitting the floor inside the view. Radius 3 mm, not
// thin, so that camera paths also find the light scattered off the beam (which they reach only
// when a segment after a scattering crosses it) within the test's budget.
SceneDesc laser_in_fog(const char* integrator_keys) {
  return load_scene_string(std::string(R"({
    "camera": { "type": "perspective", "position": [0, 40, 200], "look_at": [0, 0, 0], "fov": 45,
                "resolution": [16, 12] },
    "time": { "t_start": 300, "bin_width": 100, "bins": 10 },
    "media": { "fog": { "type": "homogeneous", "sigma_a": 0.004, "sigma_s": 0.02, "g": 0.3)") +
                               integrator_keys + R"( } },
    "shapes": [
      { "type": "box", "min": [-59, 1, -59], "max": [59, 70, 59], "medium": "fog" },
      { "type": "quad", "corner": [-60, 0, 60], "edge1": [120, 0, 0], "edge2": [0, 0, -120],
        "material": { "type": "diffuse", "albedo": 0.7 } }
    ],
    "lights": [ { "type": "laser", "position": [-80, 60, 0], "look_at": [30, 0, -10],
                  "radius": 3, "power": 200 } ]
  })",
                           "laser in fog", ".");
}
}  // namespace

// Catches: laser chords and collision next-event estimation both counting a laser's light
// (double), or neither; a chord's time or weight wrong where the beam crosses the fog and where
// the light scattered off it is seen. And the hybrid counting the beam seen directly or its spot
// on the floor twice (light tracing splats them, and the camera path keeps its chords on its own
// segment or its next-event estimation at its first vertex) or not at all. Light tracing is the
// independent estimator: it reaches the beam by sensor connections along the laser's rays.
// Measured: collisions also doing next-event estimation to lasers, max |z| 32; the hybrid's
// camera paths keeping chords on their own segment, 50; light tracing not splatting the beam's
// collisions (its rays' connections still weighted against them), 43; nor the floor's spot, 14.
TEST_CASE("camera paths with laser chords, and the hybrid, agree with light tracing",
          "[laser][hybrid][statistical]") {
  const SceneDesc d = laser_in_fog("");
  std::string why;  // no specular surface, the camera outside the fog: light tracing alone
  CHECK(resolve_integrator(d, IntegratorKind::Auto, why) == IntegratorKind::Light);
  const Scene scene(d);
  const auto lt = cells(batches(scene, IntegratorKind::Light, 30000, 24, 800), 4, 2);
  const auto pt = cells(batches(scene, IntegratorKind::Path, 1024, 24, 700), 4, 2);
  require_agreement(pt, lt, 15);
  const auto hy = cells(batches(scene, IntegratorKind::Hybrid, 32, 24, 900), 4, 2);
  require_agreement(hy, lt, 15);
}

// Catches: the hybrid counting a laser's spot on the surface the camera sees twice (light tracing
// splats it, and the camera path keeps its next-event estimation to lasers at its first vertex)
// or not at all, on a diffuse floor and on rough metal, and the same for what the spots light
// through diffuse bounces alone (the wall behind, the floor lit by the wall: light tracing's,
// the camera paths' next-event estimation along a diffuse chain from their first vertex), with
// no medium: the spots and the light they throw are all there is. Wide beams (10 mm), so that
// camera paths find the spots often enough for a double count to show. Measured: the camera's
// next-event estimation to lasers kept at its first vertex, max |z| 47, along the diffuse chain,
// 6.3; light tracing splatting no diffuse chain, 59, and the spot on the diffuse floor only, 588.
TEST_CASE("the hybrid agrees with light tracing on laser spots", "[laser][hybrid][statistical]") {
  const Scene scene(load_scene_string(R"({
    "camera": { "type": "perspective", "position": [0, 80, 120], "look_at": [0, 0, 0], "fov": 40,
                "resolution": [16, 12] },
    "time": { "t_start": 700, "bin_width": 50, "bins": 8 },
    "shapes": [
      { "type": "quad", "corner": [-60, 0, 60], "edge1": [120, 0, 0], "edge2": [0, 0, -120],
        "material": { "type": "diffuse", "albedo": 0.7 } },
      { "type": "quad", "corner": [5, 1, 30], "edge1": [40, 0, 0], "edge2": [0, 0, -60],
        "material": { "type": "rough_conductor", "reflectance": 0.9, "roughness": 0.4 } },
      { "type": "quad", "corner": [-60, 0, -40], "edge1": [120, 0, 0], "edge2": [0, 60, 0],
        "material": { "type": "diffuse", "albedo": 0.7 } }
    ],
    "lights": [ { "type": "laser", "position": [-20, 100, 0], "direction": [0, -1, 0], "radius": 10,
                  "power": 100 },
                { "type": "laser", "position": [25, 100, 0], "look_at": [25, 0, -10], "radius": 10,
                  "power": 100 } ]
  })",
                                      "laser spots", "."));
  const auto lt = cells(batches(scene, IntegratorKind::Light, 30000, 24, 800), 2, 2);
  const auto hy = cells(batches(scene, IntegratorKind::Hybrid, 32, 24, 900), 2, 2);
  require_agreement(hy, lt, 4);
}

// Catches: a laser's beam next to the pinhole counted twice or not at all by the hybrid (max |z|
// 130 with light tracing's ball beams kept for it, 173 with no chords inside the ball). Inside
// the camera ball (core/integrators/camera_ball.h) it is the camera paths' (laser chords, exact),
// not the ball beams', whose kernel blurred it by up to 12% of a 4 x 4 pixel cell on a 32 x 24
// film at 64 passes (chi-square 76 over 30 cells); these coarser cells do not show that blur.
// The camera sits in the fog 0.8 mm from the beam's edge.
TEST_CASE("the hybrid agrees with light tracing with the camera beside a laser's beam",
          "[laser][hybrid][statistical]") {
  const SceneDesc d = load_scene_string(R"({
    "camera": { "type": "perspective", "position": [-33.2, 8.0, -9.55], "look_at": [0, -40, 0],
                "fov": 60, "resolution": [16, 12] },
    "time": { "t_start": 0, "bin_width": 100, "bins": 12 },
    "media": { "fog": { "type": "homogeneous", "sigma_a": 0.002, "sigma_s": 0.02, "g": 0.3 } },
    "shapes": [
      { "type": "box", "min": [-60, -40, -60], "max": [60, 60, 60], "medium": "fog" },
      { "type": "quad", "corner": [-100, -40, 100], "edge1": [200, 0, 0], "edge2": [0, 0, -200],
        "material": { "type": "diffuse", "albedo": 0.6 } }
    ],
    "lights": [ { "type": "laser", "position": [-100, 50, 0], "look_at": [40, -40, -20],
                  "radius": 0.5, "power": 100 } ]
  })",
                                        "camera beside a laser", ".");
  std::string why;  // the camera in the fog: the hybrid keeps the pinhole's neighbourhood
  CHECK(resolve_integrator(d, IntegratorKind::Auto, why) == IntegratorKind::Hybrid);
  const Scene scene(d);
  const auto lt = cells(batches(scene, IntegratorKind::Light, 40000, 24, 800), 4, 2);
  const auto hy = cells(batches(scene, IntegratorKind::Hybrid, 32, 24, 900), 4, 2);
  require_agreement(hy, lt, 10);
}
