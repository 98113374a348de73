// The hybrid (camera paths, light tracing, surface photons and caustic beams): agreement with
// camera paths, light tracing and all beams on scenes each can compute, its defaults, and
// determinism.
#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "agreement.h"
#include "core/integrators/photon_beams.h"
#include "core/scene_loader.h"
#include "run_femto.h"
#include "scene_builders.h"
#include "temp_dir.h"

using namespace femto;
using namespace femto::test;

namespace {

/// Fog in a box over a floor, a glass sphere inside it, and `light` (JSON) above: the camera
/// looks at the fog and the floor beside the sphere, not through it. Segment connections for the
/// point light inside the fog: next-event estimation at collisions has infinite variance there
/// (1/r^2 at a collision density ~ r^2 dr), which would make batch standard errors meaningless.
/// Even so the hybrid's cells are heavy-tailed (the beams' 1/sin(theta)): across seeds and
/// distance samplers the chi-square over 21 cells ranged 40-63 with different cells off each
/// time, so these settings (mis distances) are the ones this comparison was validated with.
SceneDesc glass_in_fog(const std::string& lights, const std::string& extra_shapes) {
  return load_scene_string(R"({
    "camera": { "type": "perspective", "position": [60, 40, 150], "look_at": [25, 20, 0], "fov": 40,
                "resolution": [16, 12] },
    "time": { "t_start": 200, "bin_width": 100, "bins": 10 },
    "media": { "fog": { "type": "homogeneous", "sigma_a": 0.002, "sigma_s": 0.015, "g": 0.3, "eta": 1.0,
                        "distance_sampling": "mis", "connection_sampling": "mis" } },
    "shapes": [
      { "type": "box", "min": [-59, 1, -59], "max": [59, 90, 59], "medium": "fog" },
      { "type": "quad", "corner": [-60, 0, 60], "edge1": [120, 0, 0], "edge2": [0, 0, -120],
        "material": { "type": "diffuse", "albedo": 0.7 } },
      { "type": "sphere", "center": [-5, 35, 0], "radius": 12, "material": { "type": "dielectric", "eta": 1.5 } })" +
                               extra_shapes + R"(
    ],
    "lights": [)" + lights + R"(]
  })",
                           "glass in fog", ".");
}

// Cells (as cells() numbers them) with a pixel whose camera rays meet the sphere (c, r): light
// tracing cannot connect a vertex to the camera through smooth glass, so it misses what the
// camera sees through the sphere (docs/outputs.md, "Integrators"); those cells are not compared.
std::vector<bool> cells_seeing_sphere(const Scene& scene, const Vec3& c, double r, int block,
                                      int group) {
  const int w = scene.desc().camera.width, h = scene.desc().camera.height;
  const int bx = (w + block - 1) / block, by = (h + block - 1) / block;
  const int bt = (scene.desc().time.bins + group - 1) / group;
  std::vector<bool> skip(static_cast<size_t>(bx * by * bt), false);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      bool sees = false;
      for (int i = 0; i <= 4; ++i)
        for (int j = 0; j <= 4; ++j) {
          const Ray ray = scene.camera().generate_ray(x + 0.25 * i, y + 0.25 * j);
          const Vec3 oc = c - ray.o;
          const double along = dot(oc, ray.d);
          sees = sees || (along > 0 && length_squared(oc - ray.d * along) < r * r);
        }
      if (!sees) continue;
      for (int t = 0; t < bt; ++t)
        skip[static_cast<size_t>(((y / block) * bx + x / block) * bt + t)] = true;
    }
  return skip;
}

}  // namespace

// Catches: caustic beams or photons double-counting light that camera paths also find, or camera
// paths dropping paths that no estimator owns: an emissive sphere behind glass in fog is
// reachable by camera paths alone, so path-only and hybrid must agree.
TEST_CASE("path-only and hybrid agree for an emissive sphere above glass in fog",
          "[hybrid][beams][statistical]") {
  const SceneDesc d = glass_in_fog("", R"(,
      { "type": "sphere", "center": [-15, 70, 0], "radius": 5, "emission": 30,
        "material": { "type": "diffuse", "albedo": 0 } })");
  const Scene scene(d);
  const PhotonDesc pd = progressive(20000, 0.8, 1.0);
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
  const PhotonDesc pd = progressive(20000, 0.8, 1.0);
  const auto pt = cells(batches(scene, IntegratorKind::Path, 512, 24, 1200), 4, 2);
  const auto hy = cells(batches(scene, IntegratorKind::Hybrid, 96, 24, 1300, pd), 4, 2);
  require_agreement(pt, hy, 8, 0.08);  // a 32% error would be 4 standard errors
}

namespace {

/// 24 hybrid renders of 64 passes (`photons` light paths per pass for the photons and caustic
/// beams) against 24 light-tracing renders of 60000 paths, cells that see the glass sphere
/// (radius 12) at `sphere` left out.
void hybrid_matches_light_tracing(const Scene& scene, const Vec3& sphere, uint64_t seed_light,
                                  uint64_t seed_hybrid, int64_t photons) {
  const PhotonDesc pd = progressive(photons, 0.8, 1.0);
  const auto lt = cells(batches(scene, IntegratorKind::Light, 60000, 24, seed_light), 4, 2);
  const auto hy = cells(batches(scene, IntegratorKind::Hybrid, 64, 24, seed_hybrid, pd), 4, 2);
  require_agreement(hy, lt, 12, 0.02, cells_seeing_sphere(scene, sphere, 12.5, 4, 2));
}

}  // namespace

// Catches: wrong normalisation or timing of caustic beams and photons (camera paths cannot reach
// light -> glass -> fog from a point light; light tracing splats every fog and floor vertex to
// the camera, which sees them directly), and fog around the nested glass sphere handled
// differently by the two (the cells that see the sphere itself are left out, see above).
TEST_CASE("hybrid agrees with light tracing on a volumetric caustic from a point light",
          "[hybrid][beams][statistical]") {
  const SceneDesc d =
      glass_in_fog(R"({ "type": "point", "position": [-30, 80, 0], "intensity": 3000 })", "");
  hybrid_matches_light_tracing(Scene(d), {-5, 35, 0}, 1000, 1100, 20000);
}

// Catches: the volumetric caustic seen directly counted twice or not at all in the hybrid (it
// belongs to light tracing's sensor connections and collision splats on the camera's own segment,
// not to the caustic beams gathered there), or a biased MIS of those connections with the
// collisions through the fog box's index-matched boundary. The spot's cone lies inside the
// sphere's silhouette and there is no floor: below the sphere the fog sees only the caustic.
TEST_CASE("hybrid agrees with light tracing on a volumetric caustic seen directly without a floor",
          "[hybrid][beams][statistical]") {
  const SceneDesc d = load_scene_string(R"({
    "camera": { "type": "perspective", "position": [0, 15, 150], "look_at": [-5, 8, 0], "fov": 40,
                "resolution": [16, 12] },
    "time": { "t_start": 300, "bin_width": 100, "bins": 8 },
    "media": { "fog": { "type": "homogeneous", "sigma_a": 0.002, "sigma_s": 0.015, "g": 0.3 } },
    "shapes": [
      { "type": "box", "min": [-59, 1, -59], "max": [59, 90, 59], "medium": "fog" },
      { "type": "sphere", "center": [-5, 45, 0], "radius": 12, "material": { "type": "dielectric", "eta": 1.5 } }
    ],
    "lights": [ { "type": "spot", "position": [-5, 85, 0], "look_at": [-5, 45, 0], "intensity": 3000,
                  "cone_angle": 16, "falloff_start": 12 } ]
  })",
                                        "caustic in fog", ".");
  // Every spot photon passes the glass, so each pass's caustic beams (long, through the whole
  // box) cost most of the render; the fog they reach is seen through the sphere, left out here.
  hybrid_matches_light_tracing(Scene(d), {-5, 45, 0}, 1400, 1500, 4000);
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

// Catches: the camera's refraction into a medium, the laser's entry or the caustic beams weighted
// differently by the hybrid (camera paths scatter in the medium and gather the laser's segments
// before its first scattering) and by all beams (camera rays pass through and gather every
// light-path segment), or unwarped time handled differently by the two: a laser entering a
// dielectric-bounded medium, as in the tissue example, must give the same light cell by cell.
// Camera paths alone cannot check it (they never reach the laser through the surface).
TEST_CASE("hybrid and beams agree for a laser entering a medium through a refracting surface",
          "[hybrid][beams][statistical]") {
  const SceneDesc d = load_scene_string(R"({
    "camera": { "type": "perspective", "position": [30, 30, 45], "look_at": [0, 0, 0], "fov": 30,
                "resolution": [16, 12] },
    "time": { "t_start": 70, "bin_width": 10, "bins": 10, "mode": "unwarp" },
    "media": { "slab": { "type": "homogeneous", "sigma_a": 0.05, "sigma_s": 0.45, "g": 0.5,
                         "eta": 1.37 } },
    "shapes": [ { "type": "box", "min": [-8, -8, -8], "max": [8, 8, 8], "medium": "slab",
                  "material": { "type": "dielectric", "eta": 1.37 } } ],
    "lights": [ { "type": "laser", "position": [0, 30, 0], "direction": [0, -1, 0], "radius": 0.5,
                  "power": 1, "pulse": { "fwhm": 2 } } ]
  })",
                                        "laser into a slab", ".");
  // Only specular surfaces: auto renders such scenes with beams, and with the hybrid once a
  // diffuse (or glossy) surface could hold a caustic.
  std::string why;
  CHECK(resolve_integrator(d, IntegratorKind::Auto, why) == IntegratorKind::Beams);
  SceneDesc with_floor = d;
  with_floor.shapes.push_back(quad({-30, -9, 30}, {60, 0, 0}, {0, 0, -60}, diffuse(0.5)));
  CHECK(resolve_integrator(with_floor, IntegratorKind::Auto, why) == IntegratorKind::Hybrid);
  const Scene scene(d);
  const PhotonDesc pd = progressive(3000, 0.5, 1.0);
  const auto bm = cells(batches(scene, IntegratorKind::Beams, 16, 16, 1200, pd), 4, 2);
  // The hybrid is heavy-tailed here (camera paths must scatter their way to the laser's first
  // segments), so its cells are noisy and the totals decide: a 17% error in the hybrid's total
  // (an index factor would be 37%) is 4 combined standard errors.
  const auto hy = cells(batches(scene, IntegratorKind::Hybrid, 96, 24, 1300, pd), 4, 2);
  require_agreement(bm, hy, 10, 0.045);
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
