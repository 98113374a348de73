#include "samplers/stats.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>

#include "core/constants.h"

namespace femto::stats {

namespace {
constexpr int kMaxIterations = 100000;
constexpr double kEps = 1e-16;
constexpr double kTiny = 1e-300;
}  // namespace

double regularized_gamma_q(double a, double x) {
  if (!(a > 0.0) || !(x >= 0.0)) throw std::invalid_argument("regularized_gamma_q: need a > 0, x >= 0");
  if (x == 0.0) return 1.0;
  if (std::isinf(x)) return 0.0;
  const double log_prefactor = a * std::log(x) - x - std::lgamma(a);  // log(x^a e^-x / Gamma(a))
  if (x < a + 1.0) {
    // P(a, x) = x^a e^-x / Gamma(a) * sum_n x^n / (a (a+1) ... (a+n)).
    double term = 1.0 / a, sum = term;
    for (int n = 1; n < kMaxIterations && term > sum * kEps; ++n) {
      term *= x / (a + n);
      sum += term;
    }
    return 1.0 - sum * std::exp(log_prefactor);
  }
  // Q(a, x) = x^a e^-x / Gamma(a) * 1 / (x+1-a - 1(1-a) / (x+3-a - 2(2-a) / (x+5-a - ...))),
  // evaluated with the modified Lentz algorithm.
  double b = x + 1.0 - a, c = 1.0 / kTiny, d = 1.0 / b, h = d;
  for (int i = 1; i < kMaxIterations; ++i) {
    const double an = -i * (i - a);
    b += 2.0;
    d = an * d + b;
    if (std::abs(d) < kTiny) d = kTiny;
    c = b + an / c;
    if (std::abs(c) < kTiny) c = kTiny;
    d = 1.0 / d;
    const double delta = d * c;
    h *= delta;
    if (std::abs(delta - 1.0) < kEps) break;
  }
  return std::exp(log_prefactor) * h;
}

double chi2_survival(double chi2, double dof) {
  if (!(dof > 0.0)) throw std::invalid_argument("chi2_survival: dof must be > 0");
  return regularized_gamma_q(0.5 * dof, std::fmax(0.0, 0.5 * chi2));
}

Chi2Result chi2_test(const std::vector<double>& observed, const std::vector<double>& expected,
                     double min_expected) {
  if (observed.size() != expected.size()) throw std::invalid_argument("chi2_test: size mismatch");
  for (size_t i = 0; i < observed.size(); ++i)
    if (!(observed[i] >= 0.0) || !(expected[i] >= 0.0) || std::isinf(observed[i]) ||
        std::isinf(expected[i]))
      throw std::invalid_argument("chi2_test: counts must be finite and non-negative");

  std::vector<size_t> order(expected.size());
  std::iota(order.begin(), order.end(), size_t{0});
  std::stable_sort(order.begin(), order.end(),
                   [&](size_t i, size_t j) { return expected[i] < expected[j]; });

  double chi2 = 0.0, pool_obs = 0.0, pool_exp = 0.0;
  int used = 0, pooled = 0;
  bool impossible = false;  // an observation where the pdf is zero
  for (const size_t i : order) {
    const double o = observed[i], e = expected[i];
    if (e == 0.0) {
      impossible = impossible || o > 0.0;
      continue;
    }
    if (e < min_expected || (pooled > 0 && pool_exp < min_expected)) {
      pool_obs += o;
      pool_exp += e;
      ++pooled;
    } else {
      chi2 += (o - e) * (o - e) / e;
      ++used;
    }
  }
  if (pooled > 0) {
    chi2 += (pool_obs - pool_exp) * (pool_obs - pool_exp) / pool_exp;
    ++used;
  }
  if (used < 2) throw std::invalid_argument("chi2_test: fewer than two usable cells");
  const int dof = used - 1;
  if (impossible) return {std::numeric_limits<double>::infinity(), dof, 0.0, used, pooled};
  return {chi2, dof, chi2_survival(chi2, dof), used, pooled};
}

double ks_statistic_uniform(std::vector<double> samples, double a, double b) {
  if (samples.empty() || !(b > a)) throw std::invalid_argument("ks_statistic_uniform: bad input");
  std::sort(samples.begin(), samples.end());
  const double n = static_cast<double>(samples.size());
  double D = 0.0;
  for (size_t i = 0; i < samples.size(); ++i) {
    const double F = std::clamp((samples[i] - a) / (b - a), 0.0, 1.0);
    const double k = static_cast<double>(i);
    D = std::max({D, (k + 1.0) / n - F, F - k / n});
  }
  return D;
}

double ks_p_value(double D, std::size_t n) {
  if (n == 0) throw std::invalid_argument("ks_p_value: n must be > 0");
  const double sn = std::sqrt(static_cast<double>(n));
  const double lambda = (sn + 0.12 + 0.11 / sn) * D;
  if (!(lambda > 0.0)) return 1.0;
  double q = 0.0;
  if (lambda < 1.18) {
    // Q = 1 - sqrt(2 pi) / lambda * sum_j exp(-(2j-1)^2 pi^2 / (8 lambda^2)): fast for small lambda.
    const double k = -kPi * kPi / (8.0 * lambda * lambda);
    double sum = 0.0;
    for (int j = 1; j < 100; ++j) {
      const double t = std::exp(k * (2 * j - 1) * (2 * j - 1));
      sum += t;
      if (t <= kEps * sum) break;
    }
    q = 1.0 - std::sqrt(2.0 * kPi) / lambda * sum;
  } else {
    // Q = 2 sum_j (-1)^(j-1) exp(-2 j^2 lambda^2): fast for large lambda.
    double sign = 1.0;
    for (int j = 1; j < 100; ++j, sign = -sign) {
      const double t = std::exp(-2.0 * j * j * lambda * lambda);
      q += 2.0 * sign * t;
      if (t <= kEps * q) break;
    }
  }
  return std::clamp(q, 0.0, 1.0);
}

namespace {
constexpr int kSimpsonMinDepth = 4;
constexpr int kSimpsonMaxDepth = 50;

double simpson_step(const std::function<double(double)>& f, double a, double b, double fa,
                    double fm, double fb, double whole, double tol, int depth) {
  const double m = 0.5 * (a + b), lm = 0.5 * (a + m), rm = 0.5 * (m + b);
  const double flm = f(lm), frm = f(rm);
  const double left = (m - a) / 6.0 * (fa + 4.0 * flm + fm);
  const double right = (b - m) / 6.0 * (fm + 4.0 * frm + fb);
  const double delta = left + right - whole;
  // The relative floor stops refinement once the difference is rounding noise, so a tolerance
  // below machine precision cannot trigger 2^50 subdivisions.
  const double bound = 15.0 * std::fmax(tol, 1e-14 * (std::abs(left) + std::abs(right)));
  if (!std::isfinite(delta) || depth >= kSimpsonMaxDepth ||
      (depth >= kSimpsonMinDepth && std::abs(delta) <= bound))
    return left + right + delta / 15.0;
  return simpson_step(f, a, m, fa, flm, fm, left, 0.5 * tol, depth + 1) +
         simpson_step(f, m, b, fm, frm, fb, right, 0.5 * tol, depth + 1);
}
}  // namespace

double adaptive_simpson(const std::function<double(double)>& f, double a, double b, double tol) {
  if (a == b) return 0.0;
  const double fa = f(a), fm = f(0.5 * (a + b)), fb = f(b);
  const double whole = (b - a) / 6.0 * (fa + 4.0 * fm + fb);
  return simpson_step(f, a, b, fa, fm, fb, whole, tol, 0);
}

double integrate_2d(const std::function<double(double, double)>& f, double x0, double x1,
                    double y0, double y1, double tol) {
  if (x0 == x1 || y0 == y1) return 0.0;
  // Half the budget for the outer rule, half for the inner integrals summed over x.
  const double inner_tol = 0.5 * tol / std::abs(x1 - x0);
  const auto inner = [&](double x) {
    return adaptive_simpson([&](double y) { return f(x, y); }, y0, y1, inner_tol);
  };
  return adaptive_simpson(inner, x0, x1, 0.5 * tol);
}

}  // namespace femto::stats
