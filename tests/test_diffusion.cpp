// Tests of `femto diffusion`: the exact track-length tallies, the analytic references, the Monte
// Carlo against exact results (energy, <r^2>, scattering orders, the ballistic shell, late-time
// diffusion), determinism across thread counts, the plot module and the command line.
#include <catch2/catch.hpp>

#include "temp_dir.h"

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/constants.h"
#include "core/diffusion/analysis.h"
#include "core/diffusion/models.h"
#include "core/diffusion/report.h"
#include "core/io/plot.h"
#include "core/sampling.h"

using namespace femto;
using namespace femto::diffusion;
namespace fs = std::filesystem;

namespace {

DiffusionSetup make_setup(double sigma_s, double sigma_a, double g, double eta, Absorption abs,
                          double t0, double t1, int bins, double r_max, int shells,
                          uint64_t photons) {
  DiffusionSetup s;
  s.medium.sigma_s = sigma_s, s.medium.sigma_a = sigma_a, s.medium.g = g, s.medium.eta = eta;
  s.absorption = abs;
  s.grid.time = TimeAxis{t0, (t1 - t0) / bins, bins};
  s.grid.shells = shells;
  s.grid.dr = r_max / shells;
  s.photons = photons;
  s.seed = 7;
  s.threads = 2;
  return s;
}

std::string read_diffusion_file(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

std::string first_line(const std::string& s) {
  return s.substr(0, s.find('\n'));
}

}  // namespace

// Catches algebra or branch errors in the exp-polynomial integrals (series vs recurrence switch).
TEST_CASE("exp_moments matches quadrature on both sides of the series switch", "[diffusion]") {
  for (double k : {0.0, 1e-6, 0.3, 1.9, 2.1, 4.9, 5.0, 40.0}) {
    for (double h : {0.01, 1.0, 3.0}) {
      double J[5];
      exp_moments(k, h, J);
      for (int n = 0; n < 5; ++n) {
        double ref = 0;  // composite Gauss–Legendre resolves exp(-k s) even for k h = 120
        for (int p = 0; p < 64; ++p)
          ref += integrate_gl([&](double s) { return std::exp(-k * s) * std::pow(s, n); },
                              h * p / 64, h * (p + 1) / 64, 16);
        INFO("k " << k << " h " << h << " n " << n);
        REQUIRE(J[n] == Approx(ref).epsilon(1e-11).margin(1e-300));
      }
    }
  }
  REQUIRE(exp_integral(0.5, 1.0, 3.0) ==
          Approx((std::exp(-0.5) - std::exp(-1.5)) / 0.5).epsilon(1e-14));
}

namespace {
// A random straight flight at speed 0.25 mm/ps: start within `extent` of the origin, start time
// below t0_max, duration below d_max, weighted by exp(-k t) with k below k_max (0 on odd trials).
Segment random_segment(Rng& rng, int trial, double extent, double t0_max, double d_max,
                       double k_max) {
  Segment s;
  s.x0 = Vec3(rng.uniform() - 0.5, rng.uniform() - 0.5, rng.uniform() - 0.5) * extent;
  s.d = sample_uniform_sphere(rng.uniform(), rng.uniform());
  s.t0 = t0_max * rng.uniform();
  s.duration = d_max * rng.uniform();
  s.v = 0.25, s.w0 = 0.7;
  s.k = trial % 2 ? 0.0 : k_max * rng.uniform();
  return s;
}
}  // namespace

// Catches wrong shell-crossing times, time lost at boundaries, or wrong r^2 / r^4 polynomials.
TEST_CASE("track-length tallies equal brute-force time integrals of single segments",
          "[diffusion]") {
  Grid grid;
  grid.time = TimeAxis{0.5, 0.7, 6};
  grid.shells = 8;
  grid.dr = 0.3;
  Rng rng(11, 5);
  for (int trial = 0; trial < 40; ++trial) {
    const Segment s = random_segment(rng, trial, 4.0, 2.0, 5.0, 0.8);
    PhotonTally tally(grid);
    TallySums sums;
    sums.reset(tally.layout().size());
    tally.add(s, sums);
    tally.end_photon(sums);

    const TallyLayout& L = tally.layout();
    std::vector<double> ref(L.size(), 0.0);
    const int M = 100000;
    const double h = s.duration / M;
    double rmax = 0;
    for (int m = 0; m < M; ++m) {
      const double tau = (m + 0.5) * h;
      const int j = grid.time.bin_of(s.t0 + tau);
      const double r = length(s.x0 + s.d * (s.v * tau)), w = s.w0 * std::exp(-s.k * tau);
      rmax = std::max(rmax, r);
      if (j < 0) continue;
      const int i = static_cast<int>(r / grid.dr);
      if (i < grid.shells) ref[L.cell(i, j)] += w * h;
      ref[L.slot(Quantity::Energy, j)] += w * h;
      ref[L.slot(Quantity::R2, j)] += w * r * r * h;
      ref[L.slot(Quantity::R4, j)] += w * r * r * r * r * h;
    }
    // Stepping misplaces at most one step at each of <= 4 boundary crossings per entry.
    const double tol = 4 * h * s.w0;
    for (int j = 0; j < grid.time.bins; ++j) {
      double shells_sum = 0;
      for (int i = 0; i < grid.shells; ++i) {
        REQUIRE(std::abs(sums.sum(L.cell(i, j)) - ref[L.cell(i, j)]) <= tol);
        shells_sum += sums.sum(L.cell(i, j));
      }
      const double E = sums.sum(L.slot(Quantity::Energy, j));
      REQUIRE(std::abs(E - ref[L.slot(Quantity::Energy, j)]) <= tol);
      REQUIRE(std::abs(sums.sum(L.slot(Quantity::R2, j)) - ref[L.slot(Quantity::R2, j)]) <=
              tol * rmax * rmax);
      REQUIRE(std::abs(sums.sum(L.slot(Quantity::R4, j)) - ref[L.slot(Quantity::R4, j)]) <=
              tol * std::pow(rmax, 4));
      REQUIRE(shells_sum <= E * (1 + 1e-12));  // the shells never hold more than the bin's energy
      REQUIRE(sums.sum(L.slot(Quantity::Unscattered, j)) == E);  // s.scatterings == 0
    }
  }
}

// Catches a photon's entries squared piece by piece instead of as the photon's total (the
// per-photon variance behind every standard error), or entries lost or doubled where a photon's
// consecutive segments meet inside a bin: one straight flight tallied whole and cut into three
// consecutive segments must give the same sums and sums of squares.
TEST_CASE("a photon's consecutive segments tally as one flight", "[diffusion]") {
  Grid grid;
  grid.time = TimeAxis{0.0, 0.37, 9};
  grid.shells = 7;
  grid.dr = 0.35;
  Rng rng(5, 9);
  for (int trial = 0; trial < 20; ++trial) {
    const Segment whole = random_segment(rng, trial, 3.0, 0.5, 3.0, 0.6);
    PhotonTally tally(grid);
    TallySums one, three;
    one.reset(tally.layout().size());
    three.reset(tally.layout().size());
    tally.add(whole, one);
    tally.end_photon(one);
    const double cut[4] = {0, 0.3 * whole.duration, 0.55 * whole.duration, whole.duration};
    for (int p = 0; p < 3; ++p) {
      Segment piece = whole;
      piece.x0 = whole.x0 + whole.d * (whole.v * cut[p]);
      piece.t0 = whole.t0 + cut[p];
      piece.duration = cut[p + 1] - cut[p];
      piece.w0 = whole.w0 * std::exp(-whole.k * cut[p]);
      tally.add(piece, three);
    }
    tally.end_photon(three);
    for (size_t i = 0; i < one.size(); ++i) {
      REQUIRE(three.sum(i) == Approx(one.sum(i)).epsilon(1e-9).margin(1e-14));
      REQUIRE(three.sum2(i) == Approx(one.sum2(i)).epsilon(1e-9).margin(1e-14));
    }
  }
}

// Catches an entry added to the sums in parts (its pieces squared one by one) where a flight
// leaves a shell and comes back within one bin, around its closest approach to the source: for a
// single photon every sum of squares must be the square of the sum. The flight passes 0.29 mm
// from the source, inside shell 0 (0.3 mm) for 0.61 ps around t = 4.5 ps, all within bin [4, 6).
TEST_CASE("a photon that leaves a shell and returns within one bin tallies the shell once",
          "[diffusion]") {
  Grid grid;
  grid.time = TimeAxis{0.0, 2.0, 6};
  grid.shells = 10;
  grid.dr = 0.3;
  for (double k : {0.0, 0.05}) {
    Segment s;
    s.x0 = Vec3(-1.0, 0.29, 0.0), s.d = Vec3(1, 0, 0);
    s.t0 = 0.5, s.duration = 10.0, s.v = 0.25, s.w0 = 0.8, s.k = k, s.scatterings = 3;
    PhotonTally tally(grid);
    TallySums sums;
    sums.reset(tally.layout().size());
    tally.add(s, sums);
    tally.end_photon(sums);
    const TallyLayout& L = tally.layout();
    INFO("k " << k);
    // Bin 2 is tau in [3.5, 5.5]: shell 0 holds tau within 0.307 ps of the closest approach at
    // tau = 4, shell 1 the rest of the bin (r = 0.316 mm at 3.5, 0.474 mm at 5.5).
    const double half = std::sqrt(0.09 - 0.29 * 0.29) / 0.25;
    REQUIRE(sums.sum(L.cell(0, 2)) ==
            Approx(s.w0 * exp_integral(k, 4 - half, 4 + half)).epsilon(1e-9));
    REQUIRE(sums.sum(L.cell(1, 2)) ==
            Approx(s.w0 * (exp_integral(k, 3.5, 4 - half) + exp_integral(k, 4 + half, 5.5)))
                .epsilon(1e-9));
    for (size_t i = 0; i < sums.size(); ++i)
      REQUIRE(sums.sum2(i) == Approx(sums.sum(i) * sums.sum(i)).epsilon(1e-12).margin(1e-300));
  }
}

// Catches wrong limits or cancellation in the <r^2> formula and in Paasschens' formula.
TEST_CASE("analytic references have the right limits", "[diffusion]") {
  const double v = 0.2, a = 0.5;
  REQUIRE(prw_r2(v, a, 1e-3) == Approx(v * v * 1e-6).epsilon(1e-3));          // ballistic: (v t)^2
  REQUIRE(prw_r2(v, a, 1e4) == Approx(2 * v * v * (1e4 / a - 1 / (a * a))));  // 6 D (t - 1/a)
  REQUIRE(prw_r2(v, 0, 3) == Approx(v * v * 9));
  REQUIRE(prw_r2(v, a, 2e-4 / a) ==
          Approx(prw_r2(v, a * (1 + 1e-9), 2e-4 / a)).epsilon(1e-7));  // series switch

  // Paasschens: total energy (unscattered + continuous part) within ~2% of 1 at all times.
  const double ell = 1.0;
  for (double T : {0.05, 0.5, 2.0, 10.0, 50.0, 300.0}) {
    const double t = T * ell / v;
    double inside = 0;
    for (int p = 0; p < 400; ++p) {
      const double r0 = v * t * p / 400, r1 = v * t * (p + 1) / 400;
      inside += integrate_gl(
          [&](double r) { return 4 * kPi * r * r * paasschens_density(v, ell, r, t); }, r0, r1, 16);
    }
    INFO("T = " << T);
    REQUIRE(inside + std::exp(-T) == Approx(1).epsilon(0.025));
    if (T < 0.1) REQUIRE(std::exp(-T) > 0.95);  // early: the ballistic shell holds the energy
  }
  // Late: the centre density tends to diffusion with D = v ell / 3.
  const double t = 3000 * ell / v;
  REQUIRE(paasschens_density(v, ell, 0.3 * std::sqrt(v * ell * t), t) ==
          Approx(diffusion_green(v * ell / 3, 0.3 * std::sqrt(v * ell * t), t)).epsilon(0.01));
  // Gaussian shell masses sum to 1 and follow the radial CDF (small-z series included).
  Grid grid;
  grid.shells = 50, grid.dr = 0.1;
  const auto m = gaussian_shell_masses(grid, 0.7);
  double sum = 0;
  for (double x : m) sum += x;
  REQUIRE(sum == Approx(1).epsilon(1e-12));
  REQUIRE(gaussian_radial_cdf(0.049 * std::sqrt(1.4), 0.7) ==
          Approx(gaussian_radial_cdf(0.051 * std::sqrt(1.4), 0.7) * std::pow(0.049 / 0.051, 3))
              .epsilon(2e-3));
  REQUIRE(tv_distance(m, m) == 0);
}

// Catches a t* that ignores later excursions above the threshold, or wrong interpolation.
TEST_CASE("transition time is where the distance stays below the threshold", "[diffusion]") {
  const TimeAxis axis{0, 1, 6};  // bin centres 0.5 .. 5.5
  Transition t = transition_time(axis, {0.5, 0.2, 0.04, 0.06, 0.03, 0.01}, 0.05);
  REQUIRE(t.reached);
  REQUIRE(t.t_ps == Approx(3.5 + (0.06 - 0.05) / (0.06 - 0.03)));
  REQUIRE_FALSE(transition_time(axis, {0.5, 0.2, 0.04, 0.03, 0.03, 0.06}, 0.05).reached);
  REQUIRE(transition_time(axis, {0.01, 0.01, 0.01, 0.01, 0.01, 0.01}, 0.05).from_start);
  REQUIRE_FALSE(
      transition_time(axis, {0.01, NAN, 0.01, 0.01, 0.01, NAN}, 0.05).reached);  // NaN = above
}

// Catches photon streams, batching or reductions that depend on the thread count.
TEST_CASE("diffusion results are bit-identical for any thread count", "[diffusion]") {
  // 5 batches: one thread reduces them in rounds of 2, two threads in rounds of 4.
  DiffusionSetup s = make_setup(2.0, 0.3, 0.4, 1.2, Absorption::Analog, 0, 30, 12, 6, 20, 20000);
  s.threads = 1;
  const DiffusionResult a = simulate(s);
  s.threads = 2;
  const DiffusionResult b = simulate(s);
  REQUIRE(a.photons == 20000);
  REQUIRE(a.segments == b.segments);
  REQUIRE(a.u == b.u);
  REQUIRE(a.u_err == b.u_err);
  REQUIRE(a.r2 == b.r2);
  REQUIRE(a.energy == b.energy);
}

// Catches a wrong absorption probability or speed (analog; weighted energy is exact by design).
TEST_CASE("energy in the medium decays as exp(-sigma_a c t / eta)", "[diffusion]") {
  // Analog: photons die at absorbing collisions, so the energy is a genuine MC estimate that can
  // fail.
  DiffusionSetup s = make_setup(1.0, 0.5, 0.3, 1.33, Absorption::Analog, 0, 40, 20, 10, 10, 20000);
  const DiffusionResult r = simulate(s);
  const double k = s.medium.sigma_a * kSpeedOfLight / s.medium.eta;
  for (int j = 0; j < s.grid.time.bins; ++j) {
    const double t0 = s.grid.time.bin_start_ps(j), t1 = t0 + s.grid.time.bin_width_ps;
    const double exact = (std::exp(-k * t0) - std::exp(-k * t1)) / (k * (t1 - t0));
    INFO("bin " << j << " E " << r.energy[j] << " +- " << r.energy_err[j] << " exact " << exact);
    REQUIRE(r.energy_err[j] > 0);
    REQUIRE(std::abs(r.energy[j] - exact) <= 4 * r.energy_err[j]);
  }
  s.absorption = Absorption::Weighted;  // every photon carries exp(-sigma_a v t): exact
  s.photons = 500;
  const DiffusionResult w = simulate(s);
  for (int j = 0; j < s.grid.time.bins; ++j)
    REQUIRE(w.energy[j] == Approx(survival_integral(s.medium, s.grid.time.bin_start_ps(j),
                                                    s.grid.time.bin_start_ps(j + 1)) /
                                  s.grid.time.bin_width_ps)
                               .epsilon(1e-12));
}

// Catches a wrong HG mean cosine, direction update or moment normalisation, in both modes.
TEST_CASE("<r^2>(t) matches the exact persistent random walk for g = 0, 0.5, 0.9", "[diffusion]") {
  struct Case {
    double g, sigma_a;
    Absorption abs;
  };
  for (const Case c : {Case{0.0, 0.0, Absorption::Weighted}, Case{0.5, 0.2, Absorption::Analog},
                       Case{0.9, 0.1, Absorption::Weighted}}) {
    const double sigma_s = 2.0, eta = 1.1, v = kSpeedOfLight / eta;
    const double t_tr = 1 / (sigma_s * (1 - c.g) * v);  // transport mean free time
    DiffusionSetup s =
        make_setup(sigma_s, c.sigma_a, c.g, eta, c.abs, 0, 6 * t_tr, 15, 10, 10, 20000);
    const DiffusionResult r = simulate(s);
    const Analysis a = analyse(s, r, 0.05);
    for (int j = 0; j < s.grid.time.bins; ++j) {
      INFO("g " << c.g << " bin " << j << " r2 " << r.r2[j] << " +- " << r.r2_err[j] << " exact "
                << a.r2_exact[j]);
      REQUIRE(std::abs(r.r2[j] - a.r2_exact[j]) <= 4 * r.r2_err[j]);
    }
    // The bin-averaged reference itself: midpoint value within the curvature of the bin.
    const int j = s.grid.time.bins / 2;
    REQUIRE(a.r2_exact[j] ==
            Approx(prw_r2(v, sigma_s * (1 - c.g) * v, s.grid.time.bin_center_ps(j))).epsilon(0.01));
  }
}

// Catches a wrong speed (eta), attenuation, shell volume or scattering-order count at the front.
TEST_CASE("the unscattered shell sits at r = c t / eta with weight exp(-sigma_t r) / (4 pi r^2)",
          "[diffusion]") {
  const double eta = 1.5, v = kSpeedOfLight / eta, sigma_a = 0.7;
  DiffusionSetup s =
      make_setup(0.0, sigma_a, 0.0, eta, Absorption::Analog, 1, 13, 10, 2.9, 13, 20000);
  const DiffusionResult r = simulate(s);
  const Grid& g = s.grid;
  for (int j = 0; j < g.time.bins; ++j)
    for (int i = 0; i < g.shells; ++i) {
      // Times at which the front r = v t is inside shell i and bin j.
      const double ta = std::max(g.time.bin_start_ps(j), i * g.dr / v);
      const double tb = std::min(g.time.bin_start_ps(j + 1), (i + 1) * g.dr / v);
      // int over the cell of exp(-sigma_t r) delta(r - v t) / (4 pi r^2) dV dt, per volume and bin
      // width.
      const double volume = 4 * kPi / 3 * (std::pow((i + 1) * g.dr, 3) - std::pow(i * g.dr, 3));
      const double exact =
          tb > ta ? exp_integral(sigma_a * v, ta, tb) / (volume * g.time.bin_width_ps) : 0.0;
      const double u = r.u[r.cell(i, j)], err = r.u_err[r.cell(i, j)];
      INFO("bin " << j << " shell " << i << " u " << u << " +- " << err << " exact " << exact);
      if (exact == 0)
        REQUIRE(u == 0);  // the front is nowhere else
      else
        REQUIRE(std::abs(u - exact) <= 4 * err);
    }

  // Window up to sigma_s v t = 4: every bin keeps hundreds of unscattered photons.
  DiffusionSetup m = make_setup(2.0, 0.3, 0.6, 1.2, Absorption::Analog, 0, 8, 10, 4, 40, 20000);
  const DiffusionResult rm = simulate(m);
  const Analysis am = analyse(m, rm, 0.05);
  const double vm = kSpeedOfLight / m.medium.eta;
  for (int j = 0; j < m.grid.time.bins; ++j) {
    INFO("bin " << j);
    REQUIRE(std::abs(rm.unscattered[j] - am.unscattered_exact[j]) <= 4 * rm.unscattered_err[j]);
    REQUIRE(std::abs(rm.single[j] - am.single_exact[j]) <= 4 * rm.single_err[j]);
    for (int i = 0; i < m.grid.shells; ++i)
      if (i * m.grid.dr >= vm * m.grid.time.bin_start_ps(j + 1))
        REQUIRE(rm.u[rm.cell(i, j)] == 0);  // causality
  }
}

// Catches a wrong diffusion coefficient or density normalisation (200 transport mean free times).
TEST_CASE("late-time fluence matches diffusion out to two rms radii", "[diffusion]") {
  const double sigma_s = 1.0, v = kSpeedOfLight, a = sigma_s * v, T = 200 / a;
  const double rms = std::sqrt(prw_r2(v, a, T));
  DiffusionSetup s = make_setup(sigma_s, 0.0, 0.0, 1.0, Absorption::Weighted, 0.95 * T, 1.05 * T, 1,
                                3 * rms, 18, 100000);
  const DiffusionResult r = simulate(s);
  const Analysis an = analyse(s, r, 0.05);
  int checked = 0;
  for (int i = 0; i < s.grid.shells && s.grid.shell_center(i) <= 2 * rms; ++i, ++checked) {
    const double u = r.u[r.cell(i, 0)], err = r.u_err[r.cell(i, 0)],
                 ud = an.u_diffusion[r.cell(i, 0)];
    INFO("r " << s.grid.shell_center(i) << " mm: MC " << u << " +- " << err << " diffusion " << ud);
    REQUIRE(err < 0.04 * u);  // precise enough for the 5% claim to mean something
    REQUIRE(std::abs(u - ud) <= 0.05 * ud + 4 * err);
  }
  REQUIRE(checked >= 10);
  REQUIRE(an.gaussian_distance[0] < 0.01);
  REQUIRE(an.paasschens_distance[0] < 0.01);
}

// Catches a broken Paasschens cell average (front singularity) or a distance blind to shape.
TEST_CASE("isotropic MC matches Paasschens at all times and is non-Gaussian early", "[diffusion]") {
  const double mft = 1 / (4.1 * kSpeedOfLight);  // the seed paper's medium, sigma_t = 4.1/mm
  DiffusionSetup s =
      make_setup(4.1, 0.0, 0.0, 1.0, Absorption::Weighted, 0, 12 * mft, 12, 3.0, 60, 30000);
  const DiffusionResult r = simulate(s);
  const Analysis a = analyse(s, r, 0.05);
  int resolved = 0;
  for (int j = 0; j < s.grid.time.bins; ++j) {
    if (std::isnan(a.paasschens_distance[j])) continue;
    ++resolved;
    INFO("bin " << j << " distance to Paasschens " << a.paasschens_distance[j]);
    REQUIRE(a.paasschens_distance[j] < 0.015);  // Paasschens is accurate to ~1% for g = 0
  }
  REQUIRE(resolved >= 10);
  REQUIRE(a.gaussian_distance[2] > 0.1);    // 2.5 mean free times: far from Gaussian
  REQUIRE(a.gaussian_distance[11] < 0.04);  // 11.5 mean free times: close
  REQUIRE(a.gaussian.reached);
}

// Catches plot regressions: axes, series colours and legend must reach the image.
TEST_CASE("plot module draws axes, coloured series and a legend", "[diffusion][plot]") {
  Plot p;
  p.title = "test 1";
  p.x_label = "x";
  p.y_label = "y";
  p.log_y = true;
  PlotSeries a{"line", {0, 1, 2, 3}, {1, 10, 100, 1000}, Rgb8{255, 0, 0}, PlotSeries::Style::Line};
  PlotSeries b{"dots", {0.5, 1.5}, {5, 50}, Rgb8{0, 0, 255}, PlotSeries::Style::Markers};
  PlotSeries c{"", {0, 3}, {2, 2}, Rgb8{0, 200, 0}, PlotSeries::Style::Dashed};
  p.series = {a, b, c};
  Canvas canvas(400, 300);
  draw_plot(canvas, 0, 0, 400, 300, p, 1);
  auto count = [&](uint8_t cr, uint8_t cg, uint8_t cb) {
    size_t n = 0;
    for (size_t i = 0; i < canvas.rgb.size(); i += 3)
      n += canvas.rgb[i] == cr && canvas.rgb[i + 1] == cg && canvas.rgb[i + 2] == cb;
    return n;
  };
  REQUIRE(count(255, 0, 0) > 200);  // a line across the plot, plus its legend sample
  REQUIRE(count(0, 0, 255) > 10);
  REQUIRE(count(0, 200, 0) > 50);
  REQUIRE(count(20, 20, 20) > 100);  // text
  const AxisTicks lin = axis_ticks(0, 1, false);
  REQUIRE(lin.labels.front() == "0.0");
  REQUIRE(lin.labels.back() == "1.0");
  const AxisTicks dec = axis_ticks(-3, 2, true);
  REQUIRE(dec.labels.front() == "1e-3");
  REQUIRE(dec.labels.back() == "100");
  REQUIRE(axis_ticks(-12, 2, true).labels.size() <= 8);  // many decades are thinned out
}

namespace {

struct DiffusionRun {
  int code = -1;
  std::string err;
};

DiffusionRun run_diffusion(const std::vector<std::string>& args, const fs::path& cwd) {
  std::string cmd = "cd '" + cwd.string() + "' && '" FEMTO_BINARY "'";
  for (const auto& a : args) cmd += " '" + a + "'";
  cmd += " >/dev/null 2>stderr.txt </dev/null";
  const int status = std::system(cmd.c_str());
  DiffusionRun r;
  if (status != -1 && WIFEXITED(status)) r.code = WEXITSTATUS(status);
  r.err = read_diffusion_file(cwd / "stderr.txt");
  return r;
}

struct DiffusionDir : test::TempDir {
  DiffusionDir() : test::TempDir("femto_test_diffusion") {}
};

}  // namespace

// Catches bad flags accepted, messages not naming flag and value, or output written too early.
TEST_CASE("femto diffusion rejects bad flags with exit 2 and writes nothing", "[diffusion][cli]") {
  DiffusionDir tmp;
  struct Bad {
    std::vector<std::string> flags;
    std::string named;  // the flag the message must name
  };
  const std::vector<Bad> bad = {{{"--g", "1.5"}, "--g"},
                                {{"--sigma-s", "-1"}, "--sigma-s"},
                                {{"--sigma_a", "x"}, "--sigma-a"},
                                {{"--eta", "0.5"}, "--eta"},
                                {{"--photons", "1.5"}, "--photons"},
                                {{"--t-bins", "0"}, "--t-bins"},
                                {{"--absorption", "magic"}, "--absorption"},
                                {{"--threshold", "1"}, "--threshold"},
                                {{"--t-start", "10", "--t-end", "5"}, "--t-end"},
                                {{"--plot-times", "1,abc"}, "--plot-times"},
                                {{"--plot-times", "999"}, "--plot-times"},
                                {{"--sigma-s", "0"}, "--t-end"},  // clear medium: no default window
                                {{"--r-bins", "5000", "--t-bins", "5000"}, "--r-bins"},
                                {{"--frobnicate"}, "--frobnicate"}};
  for (const Bad& b : bad) {
    std::vector<std::string> args = {"diffusion", "--out", "out", "--quiet"};
    args.insert(args.end(), b.flags.begin(), b.flags.end());
    const DiffusionRun r = run_diffusion(args, tmp.dir);
    INFO(b.flags.front() << " -> " << r.err);
    REQUIRE(r.code == 2);
    REQUIRE(r.err.find("femto diffusion: " + b.named + ": ") != std::string::npos);
    if (b.flags != std::vector<std::string>{"--sigma-s", "0"})  // the one message without a value
      REQUIRE(r.err.find("(got '") != std::string::npos);
    REQUIRE(!fs::exists(tmp.dir / "out"));
  }
}

// Catches missing outputs, CSV columns drifting from the documentation, thread-dependent files.
TEST_CASE("femto diffusion writes the documented outputs, identical for any thread count",
          "[diffusion][cli]") {
  DiffusionDir tmp;
  const std::vector<std::string> base = {
      "diffusion", "--photons", "6000",   "--t-end", "20",      "--t-bins",     "40",
      "--r-bins",  "40",        "--seed", "3",       "--quiet", "--plot-times", "2,8,16"};
  auto with = [&](std::vector<std::string> extra) {
    std::vector<std::string> a = base;
    a.insert(a.end(), extra.begin(), extra.end());
    return a;
  };
  const DiffusionRun r1 = run_diffusion(with({"--threads", "1", "--out", "one"}), tmp.dir);
  INFO(r1.err);
  REQUIRE(r1.code == 0);
  const DiffusionRun r2 = run_diffusion(with({"--threads", "2", "--out", "two"}), tmp.dir);
  REQUIRE(r2.code == 0);
  for (const char* f : {"fluence.csv", "moments.csv", "models.csv", "fluence_models.csv",
                        "summary.json", "fluence.png", "distance.png"})
    REQUIRE(fs::exists(tmp.dir / "one" / f));
  const std::string fl = read_diffusion_file(tmp.dir / "one" / "fluence.csv"),
                    mo = read_diffusion_file(tmp.dir / "one" / "moments.csv");
  REQUIRE(first_line(fl) ==
          "t_ps,r_mm,energy_density,energy_density_stderr,fluence_rate,fluence_rate_stderr");
  REQUIRE(first_line(mo) ==
          "t_ps,energy,energy_stderr,r2_mm2,r2_stderr,r4_mm4,r4_stderr,unscattered,single,gaussian_"
          "distance");
  REQUIRE(std::count(fl.begin(), fl.end(), '\n') == 1 + 40 * 40);
  REQUIRE(std::count(mo.begin(), mo.end(), '\n') == 1 + 40);
  REQUIRE(fl == read_diffusion_file(tmp.dir / "two" / "fluence.csv"));
  REQUIRE(mo == read_diffusion_file(tmp.dir / "two" / "moments.csv"));
  const auto js = nlohmann::json::parse(read_diffusion_file(tmp.dir / "one" / "summary.json"));
  REQUIRE(js["inputs"]["medium"]["sigma_s_per_mm"] == 4.1);
  REQUIRE(js["transition"]["threshold"] == 0.05);
  REQUIRE(js["transition"]["by_threshold"].size() == 3);
  REQUIRE(js["transition"].contains("t_star_ps"));
  REQUIRE(js["models"].contains("paasschens"));
  REQUIRE(js["at_plot_times"].size() == 3);
}

// Catches a t* reported without its uncertainty or trusted when noise decides it: at 3e4
// photons and a 2% threshold the noise floor at t* is about the threshold itself (flagged); at
// 3e5 photons and 5% it is not, the jackknife interval is finite, and an independent seed's t*
// lies within the combined intervals (4 combined standard errors).
TEST_CASE("t* comes with a jackknife interval and a noise-floor flag", "[diffusion][statistical]") {
  auto run = [](uint64_t photons, uint64_t seed, double threshold) {
    DiffusionSetup s = make_setup(4.1, 0, 0, 1, Absorption::Weighted, 0, 20 / (4.1 * kSpeedOfLight), 80,
                                  20 / 4.1, 100, photons);
    s.seed = seed;
    const DiffusionResult r = simulate(s);
    const Analysis a = analyse(s, r, threshold);
    return std::make_pair(a, transition_confidence(s, r, a));
  };
  const auto [a_few, c_few] = run(30000, 7, 0.02);
  INFO("3e4 photons, 2%: t* " << a_few.gaussian.t_ps << ", floor at t* " << c_few.noise_at_t_star);
  CHECK(c_few.noise_limited);
  const auto [a1, c1] = run(300000, 7, 0.05);
  const auto [a2, c2] = run(300000, 8, 0.05);
  INFO("3e5 photons, 5%: t* " << a1.gaussian.t_ps << " +- " << c1.se_ps << " and " << a2.gaussian.t_ps << " +- "
                              << c2.se_ps << "; floor " << c1.noise_at_t_star);
  REQUIRE(a1.gaussian.reached);
  CHECK(!c1.noise_limited);
  CHECK(c1.batches == 10);
  REQUIRE(std::isfinite(c1.se_ps));
  CHECK(c1.se_ps > 0);
  CHECK(c1.ci_lo_ps < a1.gaussian.t_ps);
  CHECK(c1.ci_hi_ps > a1.gaussian.t_ps);
  CHECK(std::abs(a1.gaussian.t_ps - a2.gaussian.t_ps) <= 4 * std::hypot(c1.se_ps, c2.se_ps));
}
