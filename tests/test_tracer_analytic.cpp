// The tracer against closed-form answers. Each test states what bug it catches.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstring>

#include "core/constants.h"
#include "media/phase_hg.h"
#include "samplers/stats.h"
#include "scene_builders.h"
#include "single_scatter.h"

using namespace femto;
using namespace femto::test;

namespace {

// Orthographic camera looking down -z at a diffuse floor lit by a point light in an absorbing,
// non-scattering medium of index eta.
SceneDesc direct_light_scene(TimeMode mode, double eta, double sigma_a, const TimeAxis& axis) {
  SceneDesc d;
  d.source = "test";
  d.camera = ortho_camera({0, 0, 100}, {0, 0, 0}, 20.0, 5, 5);
  d.time = axis;
  d.time_mode = mode;
  d.media.push_back(medium("absorber", sigma_a, 0.0, 0.0, eta));
  d.global_medium = 0;
  d.shapes.push_back(quad({-50, -50, 0}, {100, 0, 0}, {0, 100, 0}, diffuse(0.5)));
  LightDesc l;
  l.type = LightDesc::Type::Point;
  l.position = {0, 0, 40};
  l.intensity = RGB(1000.0);
  d.lights.push_back(l);
  return d;
}

// Radiance leaving floor point (x, y, 0) towards +z: albedo/pi * I cos / r^2 * exp(-sigma_a r).
double floor_radiance(double x, double y, double sigma_a) {
  const double h = 40.0;
  const double r = std::sqrt(x * x + y * y + h * h);
  return 0.5 / kPi * 1000.0 * (h / r) / (r * r) * std::exp(-sigma_a * r);
}

}  // namespace

// Catches: wrong segment time (eta ignored, c in wrong units), wrong 1/r^2 or cosine falloff,
// missing or doubled medium attenuation on the light or camera segment, unwarp keeping the
// camera segment's time.
TEST_CASE("pulsed point light through an absorbing medium arrives at t = eta d / c", "[tracer][analytic]") {
  const double eta = 1.33, sigma_a = 0.01;
  const double t_direct = eta * 40.0 / kSpeedOfLight;  // light -> floor point below it
  TimeAxis axis;
  axis.bin_width_ps = 2.0;
  axis.t_start_ps = t_direct - 1.0 - 20 * axis.bin_width_ps;  // t_direct sits mid-bin 20
  axis.bins = 64;
  const int spp = 4096;
  const SceneDesc desc = direct_light_scene(TimeMode::Unwarp, eta, sigma_a, axis);
  const Scene scene(desc);
  RenderOptions opt;
  opt.spp = spp;
  opt.quiet = true;
  const RenderResult res = render(scene, opt);
  const TransientFilm& film = res.film;
  const int T = axis.bins;
  const double cam_att = std::exp(-sigma_a * 100.0);  // camera ray through the absorber

  // Centre pixel covers [-2, 2]^2 on the floor: all arrival times within 0.45 ps of t_direct.
  const float* px = film.transient() + (2 * 5 + 2) * static_cast<size_t>(T) * 3;
  for (int i = 0; i < T; ++i) {
    if (i == 20) continue;
    REQUIRE(px[3 * i] == 0.0f);
  }
  // Expected: footprint average of the radiance (exact 2-D quadrature); the estimate's standard
  // error is at most half the footprint's radiance range over sqrt(spp).
  const double expected =
      cam_att * stats::integrate_2d([&](double x, double y) { return floor_radiance(x, y, sigma_a); },
                                    -2, 2, -2, 2, 1e-10) / 16.0;
  const double range = cam_att * (floor_radiance(0, 0, sigma_a) - floor_radiance(2, 2, sigma_a));
  const double se_bound = 0.5 * range / std::sqrt(static_cast<double>(spp));
  CHECK(std::abs(px[3 * 20] - expected) <= 4.0 * se_bound + 1e-6 * expected);

  // Corner pixel (8, 8): energy lands only between the footprint's earliest and latest times
  // and its total matches the footprint average.
  const float* pc = film.transient() + (0 * 5 + 4) * static_cast<size_t>(T) * 3;  // row 0 = +y
  const double r_min = std::sqrt(6 * 6 + 6 * 6 + 40 * 40.0), r_max = std::sqrt(10 * 10 + 10 * 10 + 40 * 40.0);
  double sum = 0;
  for (int i = 0; i < T; ++i) {
    const double t0 = axis.bin_start_ps(i), t1 = t0 + axis.bin_width_ps;
    if (t1 < eta * r_min / kSpeedOfLight || t0 > eta * r_max / kSpeedOfLight) REQUIRE(pc[3 * i] == 0.0f);
    sum += pc[3 * i];
  }
  const double expected_c =
      cam_att * stats::integrate_2d([&](double x, double y) { return floor_radiance(x, y, sigma_a); },
                                    6, 10, 6, 10, 1e-10) / 16.0;
  const double range_c = cam_att * (floor_radiance(6, 6, sigma_a) - floor_radiance(10, 10, sigma_a));
  CHECK(std::abs(sum - expected_c) <= 4.0 * 0.5 * range_c / std::sqrt(static_cast<double>(spp)) + 1e-6 * expected_c);
}

// Catches: camera mode not adding the sensor segment's time eta * 100 / c.
TEST_CASE("camera time mode adds the last segment's time of flight", "[tracer][analytic]") {
  const double eta = 1.33;
  const double t_cam = eta * (40.0 + 100.0) / kSpeedOfLight;
  TimeAxis axis;
  axis.bin_width_ps = 2.0;
  axis.t_start_ps = t_cam - 1.0 - 10 * axis.bin_width_ps;
  axis.bins = 32;
  const Scene scene(direct_light_scene(TimeMode::Camera, eta, 0.0, axis));
  RenderOptions opt;
  opt.spp = 64;
  opt.quiet = true;
  const TransientFilm film = render(scene, opt).film;
  const float* px = film.transient() + (2 * 5 + 2) * static_cast<size_t>(axis.bins) * 3;
  for (int i = 0; i < axis.bins; ++i) {
    if (i == 10) REQUIRE(px[3 * i] > 0.0f);
    else REQUIRE(px[3 * i] == 0.0f);
  }
}

namespace {
// Closed box of six inward-facing quads, each emitting Le and reflecting diffusely with albedo
// rho; radiance everywhere inside is Le / (1 - rho) as long as the medium does not absorb.
SceneDesc furnace_scene(double rho, double Le, double sigma_s, double g) {
  SceneDesc d;
  d.source = "furnace";
  CameraDesc c;
  c.position = {0.3, -0.2, 0.1};
  c.look_at = {1, 0.5, -2};
  c.fov_deg = 60;
  c.width = 4;
  c.height = 4;
  d.camera = c;
  d.time.t_start_ps = 0;
  d.time.bin_width_ps = 200;
  d.time.bins = 100;  // 20 ns = 6 m of light travel: about 90 wall-to-wall chords
  const double a = 50;
  const MaterialDesc m = diffuse(rho);
  // Inward normals: e1 x e2 points into the box.
  d.shapes.push_back(quad({-a, -a, -a}, {2 * a, 0, 0}, {0, 2 * a, 0}, m));   // z = -a, +z
  d.shapes.push_back(quad({-a, -a, a}, {0, 2 * a, 0}, {2 * a, 0, 0}, m));    // z = +a, -z
  d.shapes.push_back(quad({-a, -a, -a}, {0, 0, 2 * a}, {2 * a, 0, 0}, m));   // y = -a, +y
  d.shapes.push_back(quad({-a, a, -a}, {2 * a, 0, 0}, {0, 0, 2 * a}, m));    // y = +a, -y
  d.shapes.push_back(quad({-a, -a, -a}, {0, 2 * a, 0}, {0, 0, 2 * a}, m));   // x = -a, +x
  d.shapes.push_back(quad({a, -a, -a}, {0, 0, 2 * a}, {0, 2 * a, 0}, m));    // x = +a, -x
  for (auto& s : d.shapes) {
    s.emissive = true;
    s.emission = RGB(Le);
  }
  if (sigma_s > 0) {
    d.media.push_back(medium("nonabsorbing", 0.0, sigma_s, g, 1.0));
    d.global_medium = 0;
  }
  return d;
}

#ifdef FEMTO_TEST_SANITIZED
// Instrumented, the furnace renders an eighth of the samples: the sanitizers look for memory and
// undefined-behaviour errors, and the Release build keeps the full test with its resolving power
// (69-78 s of the sanitizer ctest at full count).
constexpr int kFurnaceSpp = 8;
#else
constexpr int kFurnaceSpp = 64;
#endif

void check_furnace(double sigma_s, double g, bool medium_in_sphere = false) {
  const double rho = 0.5, Le = 1.0, expected = Le / (1.0 - rho);
  SceneDesc desc = furnace_scene(rho, Le, medium_in_sphere ? 0.0 : sigma_s, g);
  if (medium_in_sphere) {
    // The medium fills only an index-matched sphere beside the camera: shadow rays and paths
    // cross its boundary and switch media.
    desc.media.push_back(medium("ball", 0.0, sigma_s, g, 1.0));
    ShapeDesc ball;
    ball.type = ShapeDesc::Type::Sphere;
    ball.center = {10, 5, -15};
    ball.radius = 30;
    ball.interior_medium = static_cast<int>(desc.media.size()) - 1;
    desc.shapes.push_back(ball);
  }
  const auto films = render_batches(desc, kFurnaceSpp, 16);
  std::vector<double> means;
  double after = 0;
  for (const auto& f : films) {
    const RGB s = f.total_steady();
    means.push_back(s.g / 16.0);
    after += f.total_after().g;
    REQUIRE(s.r == s.g);  // grey scene: channels identical
  }
  const MeanSE m = mean_se(means);
  INFO("mean " << m.mean << " +- " << m.se << ", expected " << expected << ", after window " << after);
  if (kFurnaceSpp == 64) CHECK(m.se < 0.02 * expected);  // the test has resolving power
  CHECK(std::abs(m.mean - expected) < 4.0 * m.se);
}
}  // namespace

// Catches: biased NEE/MIS weights for area lights (double counting or missing emission),
// wrong cosine-sampling weight, energy gain/loss at medium scattering (phase sampling weight,
// albedo weighting), and paths being cut too early.
TEST_CASE("furnace: emissive diffuse box gives Le / (1 - rho) time-integrated", "[tracer][analytic]") {
  SECTION("vacuum") { check_furnace(0.0, 0.0); }
  SECTION("non-absorbing forward-scattering medium") { check_furnace(0.02, 0.6); }
  SECTION("non-absorbing back-scattering medium") { check_furnace(0.05, -0.4); }
  SECTION("medium inside an index-matched sphere") { check_furnace(0.08, 0.3, true); }
}

// Catches: wrong phase-function argument or convention, wrong transmittance on either segment,
// wrong time of the scattering vertex or of the connection, off-by-one bin placement.
TEST_CASE("single scattering from a point light matches 1-D quadrature bin by bin", "[tracer][analytic]") {
  SingleScatterSetup p;
  p.axis.t_start_ps = 100;
  p.axis.bin_width_ps = 10;
  p.axis.bins = 40;
  const SceneDesc d = p.scene();
  const int batches = 32;
  const auto films = render_batches(d, 20000, batches, /*max_depth=*/1);
  int checked = 0;
  for (int i = 0; i < p.axis.bins; ++i) {
    const MeanSE m = bin_mean_se(films, i);
    const double expected = p.bin(i);
    INFO("bin " << i << ": " << m.mean << " +- " << m.se << " expected " << expected);
    if (expected == 0.0) {
      CHECK(m.mean == 0.0);
      continue;
    }
    CHECK(std::abs(m.mean - expected) < 4.0 * m.se + 1e-9 * expected);
    ++checked;
  }
  CHECK(checked >= 30);
}

// Catches: tile scheduling or shared RNG state leaking into results.
TEST_CASE("renders are bit-identical for any thread count", "[tracer][determinism]") {
  SceneDesc d = furnace_scene(0.5, 1.0, 0.02, 0.3);
  d.camera.width = 37;  // not a multiple of the tile size
  d.camera.height = 21;
  d.time.bins = 50;
  const Scene scene(d);
  std::vector<TransientFilm> films;
  for (int threads : {1, 2, 3}) {
    RenderOptions opt;
    opt.spp = 3;
    opt.seed = 42;
    opt.threads = threads;
    opt.quiet = true;
    films.push_back(render(scene, opt).film);
  }
  const size_t n = static_cast<size_t>(37) * 21 * 50 * 3;
  REQUIRE(std::memcmp(films[0].transient(), films[1].transient(), n * sizeof(float)) == 0);
  REQUIRE(std::memcmp(films[0].transient(), films[2].transient(), n * sizeof(float)) == 0);
  // A different seed changes the result (the seed is actually used).
  RenderOptions opt;
  opt.spp = 3;
  opt.seed = 43;
  opt.quiet = true;
  const TransientFilm other = render(scene, opt).film;
  REQUIRE(std::memcmp(films[0].transient(), other.transient(), n * sizeof(float)) != 0);
}
