#pragma once
// Analytic references for a pulsed isotropic point source at t = 0 in an infinite homogeneous
// medium: scales, the exact <r^2>(t) of the persistent random walk, the diffusion Green's
// function and Paasschens' (1997) approximate transport solution, as radial shell masses.
// Absorption factors out exactly (u = exp(-sigma_a v t) u_0), so models are written for u_0
// and multiplied by the survival where needed.
#include <vector>

#include "core/diffusion/tally.h"
#include "media/homogeneous.h"

namespace femto::diffusion {

/// Scales derived from the medium coefficients.
struct Scales {
  double v;         ///< speed c / eta, mm/ps
  double sigma_t;   ///< sigma_a + sigma_s, 1/mm
  double sigma_tr;  ///< transport coefficient sigma_a + sigma_s (1 - g), 1/mm
  double a;         ///< sigma_s (1 - g) v: rate at which direction memory decays, 1/ps
  double D;  ///< diffusion coefficient v / (3 sigma_s (1 - g)), mm^2/ps (inf if no scattering)
  double mean_free_time;  ///< 1 / (sigma_t v), ps
  double ell_star;        ///< 1 / (sigma_s (1 - g)): Paasschens' mean free path for g != 0, mm
};
Scales scales_of(const HomogeneousMedium& m);

/// Integral of the survival exp(-sigma_a v t) over [t0, t1] (ps): the expected energy-time.
double survival_integral(const HomogeneousMedium& m, double t0, double t1);

/// Exact <r^2>(t) of a persistent random walk at speed v whose velocity correlation decays at
/// rate a: 2 v^2 (t / a - (1 - exp(-a t)) / a^2); v^2 t^2 when a = 0. mm^2.
double prw_r2(double v, double a, double t);

/// Diffusion Green's function without absorption, (4 pi D t)^(-3/2) exp(-r^2 / (4 D t)), 1/mm^3.
double diffusion_green(double D, double r, double t);

/// Paasschens' 3-D interpolation formula without absorption (isotropic scattering, mean free
/// path ell): the density inside the sphere r < v t, 1/mm^3 (its unscattered part, weight
/// exp(-v t / ell) on the sphere r = v t, is separate).
double paasschens_density(double v, double ell, double r, double t);

/// Energy fraction within radius R of a centred 3-D Gaussian of per-axis variance s2.
double gaussian_radial_cdf(double R, double s2);

/// Shell masses of a Gaussian of per-axis variance s2 on the grid's shells, plus a last entry
/// for everything beyond r_max (sums to 1).
std::vector<double> gaussian_shell_masses(const Grid& grid, double s2);

/// Model masses per shell (plus beyond r_max as the last entry), averaged over time bin j and
/// including absorption: (1 / dt) int_bin S(t) m_i(t) dt, i.e. the model's bin-averaged energy
/// in each shell per unit emitted energy.
std::vector<double> diffusion_bin_masses(const Grid& grid, int bin, const HomogeneousMedium& m);
/// Paasschens with ell = 1 / (sigma_s (1 - g)) (exact formula only for g = 0); the unscattered
/// shell is integrated exactly over the bin.
std::vector<double> paasschens_bin_masses(const Grid& grid, int bin, const HomogeneousMedium& m);

/// Gauss–Legendre nodes and weights on [-1, 1].
struct Quadrature {
  std::vector<double> x, w;
};
const Quadrature& gauss_legendre(int n);

/// Integral of f over [a, b] with n-point Gauss–Legendre.
template <typename F>
double integrate_gl(F&& f, double a, double b, int n) {
  const Quadrature& q = gauss_legendre(n);
  const double mid = 0.5 * (a + b), half = 0.5 * (b - a);
  double s = 0;
  for (size_t i = 0; i < q.x.size(); ++i) s += q.w[i] * f(mid + half * q.x[i]);
  return s * half;
}

}  // namespace femto::diffusion
