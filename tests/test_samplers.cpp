// Statistical tests of the warps in core/sampling.h, HG phase sampling and exponential distance
// sampling, plus sanity checks of the statistics in samplers/stats.h themselves.
//
// Significance: a chi-square / KS test fails when p < 1e-3. Every test uses fixed seeds, so each
// outcome is deterministic (no flaky failures); a correct sampler passes with the seeds used here,
// and a wrong one is expected to fail by orders of magnitude (see "chi2 test has power").
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <stdexcept>
#include <vector>

#include "core/constants.h"
#include "core/rng.h"
#include "core/sampling.h"
#include "core/vec3.h"
#include "media/phase_hg.h"
#include "samplers/distance.h"
#include "samplers/exponential_ziggurat.h"
#include "samplers/interval_exponential.h"
#include "samplers/stats.h"

using femto::kPi;
using femto::Rng;
using femto::Vec3;
namespace st = femto::stats;

namespace {

constexpr double kSamplerAlpha = 1e-3;  // reject when p < kSamplerAlpha

struct Point2 {
  double x, y;
};

/// Bins n samples of `draw` on an nx x ny grid over [x0,x1] x [y0,y1] (values are clamped into
/// the edge cells, so the grid must cover the support) and tests the counts against
/// n * cell_mass(xa, xb, ya, yb). Non-finite (invalid) samples fail the test outright.
st::Chi2Result chi2_grid(const std::function<Point2(Rng&)>& draw,
                         const std::function<double(double, double, double, double)>& cell_mass,
                         double x0, double x1, int nx, double y0, double y1, int ny, int n,
                         uint64_t seed) {
  std::vector<double> observed(static_cast<size_t>(nx * ny), 0.0), expected(observed.size());
  Rng rng(seed, 17);
  int invalid = 0;
  const auto cell = [](double v, double lo, double hi, int cells) {
    const int i = static_cast<int>(std::floor((v - lo) / (hi - lo) * cells));
    return std::min(std::max(i, 0), cells - 1);
  };
  for (int k = 0; k < n; ++k) {
    const Point2 p = draw(rng);
    if (!std::isfinite(p.x) || !std::isfinite(p.y)) {
      ++invalid;
      continue;
    }
    observed[cell(p.x, x0, x1, nx) * ny + cell(p.y, y0, y1, ny)] += 1.0;
  }
  CHECK(invalid == 0);
  double total_mass = 0.0;
  const double hx = (x1 - x0) / nx, hy = (y1 - y0) / ny;
  for (int i = 0; i < nx; ++i)
    for (int j = 0; j < ny; ++j) {
      const double m = cell_mass(x0 + i * hx, x0 + (i + 1) * hx, y0 + j * hy, y0 + (j + 1) * hy);
      expected[i * ny + j] = n * m;
      total_mass += m;
    }
  CHECK(total_mass == Approx(1.0).margin(1e-6));  // the grid must carry all the pdf's mass
  return st::chi2_test(observed, expected);
}

/// Cell mass of a density over (cos theta, phi) by numerical quadrature.
std::function<double(double, double, double, double)> integrated(
    std::function<double(double, double)> pdf) {
  return [pdf = std::move(pdf)](double xa, double xb, double ya, double yb) {
    return st::integrate_2d(pdf, xa, xb, ya, yb, 1e-10);
  };
}

/// (cos theta, phi in [0, 2 pi)) of unit vector w in frame f; NaN (failing chi2_grid) if w is
/// not unit length.
Point2 spherical(const femto::Frame& f, const Vec3& w) {
  if (std::abs(femto::length(w) - 1.0) > 1e-12) return {std::nan(""), std::nan("")};
  const Vec3 l = f.to_local(w);
  double phi = std::atan2(l.y, l.x);
  if (phi < 0.0) phi += 2.0 * kPi;
  return {l.z, phi};
}

const Vec3 kIncoming = femto::normalize(Vec3(0.3, -0.5, 0.8));

/// Chi-square of HG samples with asymmetry g_sample against the HG pdf with g_pdf.
st::Chi2Result hg_chi2(double g_sample, double g_pdf, uint64_t seed) {
  const femto::Frame frame(kIncoming);
  return chi2_grid(
      [&](Rng& r) {
        const double u1 = r.uniform(), u2 = r.uniform();
        return spherical(frame, femto::hg_sample(kIncoming, g_sample, u1, u2).dir);
      },
      integrated([g_pdf](double mu, double) { return femto::hg_eval(mu, g_pdf); }), -1.0, 1.0,
      40, 0.0, 2.0 * kPi, 20, 200000, seed);
}

/// Integral over [0, inf) of f(s) * pdf, by s = lo + t / ((1 - t) scale), t in [0, 1].
double integrate_to_infinity(const std::function<double(double)>& f, double lo, double scale) {
  return st::adaptive_simpson(
      [&](double t) {
        if (t >= 1.0) return 0.0;
        return f(lo + t / ((1.0 - t) * scale)) / ((1.0 - t) * (1.0 - t) * scale);
      },
      0.0, 1.0, 1e-12);
}

}  // namespace

// Catches a wrong HG inverse CDF, a wrong azimuth/frame construction or mirrored g sign.
TEST_CASE("HG sampling matches hg_eval (chi-square over cos theta x phi)", "[samplers][hg]") {
  uint64_t seed = 1;
  for (const double g : {-0.9, 0.0, 0.5, 0.9}) {
    const st::Chi2Result r = hg_chi2(g, g, seed++);
    INFO("g = " << g << "  chi2 = " << r.chi2 << "  dof = " << r.dof << "  p = " << r.p_value
                << "  pooled = " << r.cells_pooled);
    CHECK(r.p_value >= kSamplerAlpha);
  }
}

// Catches a random walk's HG sampler (constants worked out once per g, no renormalisation of the
// new direction) that differs from the HG density: the same chi-square over cos theta x phi.
TEST_CASE("the walk's HG direction sampler matches hg_eval (chi-square)", "[samplers][hg]") {
  uint64_t seed = 11;
  const femto::Frame frame(kIncoming);
  for (const double g : {-0.9, 0.01, 0.5, 0.9}) {
    const femto::HgCosSampler hg = femto::HgCosSampler::of(g);
    const st::Chi2Result r = chi2_grid(
        [&](Rng& rng) {
          const double u1 = rng.uniform(), u2 = rng.uniform();
          return spherical(frame, femto::hg_sample_direction(kIncoming, hg, u1, u2));
        },
        integrated([g](double mu, double) { return femto::hg_eval(mu, g); }), -1.0, 1.0, 40, 0.0,
        2.0 * kPi, 20, 200000, seed++);
    INFO("g = " << g << "  chi2 = " << r.chi2 << "  dof = " << r.dof << "  p = " << r.p_value);
    CHECK(r.p_value >= kSamplerAlpha);
  }
}

// Catches a walk whose direction drifts off the unit sphere: hg_sample_direction does not
// renormalise (that step sat on the walk's critical path), which is safe only because the frame
// of a direction of squared length 1 + delta gives a new one of 1 + k delta (plus rounding), with
// k of mean at most 1 over the azimuth, so the error wanders at tens of ulp instead of growing.
// 10^6 chained scatterings per g, lengths in long double.
TEST_CASE("chained HG scatterings keep unit directions without renormalising", "[samplers][hg]") {
  for (const double g : {-0.9, 0.01, 0.9, 0.99, 0.999}) {
    const femto::HgCosSampler hg = femto::HgCosSampler::of(g);
    Rng rng(21, 3);
    Vec3 d = kIncoming;
    double worst = 0;
    for (int k = 0; k < 1000000; ++k) {
      const double u_phi = rng.uniform32(), u_cos = rng.uniform32();
      d = femto::hg_sample_direction(d, hg, u_cos, u_phi);
      const long double x = d.x, y = d.y, z = d.z;
      worst =
          std::fmax(worst, static_cast<double>(std::fabs(std::sqrt(x * x + y * y + z * z) - 1.0L)));
    }
    INFO("g = " << g << ": max | |d| - 1 | = " << worst);
    CHECK(worst <= 1e-13);
  }
}

// Catches PhaseSample::value disagreeing with the density the direction was drawn from, or a
// non-unit sampled direction.
TEST_CASE("HG sample value equals hg_eval of the sampled cosine", "[samplers][hg]") {
  Rng rng(99, 3);
  for (const double g : {-0.9, 0.0, 0.5, 0.9}) {
    double worst_len = 0.0, worst_rel = 0.0;
    for (int k = 0; k < 10000; ++k) {
      const double u1 = rng.uniform(), u2 = rng.uniform();
      const femto::PhaseSample s = femto::hg_sample(kIncoming, g, u1, u2);
      const double pdf = femto::hg_eval(femto::dot(s.dir, kIncoming), g);
      worst_len = std::fmax(worst_len, std::abs(femto::length(s.dir) - 1.0));
      worst_rel = std::fmax(worst_rel, std::abs(s.value - pdf) / pdf);
    }
    INFO("g = " << g << "  max |len - 1| = " << worst_len << "  max rel. error = " << worst_rel);
    CHECK(worst_len < 1e-12);
    CHECK(worst_rel < 1e-9);
  }
}

// Catches a wrong normalisation constant or exponent in hg_eval, or a sign error in g.
TEST_CASE("HG integrates to one and has mean cosine g", "[samplers][hg]") {
  for (const double g : {-0.99, -0.9, -0.5, 0.0, 0.3, 0.5, 0.9, 0.99}) {
    INFO("g = " << g);
    const double norm = 2.0 * kPi *
        st::adaptive_simpson([g](double mu) { return femto::hg_eval(mu, g); }, -1.0, 1.0, 1e-11);
    const double mean = 2.0 * kPi *
        st::adaptive_simpson([g](double mu) { return mu * femto::hg_eval(mu, g); }, -1.0, 1.0,
                             1e-11);
    CHECK(norm == Approx(1.0).margin(1e-6));
    CHECK(mean == Approx(g).margin(1e-6));
  }
}

// Catches a wrong inverse CDF in sample_exponential (e.g. log(u) scale, missing 1/sigma_t) or a
// pdf that is not the density of the sampler.
TEST_CASE("Exponential distance sampling matches exponential_pdf", "[samplers][distance]") {
  uint64_t seed = 11;
  for (const double sigma_t : {0.1, 1.0, 7.5}) {
    const int bins = 50, n = 200000;
    const double s_max = 8.0 / sigma_t, h = s_max / bins;
    std::vector<double> observed(bins + 1, 0.0), expected(bins + 1, 0.0);
    Rng rng(seed++, 5);
    int invalid = 0;
    for (int k = 0; k < n; ++k) {
      const double s = femto::sample_exponential(sigma_t, rng.uniform());
      if (!(s >= 0.0) || !std::isfinite(s)) {
        ++invalid;
        continue;
      }
      observed[s >= s_max ? bins : static_cast<int>(s / h)] += 1.0;
    }
    CHECK(invalid == 0);
    const auto pdf = [sigma_t](double s) { return femto::exponential_pdf(sigma_t, s); };
    double mass = 0.0;
    for (int i = 0; i < bins; ++i) {
      const double m = st::adaptive_simpson(pdf, i * h, (i + 1) * h, 1e-12);
      expected[i] = n * m;
      mass += m;
    }
    const double tail = integrate_to_infinity(pdf, s_max, sigma_t);
    expected[bins] = n * tail;
    CHECK(mass + tail == Approx(1.0).margin(1e-9));
    const st::Chi2Result r = st::chi2_test(observed, expected);
    INFO("sigma_t = " << sigma_t << "  chi2 = " << r.chi2 << "  dof = " << r.dof
                      << "  p = " << r.p_value);
    CHECK(r.p_value >= kSamplerAlpha);
  }
}

// Catches a wrong inverse CDF in IntervalExponential (a missing offset a, the untruncated
// exponential, log(u) for log(1 - u mass)), a pdf that is not its density (a missing
// normalisation 1 - exp(-lambda L)), and a broken uniform limit or infinite interval.
TEST_CASE("Interval exponential sampling matches its pdf", "[samplers][distance]") {
  struct Case {
    double a, b, lambda;
  };
  uint64_t seed = 31;
  for (const Case c :
       {Case{2.0, 5.0, 0.7}, Case{-1.0, 0.5, 12.0}, Case{3.0, 4.0, 0.0}, Case{0.0, 1.0, 1e-10},
        Case{1.0, std::numeric_limits<double>::infinity(), 2.0}}) {
    const femto::IntervalExponential sampler(c.a, c.b, c.lambda);
    REQUIRE(sampler.valid());
    const int bins = 40, n = 200000;
    const double hi = std::isfinite(c.b) ? c.b : c.a + 8.0 / c.lambda, h = (hi - c.a) / bins;
    std::vector<double> observed(bins + 1, 0.0), expected(bins + 1, 0.0);
    Rng rng(seed++, 5);
    int outside = 0;
    for (int k = 0; k < n; ++k) {
      const double s = sampler.sample(rng.uniform());
      if (!(s >= c.a && s <= c.b)) {
        ++outside;
        continue;
      }
      observed[s >= hi ? bins : std::min(bins - 1, static_cast<int>((s - c.a) / h))] += 1.0;
    }
    CHECK(outside == 0);
    const auto pdf = [&](double s) { return sampler.pdf(s); };
    double mass = 0.0;
    for (int i = 0; i < bins; ++i) {
      const double m = st::adaptive_simpson(pdf, c.a + i * h, c.a + (i + 1) * h, 1e-12);
      expected[i] = n * m;
      mass += m;
    }
    const double tail = std::isfinite(c.b) ? 0.0 : integrate_to_infinity(pdf, hi, c.lambda);
    expected[bins] = n * tail;
    CHECK(mass + tail == Approx(1.0).margin(1e-9));
    const st::Chi2Result r = st::chi2_test(observed, expected);
    INFO("a = " << c.a << " b = " << c.b << " lambda = " << c.lambda << "  chi2 = " << r.chi2
                << "  dof = " << r.dof << "  p = " << r.p_value);
    CHECK(r.p_value >= kSamplerAlpha);
  }
  CHECK_FALSE(femto::IntervalExponential(1.0, 1.0, 1.0).valid());
  CHECK_FALSE(
      femto::IntervalExponential(0.0, std::numeric_limits<double>::infinity(), 0.0).valid());
}

// Catches a wrong ziggurat table (a layer whose area is not the others', edges that do not reach
// the top of the curve), a wedge test that accepts too much or too little (excess or deficit
// between the layers' inner edges), and a wrong tail beyond r (e.g. r + u instead of r + Exp).
TEST_CASE("Ziggurat exponential variates match exp(-x)", "[samplers][distance]") {
  const femto::ExpZiggurat& z = femto::ExpZiggurat::get();
  const double A = z.area();
  CHECK(z.edge(0) * z.height(1) == Approx(A).epsilon(1e-13));  // base rectangle + tail
  for (int i = 1; i < femto::ExpZiggurat::kLayers; ++i) {
    INFO("layer " << i);
    CHECK(z.edge(i) * (z.height(i + 1) - z.height(i)) == Approx(A).epsilon(1e-9));
    CHECK(z.edge(i + 1) < z.edge(i));
  }
  // Whole range: 300 bins of 0.04 up to 12 and an overflow bin.
  {
    const int bins = 300, n = 3000000;
    const double h = 0.04;
    std::vector<double> observed(bins + 1, 0.0), expected(bins + 1, 0.0);
    Rng rng(21, 3);
    int invalid = 0;
    for (int k = 0; k < n; ++k) {
      const double x = femto::sample_unit_exponential(rng);
      if (!(x >= 0.0 && std::isfinite(x))) {
        ++invalid;
        continue;
      }
      observed[x >= bins * h ? bins : static_cast<int>(x / h)] += 1.0;
    }
    for (int i = 0; i < bins; ++i) expected[i] = n * (std::exp(-i * h) - std::exp(-(i + 1) * h));
    expected[bins] = n * std::exp(-bins * h);
    CHECK(invalid == 0);
    const st::Chi2Result r = st::chi2_test(observed, expected);
    INFO("chi2 = " << r.chi2 << "  dof = " << r.dof << "  p = " << r.p_value);
    CHECK(r.p_value >= kSamplerAlpha);
  }
  // Beyond r (the tail, drawn from the base layer): x - r must be exponential again.
  {
    const double r = z.edge(1);
    const int bins = 40, want = 20000;
    const double h = 0.1;
    std::vector<double> observed(bins + 1, 0.0), expected(bins + 1, 0.0);
    Rng rng(22, 3);
    for (int got = 0; got < want;) {
      const double x = femto::sample_unit_exponential(rng);
      if (x < r) continue;
      const double y = x - r;
      observed[y >= bins * h ? bins : static_cast<int>(y / h)] += 1.0;
      ++got;
    }
    for (int i = 0; i < bins; ++i) expected[i] = want * (std::exp(-i * h) - std::exp(-(i + 1) * h));
    expected[bins] = want * std::exp(-bins * h);
    const st::Chi2Result t = st::chi2_test(observed, expected);
    INFO("tail: chi2 = " << t.chi2 << "  dof = " << t.dof << "  p = " << t.p_value);
    CHECK(t.p_value >= kSamplerAlpha);
  }
}

// Catches a non-normalised exponential_pdf, a pdf that is non-zero for s < 0, a transmittance
// inconsistent with the pdf, or finite distances in a non-interacting medium.
TEST_CASE("Exponential pdf normalisation, survival and sigma_t = 0", "[samplers][distance]") {
  for (const double sigma_t : {0.1, 1.0, 7.5}) {
    INFO("sigma_t = " << sigma_t);
    const auto pdf = [sigma_t](double s) { return femto::exponential_pdf(sigma_t, s); };
    CHECK(integrate_to_infinity(pdf, 0.0, sigma_t) == Approx(1.0).margin(1e-9));
    CHECK(femto::exponential_pdf(sigma_t, -1e-9) == 0.0);
    for (const double s : {0.3, 2.0, 9.0})
      CHECK(femto::exponential_survival(sigma_t, s) ==
            Approx(integrate_to_infinity(pdf, s, sigma_t)).margin(1e-9));
    CHECK(femto::sample_exponential(sigma_t, 0.0) == 0.0);
    CHECK(std::isfinite(femto::sample_exponential(sigma_t, std::nextafter(1.0, 0.0))));
  }
  for (const double u : {0.0, 0.5, 0.999})
    CHECK(femto::sample_exponential(0.0, u) == std::numeric_limits<double>::infinity());
}

// Catches cosine-hemisphere samples with the wrong radial warp (e.g. r = u1), below the horizon,
// or a pdf missing its 1/pi.
TEST_CASE("Cosine hemisphere warp matches its pdf", "[samplers][warps]") {
  const femto::Frame frame(Vec3(0.0, 0.0, 1.0));
  const auto r = chi2_grid(
      [&](Rng& rng) {
        const double u1 = rng.uniform(), u2 = rng.uniform();
        return spherical(frame, femto::sample_cosine_hemisphere(u1, u2));
      },
      integrated([](double mu, double) { return femto::cosine_hemisphere_pdf(mu); }), -1.0, 1.0,
      20, 0.0, 2.0 * kPi, 20, 200000, 21);
  INFO("chi2 = " << r.chi2 << "  dof = " << r.dof << "  p = " << r.p_value);
  CHECK(r.p_value >= kSamplerAlpha);
}

// Catches a uniform-sphere warp that clusters at the poles (e.g. z = cos(pi u1)) or a bad azimuth.
TEST_CASE("Uniform sphere warp is uniform", "[samplers][warps]") {
  const femto::Frame frame(Vec3(0.0, 0.0, 1.0));
  const auto r = chi2_grid(
      [&](Rng& rng) {
        const double u1 = rng.uniform(), u2 = rng.uniform();
        return spherical(frame, femto::sample_uniform_sphere(u1, u2));
      },
      integrated([](double, double) { return 1.0 / (4.0 * kPi); }), -1.0, 1.0, 40, 0.0,
      2.0 * kPi, 20, 200000, 22);
  INFO("chi2 = " << r.chi2 << "  dof = " << r.dof << "  p = " << r.p_value);
  CHECK(r.p_value >= kSamplerAlpha);
}

// Catches direction samplers whose output drifts off the unit sphere beyond rounding (an azimuth
// sine/cosine or a radius sqrt(1 - z^2) with errors of many ulps, e.g. from cancellation near the
// poles), which every later dot product and pdf would inherit. Lengths in long double.
TEST_CASE("Sampled directions are unit vectors to 1e-15", "[samplers][warps]") {
  const auto length_error = [](const Vec3& w) {
    const long double x = w.x, y = w.y, z = w.z;
    return static_cast<double>(std::fabs(std::sqrt(x * x + y * y + z * z) - 1.0L));
  };
  Rng rng(5, 8);
  double sphere = 0.0, hemisphere = 0.0, hg = 0.0, disc = 0.0;
  for (int k = 0; k < 300000; ++k) {
    // Every fourth u1 next to 0 or 1, where sqrt(1 - z^2) used to cancel.
    double u1 = rng.uniform();
    if (k % 4 == 0) u1 = (k % 8 == 0 ? 1.0 - u1 * 1e-9 : u1 * 1e-9);
    const double u2 = rng.uniform();
    sphere = std::fmax(sphere, length_error(femto::sample_uniform_sphere(u1, u2)));
    hemisphere = std::fmax(hemisphere, length_error(femto::sample_cosine_hemisphere(u1, u2)));
    hg = std::fmax(hg, length_error(femto::hg_sample(kIncoming, 0.7, u1, u2).dir));
    double x = 0.0, y = 0.0;
    femto::sample_uniform_disc(1.0, u2, x, y);  // the rim: radius exactly 1
    disc = std::fmax(disc, std::fabs(std::hypot(x, y) - 1.0));
  }
  INFO("max | |w| - 1 |: sphere " << sphere << ", cosine hemisphere " << hemisphere << ", HG " << hg
                                  << ", disc rim " << disc);
  CHECK(sphere <= 1e-15);
  CHECK(hemisphere <= 1e-15);
  CHECK(hg <= 1e-15);
  CHECK(disc <= 1e-15);
}

// Catches a disc warp with r = u1 (clustered centre) instead of sqrt(u1).
TEST_CASE("Uniform disc warp is uniform", "[samplers][warps]") {
  const auto r = chi2_grid(
      [](Rng& rng) {
        double x = 0.0, y = 0.0;
        const double u1 = rng.uniform(), u2 = rng.uniform();
        femto::sample_uniform_disc(u1, u2, x, y);
        double phi = std::atan2(y, x);
        if (phi < 0.0) phi += 2.0 * kPi;
        return Point2{x * x + y * y, phi};  // uniform in (r^2, phi) iff uniform in area
      },
      [](double xa, double xb, double ya, double yb) { return (xb - xa) * (yb - ya) / (2 * kPi); },
      0.0, 1.0, 20, 0.0, 2.0 * kPi, 20, 100000, 23);
  INFO("chi2 = " << r.chi2 << "  dof = " << r.dof << "  p = " << r.p_value);
  CHECK(r.p_value >= kSamplerAlpha);
}

// Catches barycentrics that cluster at a vertex (e.g. b1 = 1 - u1) or fall outside the triangle.
TEST_CASE("Uniform triangle barycentrics are uniform", "[samplers][warps]") {
  // Unit square in (b1, b2) cut into K x K cells; the triangle b1 + b2 <= 1 (density 2) covers
  // cells with i + j < K - 1 fully, cells with i + j == K - 1 by half and the others not at all.
  const int K = 20;
  const auto r = chi2_grid(
      [](Rng& rng) {
        double b1 = 0.0, b2 = 0.0;
        const double u1 = rng.uniform(), u2 = rng.uniform();
        femto::sample_uniform_triangle(u1, u2, b1, b2);
        return Point2{b1, b2};
      },
      [](double xa, double xb, double ya, double) {
        const double h = xb - xa;
        const long ij = std::lround((xa + ya) * K);  // i + j of the cell
        return ij < K - 1 ? 2.0 * h * h : (ij == K - 1 ? h * h : 0.0);
      },
      0.0, 1.0, K, 0.0, 1.0, K, 200000, 24);
  INFO("chi2 = " << r.chi2 << "  dof = " << r.dof << "  p = " << r.p_value);
  CHECK(r.p_value >= kSamplerAlpha);
}

// ---- Sanity of the statistics themselves (a broken chi2 must not silently pass) ----

// Catches a wrong series/continued-fraction in regularized_gamma_q (references: mpmath, 30 digits).
TEST_CASE("regularized_gamma_q known values", "[stats]") {
  struct Case {
    double a, x, q;
  };
  for (const Case& c : {Case{0.5, 0.2, 0.527089256865538074}, Case{3, 2.5, 0.543813115883329518},
                        Case{10, 25, 2.21476638248783581e-4}, Case{50, 45, 0.753197965599829727},
                        Case{50, 70, 5.14050245850589390e-3},
                        Case{200, 180, 0.925141965015840418}}) {
    INFO("a = " << c.a << "  x = " << c.x);
    CHECK(st::regularized_gamma_q(c.a, c.x) == Approx(c.q).epsilon(1e-12));
  }
  for (const double x : {0.01, 0.7, 3.0, 40.0}) {
    CHECK(st::regularized_gamma_q(1.0, x) == Approx(std::exp(-x)).epsilon(1e-12));
    CHECK(st::regularized_gamma_q(0.5, x) == Approx(std::erfc(std::sqrt(x))).epsilon(1e-12));
  }
  CHECK(st::regularized_gamma_q(2.0, 0.0) == 1.0);
  CHECK_THROWS_AS(st::regularized_gamma_q(0.0, 1.0), std::invalid_argument);
  CHECK_THROWS_AS(st::regularized_gamma_q(1.0, -1.0), std::invalid_argument);
}

// Catches a chi2_survival with swapped arguments or without the factor 1/2.
TEST_CASE("chi2_survival matches chi-square tables", "[stats]") {
  CHECK(st::chi2_survival(3.84146, 1) == Approx(0.05).margin(1e-4));
  CHECK(st::chi2_survival(18.307, 10) == Approx(0.05).margin(1e-4));
  CHECK(st::chi2_survival(6.63490, 1) == Approx(0.01).margin(1e-4));
  CHECK(st::chi2_survival(124.342, 100) == Approx(0.05).margin(1e-4));
  CHECK(st::chi2_survival(0.0, 5) == 1.0);
}

// Catches wrong pooling, dof or p-value plumbing in chi2_test, and silent acceptance of bad input.
TEST_CASE("chi2_test pooling and input checks", "[stats]") {
  // Cells 1,1,1,1 (sum 4 < 5) are pooled and topped up with one 10-cell: 3 cells, dof 2.
  const std::vector<double> expected{10, 1, 10, 1, 1, 10, 1};
  const st::Chi2Result same = st::chi2_test(expected, expected);
  CHECK(same.chi2 == 0.0);
  CHECK(same.p_value == Approx(1.0));
  CHECK(same.cells_pooled == 5);
  CHECK(same.cells_used == 3);
  CHECK(same.dof == 2);
  // Observed where expected is zero is impossible: p = 0.
  const st::Chi2Result bad = st::chi2_test({10, 10, 1}, {10.5, 10.5, 0});
  CHECK(bad.p_value == 0.0);
  // A grossly different histogram is rejected.
  CHECK(st::chi2_test({100, 0, 100, 0}, {50, 50, 50, 50}).p_value < 1e-20);
  CHECK_THROWS_AS(st::chi2_test({1, 2}, {1, 2, 3}), std::invalid_argument);
  CHECK_THROWS_AS(st::chi2_test({0, 0}, {0, 0}), std::invalid_argument);
  CHECK_THROWS_AS(st::chi2_test({1, 2}, {-1, 4}), std::invalid_argument);
}

// Proves the HG chi-square has power: a sampler for g = 0.5 tested against the g = 0.4 pdf fails.
TEST_CASE("chi2 test has power (HG g=0.5 samples vs g=0.4 pdf)", "[stats][hg]") {
  const st::Chi2Result r = hg_chi2(0.5, 0.4, 1234);
  INFO("chi2 = " << r.chi2 << "  dof = " << r.dof << "  p = " << r.p_value);
  CHECK(r.p_value < 1e-6);
}

// Catches a wrong KS statistic or p-value: uniform samples pass, u^1.2 samples are rejected.
TEST_CASE("Kolmogorov-Smirnov statistic and p-value", "[stats]") {
  // Kolmogorov survival Q(lambda) (mpmath); n large so the Stephens correction is negligible.
  const size_t big = 100000000;
  const double c = std::sqrt(1e8) + 0.12 + 0.11 / std::sqrt(1e8);
  CHECK(st::ks_p_value(0.5 / c, big) == Approx(0.963945243664875).epsilon(1e-9));
  CHECK(st::ks_p_value(1.0 / c, big) == Approx(0.269999671677355).epsilon(1e-9));
  CHECK(st::ks_p_value(1.3581 / c, big) == Approx(0.049999630431667).epsilon(1e-9));
  CHECK(st::ks_p_value(1.5 / c, big) == Approx(0.022217962616525).epsilon(1e-9));
  CHECK(st::ks_p_value(0.0, 10) == 1.0);
  CHECK(st::ks_statistic_uniform({0.5}, 0.0, 1.0) == Approx(0.5));

  const size_t n = 10000;
  std::vector<double> uniform(n), skewed(n);
  Rng rng(31, 2);
  for (size_t i = 0; i < n; ++i) {
    uniform[i] = rng.uniform();
    skewed[i] = std::pow(rng.uniform(), 1.2);
  }
  const double p_uniform = st::ks_p_value(st::ks_statistic_uniform(uniform, 0.0, 1.0), n);
  const double p_skewed = st::ks_p_value(st::ks_statistic_uniform(skewed, 0.0, 1.0), n);
  INFO("p(uniform) = " << p_uniform << "  p(u^1.2) = " << p_skewed);
  CHECK(p_uniform >= kSamplerAlpha);
  CHECK(p_skewed < 1e-6);
}

// Catches quadrature that misses narrow peaks or loses accuracy on 2-D rectangles.
TEST_CASE("adaptive_simpson and integrate_2d", "[stats]") {
  CHECK(st::adaptive_simpson([](double x) { return std::exp(x); }, 0.0, 1.0, 1e-12) ==
        Approx(std::exp(1.0) - 1.0).epsilon(1e-12));
  // Narrow Lorentzian peak of width 1e-4 at 0.3: integral = atan(0.7/w) + atan(0.3/w).
  const double w = 1e-4;
  CHECK(st::adaptive_simpson([w](double x) { return w / ((x - 0.3) * (x - 0.3) + w * w); }, 0.0,
                             1.0, 1e-10) ==
        Approx(std::atan(0.7 / w) + std::atan(0.3 / w)).epsilon(1e-9));
  CHECK(st::integrate_2d([](double x, double y) { return x * y * y; }, 0.0, 2.0, -1.0, 1.0,
                         1e-12) == Approx(4.0 / 3.0).epsilon(1e-12));
}
