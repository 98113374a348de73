#include "core/diffusion/models.h"

#include <cmath>
#include <limits>
#include <stdexcept>

#include "core/constants.h"

namespace femto::diffusion {

namespace {

Quadrature make_gauss_legendre(int n) {
  Quadrature q;
  for (int i = 0; i < n; ++i) {
    double x = std::cos(kPi * (i + 0.75) / (n + 0.5)), dp = 1;
    for (int it = 0; it < 100; ++it) {
      double p0 = 1, p1 = x;  // Legendre recurrence: p1 = P_n(x), p0 = P_{n-1}(x) at the end
      for (int k = 2; k <= n; ++k) {
        const double p2 = ((2 * k - 1) * x * p1 - (k - 1) * p0) / k;
        p0 = p1, p1 = p2;
      }
      dp = n * (x * p1 - p0) / (x * x - 1);
      const double dx = p1 / dp;
      x -= dx;
      if (std::abs(dx) < 1e-15) break;
    }
    q.x.push_back(x);
    q.w.push_back(2 / ((1 - x * x) * dp * dp));
  }
  return q;
}
}  // namespace

const Quadrature& gauss_legendre(int n) {
  static const Quadrature q8 = make_gauss_legendre(8), q16 = make_gauss_legendre(16);
  if (n == 8) return q8;
  if (n == 16) return q16;
  throw std::invalid_argument("gauss_legendre: only 8 and 16 points are tabulated");
}

Scales scales_of(const HomogeneousMedium& m) {
  Scales s{};
  s.v = kSpeedOfLight / m.eta;
  s.sigma_t = m.sigma_t();
  const double reduced = m.sigma_s * (1 - m.g);
  s.sigma_tr = m.sigma_a + reduced;
  s.a = reduced * s.v;
  s.D = reduced > 0 ? s.v / (3 * reduced) : kInf;
  s.mean_free_time = s.sigma_t > 0 ? 1 / (s.sigma_t * s.v) : kInf;
  s.ell_star = reduced > 0 ? 1 / reduced : kInf;
  return s;
}

double survival_integral(const HomogeneousMedium& m, double t0, double t1) {
  return exp_integral(m.sigma_a * kSpeedOfLight / m.eta, t0, t1);
}

double prw_r2(double v, double a, double t) {
  const double x = a * t;
  if (x < 1e-4) return v * v * t * t * (1 - x / 3 + x * x / 12);  // series: no cancellation
  return 2 * v * v * (x + std::expm1(-x)) / (a * a);
}

double diffusion_green(double D, double r, double t) {
  return std::pow(4 * kPi * D * t, -1.5) * std::exp(-r * r / (4 * D * t));
}

double paasschens_density(double v, double ell, double r, double t) {
  const double T = v * t / ell, rho = r / (v * t);
  if (!(rho < 1) || !(T > 0)) return 0;
  const double q = 1 - rho * rho, x = T * std::pow(q, 0.75);
  // (4 pi ell v t / 3)^(-3/2) e^(-T) G(x) with G(x) = e^x sqrt(1 + 2.026 / x); exponents combined.
  return std::pow(q, 0.125) * std::pow(4 * kPi * ell * v * t / 3, -1.5) * std::exp(x - T) *
         std::sqrt(1 + 2.026 / x);
}

double gaussian_radial_cdf(double R, double s2) {
  if (!(R > 0)) return 0;
  if (!(s2 > 0)) return 1;
  const double z = R / std::sqrt(2 * s2);
  if (z < 0.05)
    return 4 / (3 * std::sqrt(kPi)) * z * z * z * (1 - 0.6 * z * z + 3.0 / 14 * z * z * z * z);
  return std::erf(z) - 2 / std::sqrt(kPi) * z * std::exp(-z * z);
}

std::vector<double> gaussian_shell_masses(const Grid& grid, double s2) {
  std::vector<double> m(static_cast<size_t>(grid.shells) + 1);
  double below = 0;
  for (int i = 0; i < grid.shells; ++i) {
    const double F = gaussian_radial_cdf((i + 1) * grid.dr, s2);
    m[static_cast<size_t>(i)] = F - below;
    below = F;
  }
  m.back() = 1 - below;
  return m;
}

std::vector<double> diffusion_bin_masses(const Grid& grid, int bin, const HomogeneousMedium& med) {
  const Scales sc = scales_of(med);
  std::vector<double> out(static_cast<size_t>(grid.shells) + 1, 0.0);
  if (!std::isfinite(sc.D)) return std::vector<double>(out.size(), NAN);
  const double t0 = grid.time.bin_start_ps(bin), t1 = t0 + grid.time.bin_width_ps;
  const Quadrature& q = gauss_legendre(8);
  for (size_t k = 0; k < q.x.size(); ++k) {
    const double t = 0.5 * (t0 + t1) + 0.5 * (t1 - t0) * q.x[k];
    if (!(t > 0)) continue;
    const double f = 0.5 * q.w[k] * std::exp(-med.sigma_a * sc.v * t);  // weight of the bin average
    const std::vector<double> m = gaussian_shell_masses(grid, 2 * sc.D * t);
    for (size_t i = 0; i < out.size(); ++i) out[i] += f * m[i];
  }
  return out;
}

namespace {
// Mass of Paasschens' continuous part between rho0 = r0 / (v t) and rho1 (<= 1) at T = v t / ell,
// with rho = 1 - s^4: this removes the (1 - rho)^(-1/4) singularity at the front.
double paasschens_mass(double T, double rho0, double rho1, int panels) {
  if (!(rho1 > rho0)) return 0;
  const double norm = std::pow(T * 3 / (4 * kPi), 1.5);
  auto f = [&](double s) {
    const double s4 = s * s * s * s, rho = 1 - s4, q = s4 * (2 - s4), x = T * std::pow(q, 0.75);
    if (!(x > 0)) return 0.0;
    return 4 * kPi * rho * rho * std::pow(q, 0.125) * norm * std::exp(x - T) *
           std::sqrt(1 + 2.026 / x) * 4 * s * s * s;
  };
  const double s_lo = std::pow(1 - rho1, 0.25), s_hi = std::pow(1 - rho0, 0.25);
  double sum = 0;
  for (int p = 0; p < panels; ++p)
    sum += integrate_gl(f, s_lo + (s_hi - s_lo) * p / panels,
                        s_lo + (s_hi - s_lo) * (p + 1) / panels, 16);
  return sum;
}
}  // namespace

std::vector<double> paasschens_bin_masses(const Grid& grid, int bin, const HomogeneousMedium& med) {
  const Scales sc = scales_of(med);
  const double ell = sc.ell_star, v = sc.v;
  const size_t n = static_cast<size_t>(grid.shells);
  std::vector<double> out(n + 1, 0.0);
  const double t0 = grid.time.bin_start_ps(bin), t1 = t0 + grid.time.bin_width_ps, dt = t1 - t0;
  // Unscattered shell r = v t with weight exp(-v t / ell) exp(-sigma_a v t): exact over the bin.
  const double k_ball = v * (med.sigma_a + (std::isfinite(ell) ? 1 / ell : 0.0));
  for (size_t i = 0; i <= n; ++i) {
    const double ta = std::max(t0, static_cast<double>(i) * grid.dr / v);
    const double tb = i < n ? std::min(t1, static_cast<double>(i + 1) * grid.dr / v) : t1;
    if (tb > ta) out[i] += exp_integral(k_ball, ta, tb) / dt;
  }
  if (!std::isfinite(ell)) return out;
  const Quadrature& q = gauss_legendre(8);
  for (size_t k = 0; k < q.x.size(); ++k) {
    const double t = 0.5 * (t0 + t1) + 0.5 * dt * q.x[k];
    if (!(t > 0)) continue;
    const double f = 0.5 * q.w[k] * std::exp(-med.sigma_a * v * t), T = v * t / ell, front = v * t;
    for (size_t i = 0; i < n && static_cast<double>(i) * grid.dr < front; ++i)
      out[i] += f * paasschens_mass(T, static_cast<double>(i) * grid.dr / front,
                                    std::min(1.0, static_cast<double>(i + 1) * grid.dr / front), 1);
    out[n] += f * paasschens_mass(T, std::min(1.0, grid.r_max() / front), 1.0, 16);
  }
  return out;
}

}  // namespace femto::diffusion
