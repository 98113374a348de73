// The hybrid (camera paths, light tracing, surface photons and caustic beams): agreement with
// camera paths on scenes they can compute, determinism, its defaults and its light-traced share.
// Agreement with light tracing and all beams: tests/test_hybrid_light_tracing.cpp.
#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "agreement.h"
#include "core/integrators/photon_beams.h"
#include "core/scene_loader.h"
#include "hybrid_scenes.h"
#include "run_femto.h"
#include "scene_builders.h"
#include "temp_dir.h"

using namespace femto;
using namespace femto::test;

// Catches: paths lost, or counted twice, between the hybrid's camera paths and its light tracing
// where they carry a visible share of a cell: an emissive sphere above glass in fog is reachable
// by camera paths alone, so path-only and hybrid must agree. Not the weight of its caustic beams
// and photons: they gather a small share here (8 passes: 26 beam and 5 photon gathers), and twice
// their weight failed nothing (the laser test in tests/test_hybrid_light_tracing.cpp checks the
// caustic beams' weight). So they take 2500 paths a pass: 10000 gave the same errors to three
// digits at 3.9x the hybrid's CPU time.
TEST_CASE("path-only and hybrid agree for an emissive sphere above glass in fog",
          "[hybrid][beams][statistical]") {
  const SceneDesc d = glass_in_fog("", R"(,
      { "type": "sphere", "center": [-15, 70, 0], "radius": 5, "emission": 30,
        "material": { "type": "diffuse", "albedo": 0 } })");
  const Scene scene(d);
  const PhotonDesc pd = progressive(2500, 0.8, 1.0);
  const auto pt = cells(batches(scene, IntegratorKind::Path, 192, 24, 800), 4, 2);
  const auto hy = cells(batches(scene, IntegratorKind::Hybrid, 64, 24, 900, pd), 4, 2);
  require_agreement(pt, hy, 12, 0.025);  // a 10% error would be 4 standard errors
}

// Catches: light scattered in fog, or off a diffuse ceiling, and refracted by glass onto a diffuse
// surface (light -> X* M S S -> D -> camera, light -> X* D S S -> D -> camera) lost or counted
// twice between the hybrid's light paths and its camera paths. The fog and the ceiling lie above a
// black plate with a square hole; a glass sphere fills the hole from below. The emitter, just
// above the plate and far from the hole, cannot light anything under the plate directly: the
// floor there sees the fog and the ceiling only through the hole, mostly through the glass.
// Photons and caustic beams take 2500 paths a pass: 10000 gave the same cells to four digits.
TEST_CASE("path-only and hybrid agree on fog and ceiling light refracted onto the floor",
          "[hybrid][beams][statistical]") {
  const SceneDesc d = load_scene_string(R"({
    "camera": { "type": "perspective", "position": [-80, 15, 90], "look_at": [-5, 0, 0], "fov": 30,
                "resolution": [16, 12] },
    "time": { "t_start": 200, "bin_width": 100, "bins": 10 },
    "media": { "fog": { "type": "homogeneous", "sigma_a": 0.002, "sigma_s": 0.03, "g": 0.3, "eta": 1.0,
                        "distance_sampling": "mis", "connection_sampling": "mis" } },
    "shapes": [
      { "type": "box", "min": [-59, 56, -59], "max": [59, 89, 59], "medium": "fog" },
      { "type": "quad", "corner": [-60, 90, -60], "edge1": [120, 0, 0], "edge2": [0, 0, 120],
        "material": { "type": "diffuse", "albedo": 0.8 } },
      { "type": "quad", "corner": [-60, 0, 60], "edge1": [120, 0, 0], "edge2": [0, 0, -120],
        "material": { "type": "diffuse", "albedo": 0.7 } },
      { "type": "quad", "corner": [-60, 55, 60], "edge1": [45, 0, 0], "edge2": [0, 0, -120],
        "material": { "type": "diffuse", "albedo": 0 } },
      { "type": "quad", "corner": [5, 55, 60], "edge1": [55, 0, 0], "edge2": [0, 0, -120],
        "material": { "type": "diffuse", "albedo": 0 } },
      { "type": "quad", "corner": [-15, 55, 60], "edge1": [20, 0, 0], "edge2": [0, 0, -50],
        "material": { "type": "diffuse", "albedo": 0 } },
      { "type": "quad", "corner": [-15, 55, -10], "edge1": [20, 0, 0], "edge2": [0, 0, -50],
        "material": { "type": "diffuse", "albedo": 0 } },
      { "type": "sphere", "center": [-5, 42, 0], "radius": 12, "material": { "type": "dielectric", "eta": 1.5 } },
      { "type": "sphere", "center": [35, 65, 0], "radius": 5, "emission": 64,
        "material": { "type": "diffuse", "albedo": 0 } }
    ]
  })",
                                        "fog above a hole", ".");
  const Scene scene(d);
  const PhotonDesc pd = progressive(2500, 0.8, 1.0);
  const auto pt = cells(batches(scene, IntegratorKind::Path, 512, 24, 1200), 4, 2);
  const auto hy = cells(batches(scene, IntegratorKind::Hybrid, 96, 24, 1300, pd), 4, 2);
  require_agreement(pt, hy, 8, 0.08);  // a 32% error would be 4 standard errors
}

// Catches: the hybrid's light-traced splats (medium vertices after a scattering, traced in chunks
// and binned per pixel) or its photons and beams summed in an order that depends on the threads.
TEST_CASE("the hybrid is bit-identical for 1 and 2 threads", "[hybrid][beams]") {
  const Scene scene(
      glass_in_fog(R"({ "type": "point", "position": [-30, 80, 0], "intensity": 3000 })", ""));
  std::vector<std::vector<float>> out;
  for (int threads : {1, 2}) {
    RenderOptions opt;
    opt.integrator = IntegratorKind::Hybrid;
    opt.spp = 3;
    opt.photons.per_pass = 3000;
    opt.threads = threads;
    opt.quiet = true;
    const RenderResult res = render(scene, opt);
    REQUIRE(res.stats.light_paths > 0);
    const float* v = res.film.transient();
    out.emplace_back(
        v, v + static_cast<size_t>(res.film.width() * res.film.height() * res.film.bins() * 3));
  }
  CHECK(out[0] == out[1]);
}

TEST_CASE("hybrid: caustic beams default to a pixel's footprint, fewer paths and photons per pass",
          "[hybrid][beams]") {
  // In the hybrid the caustic beams carry focused light and little of a pass's variance: 1% of
  // the diagonal blurred the default scene's volumetric caustic, and 20000 paths per pass cost
  // half of each pass for nothing, 3072 still a fifth of it (docs/PERFORMANCE.md).
  CHECK(default_caustic_beam_paths_per_pass(256 * 192) == 500);
  CHECK(default_caustic_beam_paths_per_pass(1024 * 1024) == 8192);
  CHECK(default_caustic_beam_paths_per_pass(4096 * 4096) == 20000);
  // Its photons: one per two pixels per pass, within [10000, 200000]; its light paths for light
  // tracing's share: one per four pixels (each also connects its medium rays to the sensor).
  CHECK(default_hybrid_photons_per_pass(256 * 192) == 24576);
  CHECK(default_hybrid_photons_per_pass(40 * 24) == 10000);
  CHECK(default_hybrid_photons_per_pass(1024 * 1024) == 200000);
  CHECK(default_hybrid_light_paths_per_pass(256 * 192) == 12288);
  CHECK(default_hybrid_light_paths_per_pass(1) == 1);
  SceneDesc d = load_scene_string(R"({
    "camera": { "position": [0, 0, 100], "look_at": [0, 0, 0], "fov": 40, "resolution": [256, 192] },
    "time": { "t_start": 0, "bin_width": 10, "bins": 10 },
    "media": { "fog": { "type": "homogeneous", "sigma_a": 0.01, "sigma_s": 0.1 } },
    "shapes": [ { "type": "box", "min": [-300, -300, -300], "max": [300, 300, 300], "medium": "fog" } ],
    "lights": [ { "type": "point", "position": [0, 0, 0], "intensity": 1 } ]
  })",
                                  "fog box", ".");
  // One pixel at the look-at distance: 100 mm x 2 tan(20 deg) / 192 pixels.
  const double footprint = 100.0 * 2.0 * std::tan(20.0 * 3.14159265358979323846 / 180.0) / 192.0;
  CHECK(pixel_footprint_mm(d.camera) == Approx(footprint).epsilon(1e-12));
  const PhotonDesc hybrid = progressive_settings(Scene(d), IntegratorKind::Hybrid, PhotonDesc{});
  CHECK(hybrid.radius == Approx(footprint).epsilon(1e-12));
  CHECK(hybrid.per_pass == 500);
  CHECK(hybrid.alpha == Approx(2.0 / 3.0));
  // `beams` keeps 1% of the diagonal; a small scene keeps it for caustic beams too.
  const double diag = std::sqrt(3.0) * 600.0;
  CHECK(progressive_settings(Scene(d), IntegratorKind::Beams, PhotonDesc{}).radius ==
        Approx(0.01 * diag));
  d.camera.position = {0, 0, 10000};
  CHECK(progressive_settings(Scene(d), IntegratorKind::Hybrid, PhotonDesc{}).radius ==
        Approx(0.01 * diag));
}

// Catches: the hybrid's light-traced share ignoring `light_paths` (the scene key or
// --light-paths), spreading it over the passes wrongly, or render.json not saying what was used.
TEST_CASE("hybrid: light_paths sets its light-traced share per pass", "[hybrid][cli]") {
  RenderOptions opt;
  opt.spp = 4;
  CHECK(hybrid_light_paths_per_pass(opt, 256 * 192) == 12288);  // unset: one per four pixels
  opt.light_paths = 1000;
  CHECK(hybrid_light_paths_per_pass(opt, 256 * 192) == 250);
  opt.light_paths = 1002;  // 250.5 a pass: the nearest, halves up
  CHECK(hybrid_light_paths_per_pass(opt, 256 * 192) == 251);
  opt.light_paths = 1;  // at least one a pass
  CHECK(hybrid_light_paths_per_pass(opt, 256 * 192) == 1);

  // Glass in fog, no diffuse surface: a pass traces its caustic beam paths (--photons) and its
  // light-traced share, and nothing else, so the light paths counted give the share per pass.
  TempDir tmp("femto_test_hybrid_share");
  const std::string scene = R"({
    "camera": { "position": [0, 0, 120], "look_at": [0, 0, 0], "fov": 30, "resolution": [20, 12] },
    "time": { "t_start": 300, "bin_width": 50, "bins": 8 },
    "media": { "fog": { "type": "homogeneous", "sigma_a": 0.002, "sigma_s": 0.02 } },
    "medium": "fog",
    "shapes": [ { "type": "sphere", "center": [0, 0, 0], "radius": 10,
                  "material": { "type": "dielectric", "eta": 1.5 } } ],
    "lights": [ { "type": "point", "position": [0, 40, 0], "intensity": 100 } ],
    "render": { "light_paths": 3001 }
  })";
  write_file(tmp.dir / "glass.json", scene);
  struct Case {
    std::vector<std::string> flags;
    uint64_t per_pass;
    const char* set_by;
  };
  const Case cases[] = {{{}, 1501, "light_paths"},  // the scene's 3001 over 2 passes
                        {{"--light-paths", "600"}, 300, "light_paths"}};
  for (const Case& c : cases) {
    const std::filesystem::path out = tmp.dir / "out";
    std::vector<std::string> args = {
        "render", "glass.json", "--spp", "2",       "--integrator", "hybrid", "--photons",
        "500",    "--out",      "out",   "--quiet", "--frames",     "none",   "--no-previews"};
    args.insert(args.end(), c.flags.begin(), c.flags.end());
    const Run r = run_femto(args, tmp.dir);
    INFO(r.err);
    REQUIRE(r.code == 0);
    const nlohmann::json info = nlohmann::json::parse(read_file(out / "render.json"));
    const nlohmann::json& share = info["settings"]["integrator"]["light_tracing"];
    CHECK(share["light_paths_per_pass"].get<uint64_t>() == c.per_pass);
    CHECK(share["set_by"] == c.set_by);
    CHECK(info["counters"]["light_paths"].get<uint64_t>() == 2u * (500u + c.per_pass));
    std::filesystem::remove_all(out);
  }
}
