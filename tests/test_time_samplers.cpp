// Statistical tests of the time-targeted samplers: equiangular (samplers/equiangular.h),
// line-to-point (samplers/line_to_point.h) and angular (samplers/angular.h), and of the time
// uniformity they promise against mean-free-path and equiangular sampling.
//
// Significance: a chi-square / KS test fails when p < 1e-3. Seeds are fixed, so outcomes are
// deterministic; a correct sampler passes with these seeds and a wrong one fails by orders of
// magnitude (see the power checks, which require p < 1e-6 of the wrong strategy).
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <vector>

#include "core/constants.h"
#include "core/rng.h"
#include "core/sampling.h"
#include "core/vec3.h"
#include "samplers/angular.h"
#include "samplers/distance.h"
#include "samplers/equiangular.h"
#include "samplers/equiangular_outside_ball.h"
#include "samplers/line_to_point.h"
#include "samplers/stats.h"

using femto::kPi;
using femto::kSpeedOfLight;
using femto::Rng;
using femto::Vec3;
namespace st = femto::stats;

namespace {

constexpr double kTimeSamplerAlpha = 1e-3;  // reject when p < kTimeSamplerAlpha
using femto::kInf;
constexpr int kSamples = 100000;  // per chi-square test

/// Chi-square of n draws on [lo, hi] in `bins` equal bins against n times the pdf integrated
/// over each bin (adaptive Simpson); `edges` lists extra bin edges (peaks, kinks) so that the
/// quadrature never straddles them. Draws outside [lo, hi] or non-finite fail the test.
st::Chi2Result chi2_1d(const std::function<double(Rng&)>& draw,
                       const std::function<double(double)>& pdf, double lo, double hi, int bins,
                       uint64_t seed, std::vector<double> edges = {}) {
  std::vector<double> x;
  for (int i = 0; i <= bins; ++i) x.push_back(lo + (hi - lo) * i / bins);
  for (double e : edges)
    if (e > lo && e < hi) x.push_back(e);
  std::sort(x.begin(), x.end());
  const size_t cells = x.size() - 1;
  std::vector<double> observed(cells, 0.0), expected(cells, 0.0);
  Rng rng(seed, 23);
  int invalid = 0;
  for (int k = 0; k < kSamples; ++k) {
    const double v = draw(rng);
    if (!(v >= lo && v <= hi)) {
      ++invalid;
      continue;
    }
    size_t i = static_cast<size_t>(std::upper_bound(x.begin(), x.end(), v) - x.begin());
    observed[std::min(cells, std::max<size_t>(i, 1)) - 1] += 1.0;
  }
  CHECK(invalid == 0);
  double mass = 0.0;
  for (size_t i = 0; i < cells; ++i) {
    const double m = st::adaptive_simpson(pdf, x[i], x[i + 1], 1e-12);
    expected[i] = kSamples * m;
    mass += m;
  }
  CHECK(mass == Approx(1.0).margin(1e-6));  // the bins carry all of the pdf's mass
  return st::chi2_test(observed, expected);
}

struct Uniformity {
  double chi2_p, ks_p;
};

/// Chi-square (50 equal bins) and KS of times against U(a, b).
Uniformity uniformity_of(const std::vector<double>& t, double a, double b) {
  const int bins = 50;
  std::vector<double> observed(bins, 0.0), expected(bins, static_cast<double>(t.size()) / bins);
  for (double v : t) {
    const int i = static_cast<int>((v - a) / (b - a) * bins);
    observed[static_cast<size_t>(std::min(bins - 1, std::max(0, i)))] += 1.0;
  }
  return {st::chi2_test(observed, expected).p_value,
          st::ks_p_value(st::ks_statistic_uniform(t, a, b), t.size())};
}

struct RayGeometry {
  const char* name;
  Vec3 o, w, p;
};

// Sensor ray from the origin along +z; target positions relative to it.
const Vec3 kO(0, 0, 0), kW(0, 0, 1);
const RayGeometry kRayGeometries[] = {
    {"target beside the middle", kO, kW, Vec3(3, 0, 5)},
    {"target ahead, off the ray", kO, kW, Vec3(1, 2, 30)},
    {"target behind the ray start", kO, kW, Vec3(-2, 1, -6)},
    {"target near the line (h = 1e-3), foot inside", kO, kW, Vec3(1e-3, 0, 4)},
    {"target near the line (h = 1e-9), ahead", kO, kW, Vec3(1e-9, 0, 25)},
    {"target on the line behind (h = 0)", kO, kW, Vec3(0, 0, -3)},
    {"oblique ray, target beside", Vec3(1, -2, 0.5), femto::normalize(Vec3(1, 1, 1)),
     Vec3(4, 5, -3)},
};

}  // namespace

// ---------------------------------------------------------------- equiangular

// Catches a wrong inverse CDF (e.g. the tan-addition form or the subtended angle), a pdf that is
// not the sampler's density, or a broken h -> 0 limit (targets near and on the line).
TEST_CASE("equiangular: samples follow the pdf, pdf normalised, CDF round trip",
          "[samplers][time][equiangular]") {
  uint64_t seed = 100;
  for (const RayGeometry& g : kRayGeometries) {
    const double s_a = 0.5, s_b = 12.0;
    const femto::EquiangularSampler eq(g.o, g.w, g.p, s_a, s_b);
    INFO(g.name << "  Delta = " << eq.delta() << "  h = " << eq.h());
    REQUIRE(eq.valid());
    const auto pdf = [&](double s) { return eq.pdf(s); };
    const st::Chi2Result r = chi2_1d([&](Rng& rng) { return eq.sample(rng.uniform()); }, pdf, s_a,
                                     s_b, 50, seed++, {eq.delta()});
    INFO("chi2 = " << r.chi2 << "  dof = " << r.dof << "  p = " << r.p_value);
    CHECK(r.p_value >= kTimeSamplerAlpha);
    double worst = 0;
    for (int k = 0; k <= 1000; ++k) {
      const double u = k / 1000.0;
      worst = std::fmax(worst, std::abs(eq.cdf(eq.sample(u)) - u));
    }
    INFO("max |cdf(sample(u)) - u| = " << worst);
    CHECK(worst < 1e-9);
  }
}

// Catches the target-on-the-segment case returning garbage instead of refusing, and an
// empty or reversed interval being accepted.
TEST_CASE("equiangular: no sample when the target lies on the segment",
          "[samplers][time][equiangular]") {
  CHECK_FALSE(femto::EquiangularSampler(kO, kW, Vec3(0, 0, 3), 0.0, 10.0).valid());
  CHECK_FALSE(femto::EquiangularSampler(kO, kW, Vec3(1, 0, 3), 5.0, 5.0).valid());
  CHECK_FALSE(femto::EquiangularSampler(kO, kW, Vec3(1, 0, 3), 0.0, kInf).valid());
  CHECK(femto::EquiangularSampler(kO, kW, Vec3(0, 0, 3), 4.0, 10.0).valid());  // off the segment
  // No segment at all (the connections' placeholder where equiangular sampling is not used): a
  // density that some MIS sum would add must be zero.
  const femto::EquiangularSampler none;
  CHECK_FALSE(none.valid());
  CHECK(none.pdf(0.0) == 0.0);
  CHECK(none.pdf(1.0) == 0.0);
}

// ---------------------------------------------------------------- line-to-point

namespace {
// Catches a wrong pick between the two intervals around the ball's chord (the pdf would jump at
// the chord), a sample inside the ball, a pdf not normalised over what is left, and a chord
// clipped wrongly at the segment's ends.
TEST_CASE("equiangular outside a ball: samples follow the pdf and avoid the ball",
          "[samplers][time][equiangular]") {
  struct BallCase {
    const char* name;
    Vec3 p;
    double r;
  };
  const BallCase cases[] = {
      {"chord inside the segment (two intervals)", Vec3(0.3, 0, 5), 1.0},
      {"chord at the start (one interval)", Vec3(0.2, 0, 0.8), 1.0},
      {"chord past the end (the ball holds the end)", Vec3(0.1, 0, 11.5), 2.0},
      {"line misses the ball (plain equiangular)", Vec3(3, 0, 5), 1.0},
      {"target on the line (h = 0), chord inside", Vec3(0, 0, 6), 0.5},
  };
  uint64_t seed = 400;
  const double s_a = 0.5, s_b = 12.0;
  for (const BallCase& c : cases) {
    INFO(c.name);
    const femto::EquiangularOutsideBall eq(kO, kW, c.p, s_a, s_b, c.r);
    REQUIRE(eq.valid());
    const double delta = c.p.z, h = std::hypot(c.p.x, c.p.y);
    const double half = c.r > h ? std::sqrt(c.r * c.r - h * h) : 0.0;
    const auto pdf = [&](double s) { return eq.pdf(s); };
    const st::Chi2Result r = chi2_1d([&](Rng& rng) { return eq.sample(rng.uniform()); }, pdf, s_a,
                                     s_b, 50, seed++, {delta - half, delta, delta + half});
    INFO("chi2 = " << r.chi2 << "  dof = " << r.dof << "  p = " << r.p_value);
    CHECK(r.p_value >= kTimeSamplerAlpha);
    // The density is 1 / (M (h^2 + x^2)) outside the ball and 0 inside.
    Rng rng(seed++, 5);
    int inside = 0;
    for (int k = 0; k < 10000; ++k)
      if (length(kO + kW * eq.sample(rng.uniform()) - c.p) < c.r * (1 - 1e-12)) ++inside;
    CHECK(inside == 0);
    CHECK(eq.pdf(delta) == (h < c.r ? 0.0 : eq.pdf(delta)));
  }
}

struct LtpCase {
  RayGeometry g;
  double eta, t_a, t_b, s_min, s_max;
};
const LtpCase kLtpCases[] = {
    {kRayGeometries[0], 1.0, 0.0, 200.0, 0.0, kInf},     // window reaching below the direct time
    {kRayGeometries[1], 1.33, 120.0, 400.0, 0.0, kInf},  // target ahead, window inside
    {kRayGeometries[2], 1.0, 50.0, 300.0, 2.0, 60.0},    // behind; the s range clips both ends
    {kRayGeometries[3], 1.5, 0.0, 150.0, 0.0, 40.0},     // near the line: pdf ~ 0 before Delta
    {{"target on the line ahead (h = 0)", kO, kW, Vec3(0, 0, 10)}, 1.0, 0.0, 200.0, 0.0, kInf},
    {kRayGeometries[6], 1.2, 80.0, 90.0, 0.0, kInf},  // a short window
};
}  // namespace

// Catches a wrong inverse s(L) (e.g. the sign of Delta or a missing factor 2), a pdf without
// the Jacobian dL/ds, a window not intersected with the reachable range, and the h -> 0 cases.
TEST_CASE("line-to-point: samples follow the pdf, pdf normalised, round trips",
          "[samplers][time][line_to_point]") {
  uint64_t seed = 200;
  for (const LtpCase& c : kLtpCases) {
    const femto::LineToPointSampler ltp(c.g.o, c.g.w, c.g.p, c.eta);
    const auto win = ltp.window(c.t_a, c.t_b, c.s_min, c.s_max);
    INFO(c.g.name << "  window s = [" << win.s_a << ", " << win.s_b << "]");
    REQUIRE(win.valid);
    const double delta = dot(c.g.p - c.g.o, c.g.w);
    const st::Chi2Result r =
        chi2_1d([&](Rng& rng) { return ltp.sample(win, rng.uniform()); },
                [&](double s) { return ltp.pdf(win, s); }, win.s_a, win.s_b, 50, seed++, {delta});
    INFO("chi2 = " << r.chi2 << "  dof = " << r.dof << "  p = " << r.p_value);
    CHECK(r.p_value >= kTimeSamplerAlpha);
    // Round trips: the time of sample(u) is linear in u; s(L(s)) = s past the dead zone.
    const double t_lo = c.eta * win.L_a / kSpeedOfLight, t_hi = c.eta * win.L_b / kSpeedOfLight;
    double worst_t = 0, worst_s = 0;
    for (int k = 0; k <= 1000; ++k) {
      const double u = k / 1000.0, s = ltp.sample(win, u);
      worst_t = std::fmax(worst_t, std::abs(ltp.time(s) - (t_lo + u * (t_hi - t_lo))) / t_hi);
      if (ltp.dopl_ds(s) > 1e-3)
        worst_s = std::fmax(worst_s, std::abs(ltp.s_of_opl(ltp.opl(s)) - s) / (1 + s));
    }
    INFO("max rel |time(sample(u)) - linear| = " << worst_t << "  max |s(L(s)) - s| = " << worst_s);
    CHECK(worst_t < 1e-10);
    CHECK(worst_s < 1e-9);
  }
}

// Catches a window that is not intersected with the reachable times: one ending before the
// direct connection time, or an s range whose times miss the window, must give no sample.
TEST_CASE("line-to-point: empty windows give no sample", "[samplers][time][line_to_point]") {
  const femto::LineToPointSampler ltp(kO, kW, Vec3(30, 0, 0), 1.0);  // direct time 100 ps
  CHECK_FALSE(ltp.window(0.0, 99.0, 0.0, kInf).valid);
  CHECK_FALSE(ltp.window(500.0, 600.0, 0.0, 10.0).valid);  // s <= 10 mm reaches ~ 105 ps
  CHECK(ltp.window(0.0, 101.0, 0.0, kInf).valid);
}

// ---------------------------------------------------------------- angular

namespace {
struct AngCase {
  const char* name;
  double r, l;
  bool clip;  // also clip to a time window inside the range
};
const AngCase kAngCases[] = {
    {"r < |l|", 3.0, 10.0, false},
    {"r > |l|", 10.0, 3.0, false},
    {"r == |l|", 5.0, 5.0, false},
    {"tiny r (1e-6 |l|)", 1e-5, 10.0, false},
    {"r < |l|, clipped window", 3.0, 10.0, true},
    {"r > |l|, clipped window", 10.0, 3.0, true},
};
}  // namespace

// Catches a wrong inverse CDF (the paper's printed eq. 17 / S.100), a pdf normalised only for
// one ordering of r and |l| (the paper's eq. 16), a wrong azimuth or frame, or broken
// r == |l| / tiny-r limits.
TEST_CASE("angular: directions follow the pdf over (theta, phi), pdf normalised",
          "[samplers][time][angular]") {
  const Vec3 axis = femto::normalize(Vec3(0.2, -0.7, 0.4));
  const femto::Frame frame(axis);
  uint64_t seed = 300;
  for (const AngCase& c : kAngCases) {
    INFO(c.name);
    const double eta = 1.0;
    const femto::AngularTimeSampler ang(c.r, c.l, eta);
    const double span = ang.t_max() - ang.t_min();
    const auto win =
        c.clip ? ang.window(ang.t_min() + 0.2 * span, ang.t_min() + 0.7 * span) : ang.full();
    REQUIRE(win.valid);
    // Normalisation of p(theta) over [0, pi] and of p(w) over the sphere (as a density of cos).
    const double n_theta =
        st::adaptive_simpson([&](double th) { return ang.pdf_theta(win, th); }, 0.0, kPi, 1e-12);
    CHECK(n_theta == Approx(1.0).margin(1e-6));
    // theta x phi grid: 40 x 8 cells; p(theta, phi) = p(theta) / (2 pi).
    const int nt = 40, np = 8;
    std::vector<double> observed(nt * np, 0.0), expected(nt * np, 0.0);
    Rng rng(seed++, 29);
    int invalid = 0;
    for (int k = 0; k < kSamples; ++k) {
      const double u1 = rng.uniform(), u2 = rng.uniform();
      const Vec3 w = ang.sample_direction(axis, win, u1, u2);
      if (std::abs(femto::length(w) - 1.0) > 1e-12) {
        ++invalid;
        continue;
      }
      const Vec3 loc = frame.to_local(w);
      const double theta = std::atan2(std::sqrt(loc.x * loc.x + loc.y * loc.y), loc.z);
      double phi = std::atan2(loc.y, loc.x);
      if (phi < 0) phi += 2 * kPi;
      const int i = std::min(nt - 1, static_cast<int>(theta / kPi * nt));
      const int j = std::min(np - 1, static_cast<int>(phi / (2 * kPi) * np));
      observed[static_cast<size_t>(i * np + j)] += 1.0;
    }
    CHECK(invalid == 0);
    for (int i = 0; i < nt; ++i) {
      const double m = st::adaptive_simpson([&](double th) { return ang.pdf_theta(win, th); },
                                            i * kPi / nt, (i + 1) * kPi / nt, 1e-12);
      for (int j = 0; j < np; ++j) expected[static_cast<size_t>(i * np + j)] = kSamples * m / np;
    }
    const st::Chi2Result r = st::chi2_test(observed, expected);
    INFO("chi2 = " << r.chi2 << "  dof = " << r.dof << "  p = " << r.p_value);
    CHECK(r.p_value >= kTimeSamplerAlpha);
  }
}

// Catches a solid-angle pdf inconsistent with p(theta) (a missing 1 / (2 pi) or sin theta), a
// wrong closed form of the whole-range inverse CDF, or a sampled d that is not linear in u.
TEST_CASE("angular: solid-angle pdf, closed-form inverse CDF and d linear in u",
          "[samplers][time][angular]") {
  for (const AngCase& c : kAngCases) {
    INFO(c.name);
    const femto::AngularTimeSampler ang(c.r, c.l, 1.0);
    const auto win = ang.full();
    // Integral of p(w) over the sphere = 2 pi * integral over 1 - cos theta in [0, 2].
    const double n_sphere =
        2 * kPi *
        st::adaptive_simpson([&](double omc) { return ang.pdf_solid_angle(win, omc); }, 0.0, 2.0,
                             1e-12);
    if (c.r != c.l)
      CHECK(n_sphere == Approx(1.0).margin(1e-6));  // r == l: 1/d endpoint singularity
    const double m = std::min(c.r, c.l), M = std::max(c.r, c.l);
    double worst_closed = 0, worst_d = 0, worst_pdf = 0;
    for (int k = 0; k <= 1000; ++k) {
      const double u = k / 1000.0, omc = ang.sample_one_minus_cos(win, u);
      worst_closed = std::fmax(worst_closed, std::abs(omc - 2 * u * (M - m + m * u) / M));
      const double d = ang.d_of(omc);
      worst_d = std::fmax(worst_d, std::abs(d - (std::abs(c.l - c.r) + u * 2 * m)) / (c.l + c.r));
      if (omc > 1e-6) {
        const double expect = M / (4 * kPi * d);  // the derived whole-range p(w)
        worst_pdf = std::fmax(worst_pdf, std::abs(ang.pdf_solid_angle(win, omc) / expect - 1));
      }
    }
    INFO("closed form " << worst_closed << "  d linear " << worst_d << "  pdf " << worst_pdf);
    CHECK(worst_closed < 1e-12);
    CHECK(worst_d < 1e-12);
    CHECK(worst_pdf < 1e-9);
  }
}

// Catches adopting the paper's eq. 16 unchanged: r sin theta / (2 d) integrates to r / |l|
// when r < |l|, so it is a pdf only for r >= |l|.
TEST_CASE("angular: the printed eq. 16 is normalised only for r >= |l|",
          "[samplers][time][angular]") {
  for (const AngCase& c : kAngCases) {
    if (c.clip) continue;
    const auto paper = [&](double th) {
      const double half = std::sin(0.5 * th);  // d written without cancellation at r == |l|
      return c.r * std::sin(th) /
             (2 * std::sqrt((c.r - c.l) * (c.r - c.l) + 4 * c.r * c.l * half * half));
    };
    const double n = st::adaptive_simpson(paper, 1e-9, kPi, 1e-12);
    INFO(c.name << "  integral = " << n);
    CHECK(n == Approx(c.r >= c.l ? 1.0 : c.r / c.l).margin(1e-5));
  }
}

// Catches mishandled degenerate inputs: r = 0 must give unit directions with the uniform sphere
// pdf, and a window missing the single reachable time must be invalid.
TEST_CASE("angular: r = 0 gives the uniform sphere", "[samplers][time][angular]") {
  const femto::AngularTimeSampler ang(0.0, 4.0, 1.0);
  REQUIRE(ang.degenerate());
  const auto win = ang.window(0.0, 100.0);
  REQUIRE(win.valid);
  CHECK(ang.pdf_solid_angle(win, 0.3) == Approx(1.0 / (4 * kPi)));
  CHECK(ang.sample_one_minus_cos(win, 0.25) == Approx(0.5));
  CHECK_FALSE(ang.window(0.0, 1.0).valid);  // the only time, 4 / c = 13.3 ps, is outside
}

// ---------------------------------------------------------------- time uniformity and power

// Catches a time-targeted sampler that is only approximately time-uniform, and shows the tests
// have power: mean-free-path and equiangular vertices on the same ray and window (30 mean free
// times long) are far from uniform in connection time and must fail.
TEST_CASE("line-to-point times are uniform; mfp and equiangular are not",
          "[samplers][time][line_to_point][power]") {
  const double sigma_t = 0.1, eta = 1.0, t_a = 0.0, t_b = 1000.0;  // mean free time 33 ps
  const Vec3 light(20, 0, 10);
  const femto::LineToPointSampler ltp(kO, kW, light, eta);
  const auto win = ltp.window(t_a, t_b, 0.0, kInf);
  REQUIRE(win.valid);
  const double lo = eta * win.L_a / kSpeedOfLight, hi = eta * win.L_b / kSpeedOfLight;
  const femto::EquiangularSampler eq(kO, kW, light, win.s_a, win.s_b);
  const int n = 50000;
  std::vector<double> t_ltp, t_mfp, t_eq;
  Rng rng(401, 7);
  for (int k = 0; k < n; ++k) {
    t_ltp.push_back(ltp.time(ltp.sample(win, rng.uniform())));
    t_eq.push_back(ltp.time(eq.sample(rng.uniform())));
    const double t = ltp.time(femto::sample_exponential(sigma_t, rng.uniform()));
    if (t >= lo && t <= hi) t_mfp.push_back(t);  // conditional on the window
  }
  const Uniformity u_ltp = uniformity_of(t_ltp, lo, hi), u_mfp = uniformity_of(t_mfp, lo, hi),
                   u_eq = uniformity_of(t_eq, lo, hi);
  INFO("line-to-point p = " << u_ltp.chi2_p << ", " << u_ltp.ks_p << "; mfp (" << t_mfp.size()
                            << " in window) p = " << u_mfp.chi2_p << ", " << u_mfp.ks_p
                            << "; equiangular p = " << u_eq.chi2_p << ", " << u_eq.ks_p);
  CHECK(u_ltp.chi2_p >= kTimeSamplerAlpha);
  CHECK(u_ltp.ks_p >= kTimeSamplerAlpha);
  CHECK(t_mfp.size() > 1000);
  CHECK(u_mfp.chi2_p < 1e-6);
  CHECK(u_mfp.ks_p < 1e-6);
  CHECK(u_eq.chi2_p < 1e-6);
  CHECK(u_eq.ks_p < 1e-6);
}

// Catches an angular sampler whose directions, put through the actual geometry, do not give
// uniform connection times (e.g. theta measured from the wrong axis); isotropic (uniform sphere)
// directions, the phase-function choice, must fail.
TEST_CASE("angular connection times are uniform; uniform-sphere directions are not",
          "[samplers][time][angular][power]") {
  const Vec3 x(1, 2, 3), p(-4, 6, 12);
  const double eta = 1.33;
  for (const double r : {4.0, 25.0}) {  // r < |l| = 11.0 and r > |l|
    const double l = femto::length(p - x);
    const femto::AngularTimeSampler ang(r, l, eta);
    const Vec3 axis = (p - x) / l;
    std::vector<double> t_ang, t_iso;
    Rng rng(500 + static_cast<uint64_t>(r), 3);
    for (int k = 0; k < 50000; ++k) {
      const Vec3 w = ang.sample_direction(axis, ang.full(), rng.uniform(), rng.uniform());
      t_ang.push_back(eta * (r + femto::length(x + r * w - p)) / kSpeedOfLight);
      const Vec3 v = femto::sample_uniform_sphere(rng.uniform(), rng.uniform());
      t_iso.push_back(eta * (r + femto::length(x + r * v - p)) / kSpeedOfLight);
    }
    const Uniformity ua = uniformity_of(t_ang, ang.t_min(), ang.t_max());
    const Uniformity ui = uniformity_of(t_iso, ang.t_min(), ang.t_max());
    INFO("r = " << r << "  angular p = " << ua.chi2_p << ", " << ua.ks_p
                << "  uniform sphere p = " << ui.chi2_p << ", " << ui.ks_p);
    CHECK(ua.chi2_p >= kTimeSamplerAlpha);
    CHECK(ua.ks_p >= kTimeSamplerAlpha);
    CHECK(ui.chi2_p < 1e-6);
    CHECK(ui.ks_p < 1e-6);
  }
}
