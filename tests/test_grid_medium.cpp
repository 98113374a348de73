// Voxel media: exact optical depth and optical path length along rays, and distance sampling
// (mean free path, time-uniform in OPL, MIS) against its own pdfs and for unbiasedness.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>

#include "core/rng.h"
#include "media/grid_medium.h"
#include "media/volume_data.h"
#include "samplers/medium_distance.h"
#include "samplers/stats.h"

using namespace femto;

namespace {

// A grid with voxel size h and its corner at `origin`; sigma_t = density (scale 1).
VolumeData make_volume(int nx, int ny, int nz, double h, const Vec3& origin, uint64_t seed,
                       double eta_lo = 1.0, double eta_hi = 2.0) {
  VolumeData v{};
  v.density = DenseGrid(nx, ny, nz);
  v.eta = DenseGrid(nx, ny, nz);
  Rng rng(seed, 3);
  for (auto& x : v.density.v) x = static_cast<float>(rng.uniform() < 0.2 ? 0.0 : 0.5 * rng.uniform());
  for (auto& x : v.eta.v) x = static_cast<float>(eta_lo + (eta_hi - eta_lo) * rng.uniform());
  v.density.update_range();
  v.eta.update_range();
  const double g2w[12] = {h, 0, 0, origin.x, 0, h, 0, origin.y, 0, 0, h, origin.z};
  const double w2g[12] = {1 / h, 0, 0, -origin.x / h, 0, 1 / h, 0, -origin.y / h, 0, 0, 1 / h, -origin.z / h};
  std::copy(g2w, g2w + 12, v.grid_to_world);
  std::copy(w2g, w2g + 12, v.world_to_grid);
  return v;
}

VdbMediumDesc grid_desc(bool trilinear, double eta_outside = 1.0) {
  VdbMediumDesc d;
  d.sigma_t_scale = 1.0;
  d.albedo = 0.8;
  d.eta = eta_outside;
  d.interpolation = trilinear ? VdbMediumDesc::Interpolation::Trilinear : VdbMediumDesc::Interpolation::Nearest;
  return d;
}

// Independent reference: split the ray at every plane where the interpolated field can change
// (voxel faces for nearest, voxel-centre planes for trilinear) and integrate each smooth piece
// with Simpson's rule on point lookups (exact for the cubic pieces of trilinear data).
void reference_integrals(const GridMedium& m, const VolumeData& v, const Ray& ray, double s_max,
                         double& tau, double& opl) {
  std::vector<double> cuts = {0.0, s_max};
  const double off = m.trilinear() ? 0.5 : 0.0;
  const int n[3] = {v.density.nx, v.density.ny, v.density.nz};
  for (int a = 0; a < 3; ++a) {
    const double* w = v.world_to_grid + 4 * a;
    const double o = w[0] * ray.o.x + w[1] * ray.o.y + w[2] * ray.o.z + w[3] + off;
    const double d = w[0] * ray.d.x + w[1] * ray.d.y + w[2] * ray.d.z;
    if (d == 0) continue;
    for (int k = -1; k <= n[a] + 2; ++k) {
      const double s = (k - o) / d;
      if (s > 0 && s < s_max) cuts.push_back(s);
    }
  }
  std::sort(cuts.begin(), cuts.end());
  tau = opl = 0;
  for (size_t i = 0; i + 1 < cuts.size(); ++i) {
    const double a = cuts[i], b = cuts[i + 1];
    if (b <= a) continue;
    for (int q = 0; q < 4; ++q) {  // 4 Simpson panels per piece (exact for cubics anyway)
      const double x0 = a + (b - a) * q / 4, x1 = a + (b - a) * (q + 1) / 4, xm = 0.5 * (x0 + x1);
      const double hq = (x1 - x0) / 6;
      // Point lookups exactly on a cut are ambiguous for nearest: nudge the ends inwards.
      const double e = 1e-12 * (b - a);
      tau += hq * (m.sigma_t_at(ray.at(x0 + e)) + 4 * m.sigma_t_at(ray.at(xm)) + m.sigma_t_at(ray.at(x1 - e)));
      opl += hq * (m.eta_at(ray.at(x0 + e)) + 4 * m.eta_at(ray.at(xm)) + m.eta_at(ray.at(x1 - e)));
    }
  }
}

}  // namespace

// Catches: DDA skipping or repeating cells, wrong voxel indexing, OPL not counting the index
// outside the grid.
TEST_CASE("grid medium: exact OPL and optical depth along an axis-aligned ray", "[grid]") {
  VolumeData v = make_volume(4, 1, 1, 2.0, {0, 0, 0}, 1);
  v.density.v = {0.0f, 0.125f, 0.25f, 0.375f};  // exactly representable in float
  v.eta.v = {1.0f, 1.5f, 2.0f, 1.25f};
  const GridMedium m(v, grid_desc(false, 1.1));
  const Ray ray{{-1, 1, 1}, {1, 0, 0}};
  GridMedium::Walker w(m, ray, 10.0);
  double tau, opl;
  integrate_segments(w, tau, opl);
  CHECK(opl == Approx(1.1 * 1 + 2 * (1.0 + 1.5 + 2.0 + 1.25) + 1.1 * 1).epsilon(1e-14));
  CHECK(tau == Approx(2 * (0.0 + 0.125 + 0.25 + 0.375)).epsilon(1e-14));
}

// Catches: wrong cubic coefficients for trilinear data, wrong dual-cell indexing or padding,
// gaps or overlaps between segments, broken empty-space skipping.
TEST_CASE("grid medium: walker integrals equal an independent quadrature on oblique rays", "[grid]") {
  for (bool trilinear : {false, true}) {
    for (bool skipping : {true, false}) {
      VolumeData v = make_volume(13, 9, 11, 0.7, {-3, -2, -4}, 5);
      // An empty, constant-index region so that whole blocks are skipped.
      for (int k = 0; k < 11; ++k)
        for (int j = 0; j < 9; ++j)
          for (int i = 0; i < 9; ++i) {
            v.density.at(i, j, k) = 0.0f;
            v.eta.at(i, j, k) = 1.25f;
          }
      GridMedium m(v, grid_desc(trilinear, 1.25));
      m.set_empty_space_skipping(skipping);
      Rng rng(11, 2);
      for (int r = 0; r < 50; ++r) {
        const Vec3 o(-6 + 2 * rng.uniform(), -5 + 2 * rng.uniform(), -7 + 2 * rng.uniform());
        const Vec3 target(-3 + 9 * rng.uniform(), -2 + 6 * rng.uniform(), -4 + 8 * rng.uniform());
        const Ray ray{o, normalize(target - o)};
        const double s_max = length(target - o) * (0.5 + rng.uniform());
        GridMedium::Walker w(m, ray, s_max);
        MediumSegment seg;
        double prev_end = 0, tau = 0, opl = 0;
        while (w.next(seg)) {
          REQUIRE(seg.s0 == Approx(prev_end).margin(1e-12));  // contiguous
          REQUIRE(seg.s1 >= seg.s0);
          tau += seg.sigma_t.integral(seg.s1 - seg.s0);
          opl += seg.eta.integral(seg.s1 - seg.s0);
          prev_end = seg.s1;
        }
        REQUIRE(prev_end == Approx(s_max).epsilon(1e-12));
        double tau_ref, opl_ref;
        reference_integrals(m, v, ray, s_max, tau_ref, opl_ref);
        INFO("trilinear " << trilinear << " ray " << r);
        REQUIRE(opl == Approx(opl_ref).epsilon(1e-9));
        REQUIRE(tau == Approx(tau_ref).epsilon(1e-9).margin(1e-12));
      }
    }
  }
}

namespace {
// Samples many distances and returns the chi-square p-value against the strategy's own pdf,
// computed from reference integrals (bins over [0, s_max] plus a "no collision" cell).
// A mixture (kind Mixture) samples with time-uniform share q_sample and is tested against the
// pdf of share q_pdf.
double distance_chi2(const GridMedium& m, const VolumeData& v, const Ray& ray, double s_max,
                     const DistanceStrategy& st, int n, double q_sample = 0, double q_pdf = 0) {
  const int bins = 40;
  std::vector<double> observed(bins + 1, 0.0), expected(bins + 1, 0.0);
  Rng rng(99, 1);
  const bool mixture = st.kind == DistanceSampling::Mixture;
  for (int i = 0; i < n; ++i) {
    GridMedium::Walker w(m, ray, s_max);
    const DistanceEvent ev = mixture ? sample_distance_mixture(w, st, q_sample, rng.uniform())
                                     : sample_distance(w, st, rng.uniform());
    if (!ev.collided) observed[bins] += 1;
    else observed[std::min(bins - 1, static_cast<int>(ev.s / s_max * bins))] += 1;
  }
  const bool mfp = st.kind == DistanceSampling::Mfp;
  double prev_survival = 1.0;
  for (int b = 0; b < bins; ++b) {
    double tau, opl;
    reference_integrals(m, v, ray, s_max * (b + 1) / bins, tau, opl);
    const double survival = mixture ? mixture_pass(q_pdf, st.lambda, tau, opl)
                            : mfp   ? std::exp(-tau)
                                    : std::exp(-st.lambda * opl);
    expected[b] = n * (prev_survival - survival);
    prev_survival = survival;
  }
  expected[bins] = n * prev_survival;
  return stats::chi2_test(observed, expected).p_value;
}
}  // namespace

// The sanitizer build draws an eighth of the samples of the two tests below: the same code runs
// under ASan and UBSan (about a tenth of Release's speed), and the Release build keeps the full
// statistical power, which the power checks (a wrong pdf must be rejected) need.
#ifdef FEMTO_TEST_SANITIZED
constexpr int kSampleDivisor = 8;
#else
constexpr int kSampleDivisor = 1;
#endif

// Catches: time-uniform sampling done in distance instead of optical path length (wrong when eta
// varies), wrong inversion of the OPL or optical-depth integral inside a cell, and a mixture
// whose pick or split of the uniform does not give its stated density.
TEST_CASE("grid medium: sampled distances follow their pdfs (chi-square)", "[grid][chi2]") {
  const int samples = 200000 / kSampleDivisor;
  const bool power_checks = kSampleDivisor == 1;
  for (bool trilinear : {false, true}) {
    const VolumeData v = make_volume(10, 10, 10, 1.0, {0, 0, 0}, 21, 1.0, 3.0);
    const GridMedium m(v, grid_desc(trilinear, 1.0));
    const Ray ray{{-0.5, 0.3, 0.2}, normalize(Vec3(1, 0.8, 0.9))};
    DistanceStrategy tu{DistanceSampling::TimeUniform, 0.08, MisHeuristic::Balance};
    DistanceStrategy mfp{DistanceSampling::Mfp, 0.0, MisHeuristic::Balance};
    INFO("trilinear " << trilinear);
    CHECK(distance_chi2(m, v, ray, 16.0, tu, samples) > 1e-3);
    CHECK(distance_chi2(m, v, ray, 16.0, mfp, samples) > 1e-3);
    // The one-sample mixture against its own pdf, and (power) against a mixture of another share.
    DistanceStrategy mix{DistanceSampling::Mixture, 0.08, MisHeuristic::Balance};
    CHECK(distance_chi2(m, v, ray, 16.0, mix, samples, 0.35, 0.35) > 1e-3);
    if (power_checks) CHECK(distance_chi2(m, v, ray, 16.0, mix, samples, 0.35, 0.25) < 1e-6);
    // Power check: sampling in distance with the same lambda (eta ignored) must be rejected.
    if (!power_checks) continue;
    VolumeData v1 = v;
    for (auto& e : v1.eta.v) e = 1.0f;
    const GridMedium m1(v1, grid_desc(trilinear, 1.0));
    const double p_wrong = [&] {
      // Samples from the eta = 1 medium, tested against the pdf of the eta-varying one.
      const int bins = 40, n = 200000;
      std::vector<double> obs(bins + 1, 0.0), exp_(bins + 1, 0.0);
      Rng rng(5, 5);
      for (int i = 0; i < n; ++i) {
        GridMedium::Walker w(m1, ray, 16.0);
        const DistanceEvent ev = sample_distance(w, tu, rng.uniform());
        if (!ev.collided) obs[bins] += 1;
        else obs[std::min(bins - 1, static_cast<int>(ev.s / 16.0 * bins))] += 1;
      }
      double prev = 1.0;
      for (int b = 0; b < bins; ++b) {
        double tau, opl;
        reference_integrals(m, v, ray, 16.0 * (b + 1) / bins, tau, opl);
        const double sv = std::exp(-tu.lambda * opl);
        exp_[b] = n * (prev - sv);
        prev = sv;
      }
      exp_[bins] = n * prev;
      return stats::chi2_test(obs, exp_).p_value;
    }();
    CHECK(p_wrong < 1e-6);
  }
}

// Catches: MIS weights that do not sum to one (biased estimates), pdfs of the other strategy
// evaluated at the wrong point, wrong pass-through probabilities (also of the one-sample
// mixture: a weight that is not f over the mixture density).
TEST_CASE("grid medium: every strategy estimates collision and transmission integrals without bias",
          "[grid]") {
  const VolumeData v = make_volume(8, 8, 8, 1.0, {0, 0, 0}, 33, 1.0, 2.5);
  const GridMedium m(v, grid_desc(true, 1.0));
  const Ray ray{{-0.5, 0.5, 0.7}, normalize(Vec3(1, 0.7, 0.6))};
  const double s_max = 12.0;
  // Targets: T(s_max) and the integral of h(s) sigma_t(s) T(s) with h(s) = s (a smooth weight).
  double tau_end, opl_end;
  reference_integrals(m, v, ray, s_max, tau_end, opl_end);
  const int pieces = 1000;
  double target = 0, tau_acc = 0;
  for (int i = 0; i < pieces; ++i) {  // midpoint rule on the exactly integrated optical depth
    const double a = s_max * i / pieces, b = s_max * (i + 1) / pieces;
    double tau_b, opl_b;
    reference_integrals(m, v, ray, b, tau_b, opl_b);
    target += 0.5 * (a + b) * (std::exp(-tau_acc) - std::exp(-tau_b));
    tau_acc = tau_b;
  }
  const DistanceStrategy strategies[] = {
      {DistanceSampling::Mfp, 0.0, MisHeuristic::Balance},
      {DistanceSampling::TimeUniform, 0.05, MisHeuristic::Balance},
      {DistanceSampling::Mis, 0.05, MisHeuristic::Balance},
      {DistanceSampling::Mis, 0.05, MisHeuristic::Power},
      {DistanceSampling::Mixture, 0.05, MisHeuristic::Balance}};
  for (const auto& st : strategies) {
    Rng rng(17, static_cast<uint64_t>(st.kind) * 2 + static_cast<uint64_t>(st.heuristic));
    const int n = 400000 / kSampleDivisor;
    double sum_c = 0, sum_c2 = 0, sum_t = 0, sum_t2 = 0;
    for (int i = 0; i < n; ++i) {
      GridMedium::Walker w(m, ray, s_max);
      double c = 0, t = 0;
      if (st.kind == DistanceSampling::Mis) {
        // Multi-sample MIS: both collisions weighted; transmission from the mfp sample.
        const double u1 = rng.uniform(), u2 = rng.uniform();
        const DistancePair pr = sample_distance_mis(w, st, u1, u2);
        if (pr.mfp.collided) c += pr.mfp_nee_weight * pr.mfp.s;
        if (pr.tu.collided) c += pr.tu_nee_weight * pr.tu.s;
        if (!pr.mfp.collided) t = pr.mfp.weight;
      } else {
        // The mixture: one-sample MIS, time-uniform share 0.35 (its weight is f / mixture pdf).
        const DistanceEvent ev = st.kind == DistanceSampling::Mixture
                                     ? sample_distance_mixture(w, st, 0.35, rng.uniform())
                                     : sample_distance(w, st, rng.uniform());
        c = ev.collided ? ev.weight * ev.s : 0.0;
        t = ev.collided ? 0.0 : ev.weight;
      }      sum_c += c;
      sum_c2 += c * c;
      sum_t += t;
      sum_t2 += t * t;
    }
    const double mc = sum_c / n, mt = sum_t / n;
    const double se_c = std::sqrt((sum_c2 / n - mc * mc) / n), se_t = std::sqrt((sum_t2 / n - mt * mt) / n);
    INFO("strategy " << static_cast<int>(st.kind) << " heuristic " << static_cast<int>(st.heuristic)
                     << ": collision " << mc << " +- " << se_c << " (target " << target << "), pass "
                     << mt << " +- " << se_t << " (target " << std::exp(-tau_end) << ")");
    CHECK(std::abs(mc - target) < 4 * se_c + 1e-4 * target);  // 1e-4: midpoint-rule error
    CHECK(std::abs(mt - std::exp(-tau_end)) < 4 * se_t + 1e-12);
  }
}

namespace {
// Times O(s_k) / c of all vertices of straight-line sample paths restarted at each vertex, up to
// the window end, in a medium whose sigma_t and eta vary along the ray.
std::vector<double> vertex_times(const GridMedium& m, const DistanceStrategy& st, double t_end_ps, int paths) {
  std::vector<double> times;
  const Vec3 d = normalize(Vec3(1, 0.05, 0.03));
  for (int p = 0; p < paths; ++p) {
    Rng rng(777, static_cast<uint64_t>(p));
    Vec3 x(0.0, 2.5, 2.5);
    double t = 0;
    for (;;) {
      GridMedium::Walker w(m, Ray{x, d}, 1e9);
      const DistanceEvent ev = sample_distance(w, st, rng.uniform());
      if (!ev.collided) break;
      t += ev.opl / 0.299792458;
      if (t >= t_end_ps) break;
      times.push_back(t);
      x = x + d * ev.s;
    }
  }
  return times;
}
}  // namespace

// Catches: time-uniform sampling that is uniform in distance but not in time when eta varies,
// and a uniformity test too weak to tell strategies apart (mfp must fail in this medium).
TEST_CASE("time-uniform vertex times are uniform over the window; mfp's are not", "[grid][uniformity]") {
  // 60 mm along x: dense (sigma_t 2/mm) for x < 10 mm, thin (0.05/mm) beyond; eta 1.0-1.6 per voxel.
  VolumeData v = make_volume(60, 5, 5, 1.0, {0, 0, 0}, 8, 1.0, 1.6);
  for (int k = 0; k < 5; ++k)
    for (int j = 0; j < 5; ++j)
      for (int i = 0; i < 60; ++i) v.density.at(i, j, k) = i < 10 ? 2.0f : 0.05f;
  for (bool trilinear : {false, true}) {
    const GridMedium m(v, grid_desc(trilinear, 1.0));
    const double t_end = 40.0 / 0.299792458;  // 40 mm of vacuum OPL: 20 mean free paths in the dense part
    const DistanceStrategy tu{DistanceSampling::TimeUniform, 3.5 / 40.0, MisHeuristic::Balance};
    const DistanceStrategy mfp{DistanceSampling::Mfp, 0, MisHeuristic::Balance};
    const int bins = 50;
    for (const auto& [st, expect_uniform] : {std::pair{tu, true}, std::pair{mfp, false}}) {
      const std::vector<double> times = vertex_times(m, st, t_end, 20000);
      std::vector<double> observed(bins, 0.0), expected(bins, static_cast<double>(times.size()) / bins);
      for (double t : times) observed[std::min(bins - 1, static_cast<int>(t / t_end * bins))] += 1;
      const double p_chi2 = stats::chi2_test(observed, expected).p_value;
      const double D = stats::ks_statistic_uniform(times, 0.0, t_end);
      const double p_ks = stats::ks_p_value(D, times.size());
      INFO("trilinear " << trilinear << " strategy " << (expect_uniform ? "time_uniform" : "mfp") << ": " << times.size()
                        << " vertex times, chi2 p " << p_chi2 << ", KS D " << D << " p " << p_ks);
      if (expect_uniform) {
        CHECK(times.size() > 50000);
        CHECK(p_chi2 > 1e-3);
        CHECK(p_ks > 1e-3);
      } else {
        CHECK(p_chi2 < 1e-6);
        CHECK(p_ks < 1e-6);
      }
    }
  }
}
