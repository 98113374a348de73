// The hybrid's camera ball (core/integrators/camera_ball.h): with the camera inside a scattering
// medium, the medium light next to the pinhole comes from the camera's own segment gathering the
// light pieces through the ball, not from light tracing's splats (whose weight diverges there).
#include <catch2/catch.hpp>

#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "agreement.h"
#include "core/constants.h"
#include "core/integrators/camera_ball.h"
#include "core/render.h"
#include "core/scene_loader.h"
#include "run_femto.h"
#include "temp_dir.h"

using namespace femto;
using namespace femto::test;

namespace {

/// Dense fog in a box, a point light and the camera inside it; the nearest surface (the floor of
/// the box) is 17 mm from the camera.
const char* kFogAroundCamera = R"({
  "camera": { "type": "perspective", "position": [40, 18, 0], "look_at": [-5, 18, 0], "fov": 50,
              "resolution": [16, 12] },
  "time": { "t_start": 0, "bin_width": 50, "bins": 40 },
  "media": { "fog": { "type": "homogeneous", "sigma_a": 0.005, "sigma_s": 0.05, "g": 0.3 } },
  "shapes": [ { "type": "box", "min": [-59, 1, -59], "max": [59, 90, 59], "medium": "fog" } ],
  "lights": [ { "type": "point", "position": [-5, 45, 0], "intensity": 3000 } ]
})";

/// 24 hybrid renders of `passes` passes with a 12 mm camera ball against 24 renders by
/// `reference` (camera paths, `ref_work` spp, or light tracing, `ref_work` paths): 4 x 4 pixel
/// cells of `group` bins.
void ball_agrees(const Scene& scene, int passes, IntegratorKind reference, int64_t ref_work,
                 uint64_t seed0, int group, int min_cells, double resolution) {
  std::vector<TransientFilm> hybrid, ref;
  SideTime ref_time, hybrid_time;
  for (int b = 0; b < 24; ++b) {
    RenderOptions opt;
    opt.seed = seed0 + static_cast<uint64_t>(b);
    opt.threads = 2;
    opt.quiet = true;
    opt.integrator = reference;
    opt.spp = reference == IntegratorKind::Light ? 1 : static_cast<int>(ref_work);
    opt.light_paths = reference == IntegratorKind::Light ? ref_work : 0;
    ref.push_back(ref_time.run([&] { return render(scene, opt).film; }));
    opt.integrator = IntegratorKind::Hybrid;
    opt.spp = passes;
    opt.light_paths = 0;
    opt.camera_ball_mm = 12;
    const RenderResult r = hybrid_time.run([&] { return render(scene, opt); });
    REQUIRE(r.photons.camera_ball_radius == 12.0);
    CHECK(r.photons.camera_ball_beams_max > 0);
    hybrid.push_back(r.film);
  }
  ref_time.log("camera ball: reference");
  hybrid_time.log("camera ball: hybrid");
  require_agreement(cells(hybrid, 4, group), cells(ref, 4, group), min_cells, resolution);
}

}  // namespace

// Catches: the camera segment's gather of the light pieces through the ball mis-weighted (their
// transmittance to the crossing, the 1-D kernel's 1 / (2 R sin theta), the share of light paths
// per pass) or mistimed, light tracing still splatting inside the ball (counted twice) or leaving
// out more than the ball (counted never), and the equiangular connections' density outside the
// ball. Here a 12 mm ball holds 30% of the image (a render without its gather measured 0.70 of
// light tracing's total), so an error of 7% in the ball's share moves the total by 4 standard
// errors. Camera paths alone are the independent estimate: no glass, a point light in the fog.
TEST_CASE("camera ball: the hybrid agrees with camera paths with the camera inside dense fog",
          "[hybrid][camera_ball][statistical]") {
  const Scene scene(load_scene_string(kFogAroundCamera, "fog around the camera", "."));
  // Work split by each side's variance x time (FEMTO_AGREEMENT_LOG=1): 256 passes against
  // 1024 spp took 1.8x the CPU time for the same combined error (0.0074 against 0.0072).
  ball_agrees(scene, 384, IntegratorKind::Path, 384, 300, 5, 30, 0.02);
}

// Catches: the gather kernel next to the pinhole blurring a caustic that passes the camera over
// the image (a fixed 6 mm radius moved 50% more light into the outer 4 x 4 blocks than light
// tracing found), or the ball's beams missing light that reached the fog through glass. The
// spot's light, focused by the sphere, passes within 12 mm of the camera; light tracing has no
// ball (the reference), so cells are 4 x 4 pixels and the sharp caustic's one-pixel blur stays
// inside them.
TEST_CASE("camera ball: the hybrid agrees with light tracing on a caustic passing the camera",
          "[hybrid][camera_ball][statistical]") {
  const Scene scene(load_scene_string(R"({
    "camera": { "type": "perspective", "position": [5, 22, 0], "look_at": [-30, 22, 0], "fov": 60,
                "resolution": [16, 12] },
    "time": { "t_start": 0, "bin_width": 50, "bins": 40 },
    "media": { "fog": { "type": "homogeneous", "sigma_a": 0.002, "sigma_s": 0.03, "g": 0.3 } },
    "shapes": [
      { "type": "box", "min": [-59, 1, -59], "max": [59, 90, 59], "medium": "fog" },
      { "type": "sphere", "center": [-5, 45, 0], "radius": 12,
        "material": { "type": "dielectric", "eta": 1.5 } } ],
    "lights": [ { "type": "spot", "position": [-5, 85, 0], "look_at": [-5, 45, 0],
                  "intensity": 3000, "cone_angle": 16, "falloff_start": 12 } ]
  })",
                                      "caustic past the camera", "."));
  // 256 passes against 400000 light paths took 1.6x the CPU time for the same combined error.
  ball_agrees(scene, 384, IntegratorKind::Light, 150000, 500, 2, 20, 0.03);
}

// Catches: the default ball not following its rule (1% of the scene's diagonal, at most half the
// way to the nearest surface), a ball for a camera outside any medium, and a nearest-surface
// distance that misses triangles' edges and faces or spheres.
TEST_CASE("camera ball: default radius and nearest surface", "[hybrid][camera_ball]") {
  SceneDesc d = load_scene_string(kFogAroundCamera, "fog around the camera", ".");
  CHECK(nearest_surface_distance(d, {40, 18, 0}) == Approx(17.0));            // the box's floor
  CHECK(nearest_surface_distance(d, {58, 89, 58}) == Approx(1.0));            // a corner's faces
  CHECK(nearest_surface_distance(d, {60, 91, 0}) == Approx(std::sqrt(2.0)));  // outside an edge
  const Scene scene(d);
  const double diag = length(Vec3(118, 89, 118));
  const CameraBall ball = camera_ball(scene, -1);
  CHECK(ball.radius == Approx(std::min(0.01 * diag, 8.5)));
  // One pixel's angle at the look_at distance (fov 50 over 12 rows), a quarter of it at the edge.
  const double pixel = 2 * std::tan(25 * kPi / 180) / 12;
  CHECK(ball.slope == Approx(pixel));
  CHECK(ball.r_min == Approx(pixel * ball.radius / 4));
  CHECK(ball.reach == Approx(ball.radius * (1 + pixel)));
  CHECK(camera_ball(scene, 0).radius == 0.0);
  CHECK(camera_ball(scene, 5).radius == 5.0);
  d.camera.position = Vec3(40, 2, 0);  // 1 mm above the box's floor: half of it
  CHECK(camera_ball(Scene(d), -1).radius == Approx(0.5));
  d.camera.position = Vec3(40, 18, 80);  // outside the box: no medium around the camera
  CHECK_FALSE(camera_ball(Scene(d), -1).active());
}

// Catches: a ball that would hold a surface accepted (camera paths gather only the camera's
// medium inside it), the flag accepted by an integrator that has no ball, and bad values of the
// scene key; each must exit 2 naming the flag or key and the value.
TEST_CASE("camera ball: bad radii are refused", "[hybrid][camera_ball][cli]") {
  TempDir tmp("femto_test_camera_ball");
  write_file(tmp.dir / "fog.json", kFogAroundCamera);
  const std::vector<std::string> base = {"render", "fog.json", "--spp",  "1",
                                         "--out",  "out",      "--quiet"};
  auto run = [&](std::vector<std::string> extra) {
    std::vector<std::string> args = base;
    args.insert(args.end(), extra.begin(), extra.end());
    return run_femto(args, tmp.dir);
  };
  Run r = run({"--integrator", "hybrid", "--camera-ball", "20"});
  CHECK(r.code == 2);
  CHECK(r.err.find("--camera-ball 20") != std::string::npos);
  CHECK(r.err.find("nearest is 17 mm") != std::string::npos);
  r = run({"--integrator", "path", "--camera-ball", "5"});
  CHECK(r.code == 2);
  CHECK(r.err.find("--camera-ball") != std::string::npos);
  r = run({"--integrator", "hybrid", "--camera-ball", "-1"});
  CHECK(r.code == 2);
  CHECK_FALSE(std::filesystem::exists(tmp.dir / "out"));
  std::string scene = kFogAroundCamera;
  scene.insert(scene.rfind('}'), R"(, "render": { "camera_ball": "big" })");
  write_file(tmp.dir / "bad.json", scene);
  r = run_femto({"render", "bad.json", "--integrator", "hybrid", "--out", "out", "--quiet"},
                tmp.dir);
  CHECK(r.code == 2);
  CHECK(r.err.find("/render/camera_ball") != std::string::npos);
  r = run({"--integrator", "hybrid", "--camera-ball", "5", "--frames", "none", "--no-previews"});
  INFO(r.err);
  CHECK(r.code == 0);
  const nlohmann::json info = nlohmann::json::parse(read_file(tmp.dir / "out" / "render.json"));
  CHECK(info["settings"]["integrator"]["light_tracing"]["camera_ball"]["radius_mm"] == 5.0);
}
