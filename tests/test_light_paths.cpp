// Light paths: light tracing against camera paths where both converge, camera paths + photons
// against camera paths and light tracing where caustics can be reached, the progressive
// schedule, and determinism of the light-side integrators.
#include <catch2/catch.hpp>

#include <cmath>
#include <string>
#include <vector>

#include "agreement.h"
#include "core/constants.h"
#include "core/integrators/ppm_schedule.h"
#include "core/scene_loader.h"
#include "media/volume_data.h"
#include "samplers/stats.h"
#include "scene_builders.h"
#include "temp_dir.h"

using namespace femto;
using namespace femto::test;

namespace {

MaterialDesc glass(double eta) {
  MaterialDesc m;
  m.type = MaterialDesc::Type::Dielectric;
  m.eta = eta;
  return m;
}

ShapeDesc sphere(const Vec3& c, double r, const MaterialDesc& m) {
  ShapeDesc s;
  s.type = ShapeDesc::Type::Sphere;
  s.center = c;
  s.radius = r;
  s.material = m;
  return s;
}

/// A point light beside and above a glass sphere over a diffuse floor; the orthographic camera
/// looks straight down at the floor where the caustic lands, and does not see the sphere.
SceneDesc caustic_scene(const TimeAxis& axis);

TimeAxis axis_of(double t0, double width, int bins) {
  TimeAxis a;
  a.t_start_ps = t0;
  a.bin_width_ps = width;
  a.bins = bins;
  return a;
}

SceneDesc caustic_scene(const TimeAxis& axis) {
  SceneDesc d;
  d.source = "caustic";
  d.camera = ortho_camera({30, 100, 0}, {30, 0, 0}, 30, 12, 12);
  d.time = axis;
  d.shapes.push_back(quad({-80, 0, 60}, {160, 0, 0}, {0, 0, -120}, diffuse(0.8)));
  d.shapes.push_back(sphere({0, 25, 0}, 12, glass(1.5)));
  d.lights.push_back(point_light({-40, 70, 0}, 5000.0));
  return d;
}

}  // namespace

// Catches: a wrong sensor importance (cos^3, pixel area, distance), a missing phase or BSDF factor
// in the camera connection, medium time taken from distance instead of OPL, or time added in the
// wrong place: light tracing and camera paths estimate the same bins only if all are right.
TEST_CASE("light tracing agrees with camera paths: fog with a point light and diffuse walls",
          "[light-paths][statistical]") {
  // The fog fills a box (kept clear of the walls: coincident faces are ambiguous) that leaves out
  // the camera and the light: a camera inside a medium gives light tracing infinite variance
  // (1 / d^2 connections from vertices next to the sensor), and a point light inside one gives
  // camera paths heavy tails (batches mostly low, seen over seed sweeps), so the batch standard
  // errors would not be trustworthy.
  const SceneDesc d = load_scene_string(R"({
    "camera": { "type": "perspective", "position": [0, 30, 140], "look_at": [0, 25, 0], "fov": 45,
                "resolution": [16, 12] },
    "time": { "t_start": 350, "bin_width": 75, "bins": 12 },
    "media": { "fog": { "type": "homogeneous", "sigma_a": 0.004, "sigma_s": 0.02, "g": 0.4, "eta": 1.33,
                        "connection_sampling": "mis" } },
    "shapes": [
      { "type": "box", "min": [-59, 1, -59], "max": [59, 60, 59], "medium": "fog" },
      { "type": "quad", "corner": [-60, 0, 60], "edge1": [120, 0, 0], "edge2": [0, 0, -120],
        "material": { "type": "diffuse", "albedo": 0.7 } },
      { "type": "quad", "corner": [-60, 0, -60], "edge1": [120, 0, 0], "edge2": [0, 80, 0],
        "material": { "type": "diffuse", "albedo": 0.5 } }
    ],
    "lights": [ { "type": "point", "position": [10, 75, -10], "intensity": 2000 } ]
  })",
                                        "fog box", ".");
  const Scene scene(d);
  const auto pt = cells(batches(scene, IntegratorKind::Path, 128, 24, 100), 4, 3);
  const auto lt = cells(batches(scene, IntegratorKind::Light, 100000, 24, 200), 4, 3);
  require_agreement(pt, lt, 15);
}

// Catches: the emitter vertex (an area light seen directly), cosines at diffuse vertices, or the
// one-sided emission of area lights handled differently on the two sides.
TEST_CASE(
    "light tracing agrees with camera paths: a diffuse room with an area light and a point light",
    "[light-paths][statistical]") {
  SceneDesc d;
  d.source = "room";
  d.camera = perspective({0, 40, 150}, {0, 35, 0}, 50, 16, 12);
  d.time = axis_of(300, 100, 10);
  d.shapes.push_back(quad({-50, 0, 50}, {100, 0, 0}, {0, 0, -100}, diffuse(0.6)));  // floor
  d.shapes.push_back(quad({-50, 0, -50}, {100, 0, 0}, {0, 80, 0}, diffuse(0.6)));   // back
  d.shapes.push_back(quad({-50, 0, 50}, {0, 0, -100}, {0, 80, 0}, diffuse(0.4)));   // left
  d.shapes.push_back(quad({50, 0, -50}, {0, 0, 100}, {0, 80, 0}, diffuse(0.4)));    // right
  ShapeDesc lamp = quad({-15, 79, -15}, {30, 0, 0}, {0, 0, 30}, MaterialDesc{});    // faces down
  lamp.emissive = true;
  lamp.emission = RGB(2.0);
  lamp.material = diffuse(0.0);
  d.shapes.push_back(lamp);
  d.lights.push_back(point_light({-20, 30, 10}, 300.0));
  const Scene scene(d);
  const auto pt = cells(batches(scene, IntegratorKind::Path, 64, 24, 300), 4, 2);
  const auto lt = cells(batches(scene, IntegratorKind::Light, 50000, 24, 400), 4, 2);
  require_agreement(pt, lt, 20);
}

// Catches: light paths and camera paths scattering off rough surfaces differently: the
// importance-mode BSDF (no 1/eta^2 on refraction), rough refraction seen by the camera through
// connections from the exit vertex, and the two-sided rough conductor.
TEST_CASE("light tracing agrees with camera paths through rough glass and off rough metal",
          "[light-paths][statistical]") {
  SceneDesc d;
  d.source = "rough";
  d.camera = perspective({0, 30, 120}, {0, 20, 0}, 45, 16, 12);
  d.time = axis_of(300, 100, 8);
  d.shapes.push_back(quad({-60, 0, 60}, {120, 0, 0}, {0, 0, -120}, diffuse(0.7)));
  MaterialDesc metal;
  metal.type = MaterialDesc::Type::RoughConductor;
  metal.reflectance = RGB(0.9, 0.7, 0.4);
  metal.roughness = 0.3;
  d.shapes.push_back(quad({-60, 0, -40}, {120, 0, 0}, {0, 70, -10}, metal));
  MaterialDesc frosted;
  frosted.type = MaterialDesc::Type::RoughDielectric;
  frosted.eta = 1.5;
  frosted.roughness = 0.3;
  d.shapes.push_back(sphere({-5, 18, 10}, 14, frosted));
  ShapeDesc lamp = quad({-20, 70, -20}, {40, 0, 0}, {0, 0, 40}, diffuse(0.0));  // faces down
  lamp.emissive = true;
  lamp.emission = RGB(3.0);
  d.shapes.push_back(lamp);
  d.lights.push_back(point_light({25, 40, 20}, 400.0));
  const Scene scene(d);
  const auto pt = cells(batches(scene, IntegratorKind::Path, 128, 24, 1400), 4, 2);
  const auto lt = cells(batches(scene, IntegratorKind::Light, 80000, 24, 1500), 4, 2);
  require_agreement(pt, lt, 15);
}

// Catches: emission sampling of spot lights (cone, falloff) and lasers (beam radius, flux), and
// pulses (Gaussian width, offset) on the light side: both lights with pulses, in fog over a floor.
TEST_CASE("light tracing agrees with camera paths for a spot light and a laser with pulses",
          "[light-paths][statistical]") {
  const SceneDesc d = load_scene_string(R"({
    "camera": { "type": "perspective", "position": [0, 40, 130], "look_at": [0, 15, 0], "fov": 45,
                "resolution": [16, 12] },
    "time": { "t_start": 300, "bin_width": 80, "bins": 12 },
    "media": { "fog": { "type": "homogeneous", "sigma_a": 0.002, "sigma_s": 0.015, "g": 0.5, "eta": 1.2,
                        "connection_sampling": "mis", "distance_sampling": "mis" } },
    "shapes": [
      { "type": "box", "min": [-59, 1, -59], "max": [59, 90, 59], "medium": "fog" },
      { "type": "quad", "corner": [-60, 0, 60], "edge1": [120, 0, 0], "edge2": [0, 0, -120],
        "material": { "type": "diffuse", "albedo": 0.7 } }
    ],
    "lights": [
      { "type": "spot", "position": [-20, 60, 0], "direction": [0.3, -1, 0], "intensity": 800,
        "cone_angle": 30, "falloff_start": 20, "pulse": { "fwhm": 60, "offset": 40 } },
      { "type": "laser", "position": [20, 70, -10], "direction": [-0.2, -1, 0.1], "radius": 4,
        "power": 300, "pulse": { "fwhm": 30 } }
    ]
  })",
                                        "spot and laser", ".");
  const Scene scene(d);
  // Light tracing's errors here are a seventh of camera paths' at the same time, so it takes few
  // paths (60000 and 320 spp gave a 10% larger combined error at twice the time).
  const auto pt = cells(batches(scene, IntegratorKind::Path, 384, 24, 1600), 4, 3);
  const auto lt = cells(batches(scene, IntegratorKind::Light, 10000, 24, 1700), 4, 3);
  require_agreement(pt, lt, 15);
}

// Catches: light paths that do not follow the per-voxel index (time from the wrong eta, or the
// voxel medium's albedo and extinction ignored on the light side).
TEST_CASE("light tracing agrees with camera paths in a voxel medium with per-voxel eta",
          "[light-paths][statistical]") {
  TempDir tmp("femto_light_paths");
  const MediumDesc m = graded_voxel_medium(tmp.dir);
  SceneDesc d;
  d.source = "voxels";
  d.camera = perspective({0, 30, 130}, {0, 25, 0}, 50, 16, 12);
  d.time = axis_of(300, 100, 10);
  d.media.push_back(m);
  d.global_medium = 0;
  d.shapes.push_back(quad({-60, 0, 60}, {120, 0, 0}, {0, 0, -120}, diffuse(0.6)));
  d.lights.push_back(point_light({0, 80, 0}, 3000.0));  // above the grid: finite-variance NEE
  const Scene scene(d);
  const auto pt = cells(batches(scene, IntegratorKind::Path, 64, 24, 500), 4, 2);
  const auto lt = cells(batches(scene, IntegratorKind::Light, 50000, 24, 600), 4, 2);
  require_agreement(pt, lt, 15);
}

// Catches: photons stored or gathered with the wrong normalisation or time, the caustic partition
// dropping or double-counting paths (camera paths cannot reach light -> glass -> floor from a
// point light at all, so both estimators here see caustics through different techniques).
TEST_CASE("camera paths + photons agree with light tracing on a caustic from a point light",
          "[light-paths][statistical]") {
  const Scene scene(caustic_scene(axis_of(250, 60, 8)));
  const PhotonDesc pd = progressive(4000, 0.5, 1.0);
  const auto ph = cells(batches(scene, IntegratorKind::Photons, 16, 24, 700, pd), 3, 2);
  const auto lt = cells(batches(scene, IntegratorKind::Light, 40000, 24, 800), 3, 2);
  require_agreement(ph, lt, 10);
}

// Catches: without a scattering medium, the hybrid (auto's choice there) dropping or double
// counting the caustic seen directly (light tracing's splats; no photons at the camera's first
// vertex), or failing when it traces no caustic beams (max |z| 53 without the splat). The photons
// test above checks the photons themselves on the same scene.
TEST_CASE("the hybrid without a medium agrees with light tracing on a caustic from a point light",
          "[light-paths][hybrid][statistical]") {
  const SceneDesc d = caustic_scene(axis_of(250, 60, 8));
  std::string why;
  CHECK(resolve_integrator(d, IntegratorKind::Auto, why) == IntegratorKind::Hybrid);
  const Scene scene(d);
  {  // No scattering medium: no caustic beams are traced, light tracing's share is.
    RenderOptions opt;
    opt.integrator = IntegratorKind::Hybrid;
    opt.spp = 2;
    opt.threads = 2;
    opt.quiet = true;
    const RenderResult r = render(scene, opt);
    CHECK_FALSE(r.photons.hybrid_beams);
    CHECK(r.photons.seconds_beams == 0);
    CHECK(r.photons.hybrid_light_paths > 0);
  }
  // The cells compared hold little of the photons' light (a camera path's second diffuse
  // vertex): 400 paths a pass gave the same errors to four digits at 2.3x the hybrid's CPU time.
  const PhotonDesc pd = progressive(100, 0.5, 1.0);
  const auto hy = cells(batches(scene, IntegratorKind::Hybrid, 1024, 24, 730, pd), 3, 2);
  const auto lt = cells(batches(scene, IntegratorKind::Light, 80000, 24, 830), 3, 2);
  require_agreement(hy, lt, 10);
}

// Catches: camera paths still counting light -> glass -> floor -> camera when photons are on
// (double counting), or dropping other paths: an emissive sphere behind glass is reachable by
// camera paths alone, so path-only and path + photons must agree.
TEST_CASE("path-only and path + photons agree for an emissive sphere behind glass",
          "[light-paths][statistical]") {
  SceneDesc d;
  d.source = "partition";
  d.camera = perspective({0, 60, 90}, {0, 0, 0}, 50, 16, 12);
  d.time = axis_of(250, 150, 6);
  d.shapes.push_back(quad({-60, 0, 60}, {120, 0, 0}, {0, 0, -120}, diffuse(0.8)));
  d.shapes.push_back(sphere({0, 20, 0}, 10, glass(1.5)));
  ShapeDesc lamp = sphere({0, 55, 0}, 6, diffuse(0.0));
  lamp.emissive = true;
  lamp.emission = RGB(20.0);
  d.shapes.push_back(lamp);
  std::string why;  // no delta light: camera paths reach everything, so auto keeps them
  CHECK(resolve_integrator(d, IntegratorKind::Auto, why) == IntegratorKind::Path);
  const Scene scene(d);
  // The photon side's error is mostly its camera part: 20000 photons a pass instead of 10000
  // took its standard error from 0.0051 to 0.0048 at twice its time.
  const PhotonDesc pd = progressive(10000, 0.8, 1.0);
  const auto pt = cells(batches(scene, IntegratorKind::Path, 64, 24, 900), 4, 2);
  const auto ph = cells(batches(scene, IntegratorKind::Photons, 64, 24, 1000, pd), 4, 2);
  require_agreement(pt, ph, 15);
}

// Catches: a schedule that does not shrink, or shrinks the wrong power: R^2 T must fall by
// (j + alpha) / (j + 1) per pass, R^2 by its beta_R = 1 - beta_T power and T by beta_T.
TEST_CASE("progressive radius and bandwidth follow the schedule", "[light-paths]") {
  const double alpha = 4.0 / 7.0, beta_t = 1.0 / 3.0;
  PpmSchedule s(2.0, 10.0, alpha, beta_t);
  double volume = 4.0 * 10.0;
  for (int j = 1; j < 200; ++j) {
    const double before_r2 = s.radius() * s.radius(), before_T = s.bandwidth();
    s.advance();
    const double ratio = (j + alpha) / (j + 1.0);
    volume *= ratio;
    CHECK(s.radius() * s.radius() * s.bandwidth() == Approx(volume).epsilon(1e-12));
    CHECK(s.radius() * s.radius() / before_r2 ==
          Approx(std::pow(ratio, 1 - beta_t)).epsilon(1e-12));
    CHECK(s.bandwidth() / before_T == Approx(std::pow(ratio, beta_t)).epsilon(1e-12));
  }
  // The product telescopes to Gamma(n + alpha) / (Gamma(1 + alpha) Gamma(n + 1)) ~ n^(alpha - 1).
  const double n = 200;
  CHECK(volume / 40.0 ==
        Approx(std::exp(std::lgamma(n + alpha) - std::lgamma(1 + alpha) - std::lgamma(n + 1)))
            .epsilon(1e-9));
}

// Catches: photon-mapping bias that does not go away: at a caustic's sharp edge the disc kernel
// blurs light out of the caustic; with the progressive schedule the radius shrinks and the
// estimate of the edge region must move towards the unbiased light-tracing answer.
TEST_CASE("the photon estimate's bias shrinks as passes go on", "[light-paths][statistical]") {
  const Scene scene(caustic_scene(axis_of(0, 2000, 1)));
  const int W = 12;
  auto pixel = [&](const TransientFilm& f, int x, int y) {
    return f.steady()[3 * static_cast<size_t>(y * W + x) + 1];
  };
  // The reference's error decides the checks below (with 100000 light paths a render it was 36x
  // and 7x the two photon renders'), and light paths are cheap: 400000 a render, and 10000
  // photons a pass (half as many as before, for the same passes and so the same kernel bias).
  const auto ref_films = batches(scene, IntegratorKind::Light, 400000, 12, 1100);
  // The caustic's peak: the brightest 2 x 2 block of the unbiased light-tracing answer.
  int bx = 0, by = 0;
  double best = -1;
  for (int y = 0; y + 1 < W; ++y)
    for (int x = 0; x + 1 < W; ++x) {
      double s = 0;
      for (const auto& f : ref_films)
        s += pixel(f, x, y) + pixel(f, x + 1, y) + pixel(f, x, y + 1) + pixel(f, x + 1, y + 1);
      if (s > best) best = s, bx = x, by = y;
    }
  auto core = [&](const TransientFilm& f) {
    return pixel(f, bx, by) + pixel(f, bx + 1, by) + pixel(f, bx, by + 1) +
           pixel(f, bx + 1, by + 1);
  };
  std::vector<double> ref;
  for (const auto& f : ref_films) ref.push_back(core(f));
  const MeanSE r = mean_se(ref);
  PhotonDesc fixed;
  fixed.per_pass = 10000;
  fixed.radius = 4.0;
  fixed.bandwidth_ps = 100;
  fixed.alpha = 1.0;  // no shrinking: every pass keeps the first pass's bias
  PhotonDesc progressive = fixed;
  progressive.alpha = 0.3;  // fast shrinking, to resolve the change within a short test
  std::vector<double> a, b;
  for (const auto& f : batches(scene, IntegratorKind::Photons, 48, 8, 1200, fixed))
    a.push_back(core(f));
  for (const auto& f : batches(scene, IntegratorKind::Photons, 48, 8, 1300, progressive))
    b.push_back(core(f));
  const MeanSE fa = mean_se(a), fb = mean_se(b);
  const double bias_fixed = fa.mean - r.mean, bias_prog = fb.mean - r.mean;
  INFO("peak block at " << bx << "," << by << ": reference " << r.mean << " +- " << r.se
                        << ", fixed radius " << fa.mean << " +- " << fa.se << ", progressive "
                        << fb.mean << " +- " << fb.se);
  // The wide fixed kernel blurs light out of the peak (significantly); shrinking removes much of
  // it.
  REQUIRE(bias_fixed < -4.0 * std::hypot(fa.se, r.se));
  CHECK(std::abs(bias_prog) < 0.6 * std::abs(bias_fixed));
  CHECK(bias_prog - bias_fixed > 4.0 * std::hypot(fa.se, fb.se));
}

// Catches: splat order or photon order depending on how work is split between threads.
TEST_CASE("light tracing and photon mapping are bit-identical for 1 and 2 threads",
          "[light-paths]") {
  SceneDesc d;
  d.source = "determinism";
  d.camera = perspective({0, 30, 100}, {0, 10, 0}, 50, 12, 10);
  d.time = axis_of(200, 100, 8);
  d.media.push_back(medium("fog", 0.002, 0.01, 0.3, 1.2));
  d.global_medium = 0;
  d.shapes.push_back(quad({-60, 0, 60}, {120, 0, 0}, {0, 0, -120}, diffuse(0.8)));
  d.shapes.push_back(sphere({0, 20, 0}, 10, glass(1.5)));
  d.lights.push_back(point_light({0, 50, 0}, 2000.0));
  const Scene scene(d);
  for (IntegratorKind kind : {IntegratorKind::Light, IntegratorKind::Photons}) {
    std::vector<std::vector<float>> out;
    for (int threads : {1, 2}) {
      RenderOptions opt;
      opt.integrator = kind;
      opt.spp = 4;
      opt.light_paths = 30000;
      opt.photons.per_pass = 5000;
      opt.threads = threads;
      opt.quiet = true;
      const RenderResult res = render(scene, opt);
      const float* v = res.film.transient();
      out.emplace_back(
          v, v + static_cast<size_t>(res.film.width() * res.film.height() * res.film.bins() * 3));
    }
    CHECK(out[0] == out[1]);
  }
}
