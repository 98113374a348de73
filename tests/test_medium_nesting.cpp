// Nested media: which shape encloses which, the media on both sides of every surface, the
// camera's medium, and the loader's refusal of crossing or touching medium shapes.
#include <catch2/catch.hpp>

#include <cmath>
#include <string>

#include "core/constants.h"
#include "core/error.h"
#include "core/medium_nesting.h"
#include "core/render.h"
#include "core/scene.h"
#include "core/scene_loader.h"

using namespace femto;
using Catch::Matchers::Contains;

namespace {

SceneDesc nesting_scene_with(const std::string& shapes,
                             const std::string& camera_position = "[0, 0, 200]") {
  return load_scene_string(R"({
    "camera": { "type": "orthographic", "position": )" +
                               camera_position +
                               R"(, "look_at": [0, 0, -100], "width": 40, "resolution": [8, 8] },
    "time": { "t_start": 0, "bin_width": 1, "bins": 4 },
    "media": { "a": { "type": "homogeneous", "sigma_a": 0.02, "sigma_s": 0, "eta": 1.33 },
               "b": { "type": "homogeneous", "sigma_a": 0.05, "sigma_s": 0, "eta": 1.5 } },
    "shapes": [)" + shapes + R"(],
    "lights": [ { "type": "point", "position": [0, 0, 500], "intensity": 1 } ]
  })",
                           "nesting.json", ".");
}

std::string nesting_load_error(const std::string& shapes) {
  try {
    nesting_scene_with(shapes);
  } catch (const InputError& e) {
    return e.what();
  }
  FAIL("expected an InputError");
  return "";
}

const char* kBoxA =
    R"({ "type": "box", "min": [-30, -30, -20], "max": [30, 30, 20], "medium": "a" })";

}  // namespace

// Catches: a wrong containment test (parity, sphere-in-box, box-in-sphere, a rotated box) or the
// outermost instead of the innermost enclosing shape being chosen.
TEST_CASE("enclosing shapes: spheres, boxes, rotated boxes, three levels, siblings", "[nesting]") {
  const SceneDesc d = nesting_scene_with(std::string(kBoxA) + R"(,
    { "type": "sphere", "center": [0, 0, 0], "radius": 12, "medium": "b" },
    { "type": "box", "min": [-3, -3, -3], "max": [3, 3, 3], "transform": { "rotate": [20, 30, 40] },
      "material": { "type": "dielectric", "eta": 1.6 } },
    { "type": "sphere", "center": [22, 22, 10], "radius": 4, "material": { "type": "dielectric", "eta": 1.4 } },
    { "type": "sphere", "center": [-22, -22, 10], "radius": 4, "material": { "type": "diffuse", "albedo": 0.5 } },
    { "type": "quad", "corner": [-50, -50, -25], "edge1": [100, 0, 0], "edge2": [0, 100, 0],
      "material": { "type": "diffuse", "albedo": 0.5 } },
    { "type": "box", "min": [200, 0, 0], "max": [210, 10, 10], "medium": "b" },
    { "type": "sphere", "center": [0, 0, 0], "radius": 100, "medium": "a" })");
  const std::vector<int> e = enclosing_shapes(d);
  REQUIRE(e.size() == 8);
  CHECK(e[0] == 7);   // the box inside the big sphere
  CHECK(e[1] == 0);   // the sphere inside the box
  CHECK(e[2] == 1);   // the rotated box inside the sphere: innermost of three
  CHECK(e[3] == 0);   // a sibling of the sphere, in the corner of the box
  CHECK(e[4] == 0);   // an opaque sphere inside the box
  CHECK(e[5] == 7);   // a floor below the box, inside the big sphere
  CHECK(e[6] == -1);  // a box far outside everything
  CHECK(e[7] == -1);
}

// Catches: overlapping or touching medium shapes slipping through (their media would be
// undefined), and messages that do not name both shapes.
TEST_CASE("crossing or touching medium shapes are refused, naming both", "[nesting]") {
  std::string msg = nesting_load_error(
      std::string(kBoxA) +
      R"(, { "type": "box", "min": [20, 20, 0], "max": [40, 40, 10], "medium": "b" })");
  CHECK_THAT(msg, Contains("nesting.json: /shapes/0 and /shapes/1"));
  CHECK_THAT(msg, Contains("cross"));
  msg = nesting_load_error(
      std::string(kBoxA) +
      R"(, { "type": "sphere", "center": [30, 0, 0], "radius": 5, "material": { "type": "dielectric" } })");
  CHECK_THAT(msg, Contains("/shapes/0 and /shapes/1"));
  CHECK_THAT(msg, Contains("cross"));
  msg = nesting_load_error(R"({ "type": "sphere", "center": [0, 0, 0], "radius": 5, "medium": "a" },
                      { "type": "sphere", "center": [10, 0, 0], "radius": 5, "medium": "b" })");
  CHECK_THAT(msg, Contains("touch"));
  msg = nesting_load_error(
      std::string(kBoxA) +
      R"(, { "type": "box", "min": [30, -30, -20], "max": [50, 30, 20], "medium": "b" })");
  CHECK_THAT(msg, Contains("touch"));
  // A rotated box whose corners poke out of a sphere around it.
  msg = nesting_load_error(R"({ "type": "sphere", "center": [0, 0, 0], "radius": 6, "medium": "a" },
                      { "type": "box", "min": [-4, -4, -4], "max": [4, 4, 4], "transform": { "rotate": [0, 45, 0] },
                        "medium": "b" })");
  CHECK_THAT(msg, Contains("cross"));
  // Shapes without a medium may cross medium boundaries (a floor through fog).
  CHECK_NOTHROW(
      nesting_scene_with(std::string(kBoxA) + R"(, { "type": "quad", "corner": [-50, -50, 0],
      "edge1": [100, 0, 0], "edge2": [0, 100, 0], "material": { "type": "diffuse", "albedo": 0.5 } })"));
}

// Catches: the medium after leaving a nested shape falling back to the global medium (vacuum)
// instead of the enclosing one, a wrong exterior index at a nested dielectric, and a camera
// inside a medium treated as in vacuum. Absorbing media only: each pixel's radiance is
// Le exp(-sum sigma_a L) and all of it arrives at t = sum(eta L) / c, so the estimator is a
// Bernoulli variable of known variance; 4 standard errors.
TEST_CASE("transmittance and time through nested media match the analytic answer",
          "[nesting][analytic]") {
  const double La = 40, Lb = 10;  // thickness of box a along z, and of box b nested in it
  const std::string emitter = R"(, { "type": "quad", "corner": [-30, -30, -40], "edge1": [60, 0, 0],
      "edge2": [0, 60, 0], "emission": 1 })";
  for (const bool camera_inside : {false, true}) {
    // Box b covers the left half of the film (x < 0).
    SceneDesc d = nesting_scene_with(std::string(kBoxA) + R"(, { "type": "box", "min": [-25, -25, -5],
        "max": [0, 25, 5], "medium": "b" })" +
                                 emitter,
                             camera_inside ? "[0, 0, 15]" : "[0, 0, 200]");
    const double vacuum = camera_inside ? 0.0 : 200.0 - 20.0;  // camera to box a
    const double in_a = camera_inside ? 15.0 - (-20.0) : La;   // path length in box a's outline
    const double to_quad = 20.0;                               // box a's bottom to the emitter
    d.time.t_start_ps = 0;
    d.time.bin_width_ps = 1;
    d.time.bins = 1200;
    d.time_mode = TimeMode::Camera;
    const Scene scene(d);
    CHECK(scene.camera_medium() ==
          (camera_inside ? scene.inside_medium(0) : scene.global_medium()));
    RenderOptions opt;
    opt.spp = 4000;
    opt.seed = 3;
    opt.quiet = true;
    opt.integrator = IntegratorKind::Path;
    const TransientFilm film = render(scene, opt).film;
    const int T = d.time.bins;
    for (const int x : {1, 6}) {
      const bool through_b = x < 4;
      const double tau = through_b ? 0.02 * (in_a - Lb) + 0.05 * Lb : 0.02 * in_a;
      const double opl =
          vacuum + to_quad + (through_b ? 1.33 * (in_a - Lb) + 1.5 * Lb : 1.33 * in_a);
      const double expected = std::exp(-tau);
      const int bin = static_cast<int>(opl / kSpeedOfLight);
      REQUIRE(std::abs(opl / kSpeedOfLight - std::round(opl / kSpeedOfLight)) > 0.01);  // mid-bin
      const float* px =
          film.transient() + static_cast<size_t>(4 * 8 + x) * static_cast<size_t>(T) * 3;
      double total = 0;
      for (int i = 0; i < T; ++i) {
        if (i != bin) CHECK(px[3 * i] == 0.0f);
        total += px[3 * i];
      }
      const double se = std::sqrt(expected * (1 - expected) / opt.spp);
      INFO("camera inside: " << camera_inside << ", pixel " << x << ": " << total << " vs "
                             << expected << " +- " << se);
      CHECK(std::abs(total - expected) < 4 * se);
    }
  }
}
