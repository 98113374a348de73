#include "core/diffusion/tally.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/constants.h"

namespace femto::diffusion {

double Grid::shell_volume(int i) const {
  const double k = i;  // (k + 1)^3 - k^3 = 3 k^2 + 3 k + 1, without cancellation
  return 4.0 / 3.0 * kPi * dr * dr * dr * (3 * k * k + 3 * k + 1);
}

void TallySums::reset(size_t n) {
  sum.assign(n, 0.0);
  sum2.assign(n, 0.0);
  photons = segments = 0;
}

void TallySums::add(const TallySums& other) {
  for (size_t i = 0; i < sum.size(); ++i) sum[i] += other.sum[i];
  for (size_t i = 0; i < sum2.size(); ++i) sum2[i] += other.sum2[i];
  photons += other.photons;
  segments += other.segments;
}

namespace {
// 1 / q for q = 0..kTerms + 5: the series below multiplies instead of dividing.
constexpr int kTerms = 60;
struct Reciprocals {
  double r[kTerms + 6];
  constexpr Reciprocals() : r() {
    for (int q = 1; q < kTerms + 6; ++q) r[q] = 1.0 / q;
  }
};
constexpr Reciprocals kRecip;
}  // namespace

void exp_moments(double k, double h, double J[5]) {
  const double x = k * h;
  if (x == 0) {  // no absorption weighting: plain powers
    double hp = h;
    for (int n = 0; n < 5; ++n, hp *= h) J[n] = hp * kRecip.r[n + 1];
    return;
  }
  if (x < 2.0) {  // J_n = h^(n+1) sum_m (-x)^m / (m! (n + m + 1)); no cancellation for x < 2
    double s[5] = {0, 0, 0, 0, 0}, term = 1;
    for (int m = 0; m < kTerms && term != 0; ++m) {
      for (int n = 0; n < 5; ++n) s[n] += term * kRecip.r[n + m + 1];
      term *= -x * kRecip.r[m + 1];
      if (std::abs(term) < 1e-17) break;
    }
    double hp = h;
    for (int n = 0; n < 5; ++n, hp *= h) J[n] = hp * s[n];
    return;
  }
  // J_n = (n J_{n-1} - h^n e^{-x}) / k: each step multiplies errors by n / x < 2.
  const double e = std::exp(-x);
  J[0] = -std::expm1(-x) / k;
  double hn = 1;
  for (int n = 1; n < 5; ++n) {
    hn *= h;
    J[n] = (n * J[n - 1] - hn * e) / k;
  }
}

PhotonTally::PhotonTally(const Grid& grid)
    : grid_(grid), layout_{grid.shells, grid.time.bins}, shell_(static_cast<size_t>(grid.shells), 0.0) {}

void PhotonTally::enter_bin(int j, TallySums& into) {
  if (j == bin_) return;
  finish_bin(into);
  bin_ = j;
}

// The current bin's entries are this photon's final values: add them and their squares.
void PhotonTally::finish_bin(TallySums& into) {
  if (bin_ < 0) return;
  auto flush = [&](size_t i, double& v) {
    into.sum[i] += v;
    into.sum2[i] += v * v;
    v = 0;
  };
  for (int q = 0; q < kQuantities; ++q)
    if (q_[q] != 0) flush(layout_.slot(static_cast<Quantity>(q), bin_), q_[q]);
  for (int i = i_lo_; i <= i_hi_; ++i)
    if (shell_[static_cast<size_t>(i)] != 0) flush(layout_.cell(i, bin_), shell_[static_cast<size_t>(i)]);
  i_lo_ = std::numeric_limits<int>::max();
  i_hi_ = -1;
  bin_ = -1;
}

void PhotonTally::end_photon(TallySums& into) {
  finish_bin(into);
  into.photons += 1;
  into.segments += segments_;
  segments_ = 0;
}

double PhotonTally::bin_end(int j, double hi) const {
  const TimeAxis& ax = grid_.time;
  return j == ax.bins - 1 ? hi : std::min(hi, ax.bin_start_ps(j + 1));
}

// The per-bin integrals of the part tau in [tau1, tau2] (time since the segment start) of a
// segment, inside the current bin.
void PhotonTally::bin_moments(const Segment& s, double tau1, double tau2) {
  // With sigma = tau - tau1, r^2 = A + B sigma + C sigma^2 and the weight is w1 exp(-k sigma),
  // so each integral is a combination of J_n = int exp(-k sigma) sigma^n.
  double J[5];
  const double h = tau2 - tau1;
  if (s.k == 0) {  // unweighted (analog absorption): plain powers, without a call
    const double h2 = h * h, h3 = h2 * h;
    J[0] = h, J[1] = 0.5 * h2, J[2] = h3 * (1.0 / 3), J[3] = 0.25 * h3 * h, J[4] = 0.2 * h3 * h2;
  } else {
    exp_moments(s.k, h, J);
  }
  const double w1 = s.k == 0 ? s.w0 : s.w0 * std::exp(-s.k * tau1);
  const Vec3 x1 = s.x0 + s.d * (s.v * tau1);
  const double A = dot(x1, x1), B = 2 * s.v * dot(x1, s.d), C = s.v * s.v;
  const double energy = w1 * J[0];
  q_[static_cast<int>(Quantity::Energy)] += energy;
  q_[static_cast<int>(Quantity::R2)] += w1 * (A * J[0] + B * J[1] + C * J[2]);
  q_[static_cast<int>(Quantity::R4)] +=
      w1 * (A * A * J[0] + 2 * A * B * J[1] + (B * B + 2 * A * C) * J[2] + 2 * B * C * J[3] +
            C * C * J[4]);
  if (s.scatterings == 0) q_[static_cast<int>(Quantity::Unscattered)] += energy;
  if (s.scatterings == 1) q_[static_cast<int>(Quantity::Single)] += energy;
}

// One sweep along the segment over the times at which it crosses a bin boundary or a shell
// radius, in order; each piece between two such times adds to one (shell, bin) cell.
// r(tau)^2 = p^2 + v^2 (tau - tm)^2 falls until the closest approach tm, then rises, so the
// crossing times of the radii i dr are explicit on each side.
void PhotonTally::add(const Segment& s, TallySums& into) {
  ++segments_;
  const TimeAxis& ax = grid_.time;
  const double lo = std::max(s.t0, ax.t_start_ps), hi = std::min(s.t0 + s.duration, ax.t_end_ps());
  if (!(hi > lo)) return;
  int j = std::clamp(static_cast<int>(std::floor((lo - ax.t_start_ps) / ax.bin_width_ps)), 0,
                     ax.bins - 1);
  const int n = grid_.shells;
  const double dr = grid_.dr, inv_v = 1.0 / s.v;
  const double b = dot(s.x0, s.d), tm = -b * inv_v, p2 = std::max(0.0, dot(s.x0, s.x0) - b * b);
  const double tau_lo = lo - s.t0, tau_hi = hi - s.t0;
  const double r_lo = std::sqrt(p2 + s.v * s.v * (tau_lo - tm) * (tau_lo - tm));
  const double i_lo = std::floor(r_lo / dr);
  int i = i_lo >= n ? n : static_cast<int>(i_lo);
  bool inward = tau_lo < tm;
  double a = tau_lo;
  double E = s.k == 0 ? 1.0 : std::exp(-s.k * tau_lo);  // exp(-k a): weight at a vs the start
  for (; j < ax.bins && a < tau_hi; ++j) {
    enter_bin(j, into);
    const double a_bin = a, e_bin = bin_end(j, hi) - s.t0;
    if (e_bin > a_bin) bin_moments(s, a_bin, e_bin);
    while (a < e_bin && (inward || i < n)) {
      double ts;  // the next shell event: a crossing, or the turn at tm
      bool turn = false;
      if (inward) {
        const double R = i * dr;
        turn = !(i > 0 && R * R > p2);
        ts = turn ? tm : tm - std::sqrt(R * R - p2) * inv_v;
      } else {
        const double R = (i + 1) * dr;
        ts = tm + std::sqrt(std::max(0.0, R * R - p2)) * inv_v;
      }
      ts = std::max(ts, a);
      const double e = std::min(ts, e_bin);
      if (e > a) {
        if (s.k == 0) {
          if (i < n) put_cell(i, s.w0 * (e - a));
        } else {
          const double m = std::expm1(-s.k * (e - a));
          if (i < n) put_cell(i, s.w0 * E * -m / s.k);
          E *= 1 + m;
        }
        a = e;
      }
      if (ts > e_bin) break;  // the bin ends first
      if (!inward)
        ++i;
      else if (turn)
        inward = false;
      else
        --i;
    }
    a = std::max(a, e_bin);
  }
}

}  // namespace femto::diffusion
