// Temporal smoothing kernels: normalisation, CDFs against quadrature, exact bin integration and
// the progressive bandwidth schedule.
#include <catch2/catch.hpp>

#include <cmath>

#include "core/temporal_kernel.h"
#include "samplers/stats.h"

using namespace femto;

// Catches: kernels that do not integrate to one (energy gain or loss), CDFs that disagree with
// their kernel (bins receiving the wrong share), asymmetric kernels (shifted arrival times).
TEST_CASE("temporal kernels integrate to one and their CDFs match quadrature", "[kernel]") {
  for (TemporalKernel k : {TemporalKernel::Perlin, TemporalKernel::Epanechnikov}) {
    auto f = [k](double u) { return kernel_value(k, u); };
    CHECK(stats::adaptive_simpson(f, -1.0, 1.0, 1e-13) == Approx(1.0).epsilon(1e-12));
    CHECK(kernel_value(k, 1.0) == 0.0);
    CHECK(kernel_value(k, 0.3) == kernel_value(k, -0.3));
    for (double u : {-0.9, -0.5, -0.1, 0.0, 0.2, 0.7, 0.99}) {
      INFO("kernel " << static_cast<int>(k) << " u " << u);
      CHECK(kernel_cdf(k, u) == Approx(stats::adaptive_simpson(f, -1.0, u, 1e-13)).epsilon(1e-11));
    }
    CHECK(kernel_cdf(k, -1.0) == 0.0);
    CHECK(kernel_cdf(k, 1.0) == 1.0);
    // The first moment vanishes: a deposit's mean time stays where the sample arrived.
    CHECK(stats::adaptive_simpson([k](double u) { return u * kernel_value(k, u); }, -1.0, 1.0, 1e-13) ==
          Approx(0.0).margin(1e-13));
  }
}

// Catches: bin weights that leak energy at bin edges or depend on where the deposit sits.
TEST_CASE("bin-integrated weights of one deposit sum to one", "[kernel]") {
  for (TemporalKernel k : {TemporalKernel::Perlin, TemporalKernel::Epanechnikov}) {
    for (double t : {10.0, 10.37, 12.999}) {
      for (double T : {0.3, 1.0, 4.7}) {
        double sum = 0, mean = 0;
        for (int i = 0; i < 40; ++i) {
          const double w = kernel_bin_weight(k, t, T, i * 0.5, (i + 1) * 0.5);
          REQUIRE(w >= 0.0);
          sum += w;
          mean += w * (i + 0.5) * 0.5;
        }
        CHECK(sum == Approx(1.0).epsilon(1e-12));
        if (T <= 0.3) continue;  // bins coarser than the kernel quantise the mean
        CHECK(mean == Approx(t).epsilon(0.01));
      }
    }
  }
}

// Catches: a schedule that shrinks too fast (inconsistent: bias never vanishes) or not at all.
TEST_CASE("progressive bandwidth shrinks as prod (j + alpha) / (j + 1)", "[kernel]") {
  const double alpha = 0.8;
  double T = 2.0;
  for (int j = 1; j <= 1000; ++j) T = next_bandwidth(T, j, alpha);
  // prod_{j=1}^{n} (j + alpha) / (j + 1) = Gamma(n + 1 + alpha) / (Gamma(1 + alpha) Gamma(n + 2)) ~ n^(alpha - 1).
  const double expected = 2.0 * std::exp(std::lgamma(1001 + alpha) - std::lgamma(1 + alpha) - std::lgamma(1002.0));
  CHECK(T == Approx(expected).epsilon(1e-9));
  CHECK(T < 2.0 * std::pow(1000.0, alpha - 1) * 1.2);
  CHECK(T > 0.0);
}
