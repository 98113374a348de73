// Time-targeted sampling inside the path tracer: segment connections (equiangular, line-to-point,
// MIS) and angular direction sampling must leave every time bin unbiased.
#include <catch2/catch.hpp>

#include <unistd.h>
#include <cmath>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include "core/constants.h"
#include "core/integrators/connection_choice.h"
#include "core/rng.h"
#include "core/scene.h"
#include "core/scene_loader.h"
#include "media/volume_data.h"
#include "scene_builders.h"
#include "single_scatter.h"
#include "temp_dir.h"

using namespace femto;
using namespace femto::test;

namespace {

const char* name_of(ConnectionSampling c) {
  return connection_sampling_name(c);
}

struct BinStats {
  std::vector<double> mean, se;
};

/// Per-bin mean and standard error over batches of the sum over all pixels (green channel).
BinStats bin_stats(const std::vector<TransientFilm>& films) {
  const int T = films[0].bins();
  const size_t pixels =
      static_cast<size_t>(films[0].width()) * static_cast<size_t>(films[0].height());
  BinStats out;
  for (int i = 0; i < T; ++i) {
    std::vector<double> v;
    for (const auto& f : films) {
      double s = 0;
      for (size_t p = 0; p < pixels; ++p)
        s += f.transient()[(p * static_cast<size_t>(T) + static_cast<size_t>(i)) * 3 + 1];
      v.push_back(s);
    }
    const MeanSE m = mean_se(v);
    out.mean.push_back(m.mean);
    out.se.push_back(m.se);
  }
  return out;
}

/// Every bin within 4 combined standard errors; returns the number of bins with signal.
int check_agreement(const BinStats& a, const BinStats& b, const std::string& what) {
  int compared = 0;
  for (size_t i = 0; i < a.mean.size(); ++i) {
    const double se = std::sqrt(a.se[i] * a.se[i] + b.se[i] * b.se[i]);
    INFO(what << " bin " << i << ": " << a.mean[i] << " +- " << a.se[i] << " vs " << b.mean[i]
              << " +- " << b.se[i]);
    CHECK(std::abs(a.mean[i] - b.mean[i]) <= 4.0 * se + 1e-12 * std::abs(b.mean[i]));
    if (b.mean[i] > 0) ++compared;
  }
  return compared;
}

/// Bin i of single-scattering renders against its exact value: within 4 standard errors.
struct BinCheck {
  MeanSE m;
  double expected;
};
BinCheck check_bin(const std::vector<TransientFilm>& films, const SingleScatterSetup& p, int i,
                   const char* name) {
  const MeanSE m = bin_mean_se(films, i);
  const double expected = p.bin(i);
  INFO(name << " bin " << i << ": " << m.mean << " +- " << m.se << " expected " << expected);
  CHECK(std::abs(m.mean - expected) <= 4.0 * m.se + 1e-9 * expected);
  return {m, expected};
}

}  // namespace

// Catches: a wrong equiangular or line-to-point pdf in the tracer, a vertex time or
// transmittance computed from the wrong point, a window that drops reachable vertices, MIS
// weights that do not sum to one, and point lights estimated twice (segment + collision) or by
// neither (auto: the split between connections and collisions must be exact).
TEST_CASE("segment connections match the single-scattering answer bin by bin", "[time-sampling]") {
  SingleScatterSetup p;
  p.axis.t_start_ps = 100;
  p.axis.bin_width_ps = 10;
  p.axis.bins = 40;
  for (ConnectionSampling c : {ConnectionSampling::Equiangular, ConnectionSampling::LineToPoint,
                               ConnectionSampling::Mis, ConnectionSampling::Auto}) {
    SceneDesc d = p.scene();
    d.media[0].connection = c;
    // auto leaves far segments to collisions, noisier in late bins: more samples, same resolution.
    const auto films =
        render_batches(d, c == ConnectionSampling::Auto ? 4000 : 2000, 16, /*max_depth=*/1);
    int checked = 0;
    for (int i = 0; i < p.axis.bins; ++i) {
      const auto [m, expected] = check_bin(films, p, i, name_of(c));
      if (expected > 0) {
        CHECK(m.se < 0.1 * expected);  // enough resolving power to see a missing term
        ++checked;
      }
    }
    CHECK(checked >= 30);
  }
}

// Catches: segment connections and angular sampling that are biased with multiple scattering,
// surfaces, a spot light beside an area light (MIS with the phase/angular mixture), the
// time-uniform + MIS distance sampler (shared r_aux), the one-sample mixture continuing paths
// (its weights), unwarped camera segments, and a heterogeneous
// voxel medium with varying index. Reference: collision NEE + phase sampling (mean free path
// for the mixture).
TEST_CASE("time-targeted sampling agrees with the reference estimator with multiple scattering",
          "[time-sampling][statistical]") {
  TempDir tmp("femto_time_sampling");
  // A heterogeneous voxel medium with a varying index of refraction.
  const int n = 16;
  DenseGrid density(n, n, n), eta(n, n, n);
  Rng rng(77, 3);
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        density.at(i, j, k) = static_cast<float>(0.15 * rng.uniform());
        eta.at(i, j, k) = static_cast<float>(1.0 + 0.4 * rng.uniform());
      }
  density.update_range();
  eta.update_range();
  const std::string vdb = (tmp.dir / "hetero.vdb").string();
  write_volume(vdb, density, nullptr, &eta, 2.5, {-20, -20, -20});

  for (int variant = 0; variant < 5; ++variant) {
    SceneDesc d;
    d.source = "time sampling";
    d.camera = ortho_camera({0, 0, 40}, {0, 0, 0}, 30, 4, 3);
    d.time.t_start_ps = 60;
    d.time.bin_width_ps = 20;
    d.time.bins = 14;
    if (variant == 0 || variant == 3) {
      d.media.push_back(medium("fog", 0.01, 0.12, 0.5, 1.33));  // homogeneous, eta 1.33
    } else if (variant == 1) {
      d.media.push_back(medium("fog", 0.005, 0.08, -0.3, 1.0));
      d.media[0].sampling = DistanceSampling::Mis;  // the time-uniform collision shares r_aux
      d.time_mode = TimeMode::Unwarp;
    } else {
      MediumDesc m;
      m.name = "cloud";
      m.type = MediumDesc::Type::Vdb;
      m.vdb.file = vdb;
      m.vdb.albedo = 0.9;
      m.vdb.eta_grid = "eta";
      m.medium.g = 0.3;
      m.sampling = DistanceSampling::Mis;
      d.media.push_back(m);
    }
    d.global_medium = 0;
    d.shapes.push_back(quad({-25, -25, -15}, {50, 0, 0}, {0, 50, 0}, diffuse(0.7)));
    ShapeDesc lamp =
        quad({-20, 14, 20}, {0, 0, -40}, {40, 0, 0}, MaterialDesc{});  // large: MIS matters
    lamp.emissive = true;
    lamp.emission = RGB(1.0);
    d.shapes.push_back(lamp);  // an area light facing down
    LightDesc spot;
    spot.type = LightDesc::Type::Spot;
    spot.position = {6, -5, 10};
    spot.direction = normalize(Vec3(-0.4, 0.3, -1));
    spot.intensity = RGB(300.0);
    spot.cone_angle_deg = 50;
    spot.falloff_deg = 40;
    d.lights.push_back(spot);
    LightDesc point;
    point.position = {-8, 3, 2};
    point.intensity = RGB(150.0);
    d.lights.push_back(point);

    // Variants 3 and 4: the one-sample mixture (time-uniform share about 0.45 here) continues
    // the paths, against a mean-free-path reference.
    const bool mixture = variant >= 3;
    if (mixture) d.media[0].sampling = DistanceSampling::Mfp;
    const BinStats ref = bin_stats(render_batches(d, 256, 16, /*max_depth=*/8));
    if (mixture) d.media[0].sampling = DistanceSampling::Mixture;
    for (ConnectionSampling c :
         {ConnectionSampling::LineToPoint, ConnectionSampling::Mis, ConnectionSampling::Auto}) {
      for (DirectionSampling dir : {DirectionSampling::Phase, DirectionSampling::Angular}) {
        SceneDesc e = d;
        e.media[0].connection = c;
        e.media[0].direction = dir;
        const BinStats got = bin_stats(render_batches(e, 256, 16, /*max_depth=*/8));
        const std::string what = "variant " + std::to_string(variant) + " " + name_of(c) +
                                 (dir == DirectionSampling::Angular ? " + angular" : " + phase");
        CHECK(check_agreement(got, ref, what) >= 8);
      }
    }
  }
}

// Catches: the auto rule reading the wrong distance (the light's distance from the line when the
// closest point lies outside the segment, or the segment length instead of the mean free path as
// the collisions' spread), which would hand near-light segments to collisions (fireflies) or far
// ones to connections (cost).
TEST_CASE("auto connects the segments whose light term peaks narrowly", "[time-sampling]") {
  const Vec3 o(0, 0, 0), d(1, 0, 0);
  // Foot on the segment: distance from the line against 0.1 x min(length, mean free path).
  CHECK(connect_segment_to(o, d, 100.0, 0.1, {50, 0.9, 0}));  // 0.9 < 0.1 x 10
  CHECK_FALSE(connect_segment_to(o, d, 100.0, 0.1, {50, 1.1, 0}));
  CHECK(connect_segment_to(o, d, 5.0, 0.0001, {2.5, 0.4, 0}));  // short segment: 0.1 x 5
  CHECK_FALSE(connect_segment_to(o, d, 5.0, 0.0001, {2.5, 0.6, 0}));
  // Foot behind the start: distance from the start; beyond the end: from the end.
  CHECK(connect_segment_to(o, d, 100.0, 0.1, {-0.5, 0.5, 0}));  // |(-0.5, 0.5)| = 0.71 < 1
  CHECK_FALSE(connect_segment_to(o, d, 100.0, 0.1, {-5, 0.1, 0}));
  CHECK(connect_segment_to(o, d, 20.0, 0.1, {20.5, 0.5, 0}));
  CHECK_FALSE(connect_segment_to(o, d, 20.0, 0.1, {25, 0.1, 0}));
  // A clear, endless segment has no collisions to lean on.
  CHECK(connect_segment_to(o, d, std::numeric_limits<double>::infinity(), 0.0, {1e3, 1e3, 0}));
  // The wider fraction of the mean-free-path pairs, on the same segment.
  const double k = kNearPairFraction * 10;
  CHECK(connect_segment_to(o, d, 100.0, 0.1, {50, 0.95 * k, 0}, kNearPairFraction));
  CHECK_FALSE(connect_segment_to(o, d, 100.0, 0.1, {50, 1.05 * k, 0}, kNearPairFraction));
  // A segment shorter than the mean free path keeps 0.1 of its length.
  CHECK_FALSE(connect_segment_to(o, d, 5.0, 0.0001, {2.5, 0.6, 0}, kNearPairFraction));
}

// Catches: a bound in box_far_from_light that is too small (auto would skip the first rule on a
// medium where some segment should connect: fireflies near the light come back) or one that
// never holds (the shortcut that spares a dense medium's segments the rule would never fire).
// Segments start anywhere in the box, in any direction, and run to the box's wall; the light is
// anywhere outside, from just beyond the bound to a few times it; the extinction is the
// medium's (homogeneous) or any value at the segment's start (voxel media: unknown).
TEST_CASE("no segment inside a box connects to a light the box is far from", "[time-sampling]") {
  Rng rng(20261203, 1);
  int far = 0, near_edge = 0, segments = 0;
  const double fraction = std::fmax(kConnectionPeakFraction, kNearPairFraction);  // the wider
  for (int trial = 0; trial < 4000; ++trial) {
    const Vec3 lo(rng.uniform() * 10 - 5, rng.uniform() * 10 - 5, rng.uniform() * 10 - 5);
    const Vec3 hi =
        lo + Vec3(0.1 + rng.uniform() * 20, 0.1 + rng.uniform() * 20, 0.1 + rng.uniform() * 20);
    const bool homogeneous = trial % 2 == 0;
    const double sigma_t = std::pow(10.0, rng.uniform() * 4 - 2);  // 0.01 to 100 per mm
    double bound = fraction * length(hi - lo);
    if (homogeneous) bound = std::fmin(bound, fraction / sigma_t);
    // A light off the middle of a random face, 0.3 to 3 bounds away from it.
    const int axis = trial % 3, side = (trial / 3) % 2;
    Vec3 p((lo.x + hi.x) / 2, (lo.y + hi.y) / 2, (lo.z + hi.z) / 2);
    const double gap = bound * (0.3 + 2.7 * rng.uniform());
    (axis == 0   ? p.x
     : axis == 1 ? p.y
                 : p.z) = side ? (axis == 0   ? hi.x
                                  : axis == 1 ? hi.y
                                              : hi.z) +
                                     gap
                               : (axis == 0   ? lo.x
                                  : axis == 1 ? lo.y
                                              : lo.z) -
                                     gap;
    const bool is_far = box_far_from_light(lo, hi, homogeneous ? sigma_t : 0.0, p);
    if (gap > 1.011 * bound) CHECK(is_far);  // no looser than the bound with its 1% slack
    if (!is_far) continue;
    ++far;
    near_edge += gap < 1.1 * bound;
    for (int k = 0; k < 50; ++k, ++segments) {
      // Half start anywhere, half just inside the face below the light (the worst case).
      Vec3 o(lo.x + rng.uniform() * (hi.x - lo.x), lo.y + rng.uniform() * (hi.y - lo.y),
             lo.z + rng.uniform() * (hi.z - lo.z));
      if (k % 2) {
        const double width = axis == 0 ? hi.x - lo.x : axis == 1 ? hi.y - lo.y : hi.z - lo.z;
        const double inset = std::fmin(bound, width) * rng.uniform() * rng.uniform();
        double& c = axis == 0 ? o.x : axis == 1 ? o.y : o.z;
        c = side ? (axis == 0   ? hi.x
                    : axis == 1 ? hi.y
                                : hi.z) -
                       inset
                 : (axis == 0   ? lo.x
                    : axis == 1 ? lo.y
                                : lo.z) +
                       inset;
      }
      const double z = 2 * rng.uniform() - 1, phi = 2 * kPi * rng.uniform();
      const double r = std::sqrt(1 - z * z);
      const Vec3 d(r * std::cos(phi), r * std::sin(phi), z);
      double s_full = kInf;  // to the box's wall
      for (double t : {((d.x > 0 ? hi.x : lo.x) - o.x) / d.x, ((d.y > 0 ? hi.y : lo.y) - o.y) / d.y,
                       ((d.z > 0 ? hi.z : lo.z) - o.z) / d.z})
        if (t >= 0) s_full = std::fmin(s_full, t);
      const double sigma_o = homogeneous ? sigma_t : std::pow(10.0, rng.uniform() * 6 - 3);
      CHECK_FALSE(connect_segment_to(o, d, s_full, sigma_o, p, fraction));
    }
    // And the worst case: a segment across the whole face, just inside it, under the light.
    {
      const int ta = (axis + 1) % 3;  // a tangent axis
      const double width = axis == 0 ? hi.x - lo.x : axis == 1 ? hi.y - lo.y : hi.z - lo.z;
      Vec3 o = p, d(0, 0, 0);
      double& c = axis == 0 ? o.x : axis == 1 ? o.y : o.z;
      c = side ? (axis == 0   ? hi.x
                  : axis == 1 ? hi.y
                              : hi.z) -
                     1e-3 * std::fmin(bound, width)
               : (axis == 0   ? lo.x
                  : axis == 1 ? lo.y
                              : lo.z) +
                     1e-3 * std::fmin(bound, width);
      (ta == 0 ? o.x : ta == 1 ? o.y : o.z) = ta == 0 ? lo.x : ta == 1 ? lo.y : lo.z;
      (ta == 0 ? d.x : ta == 1 ? d.y : d.z) = 1.0;
      const double s_full = ta == 0 ? hi.x - lo.x : ta == 1 ? hi.y - lo.y : hi.z - lo.z;
      CHECK_FALSE(
          connect_segment_to(o, d, s_full, homogeneous ? sigma_t : 1.0 / s_full, p, fraction));
    }
  }
  CHECK(far > 2500);
  CHECK(near_edge > 100);  // the edge of the bound is exercised
  // Closer than the bound, a segment along the face below the light connects, and the box is
  // not far: the bound is not loose by much.
  const Vec3 lo(0, 0, 0), hi(10, 10, 10), p(5, 5, 10 + 0.5 * fraction);
  CHECK_FALSE(box_far_from_light(lo, hi, 1.0, p));  // half the bound (mean free path 1)
  CHECK(connect_segment_to({5, 5, 9.99}, {1, 0, 0}, 3.0, 1.0, p, fraction));
  CHECK(box_far_from_light(lo, hi, 1.0, {5, 5, 10 + 1.02 * fraction}));
}

// Catches: the starvation rule reading the window or the extinction wrongly (a camera segment
// that spans many mean free paths handed to collisions alone, or a short one or one deep in a
// dense medium given a needless connection), and the light's side of the segment start read with
// the wrong sign.
TEST_CASE("auto adds line-to-point on camera segments whose late frames starve",
          "[time-sampling]") {
  // sigma_t x min(segment, budget) against 3 mean free paths.
  CHECK(starved_segment(1000.0, 2000.0, 0.004));       // 4 mean free paths
  CHECK_FALSE(starved_segment(1000.0, 500.0, 0.004));  // the window ends after 2
  CHECK_FALSE(starved_segment(200.0, 1e4, 0.01));      // the medium ends after 2
  CHECK(starved_segment(std::numeric_limits<double>::infinity(), 150.0, 0.06));
  // ... but not where the window reaches so deep that light scattered once along the segment is
  // nil there (the tissue bench: mu_t 10/mm, 20 mm of block, 33 mm of window: 200 mean free
  // paths).
  const double endless = std::numeric_limits<double>::infinity();
  CHECK(starved_segment(endless, 3990.0, 0.004));  // 15.96 mean free paths
  CHECK_FALSE(starved_segment(endless, 4010.0, 0.004));
  CHECK_FALSE(starved_segment(5000.0, 4010.0, 0.004));
  CHECK_FALSE(starved_segment(20.0, 33.0, 10.01));
  // The light behind (or level with) the segment's start lights it from there on.
  const Vec3 o(0, 0, 0), d(0, 0, -1);
  CHECK(lights_from_start(o, d, {0, 4, 30}));
  CHECK(lights_from_start(o, d, {0, 30, 0}));
  CHECK_FALSE(lights_from_start(o, d, {0, 4, -30}));
}

// Catches: a time_mis camera segment whose collisions and line-to-point connection do not share
// the light by weights summing to one (bias in every bin, e.g. the collisions keeping weight 1),
// and a rule that never engages. On the single-scattering ray (light level with the camera, the
// window 9 mean free paths long) collisions put exp(-9) of their density at the last frames, and
// the connection is uniform in time: at equal samples, the late bins' standard errors under auto
// must be several times smaller than under collisions alone (which get 4x the samples here, so
// that their late bins have enough collisions for a trustworthy standard error).
TEST_CASE("auto's camera-segment MIS is unbiased and pays in the late frames", "[time-sampling]") {
  SingleScatterSetup p;
  p.axis.t_start_ps = 100;
  p.axis.bin_width_ps = 10;
  p.axis.bins = 40;
  std::vector<double> se_auto, se_collision;
  for (ConnectionSampling c : {ConnectionSampling::Auto, ConnectionSampling::Collision}) {
    SceneDesc d = p.scene();
    d.media[0].connection = c;
    const bool is_auto = c == ConnectionSampling::Auto;
    const auto films = render_batches(d, is_auto ? 1000 : 4000, 16, /*max_depth=*/1);
    for (int i = 0; i < p.axis.bins; ++i) {
      const auto [m, expected] = check_bin(films, p, i, name_of(c));
      // Relative standard errors at 1000 samples per batch.
      (is_auto ? se_auto : se_collision).push_back(m.se / expected * (is_auto ? 1.0 : 2.0));
    }
  }
  // The last quarter of the window: relative variances at equal samples, pooled over its 10
  // bins (measured: about 0.12; each bin's own ratio is too noisy with 16 batches).
  double v_auto = 0, v_collision = 0;
  for (size_t i = 30; i < se_auto.size(); ++i) {
    v_auto += se_auto[i] * se_auto[i];
    v_collision += se_collision[i] * se_collision[i];
  }
  INFO("late relative variance, auto " << v_auto << ", collisions " << v_collision);
  CHECK(v_auto < 0.25 * v_collision);
}

// Catches: a near-light segment whose equiangular connection and collisions do not share the
// light by weights summing to one (e.g. the collisions keeping weight 1: the light counted twice
// in every bin), a pair that never engages (the light's peak left to collisions, whose 1 / r^2
// there gives fireflies) and the connection alone (the frames far from the light's foot, where
// equiangular sampling puts few vertices and collisions many). The light sits 1 mm beside the
// camera ray, 40 mm ahead (one tenth of the mean free path is 1.7 mm: a near segment): every
// vertex before it lands in the same frame, the peak; the later frames see the ray beyond it.
TEST_CASE("auto's near-light MIS of an equiangular connection and the collisions",
          "[time-sampling]") {
  SingleScatterSetup p;
  p.h = 1.0;
  p.z0 = 40.0;
  p.axis.t_start_ps = 140;
  p.axis.bin_width_ps = 10;
  p.axis.bins = 30;
  const int peak = p.axis.bin_of(p.onset_ps());
  REQUIRE(peak >= 0);
  std::vector<double> rv[3];  // relative variances per bin at 1000 samples
  const ConnectionSampling kinds[3] = {ConnectionSampling::Auto, ConnectionSampling::Equiangular,
                                       ConnectionSampling::Collision};
  for (int k = 0; k < 3; ++k) {
    SceneDesc d = p.scene();
    d.media[0].connection = kinds[k];
    const auto films = render_batches(d, 1000, 16, /*max_depth=*/1);
    for (int i = 0; i < p.axis.bins; ++i) {
      const auto [m, expected] = check_bin(films, p, i, name_of(kinds[k]));
      rv[k].push_back(expected > 0 ? std::pow(m.se / expected, 2) : 0.0);
    }
  }
  INFO("peak bin " << peak << ": relative variance auto " << rv[0][peak] << ", equiangular "
                   << rv[1][peak] << ", collisions " << rv[2][peak]);
  double far[3] = {0, 0, 0};  // pooled over the frames well past the peak
  for (int k = 0; k < 3; ++k)
    for (int i = peak + 5; i < p.axis.bins; ++i) far[k] += rv[k][i];
  INFO("far bins: auto " << far[0] << ", equiangular " << far[1] << ", collisions " << far[2]);
  // Measured: 0.036 of the collisions' at the peak; 0.38 of equiangular's and 0.64 of the
  // collisions' in the far bins.
  CHECK(rv[0][peak] < 0.2 * rv[2][peak]);
  CHECK(far[0] < 0.6 * far[1]);
  CHECK(far[0] < 1.2 * far[2]);
}

// Catches: with several point lights (no single light's plan made once per segment), a light
// gathered twice or by neither: one light level with the camera (the camera segment's MIS of
// collisions and line-to-point) and one ahead of it beside the ray (collisions alone) add their
// own single scattering, bin by bin.
TEST_CASE("auto's camera-segment MIS with two point lights", "[time-sampling]") {
  SingleScatterSetup p;
  p.axis.t_start_ps = 100;
  p.axis.bin_width_ps = 20;
  p.axis.bins = 20;
  SingleScatterSetup ahead = p;
  ahead.z0 = 40;
  SceneDesc d = p.scene();
  d.media[0].connection = ConnectionSampling::Auto;
  LightDesc second = d.lights.front();
  second.position = {0, -ahead.h, ahead.z0};  // the mirror image: the same single scattering
  d.lights.push_back(second);
  const auto films = render_batches(d, 8000, 16, /*max_depth=*/1);
  int checked = 0;
  for (int i = 0; i < p.axis.bins; ++i) {
    const MeanSE m = bin_mean_se(films, i);
    const double expected = p.bin(i) + ahead.bin(i);
    INFO("bin " << i << ": " << m.mean << " +- " << m.se << " expected " << expected);
    CHECK(std::abs(m.mean - expected) <= 4.0 * m.se + 1e-9 * expected);
    if (expected > 0) {
      CHECK(m.se < 0.1 * expected);
      ++checked;
    }
  }
  CHECK(checked >= 15);
}

// Catches: the third auto rule's segment test reading the window or the depths wrongly, and
// Scene::medium_at (where the lights are) reading the wrong side of a box.
TEST_CASE("auto's third rule: thin segments, lights outside the scattering media",
          "[time-sampling]") {
  CHECK(thin_segment(40.0, 1e4, 0.02));        // optical depth 0.8
  CHECK_FALSE(thin_segment(60.0, 1e4, 0.02));  // 1.2
  CHECK(thin_segment(4.0, 1e4, 0.02));         // 0.08
  CHECK_FALSE(thin_segment(2.0, 1e4, 0.02));   // 0.04: too little light for a shadow ray
  CHECK(thin_segment(1e3, 40.0, 0.02));        // the window ends first: 0.8
  CHECK_FALSE(thin_segment(std::numeric_limits<double>::infinity(), 1e3, 0.01));
  const SceneDesc d = load_scene_string(R"({
    "camera": { "type": "perspective", "position": [0, 0, 100], "look_at": [0, 0, 0], "fov": 20,
                "resolution": [4, 4] },
    "time": { "t_start": 0, "bin_width": 10, "bins": 10 },
    "media": { "fog": { "type": "homogeneous", "sigma_a": 0.001, "sigma_s": 0.01 } },
    "shapes": [ { "type": "box", "min": [-20, -20, -40], "max": [20, 20, 0], "medium": "fog" } ],
    "lights": [ { "type": "point", "position": [0, 25, 10], "intensity": 100 } ]
  })",
                                        "thin fog", ".");
  const Scene scene(d);
  CHECK_FALSE(scene.media()[static_cast<size_t>(scene.medium_at({0, 25, 10}))].interacts());
  CHECK(scene.media()[static_cast<size_t>(scene.medium_at({0, 15, -10}))].interacts());
  CHECK(scene.medium_at({0, 0, 100}) == scene.camera_medium());
}

// Catches: thin segments whose collisions and line-to-point connection do not share the light by
// weights summing to one (a light outside the fog: every segment in the box is thin, so every
// bin of every path length would be off, e.g. by the collisions keeping weight 1), and a rule
// that never engages. Reference: collisions alone (next-event estimation at mean-free-path
// collisions), with 4x the samples. At equal samples the thin segments' connections must also
// lower the pooled variance well below the collisions' (measured: 0.37 of it; 1.1 without the
// rule): in a box of optical depth 0.5 most segments hold no collision.
TEST_CASE("auto's thin-segment MIS with a light outside the fog agrees with collisions",
          "[time-sampling][statistical]") {
  const SceneDesc d = load_scene_string(R"({
    "camera": { "type": "orthographic", "position": [0, 0, 100], "look_at": [0, 0, 0],
                "width": 40, "resolution": [4, 3] },
    "time": { "t_start": 300, "bin_width": 25, "bins": 16 },
    "media": { "fog": { "type": "homogeneous", "sigma_a": 0.002, "sigma_s": 0.01, "g": 0.3 } },
    "shapes": [ { "type": "box", "min": [-20, -20, -40], "max": [20, 20, 0], "medium": "fog" } ],
    "lights": [ { "type": "point", "position": [0, 25, 10], "intensity": 1000 } ]
  })",
                                        "thin fog, light outside", ".");
  std::vector<BinStats> got;
  for (ConnectionSampling c : {ConnectionSampling::Auto, ConnectionSampling::Collision}) {
    SceneDesc e = d;
    e.media[0].connection = c;
    const bool is_auto = c == ConnectionSampling::Auto;
    got.push_back(bin_stats(render_batches(e, is_auto ? 256 : 1024, 16, /*max_depth=*/4)));
  }
  CHECK(check_agreement(got[0], got[1], "auto vs collisions") >= 12);
  double v_auto = 0, v_collision = 0;  // relative variances at equal samples
  for (size_t i = 0; i < got[0].mean.size(); ++i) {
    if (!(got[1].mean[i] > 0)) continue;
    v_auto += std::pow(got[0].se[i] / got[1].mean[i], 2);
    v_collision += 4 * std::pow(got[1].se[i] / got[1].mean[i], 2);
  }
  INFO("pooled relative variance at equal samples, auto " << v_auto << ", collisions "
                                                          << v_collision);
  CHECK(v_auto < 0.6 * v_collision);
}
