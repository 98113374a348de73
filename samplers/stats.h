#pragma once
// Goodness-of-fit statistics and quadrature used to validate the samplers (see tests/).
#include <cstddef>
#include <functional>
#include <vector>

namespace femto::stats {

/// Upper regularized incomplete gamma function Q(a, x) = Gamma(a, x) / Gamma(a), for a > 0 and
/// x >= 0 (Q(a, 0) = 1, Q(a, inf) = 0). Uses the power series of P = 1 - Q when x < a + 1 and a
/// Lentz continued fraction for Q otherwise; relative accuracy ~1e-12 or better.
/// Throws std::invalid_argument when a <= 0, x < 0 or either is NaN.
double regularized_gamma_q(double a, double x);

/// Probability that a chi-square variable with `dof` degrees of freedom exceeds `chi2`
/// (the p-value of a chi-square test): Q(dof / 2, chi2 / 2). Requires dof > 0.
double chi2_survival(double chi2, double dof);

struct Chi2Result {
  double chi2;       ///< Pearson statistic sum (O - E)^2 / E over the cells actually used
  int dof;           ///< cells_used - 1
  double p_value;    ///< chi2_survival(chi2, dof); 0 if a cell with E == 0 was observed
  int cells_used;    ///< cells in the statistic, a pooled group counting as one
  int cells_pooled;  ///< original cells merged into the pooled group
};

/// Pearson chi-square goodness-of-fit test of histogram `observed` against `expected` counts
/// (both in samples; `expected` must sum to the number of samples, so add an overflow cell for
/// mass outside the histogram). As in Mitsuba's chi2 test, cells are visited in increasing order
/// of expected count; those with expected < min_expected are merged into one pool, topped up with
/// the next smallest cells until the pool's expected count reaches min_expected; the pool then
/// counts as one cell. Cells with expected == 0 and observed == 0 are ignored; an observation in
/// a cell with expected == 0 gives chi2 = inf and p = 0. dof = cells_used - 1: the only fitted
/// constraint is the total count, since `expected` is fully specified by the pdf.
/// Throws std::invalid_argument if the sizes differ, a count is negative or not finite, or fewer
/// than two usable cells remain.
Chi2Result chi2_test(const std::vector<double>& observed, const std::vector<double>& expected,
                     double min_expected = 5.0);

/// One-sample Kolmogorov–Smirnov statistic D = sup |F_n(x) - F(x)| of `samples` against U(a, b).
/// Throws std::invalid_argument if samples is empty or b <= a.
double ks_statistic_uniform(std::vector<double> samples, double a, double b);

/// Asymptotic p-value P(D_n > D) from the Kolmogorov distribution, evaluated at
/// lambda = (sqrt(n) + 0.12 + 0.11 / sqrt(n)) D (Stephens' small-n correction).
double ks_p_value(double D, std::size_t n);

/// Integral of f over [a, b] by adaptive Simpson quadrature with absolute tolerance `tol`
/// (Richardson-corrected). Always subdivides at least 4 levels (16 panels), which makes missing
/// a narrow interior feature less likely but not impossible: put known peaks at an endpoint or
/// split the interval there. At most 50 levels; refinement also stops once the difference is at
/// rounding level (1e-14 relative), so a tolerance below machine precision is harmless.
double adaptive_simpson(const std::function<double(double)>& f, double a, double b, double tol);

/// Integral of f(x, y) over [x0, x1] x [y0, y1] by nested adaptive Simpson (outer in x, inner in
/// y), with absolute tolerance `tol` for the whole rectangle.
double integrate_2d(const std::function<double(double, double)>& f, double x0, double x1,
                    double y0, double y1, double tol);

}  // namespace femto::stats
