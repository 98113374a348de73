// femto-bench-caustics: equal-time error on the caustic under the default scene's glass sphere.
// Estimators: camera paths with the spot light replaced by a small emissive sphere of the same
// radiant intensity (camera paths cannot reach a spot light through glass at all), inside a black
// cone of the spot's angle (the fair baseline) and open; light tracing; and the photons, hybrid
// and beams integrators. Each is compared with a long
// light-tracing reference of its own scene over a crop of floor pixels around the caustic that
// see no glass (light tracing cannot see through glass, so its reference is complete there).
// Reports relative RMSE of the steady crop and of the crop's time bins at (nearly) equal wall
// time, plus the equal-time error ratios.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

#include "bench/bench_util.h"
#include "bench/caustics_errors.h"
#include "bench/caustics_scenes.h"
#include "core/default_scene.h"
#include "core/render.h"
#include "core/scene_loader.h"

using namespace femto;
using femto::bench::average;
using femto::bench::blocks;
using femto::bench::cpu_model;
using femto::bench::Errors;
using femto::bench::errors;
using femto::bench::glass_blocks;
using femto::bench::housed_emitter_scene;
using femto::bench::mean_of;
using femto::bench::median_of;
using femto::bench::now_s;
using femto::bench::pixel_sees_sphere;
using femto::bench::Reference;
using femto::bench::sphere_emitter_scene;

namespace {

struct Options {
  double seconds = 20;     ///< wall-time budget per estimator
  double ref_paths = 2e8;  ///< light paths of each reference
  int threads = 2;
  int x0 = 96, y0 = 136, x1 = 160, y1 = 180;  ///< crop (pixels, end exclusive)
  uint64_t seed = 7;
  /// Renders per estimator (seeds seed, seed + 1, ...; default-scene mode): errors are the RMS
  /// over them, seconds their mean. Heavy-tailed estimators need several for a steady figure.
  int seeds = 1;
  /// The hybrid's light-traced share, in light paths per pixel per pass: one hybrid line per
  /// value (default-scene mode; 0 = its default, one per four pixels).
  std::vector<double> hybrid_light_paths = {0.0};
  /// The hybrid's camera ball radius, mm: one hybrid line per value and share (-1: the default
  /// rule, 0: none).
  std::vector<double> hybrid_camera_balls = {-1.0};
};

/// Parses "X,Y,..." into `out`: numbers in [lo, hi]; false on an empty or bad item.
bool number_list(const std::string& v, double lo, double hi, std::vector<double>& out) {
  out.clear();
  size_t at = 0;
  while (at <= v.size()) {
    const size_t comma = std::min(v.find(',', at), v.size());
    char* end = nullptr;
    const std::string item = v.substr(at, comma - at);
    const double x = std::strtod(item.c_str(), &end);
    if (item.empty() || *end != '\0' || !(x >= lo) || x > hi) return false;
    out.push_back(x);
    at = comma + 1;
  }
  return true;
}

/// Crop pixels whose camera rays (centre and corners) miss the glass sphere.
std::vector<int> crop_pixels(const Scene& scene, const Options& o, const ShapeDesc& glass) {
  std::vector<int> px;
  const Camera& cam = scene.camera();
  for (int y = o.y0; y < o.y1; ++y)
    for (int x = o.x0; x < o.x1; ++x)
      if (!pixel_sees_sphere(cam, x, y, glass)) px.push_back(y * cam.width() + x);
  return px;
}

/// `per_pixel`: the hybrid's light paths per pixel per pass (0: its default); `ball`: its camera
/// ball radius (-1: the default rule).
RenderResult run(const Scene& scene, IntegratorKind kind, int64_t work, const Options& o,
                 uint64_t seed, double per_pixel = 0, double ball = -1) {
  RenderOptions opt;
  opt.camera_ball_mm = ball;
  opt.integrator = kind;
  opt.spp = kind == IntegratorKind::Light ? 1 : static_cast<int>(std::max<int64_t>(1, work));
  opt.light_paths = kind == IntegratorKind::Light ? work : 0;
  if (kind == IntegratorKind::Hybrid && per_pixel > 0)
    opt.light_paths = std::max<int64_t>(
        1, std::llround(per_pixel * scene.camera().width() * scene.camera().height() * opt.spp));
  opt.photons = scene.desc().integrator.photons;
  opt.threads = o.threads;
  opt.seed = seed;
  opt.quiet = true;
  return render(scene, opt);
}

/// Work (spp, passes or light paths) that takes about o.seconds, from a short calibration run.
int64_t work_for_budget(const Scene& scene, IntegratorKind kind, const Options& o,
                        double per_pixel = 0, double ball = -1) {
  const int64_t pixels = static_cast<int64_t>(scene.camera().width()) * scene.camera().height();
  // One pass of all beams is slow in this large, thin fog: probe with one.
  const int64_t probe = kind == IntegratorKind::Light   ? 4 * pixels
                        : kind == IntegratorKind::Beams ? 1
                                                        : 4;
  const double t0 = now_s();
  run(scene, kind, probe, o, 999, per_pixel, ball);
  const double dt = now_s() - t0;
  return std::max<int64_t>(1, static_cast<int64_t>(static_cast<double>(probe) * o.seconds / dt));
}

/// A scene file whose light camera paths cannot reach (the tissue example: a laser behind a
/// refracting surface): hybrid, beams and camera paths against a long beams reference (two
/// halves), over blocks of 8 x 8 pixels and 4 bins whose reference is above 1% of the brightest
/// block and that see no glass sphere. With a single spot light, also camera paths with the spot
/// replaced by a 2 mm emitter in a black housing of the spot's cone (which camera paths can
/// reach through glass), against a beams reference of that scene.
int run_scene_file(const std::string& file, const Options& o, int ref_passes, int width,
                   int height) {
  SceneDesc desc;
  try {
    desc = load_scene_file(file);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "femto-bench-caustics: %s\n", e.what());
    return 2;
  }
  if (width > 0) desc.camera.width = width, desc.camera.height = height;
  const Scene scene(desc);
  constexpr int kBlock = 8, kGroup = 4;
  std::printf(
      "scene %s at %d x %d; reference: beams, two halves of %d passes; blocks of %d x %d "
      "pixels and %d bins\n",
      file.c_str(), desc.camera.width, desc.camera.height, ref_passes, kBlock, kBlock, kGroup);
  std::fflush(stdout);
  struct BlockReference {
    Reference ref;
    std::vector<int> lit;  ///< blocks above 1% of the brightest
  };
  const std::vector<bool> glass = glass_blocks(scene, kBlock);
  auto reference = [&](const Scene& sc, uint64_t seed, const char* name, int passes) {
    const double t0 = now_s();
    const Reference a =
        blocks(run(sc, IntegratorKind::Beams, passes, o, seed).film, kBlock, kGroup);
    const Reference b =
        blocks(run(sc, IntegratorKind::Beams, passes, o, seed + 1).film, kBlock, kGroup);
    BlockReference r{average(a, b), {}};
    const size_t n_blocks = r.ref.steady.size() / 3;
    double peak = 0;
    for (size_t q = 0; q < n_blocks; ++q)
      peak =
          std::max(peak, r.ref.steady[3 * q] + r.ref.steady[3 * q + 1] + r.ref.steady[3 * q + 2]);
    for (size_t q = 0; q < n_blocks; ++q)
      if (r.ref.steady[3 * q] + r.ref.steady[3 * q + 1] + r.ref.steady[3 * q + 2] > 0.01 * peak &&
          !glass[q])
        r.lit.push_back(static_cast<int>(q));
    const Errors e_ref = errors(a.steady.data(), a.transient.data(), b, r.lit);
    std::printf(
        "%s reference (2 x %d passes) took %.0f s; %zu of %zu blocks above 1%% of the "
        "brightest and not seeing glass; its own relative RMSE: steady %.4f, transient %.4f\n",
        name, passes, now_s() - t0, r.lit.size(), n_blocks, e_ref.steady / 2, e_ref.transient / 2);
    std::fflush(stdout);
    return r;
  };
  const BlockReference ref = reference(scene, o.seed + 100, "scene", ref_passes);
  // A single spot light: also camera paths with it replaced by a small housed emitter (the
  // spot's cone, a convergent camera-path baseline for light behind glass), against a beams
  // reference of that scene.
  const bool spot = desc.lights.size() == 1 && desc.lights.front().type == LightDesc::Type::Spot;
  std::optional<Scene> housed;
  BlockReference ref_housed;
  if (spot) {
    // Its Lambertian sphere sends only (1 - cos theta) / 2 of its power out of the housing's
    // opening: as many light paths leave it per pass as leave the spot when it emits that much
    // more (else its reference would take far more passes, each with a smaller radius).
    SceneDesc hd = housed_emitter_scene(desc, 2.0);
    const double theta = desc.lights.front().cone_angle_deg * 3.14159265358979323846 / 180.0;
    const int64_t per_pass =
        progressive_settings(scene, IntegratorKind::Beams, desc.integrator.photons).per_pass;
    hd.integrator.photons.per_pass =
        static_cast<int64_t>(static_cast<double>(per_pass) / (0.5 * (1.0 - std::cos(theta))));
    housed.emplace(hd);
    ref_housed = reference(*housed, o.seed + 200, "housed-emitter scene", ref_passes);
  }
  std::printf("\n%-22s %8s %9s %13s %16s %28s\n", "estimator", "passes", "seconds", "steady rRMSE",
              "transient rRMSE", "equal-time steady / transient");
  double base_s = 0, base_t = 0;
  struct Case {
    const char* name;
    const Scene* scene;
    IntegratorKind kind;
    const BlockReference* ref;
  };
  std::vector<Case> cases = {{"hybrid", &scene, IntegratorKind::Hybrid, &ref},
                             {"beams", &scene, IntegratorKind::Beams, &ref},
                             {"path", &scene, IntegratorKind::Path, &ref}};
  if (spot) cases.push_back({"path, housed emitter", &*housed, IntegratorKind::Path, &ref_housed});
  for (const Case& c : cases) {
    const int64_t work = work_for_budget(*c.scene, c.kind, o);
    const double t0 = now_s();
    const RenderResult r = run(*c.scene, c.kind, work, o, o.seed);
    const double secs = now_s() - t0;
    const Reference got = blocks(r.film, kBlock, kGroup);
    double total = 0;
    for (double v : got.steady) total += v;
    if (c.kind == IntegratorKind::Path && !(total > 0)) {
      std::printf("%-22s %8lld %9.1f   estimate zero: camera paths cannot reach the light\n",
                  c.name, static_cast<long long>(work), secs);
      continue;
    }
    const Errors e = errors(got.steady.data(), got.transient.data(), c.ref->ref, c.ref->lit);
    const double scale = std::sqrt(secs / o.seconds);
    if (c.kind == IntegratorKind::Hybrid) base_s = e.steady * scale, base_t = e.transient * scale;
    std::printf("%-22s %8lld %9.1f %13.4f %16.4f %10.4f / %.4f (%.1fx / %.1fx)\n", c.name,
                static_cast<long long>(work), secs, e.steady, e.transient, e.steady * scale,
                e.transient * scale, base_s / (e.steady * scale), base_t / (e.transient * scale));
    std::fflush(stdout);
  }
  std::printf("\nratios against the hybrid\n");
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  std::string scene_file;
  int ref_passes = 100, width = 0, height = 0;
  bool through_glass = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "femto-bench-caustics: %s needs a value\n", a.c_str());
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--seconds")
      o.seconds = std::atof(next().c_str());
    else if (a == "--ref-paths")
      o.ref_paths = std::atof(next().c_str());
    else if (a == "--threads")
      o.threads = std::atoi(next().c_str());
    else if (a == "--seed")
      o.seed = std::strtoull(next().c_str(), nullptr, 10);
    else if (a == "--seeds") {
      o.seeds = std::atoi(next().c_str());
      if (o.seeds < 1 || o.seeds > 99) {  // the references use seeds from seed + 100 on
        std::fprintf(stderr, "femto-bench-caustics: --seeds must be 1 to 99\n");
        return 2;
      }
    } else if (a == "--hybrid-light-paths") {
      // X,Y,...: light paths per pixel per pass, one hybrid line each (0: the default)
      const std::string v = next();
      if (!number_list(v, 0, 1000, o.hybrid_light_paths)) {
        std::fprintf(stderr,
                     "femto-bench-caustics: --hybrid-light-paths expects numbers 0 to 1000 "
                     "separated by commas (got '%s')\n",
                     v.c_str());
        return 2;
      }
    } else if (a == "--hybrid-camera-balls") {
      // R,...: camera ball radii in mm, one hybrid line each per share (-1: default, 0: none)
      const std::string v = next();
      if (!number_list(v, -1, 1e6, o.hybrid_camera_balls)) {
        std::fprintf(stderr,
                     "femto-bench-caustics: --hybrid-camera-balls expects radii in mm (-1: the "
                     "default, 0: none) separated by commas (got '%s')\n",
                     v.c_str());
        return 2;
      }
    } else if (a == "--scene")
      scene_file = next();
    else if (a == "--through-glass")
      through_glass = true;
    else if (a == "--ref-passes")
      ref_passes = std::atoi(next().c_str());
    else if (a == "--size") {
      if (std::sscanf(next().c_str(), "%d,%d", &width, &height) != 2 || width < 1 || height < 1) {
        std::fprintf(stderr, "femto-bench-caustics: --size expects W,H (pixels)\n");
        return 2;
      }
    } else if (a == "--crop") {
      if (std::sscanf(next().c_str(), "%d,%d,%d,%d", &o.x0, &o.y0, &o.x1, &o.y1) != 4) {
        std::fprintf(stderr, "femto-bench-caustics: --crop expects X0,Y0,X1,Y1\n");
        return 2;
      }
    } else if (a == "--help") {
      std::printf(
          "Usage: femto-bench-caustics [--seconds S] [--ref-paths N] [--threads N] [--seed S] "
          "[--crop X0,Y0,X1,Y1] [--through-glass] [--seeds K] [--hybrid-light-paths X,...] "
          "[--hybrid-camera-balls R,...]\n"
          "  default crop: the caustic on the "
          "floor; "
          "--crop 100,88,156,128: the fog under the sphere; --through-glass: the spot aimed at "
          "the sphere, its cone inside the sphere's silhouette (all of its light enters the "
          "glass); --seeds K: K renders per estimator, errors as their RMS (1 to 99); "
          "--hybrid-light-paths X,...: one hybrid line per value of its light-traced share, in "
          "light paths per pixel per pass (0: the default, 0.25); --hybrid-camera-balls R,...: one "
          "hybrid line per camera ball radius in mm and share (-1: the default, 0: none)\n"
          "       femto-bench-caustics --scene FILE [--ref-passes N] [--size W,H] [--seconds S] "
          "[--threads N]\n"
          "  a scene whose light camera paths cannot reach (data/scenes/tissue_laser.json): "
          "hybrid, beams and camera paths against a beams reference of 2 x N passes (a single "
          "spot light: also camera paths with a housed 2 mm emitter)\n");
      return 0;
    } else {
      std::fprintf(stderr, "femto-bench-caustics: unknown option %s\n", a.c_str());
      return 2;
    }
  }
  if (!scene_file.empty()) {
    std::printf("femto-bench-caustics: CPU %s, %d threads, %.0f s per estimator\n",
                cpu_model().c_str(), o.threads, o.seconds);
    return run_scene_file(scene_file, o, ref_passes, width, height);
  }
  std::printf(
      "femto-bench-caustics: CPU %s, %d threads, %.0f s per estimator and render, %d render(s) "
      "each, references of %.3g light paths\n",
      cpu_model().c_str(), o.threads, o.seconds, o.seeds, o.ref_paths);
  SceneDesc spot_desc = load_scene_string(default_scene_json(), "<default scene>", ".");
  const ShapeDesc* glass = nullptr;
  for (const ShapeDesc& s : spot_desc.shapes)
    if (s.material.type == MaterialDesc::Type::Dielectric) glass = &s;
  if (through_glass) {
    // All of the spot's light through the sphere: aimed at its centre, the cone inside its
    // silhouette. Below the sphere the fog and the floor get only light that passed the glass
    // (and what the fog above it, lit directly, scatters).
    LightDesc& l = spot_desc.lights.front();
    const Vec3 to = glass->center - l.position;
    l.direction = normalize(to);
    l.cone_angle_deg =
        0.95 * std::asin(glass->radius / length(to)) * 180.0 / 3.14159265358979323846;
    l.falloff_deg = 0.8 * l.cone_angle_deg;
    std::printf("spot aimed at the glass sphere, cone half-angle %.2f deg (falloff from %.2f)\n",
                l.cone_angle_deg, l.falloff_deg);
  }
  const Scene spot(spot_desc);
  const Scene sphere(sphere_emitter_scene(spot_desc, 2.0));
  const Scene housed(housed_emitter_scene(spot_desc, 2.0));
  const std::vector<int> px = crop_pixels(spot, o, *glass);
  std::printf("crop x [%d, %d) y [%d, %d): %zu pixels that see no glass\n", o.x0, o.x1, o.y0, o.y1,
              px.size());

  std::printf("references (light tracing, two halves each)...\n");
  std::fflush(stdout);
  double t0 = now_s();
  auto reference = [&](const Scene& scene, uint64_t seed, const char* name) {
    const auto half = static_cast<int64_t>(o.ref_paths / 2);
    const RenderResult a = run(scene, IntegratorKind::Light, half, o, seed);
    const RenderResult b = run(scene, IntegratorKind::Light, half, o, seed + 1);
    const Reference r = mean_of(a.film, b.film);
    // The mean of two halves has half the variance of one: its error is RMSE(a - b) / 2.
    const Reference b_only = mean_of(b.film, b.film);
    const Errors e = errors(a.film.steady(), a.film.transient(), b_only, px);
    std::printf("  %s: relative RMSE of the reference itself: steady %.4f, transient %.4f\n", name,
                e.steady / 2, e.transient / 2);
    Reference out = r;
    out.own = {e.steady / 2, e.transient / 2};
    return out;
  };
  const Reference ref_spot = reference(spot, o.seed + 100, "spot scene");
  const Reference ref_sphere = reference(sphere, o.seed + 200, "sphere-emitter scene");
  const Reference ref_housed = reference(housed, o.seed + 300, "housed sphere-emitter scene");
  std::printf("references took %.0f s\n", now_s() - t0);

  struct Case {
    std::string name;
    const Scene* scene;
    IntegratorKind kind;
    const Reference* ref;
    double per_pixel = 0;  ///< hybrid: light paths per pixel per pass (0: default)
    double ball = -1;      ///< hybrid: camera ball radius, mm (-1: default)
  };
  std::vector<Case> cases = {
      {"path (housed sphere emitter)", &housed, IntegratorKind::Path, &ref_housed},
      {"path (open sphere emitter)", &sphere, IntegratorKind::Path, &ref_sphere},
      {"light tracing", &spot, IntegratorKind::Light, &ref_spot},
      {"path + photons", &spot, IntegratorKind::Photons, &ref_spot}};
  for (double x : o.hybrid_light_paths)
    for (double b : o.hybrid_camera_balls) {
      std::string name = "hybrid";
      char part[48];
      if (x > 0) {
        std::snprintf(part, sizeof(part), ", %g light paths/px", x);
        name += part;
      }
      if (b == 0) {
        name += ", no ball";
      } else if (b > 0) {
        std::snprintf(part, sizeof(part), ", ball %g mm", b);
        name += part;
      }
      cases.push_back({name, &spot, IntegratorKind::Hybrid, &ref_spot, x, b});
    }
  cases.push_back({"beams", &spot, IntegratorKind::Beams, &ref_spot});
  std::printf("\n%-32s %14s %9s %13s %16s %22s\n", "estimator", "work", "seconds", "steady rRMSE",
              "transient rRMSE", "equal-time transient");
  double base_steady = 0, base_transient = 0, base_steady_c = 0, base_transient_c = 0;
  double base_median_steady = 0, base_median_transient = 0;
  // An error against a reference holds the reference's own variance too (independent of the
  // estimator's): taking it out estimates the error against the exact image.
  auto without_ref = [](double e, double own) {
    return std::sqrt(std::max(0.0, e * e - own * own));
  };
  for (const Case& c : cases) {
    const int64_t work = work_for_budget(*c.scene, c.kind, o, c.per_pixel, c.ball);
    // K renders: squared errors and seconds averaged (errors with the reference's own variance
    // taken out, per render, for the corrected figures).
    double sq_steady = 0, sq_transient = 0, sq_steady_c = 0, sq_transient_c = 0, secs = 0;
    // Per render (reference's own error taken out): the median is a typical render's error,
    // which one rare firefly among K renders cannot move (the RMS holds the tail).
    std::vector<double> each_steady, each_transient;
    for (int k = 0; k < o.seeds; ++k) {
      t0 = now_s();
      const RenderResult r =
          run(*c.scene, c.kind, work, o, o.seed + static_cast<uint64_t>(k), c.per_pixel, c.ball);
      secs += now_s() - t0;
      const Errors ek = errors(r.film.steady(), r.film.transient(), *c.ref, px);
      sq_steady += ek.steady * ek.steady;
      sq_transient += ek.transient * ek.transient;
      const double cs = without_ref(ek.steady, c.ref->own.steady),
                   ct = without_ref(ek.transient, c.ref->own.transient);
      sq_steady_c += cs * cs;
      sq_transient_c += ct * ct;
      each_steady.push_back(cs);
      each_transient.push_back(ct);
    }
    secs /= o.seeds;
    const Errors e{std::sqrt(sq_steady / o.seeds), std::sqrt(sq_transient / o.seeds)};
    // Variance falls as 1 / time: scale each error to the budget before taking ratios.
    const double scale = std::sqrt(secs / o.seconds);
    const double steady_eq = e.steady * scale, transient_eq = e.transient * scale;
    // The ratios are against the housed emitter (the first line): the spot's own cone of light.
    if (&c == &cases[0]) base_steady = steady_eq, base_transient = transient_eq;
    std::printf("%-32s %14lld %9.1f %13.4f %16.4f %12.4f (%5.1fx)\n", c.name.c_str(),
                static_cast<long long>(work), secs, e.steady, e.transient, transient_eq,
                base_transient / transient_eq);
    std::printf("%-32s %14s %9s %13s %16s steady %.4f (%5.1fx)\n", "", "", "", "", "", steady_eq,
                base_steady / steady_eq);
    const double steady_c = std::sqrt(sq_steady_c / o.seeds) * scale,
                 transient_c = std::sqrt(sq_transient_c / o.seeds) * scale;
    if (&c == &cases[0]) base_steady_c = steady_c, base_transient_c = transient_c;
    std::printf(
        "%-32s %14s %9s %13s %16s without the reference's own error: steady %.4f (%5.1fx), "
        "transient %.4f (%5.1fx)\n",
        "", "", "", "", "", steady_c, base_steady_c / steady_c, transient_c,
        base_transient_c / transient_c);
    const double median_steady = median_of(each_steady) * scale,
                 median_transient = median_of(each_transient) * scale;
    if (&c == &cases[0])
      base_median_steady = median_steady, base_median_transient = median_transient;
    std::printf(
        "%-32s %14s %9s %13s %16s median of the renders: steady %.4f (%5.1fx), transient %.4f "
        "(%5.1fx)\n",
        "", "", "", "", "", median_steady, base_median_steady / median_steady, median_transient,
        base_median_transient / median_transient);
    std::fflush(stdout);
  }
  std::printf(
      "\nwork: spp (path), passes of 1 spp + photons / beams / light paths (photons, hybrid, "
      "beams), light paths (light tracing); ratios against the housed emitter\n");
  return 0;
}
