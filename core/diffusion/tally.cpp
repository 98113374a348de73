#include "core/diffusion/tally.h"

#include <algorithm>
#include <cmath>

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

void exp_moments(double k, double h, double J[5]) {
  const double x = k * h;
  if (x == 0) {  // no absorption weighting: plain powers
    double hp = h;
    for (int n = 0; n < 5; ++n, hp *= h) J[n] = hp / (n + 1);
    return;
  }
  if (x < 2.0) {  // J_n = h^(n+1) sum_m (-x)^m / (m! (n + m + 1)); no cancellation for x < 2
    double s[5] = {0, 0, 0, 0, 0}, term = 1;
    for (int m = 0; m < 60 && term != 0; ++m) {
      for (int n = 0; n < 5; ++n) s[n] += term / (n + m + 1);
      term *= -x / (m + 1);
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
    : grid_(grid),
      layout_{grid.shells, grid.time.bins},
      value_(layout_.size(), 0.0),
      stamp_(layout_.size(), 0) {}

void PhotonTally::put(size_t i, double x) {
  if (stamp_[i] != photon_) {
    stamp_[i] = photon_;
    value_[i] = 0;
    touched_.push_back(i);
  }
  value_[i] += x;
}

void PhotonTally::end_photon(TallySums& into) {
  for (size_t i : touched_) {
    const double v = value_[i];
    into.sum[i] += v;
    into.sum2[i] += v * v;
  }
  touched_.clear();
  ++photon_;
  into.photons += 1;
  into.segments += segments_;
  segments_ = 0;
}

void PhotonTally::add(const Segment& s) {
  ++segments_;
  const TimeAxis& ax = grid_.time;
  const double lo = std::max(s.t0, ax.t_start_ps), hi = std::min(s.t0 + s.duration, ax.t_end_ps());
  if (!(hi > lo)) return;
  int j = std::clamp(static_cast<int>(std::floor((lo - ax.t_start_ps) / ax.bin_width_ps)), 0,
                     ax.bins - 1);
  for (double t = lo; t < hi && j < ax.bins; ++j) {
    const double te = j == ax.bins - 1 ? hi : std::min(hi, ax.bin_start_ps(j + 1));
    if (te > t) bin_piece(s, j, t - s.t0, te - s.t0);
    t = std::max(t, te);
  }
}

// The part tau in [tau1, tau2] (time since the segment start) of a segment, inside bin j.
void PhotonTally::bin_piece(const Segment& s, int j, double tau1, double tau2) {
  // Per-bin integrals: with sigma = tau - tau1, r^2 = A + B sigma + C sigma^2 and the weight is
  // w1 exp(-k sigma), so each integral is a combination of J_n = int exp(-k sigma) sigma^n.
  double J[5];
  exp_moments(s.k, tau2 - tau1, J);
  const double w1 = s.k == 0 ? s.w0 : s.w0 * std::exp(-s.k * tau1);
  const Vec3 x1 = s.x0 + s.d * (s.v * tau1);
  const double A = dot(x1, x1), B = 2 * s.v * dot(x1, s.d), C = s.v * s.v;
  put(layout_.slot(Quantity::Energy, j), w1 * J[0]);
  put(layout_.slot(Quantity::R2, j), w1 * (A * J[0] + B * J[1] + C * J[2]));
  put(layout_.slot(Quantity::R4, j),
      w1 * (A * A * J[0] + 2 * A * B * J[1] + (B * B + 2 * A * C) * J[2] + 2 * B * C * J[3] +
            C * C * J[4]));
  if (s.scatterings == 0) put(layout_.slot(Quantity::Unscattered, j), w1 * J[0]);
  if (s.scatterings == 1) put(layout_.slot(Quantity::Single, j), w1 * J[0]);

  // Shells: r(tau)^2 = p^2 + v^2 (tau - tm)^2 decreases until the closest approach tm, then
  // increases; on each side the times of crossing the radii i dr are explicit.
  const int n = grid_.shells;
  const double dr = grid_.dr;
  const double b = dot(s.x0, s.d), tm = -b / s.v, p2 = std::max(0.0, dot(s.x0, s.x0) - b * b);
  auto radius = [&](double tau) {
    const double q = s.v * (tau - tm);
    return std::sqrt(p2 + q * q);
  };
  auto shell_of = [&](double r) {
    const double i = std::floor(r / dr);
    return i >= n ? n : static_cast<int>(i);
  };
  auto crossing = [&](int i, double side) {
    const double R = i * dr;
    return tm + side * std::sqrt(std::max(0.0, R * R - p2)) / s.v;
  };
  auto cell = [&](int i, double a, double e) {
    if (i < n && e > a) put(layout_.cell(i, j), s.w0 * exp_integral(s.k, a, e));
  };
  if (tau1 < tm) {  // inward: from shell of r(tau1) down to shell of r(te)
    const double te = std::min(tau2, tm);
    int i = shell_of(radius(tau1));
    const int last = shell_of(radius(te));
    double t = tau1;
    for (; i > last; --i) {
      const double tc = std::clamp(crossing(i, -1.0), t, te);
      cell(i, t, tc);
      t = tc;
    }
    cell(last, t, te);
  }
  if (tau2 > tm) {  // outward: from shell of r(ts) up to shell of r(tau2), stopping at r_max
    const double ts = std::max(tau1, tm);
    int i = shell_of(radius(ts));
    const int last = shell_of(radius(tau2));
    double t = ts;
    for (; i < last && i < n; ++i) {
      const double tc = std::clamp(crossing(i + 1, 1.0), t, tau2);
      cell(i, t, tc);
      t = tc;
    }
    if (i == last) cell(last, t, tau2);
  }
}

}  // namespace femto::diffusion
