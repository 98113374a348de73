// Tests of the PCG32 generator and the per-(seed, pixel, sample) streams in core/rng.h.
// Significance: reject when p < 1e-3; seeds are fixed, so every outcome is deterministic.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdint>
#include <vector>

#include "core/rng.h"
#include "samplers/stats.h"

using femto::Rng;
namespace st = femto::stats;

namespace {

std::vector<double> draw(Rng rng, size_t n) {
  std::vector<double> v(n);
  for (double& x : v) x = rng.uniform();
  return v;
}

/// Pearson sample correlation of a and b.
double correlation(const std::vector<double>& a, const std::vector<double>& b) {
  const double n = static_cast<double>(a.size());
  double ma = 0, mb = 0;
  for (size_t i = 0; i < a.size(); ++i) ma += a[i], mb += b[i];
  ma /= n, mb /= n;
  double sab = 0, saa = 0, sbb = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    sab += (a[i] - ma) * (b[i] - mb);
    saa += (a[i] - ma) * (a[i] - ma);
    sbb += (b[i] - mb) * (b[i] - mb);
  }
  return sab / std::sqrt(saa * sbb);
}

size_t count_equal(const std::vector<double>& a, const std::vector<double>& b) {
  size_t k = 0;
  for (size_t i = 0; i < a.size(); ++i) k += a[i] == b[i];
  return k;
}

}  // namespace

// Catches a PCG32 that deviates from the reference generator (pcg32_srandom(42, 54) demo output).
TEST_CASE("PCG32 reproduces the reference sequence", "[rng]") {
  Rng rng(42, 54);
  for (const uint32_t expected : {0xa15c02b7u, 0x7b47f409u, 0xba1d3330u, 0x83d2f293u,
                                  0xbfa4784bu, 0xcbed606eu})
    CHECK(rng.next_u32() == expected);
}

// Catches uniform() returning 1.0 or negatives, or a non-uniform bit combination.
TEST_CASE("Rng::uniform is in [0, 1) and uniform over 100 bins", "[rng]") {
  const int bins = 100, n = 1000000;
  std::vector<double> observed(bins, 0.0), expected(bins, double(n) / bins);
  Rng rng(2024, 7);
  double lo = 1.0, hi = 0.0;
  for (int i = 0; i < n; ++i) {
    const double u = rng.uniform();
    lo = std::fmin(lo, u);
    hi = std::fmax(hi, u);
    if (u >= 0.0 && u < 1.0) observed[static_cast<int>(u * bins)] += 1.0;
  }
  CHECK(lo >= 0.0);
  CHECK(hi < 1.0);
  const st::Chi2Result r = st::chi2_test(observed, expected);
  INFO("chi2 = " << r.chi2 << "  dof = " << r.dof << "  p = " << r.p_value << "  min = " << lo
                 << "  max = " << hi);
  CHECK(r.p_value >= 1e-3);
  CHECK(r.dof == bins - 1);
}

// Catches neighbouring pixels or samples sharing (or linearly tracking) one random stream.
TEST_CASE("for_sample streams of neighbouring pixels and samples are independent", "[rng]") {
  const size_t n = 10000;
  const double bound = 4.0 / std::sqrt(static_cast<double>(n));
  const uint64_t seed = 12345;
  const std::vector<double> base = draw(Rng::for_sample(seed, 0, 0), n);
  const std::vector<std::vector<double>> others = {
      draw(Rng::for_sample(seed, 1, 0), n), draw(Rng::for_sample(seed, 0, 1), n),
      draw(Rng::for_sample(seed, 1, 1), n), draw(Rng::for_sample(seed + 1, 0, 0), n)};
  for (size_t k = 0; k < others.size(); ++k) {
    const double rho = correlation(base, others[k]);
    INFO("stream " << k << "  correlation = " << rho);
    CHECK(count_equal(base, others[k]) == 0);
    CHECK(std::abs(rho) < bound);
  }
  // Successive outputs of one stream are uncorrelated too (lag-1).
  const std::vector<double> head(base.begin(), base.end() - 1), tail(base.begin() + 1, base.end());
  CHECK(std::abs(correlation(head, tail)) < bound);
}

// Catches hidden state (globals, time, addresses) leaking into the streams.
TEST_CASE("Same inputs give identical sequences", "[rng]") {
  CHECK(draw(Rng::for_sample(7, 123, 45), 1000) == draw(Rng::for_sample(7, 123, 45), 1000));
  CHECK(draw(Rng(99, 3), 1000) == draw(Rng(99, 3), 1000));
  Rng reseeded(1, 1);
  reseeded.next_u32();
  reseeded.seed(99, 3);
  CHECK(draw(reseeded, 1000) == draw(Rng(99, 3), 1000));
}
