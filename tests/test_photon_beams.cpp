// Photon beams: agreement with camera paths for all light scattered in a medium, the
// progressive schedule's bias shrinking, and determinism.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "agreement.h"
#include "core/constants.h"
#include "core/integrators/photon_beams.h"
#include "core/integrators/ppm_schedule.h"
#include "core/rng.h"
#include "core/scene_loader.h"
#include "media/volume_data.h"
#include "samplers/stats.h"
#include "scene_builders.h"
#include "temp_dir.h"

using namespace femto;
using namespace femto::test;

namespace {

// Fog in a box (clear of the walls and of the camera) with a point light inside, a floor and a
// back wall.
SceneDesc fog_box(int w, int h) {
  SceneDesc d = load_scene_string(R"({
    "camera": { "type": "perspective", "position": [0, 30, 140], "look_at": [0, 25, 0], "fov": 45,
                "resolution": [16, 12] },
    "time": { "t_start": 350, "bin_width": 75, "bins": 12 },
    "media": { "fog": { "type": "homogeneous", "sigma_a": 0.004, "sigma_s": 0.02, "g": 0.4, "eta": 1.33,
                        "connection_sampling": "mis" } },
    "shapes": [
      { "type": "box", "min": [-59, 1, -59], "max": [59, 80, 59], "medium": "fog" },
      { "type": "quad", "corner": [-60, 0, 60], "edge1": [120, 0, 0], "edge2": [0, 0, -120],
        "material": { "type": "diffuse", "albedo": 0.7 } },
      { "type": "quad", "corner": [-60, 0, -60], "edge1": [120, 0, 0], "edge2": [0, 80, 0],
        "material": { "type": "diffuse", "albedo": 0.5 } }
    ],
    "lights": [ { "type": "point", "position": [10, 40, -10], "intensity": 1000 } ]
  })",
                                  "fog box", ".");
  d.camera.width = w;
  d.camera.height = h;
  return d;
}

}  // namespace

// Catches: a wrong beam estimator (the 1 / sin(theta) factor, the 1-D kernel's 1 / (2R), the phase
// function's direction, transmittance along the camera ray, sigma_s at the crossing), beam times
// (OPL along the beam and the camera ray), or paths counted twice or lost between beams and
// camera paths: all light scattered in the fog comes from beams here, and must match camera paths
// cell by cell within 4 combined standard errors.
TEST_CASE("photon beams agree with camera paths in a fog box, bin by bin", "[beams][statistical]") {
  const Scene scene(fog_box(16, 12));
  // Radius small against the 4 x 4 pixel blocks compared: kernel bias far below the noise.
  // Each side's work follows its variance x time (FEMTO_AGREEMENT_LOG=1): 4000 paths a pass and
  // 128 spp took 3x the CPU time for a combined error 1.3x as large.
  const PhotonDesc pd = progressive(1000, 1.0, 1.0);
  const auto pt = cells(batches(scene, IntegratorKind::Path, 384, 24, 100), 4, 3);
  const auto bm = cells(batches(scene, IntegratorKind::Beams, 16, 24, 200, pd), 4, 3);
  require_agreement(pt, bm, 15);
}

// Catches: a schedule that does not shrink the beam radius (or shrinks R^2 instead of R): the
// kernel volume R T must fall by (j + alpha) / (j + 1) per pass.
TEST_CASE("beam radius and bandwidth follow the 1-D schedule", "[beams]") {
  const double alpha = 2.0 / 3.0, beta_t = 0.5;
  PpmSchedule s(3.0, 10.0, alpha, beta_t, 1);
  double volume = 30.0;
  for (int j = 1; j < 100; ++j) {
    s.advance();
    volume *= (j + alpha) / (j + 1.0);
    CHECK(s.radius() * s.bandwidth() == Approx(volume).epsilon(1e-12));
    CHECK(s.radius() / 3.0 ==
          Approx(s.bandwidth() / 10.0).epsilon(1e-12));  // beta_t = 1/2: equal shares
  }
}

// Catches: beam-kernel bias that stays: near the point light the fluence falls off fast, so a
// wide fixed beam radius blurs light away from the beams' cores; shrinking radii must move the
// estimate of the brightest region towards the camera-path answer.
TEST_CASE("the beam estimate's bias shrinks as passes go on", "[beams][statistical]") {
  SceneDesc d = fog_box(16, 12);
  d.time.t_start_ps = 0;
  d.time.bin_width_ps = 3000;
  d.time.bins = 1;
  const Scene scene(d);
  // The brightest 2 x 2 block of the camera-path answer (around the light).
  const auto ref_films = batches(scene, IntegratorKind::Path, 512, 12, 300);
  auto px = [&](const TransientFilm& f, int x, int y) {
    return f.steady()[3 * static_cast<size_t>(y * 16 + x) + 1];
  };
  int bx = 0, by = 0;
  double best = -1;
  for (int y = 0; y + 1 < 12; ++y)
    for (int x = 0; x + 1 < 16; ++x) {
      double s = 0;
      for (const auto& f : ref_films)
        s += px(f, x, y) + px(f, x + 1, y) + px(f, x, y + 1) + px(f, x + 1, y + 1);
      if (s > best) best = s, bx = x, by = y;
    }
  auto block = [&](const TransientFilm& f) {
    return px(f, bx, by) + px(f, bx + 1, by) + px(f, bx, by + 1) + px(f, bx + 1, by + 1);
  };
  std::vector<double> ref, a, b;
  for (const auto& f : ref_films) ref.push_back(block(f));
  PhotonDesc fixed;
  fixed.per_pass = 2000;
  fixed.radius = 12.0;
  fixed.bandwidth_ps = 1.0;
  fixed.alpha = 1.0;  // no shrinking
  PhotonDesc progressive = fixed;
  progressive.alpha = 0.2;  // fast shrinking, to resolve the change within a short test
  for (const auto& f : batches(scene, IntegratorKind::Beams, 32, 8, 400, fixed))
    a.push_back(block(f));
  for (const auto& f : batches(scene, IntegratorKind::Beams, 32, 8, 500, progressive))
    b.push_back(block(f));
  const MeanSE r = mean_se(ref), fa = mean_se(a), fb = mean_se(b);
  const double bias_fixed = fa.mean - r.mean, bias_prog = fb.mean - r.mean;
  INFO("block " << bx << "," << by << ": camera paths " << r.mean << " +- " << r.se << ", fixed R "
                << fa.mean << " +- " << fa.se << ", shrinking R " << fb.mean << " +- " << fb.se);
  REQUIRE(std::abs(bias_fixed) > 4.0 * std::hypot(fa.se, r.se));
  CHECK(std::abs(bias_prog) < 0.6 * std::abs(bias_fixed));
}

// Catches: a progressive beam estimate that does not converge to the path-traced answer in
// time-resolved cells (a radius or bandwidth that stops shrinking, a bias in time that stays, a
// variance that grows faster than the passes average it away): the squared error of one render
// against a converged camera-path reference, over 2 x 2-pixel cells and every time bin, must
// fall from 2 to 8 and from 8 to 32 passes. Compared by ranks (the fraction of render pairs in
// which the later one has the smaller error, 4 standard deviations above the 1/2 of no change),
// because the beam estimator's 1/sin(theta) makes squared errors heavy-tailed.
// With the radius held fixed (alpha = 1) the error stalls at the kernel's bias and this fails.
TEST_CASE("beam renders converge to the camera-path answer bin by bin as passes go on",
          "[beams][statistical]") {
  const Scene scene(fog_box(16, 12));
  const auto ref = cells(batches(scene, IntegratorKind::Path, 512, 16, 1300), 2, 1);
  // Wide at first (visible blur near the light), shrinking by the schedule.
  const PhotonDesc pd = progressive(2000, 10.0, 40.0);
  const int n = 24;
  std::vector<std::vector<double>> errors;
  for (int passes : {2, 8, 32}) {
    const auto bm = cells(batches(scene, IntegratorKind::Beams, passes, n, 1400, pd), 2, 1);
    std::vector<double> err(static_cast<size_t>(n), 0.0);
    for (size_t c = 0; c < bm.size(); ++c) {
      const double r = mean_se(ref[c]).mean;
      for (size_t k = 0; k < err.size(); ++k) err[k] += (bm[c][k] - r) * (bm[c][k] - r);
    }
    errors.push_back(err);
  }
  // Mann-Whitney: P(later < earlier) over all pairs; under no change its mean is 1/2 and its
  // standard deviation sqrt((2n + 1) / (12 n^2)).
  auto fraction_lower = [&](const std::vector<double>& later, const std::vector<double>& earlier) {
    double wins = 0;
    for (double a : later)
      for (double b : earlier) wins += a < b ? 1.0 : (a == b ? 0.5 : 0.0);
    return wins / static_cast<double>(later.size() * earlier.size());
  };
  const double sd = std::sqrt((2.0 * n + 1.0) / (12.0 * n * n));
  const double f8 = fraction_lower(errors[1], errors[0]),
               f32 = fraction_lower(errors[2], errors[1]);
  INFO("P(error at 8 < at 2) = " << f8 << ", P(error at 32 < at 8) = " << f32 << ", threshold "
                                 << 0.5 + 4.0 * sd);
  CHECK(f8 > 0.5 + 4.0 * sd);
  CHECK(f32 > 0.5 + 4.0 * sd);
}

// Catches: beam order (and so the tree and the sums) depending on how work is split.
TEST_CASE("photon beams are bit-identical for 1 and 2 threads", "[beams]") {
  const Scene scene(fog_box(12, 10));
  std::vector<std::vector<float>> out;
  for (int threads : {1, 2}) {
    RenderOptions opt;
    opt.integrator = IntegratorKind::Beams;
    opt.spp = 3;
    opt.photons.per_pass = 1000;
    opt.threads = threads;
    opt.quiet = true;
    const RenderResult res = render(scene, opt);
    const float* v = res.film.transient();
    out.emplace_back(
        v, v + static_cast<size_t>(res.film.width() * res.film.height() * res.film.bins() * 3));
  }
  CHECK(out[0] == out[1]);
}

// Catches: beam times that ignore the per-voxel index (OPL along the beam and along the camera
// ray) or sigma_s read at the wrong place in a heterogeneous medium.
TEST_CASE("photon beams agree with camera paths in a voxel medium with per-voxel eta",
          "[beams][statistical]") {
  TempDir tmp("femto_beams");
  const MediumDesc m = graded_voxel_medium(tmp.dir);
  SceneDesc d = fog_box(16, 12);
  d.shapes.erase(d.shapes.begin());  // no fog box: the voxel medium fills everything
  d.media.clear();
  d.media.push_back(m);
  d.global_medium = 0;
  for (auto& s : d.shapes) s.interior_medium = -1;
  d.lights.front().position = {0, 80, 0};  // above the grid
  d.lights.front().intensity = RGB(3000.0);
  d.time.t_start_ps = 300;
  d.time.bin_width_ps = 100;
  d.time.bins = 10;
  const Scene scene(d);
  // Work split by each side's variance x time, as in the fog box above.
  const PhotonDesc pd = progressive(2500, 1.0, 1.0);
  const auto pt = cells(batches(scene, IntegratorKind::Path, 384, 16, 600), 4, 2);
  const auto bm = cells(batches(scene, IntegratorKind::Beams, 16, 16, 700, pd), 4, 2);
  require_agreement(pt, bm, 10);
}

TEST_CASE("beams: the default light paths per pass follow the film's pixels", "[beams]") {
  // Half a path per pixel keeps a pass's beams in step with its camera samples (a 64 x 48 hybrid
  // with 20000 paths per pass had 2-5x the error at equal time); full-size films keep 20000.
  CHECK(default_beam_paths_per_pass(64 * 48) == 1536);
  CHECK(default_beam_paths_per_pass(128 * 96) == 6144);
  CHECK(default_beam_paths_per_pass(256 * 192) == 20000);
  CHECK(default_beam_paths_per_pass(40 * 24) == 1000);
  SceneDesc d = load_scene_string(R"({
    "camera": { "position": [0, 0, 60], "look_at": [0, 0, 0], "resolution": [64, 48] },
    "time": { "t_start": 0, "bin_width": 10, "bins": 10 },
    "media": { "fog": { "type": "homogeneous", "sigma_a": 0.01, "sigma_s": 0.1 } },
    "shapes": [ { "type": "box", "min": [-8, -8, -8], "max": [8, 8, 8], "medium": "fog" } ],
    "lights": [ { "type": "point", "position": [0, 0, 0], "intensity": 1 } ]
  })",
                                  "fog box", ".");
  CHECK(progressive_settings(Scene(d), IntegratorKind::Beams, PhotonDesc{}).per_pass == 1536);
  d.integrator.photons.per_pass = 700;  // a scene's (or the command line's) value decides
  CHECK(progressive_settings(Scene(d), IntegratorKind::Beams, d.integrator.photons).per_pass ==
        700);
}

// Catches: a tree that drops beams (a split that loses pieces, children or leaves skipped, a
// stack that overflows) or visits a piece twice. The query must hand over, once each, every
// piece whose box the segment meets, so every beam that passes within R of the segment with its
// closest approach inside the segment is found; checked against a brute-force loop over all beams,
// on a bundle converging to a focus (what the surface-area splits work hardest on), with many
// copies of one beam (centres that no split separates) and a few scattered beams.
TEST_CASE("the beam tree finds every beam a camera segment passes within R of", "[beams]") {
  Rng rng(12345, 0);
  const double R = 0.7;
  std::vector<Beam> beams;
  const Vec3 focus(0, 0, 0);
  for (int i = 0; i < 3000; ++i) {  // from a disc 100 mm above the focus, through it
    const double r = 40 * std::sqrt(rng.uniform()), phi = 2 * kPi * rng.uniform();
    const Vec3 o(r * std::cos(phi), 100, r * std::sin(phi));
    const Vec3 d = normalize(focus - o + Vec3(rng.uniform() - 0.5, 0, rng.uniform() - 0.5));
    beams.push_back({o, d, 20 + 180 * rng.uniform(), RGB(1.0), 0, 0, 0, 0});
  }
  for (int i = 0; i < 200; ++i)  // identical beams
    beams.push_back({Vec3(5, -20, 5), normalize(Vec3(1, -1, 0.5)), 60, RGB(1.0), 0, 0, 0, 0});
  for (int i = 0; i < 300; ++i) {  // scattered anywhere
    const Vec3 o(200 * rng.uniform() - 100, 200 * rng.uniform() - 100, 200 * rng.uniform() - 100);
    const Vec3 d = normalize(Vec3(rng.uniform() - 0.5, rng.uniform() - 0.5, rng.uniform() - 0.5));
    beams.push_back({o, d, 300 * rng.uniform(), RGB(1.0), 0, 0, 0, 0});
  }
  // The gather's acceptance test: closest approach of the lines inside the segment and the beam,
  // within R.
  auto crosses = [&](const Vec3& o, const Vec3& u, double s_max, const Beam& b) {
    const Vec3 w0 = o - b.o;
    const double c = dot(u, b.d), du = dot(u, w0), db = dot(b.d, w0), sin2 = 1 - c * c;
    if (!(sin2 > 1e-12)) return false;
    const double tc = (c * db - du) / sin2, vb = (db - c * du) / sin2;
    if (!(tc >= 0 && tc < s_max && vb >= 0 && vb < b.length)) return false;
    return length_squared(o + u * tc - (b.o + b.d * vb)) < R * R;
  };
  for (size_t i = 0; i < beams.size(); ++i) beams[i].t_ps = static_cast<double>(i);  // its id
  BeamBvh bvh;
  bvh.build(beams, R);
  CHECK(bvh.size() == beams.size());
  // Enough pieces (about 54000) that at least the root's halves build in parallel and the right
  // one is spliced (at 16384 pieces or more).
  CHECK(bvh.pieces() > 2 * 16384);
  size_t found_total = 0;
  for (int q = 0; q < 2000; ++q) {
    // Segments through the bundle (half of them) or anywhere.
    const Vec3 o(160 * rng.uniform() - 80, 160 * rng.uniform() - 60, 160 * rng.uniform() - 80);
    const Vec3 target = q % 2 == 0 ? Vec3(10 * rng.uniform() - 5, 60 * rng.uniform(), 0) : Vec3(0);
    const Vec3 u =
        q % 2 == 0 ? normalize(target - o)
                   : normalize(Vec3(rng.uniform() - 0.5, rng.uniform() - 0.5, rng.uniform() - 0.5));
    const double s_max = 50 + 250 * rng.uniform();
    std::vector<int> expected(beams.size(), 0), seen(beams.size(), 0);
    for (size_t i = 0; i < beams.size(); ++i) expected[i] = crosses(o, u, s_max, beams[i]);
    std::vector<std::pair<size_t, float>> pieces;
    bvh.query(o, u, s_max, [&](const Beam& b, const BeamBvh::Piece& piece) {
      const auto i = static_cast<size_t>(b.t_ps);
      pieces.emplace_back(i, piece.v0);
      if (crosses(o, u, s_max, b)) seen[i] = 1;
    });
    std::sort(pieces.begin(), pieces.end());
    CHECK(std::adjacent_find(pieces.begin(), pieces.end()) == pieces.end());  // once each
    for (size_t i = 0; i < beams.size(); ++i) {
      if (expected[i] != seen[i]) FAIL("query " << q << " beam " << i << " missed");
      found_total += static_cast<size_t>(expected[i]);
    }
  }
  CHECK(found_total > 2000);  // the segments do cross the bundle
}
