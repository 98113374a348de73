// Pulse statistics of tissue detectors' TPSFs (docs/tissue.md, "Pulse spreading"): moments,
// peak, Gaussian distance, their jackknife intervals and noise flags.
#include <catch2/catch.hpp>

#include <cmath>
#include <vector>

#include "core/constants.h"
#include "core/rng.h"
#include "core/tissue/pulse.h"

using namespace femto;
using namespace femto::tissue;

// Catches wrong pulse moments or intervals: a sampled Gaussian pulse histogram has the pulse's
// mean, its rms width (after Sheppard's correction) and its peak; identical batches give zero
// jackknife errors, and a flat-topped noisy TPSF has its peak flagged as noise-decided.
TEST_CASE("pulse statistics of a TPSF with jackknife intervals", "[tissue]") {
  const TimeAxis axis{0, 10, 60};
  const double mu = 233, sigma = 41;
  std::vector<double> h(60);
  for (int j = 0; j < 60; ++j) {
    const double a = (axis.bin_start_ps(j) - mu) / (sigma * std::sqrt(2.0)),
                 b = (axis.bin_start_ps(j + 1) - mu) / (sigma * std::sqrt(2.0));
    h[static_cast<size_t>(j)] = 0.5 * (std::erf(b) - std::erf(a));
  }
  const PulseStats s = pulse_stats(axis, std::vector<std::vector<double>>(5, h));
  REQUIRE(s.defined);
  CHECK(s.mean.value == Approx(mu).margin(1e-6));
  CHECK(s.rms.value == Approx(sigma).epsilon(1e-4));  // Sheppard: exact to O(bin^4 / sigma^3)
  CHECK(s.peak.value == Approx(mu).margin(0.5));      // a parabola through three gates
  CHECK(s.mean.se == Approx(0).margin(1e-9));
  CHECK(!s.peak_noise_limited);
  CHECK(!s.width_noise_limited);
  CHECK(s.gaussian_distance.value < 1e-4);  // the pulse is its own Gaussian
  CHECK(s.gaussian_noise == 0);
  // Noisy flat top: Poisson-like batch noise on a plateau.
  std::vector<std::vector<double>> noisy(10, std::vector<double>(60, 0.0));
  Rng rng(3, 4);
  for (auto& b : noisy)
    for (int j = 20; j < 40; ++j) b[static_cast<size_t>(j)] = 100 + 10 * (rng.uniform() - 0.5);
  const PulseStats f = pulse_stats(axis, noisy);
  CHECK(f.peak_noise_limited);
  CHECK(f.mean.value == Approx(300).margin(2));
  CHECK(f.mean.ci_lo < f.mean.value);
  CHECK(f.mean.ci_hi > f.mean.value);
}

// Catches a Gaussian distance that is not the total-variation distance from the Gaussian pulse of
// the TPSF's own mean and width (wrong moments, a width without Sheppard's correction, gates
// misplaced), and a noise floor in the wrong units: an exponential pulse's distance against
// the continuous densities integrated independently (midpoint rule, 2 x 10^5 steps), and a
// Gaussian pulse with batch noise, whose distance is all noise.
TEST_CASE("a TPSF's distance from a Gaussian pulse and its noise floor", "[tissue]") {
  // exp(-t / tau) / tau: mean tau, rms tau; fine gates over 12 tau (the tail beyond: e^-12).
  const double tau = 100;
  const TimeAxis axis{0, 2, 600};
  std::vector<double> h(600);
  for (int j = 0; j < 600; ++j)
    h[static_cast<size_t>(j)] =
        std::exp(-axis.bin_start_ps(j) / tau) - std::exp(-axis.bin_start_ps(j + 1) / tau);
  const PulseStats e = pulse_stats(axis, std::vector<std::vector<double>>(4, h));
  REQUIRE(e.defined);
  // The same distance of the continuous densities on the window [0, 12 tau], each normalised
  // there (as the gates are): f the exponential, g the normal density of mean and rms tau.
  const int n = 200000;
  const double dt = 12 * tau / n;
  std::vector<double> f(n), gn(n);
  double F = 0, G = 0;
  for (int i = 0; i < n; ++i) {
    const double t = (i + 0.5) * dt, z = (t - tau) / tau;
    F += f[static_cast<size_t>(i)] = std::exp(-t / tau);
    G += gn[static_cast<size_t>(i)] = std::exp(-0.5 * z * z);
  }
  double tv = 0;
  for (size_t i = 0; i < f.size(); ++i) tv += std::abs(f[i] / F - gn[i] / G);
  tv *= 0.5;
  // Gates of tau / 50 blur the crossings of f and g and the moments by about 1e-3.
  CHECK(e.gaussian_distance.value == Approx(tv).epsilon(0.005));
  CHECK(e.gaussian_distance.value > 0.1);
  CHECK_FALSE(e.gaussian_noise_limited);

  // A Gaussian pulse with Poisson-like noise (sd proportional to the square root of the gate's
  // mass) in each of 20 batches: its distance is about the noise floor.
  const TimeAxis ax{0, 10, 60};
  std::vector<double> g(60);
  const double k = 1 / (40 * std::sqrt(2.0));
  for (int j = 0; j < 60; ++j)
    g[static_cast<size_t>(j)] = 0.5 * (std::erf((ax.bin_start_ps(j + 1) - 300) * k) -
                                       std::erf((ax.bin_start_ps(j) - 300) * k));
  std::vector<std::vector<double>> noisy(20, g);
  Rng rng(5, 6);
  double floor = 0;  // 0.5 sqrt(2 / pi) sum_j sd(sum over batches)_j / total
  for (size_t j = 0; j < 60; ++j) {
    const double sd = 0.01 * std::sqrt(g[j]);  // per batch; a uniform's sd is its width / sqrt(12)
    for (auto& b : noisy) b[j] += sd * std::sqrt(12.0) * (rng.uniform() - 0.5);
    floor += std::sqrt(20.0) * sd;
  }
  floor *= 0.5 * std::sqrt(2 / kPi) / 20;
  const PulseStats q = pulse_stats(ax, noisy);
  REQUIRE(q.defined);
  // The sample errors of 20 batches scatter by about 1/sqrt(19) per gate; the floor sums them.
  CHECK(q.gaussian_noise == Approx(floor).epsilon(0.1));
  CHECK(q.gaussian_distance.value < 2 * q.gaussian_noise);
  CHECK(q.gaussian_noise_limited);
  CHECK(q.gaussian_distance.ci_lo < q.gaussian_distance.value);
  CHECK(q.gaussian_distance.ci_hi > q.gaussian_distance.value);
}
