#include "core/diffusion/tally.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/constants.h"
#include "core/transport/tissue_walk.h"

namespace femto::diffusion {

double Grid::shell_volume(int i) const {
  const double k = i;  // (k + 1)^3 - k^3 = 3 k^2 + 3 k + 1, without cancellation
  return 4.0 / 3.0 * kPi * dr * dr * dr * (3 * k * k + 3 * k + 1);
}

void TallySums::reset(size_t n) {
  sums.assign(2 * n, 0.0);
  photons = segments = 0;
}

void TallySums::add(const TallySums& other) {
  for (size_t i = 0; i < sums.size(); ++i) sums[i] += other.sums[i];
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

// The series below for x < kSmallX as fixed polynomials: c[n][m] = (-1)^m / (m! (n + m + 1)),
// m <= kSmallTerms - 1; the first term left out is below 1e-18 of the sum. Evaluated by Horner,
// with no loop exit that depends on x (weighted absorption puts most bins here).
constexpr double kSmallX = 0.05;
constexpr int kSmallTerms = 9;
struct SmallSeries {
  double c[5][kSmallTerms];
  constexpr SmallSeries() : c() {
    for (int n = 0; n < 5; ++n) {
      double f = 1;  // (-1)^m / m!
      for (int m = 0; m < kSmallTerms; ++m) {
        c[n][m] = f / (n + m + 1);
        f = -f / (m + 1);
      }
    }
  }
};
constexpr SmallSeries kSmall;
}  // namespace

void exp_moments(double k, double h, double J[5]) {
  const double x = k * h;
  if (x == 0) {  // no absorption weighting: plain powers
    double hp = h;
    for (int n = 0; n < 5; ++n, hp *= h) J[n] = hp * kRecip.r[n + 1];
    return;
  }
  if (x < kSmallX) {
    double hp = h;
    for (int n = 0; n < 5; ++n, hp *= h) {
      double sn = kSmall.c[n][kSmallTerms - 1];
      for (int m = kSmallTerms - 2; m >= 0; --m) sn = sn * x + kSmall.c[n][m];
      J[n] = hp * sn;
    }
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

namespace {
// A photon's final value v of one entry: p[0] (the sum) += v, p[1] (the sum of squares) += v^2.
inline void put(double* p, double v) {
  p[0] += v;
  p[1] += v * v;
}

struct BinMoments {
  double energy, r2, r4;  ///< integrals of w, w r^2 and w r^4
};

// The integrals over tau in [a, e] of a segment whose weight is w at a and decays at rate k
// (kWeighted) or stays w, and whose r(tau)^2 = p2 + v2 (tau - tm)^2.
template <bool kWeighted>
inline BinMoments moments(double a, double e, double w, double k, double tm, double p2, double v2) {
  const double h = e - a, u1 = a - tm;
  if (kWeighted) {
    // With sigma = tau - a, r^2 = A + B sigma + C sigma^2 and the weight is w exp(-k sigma):
    // combinations of J_n = int exp(-k sigma) sigma^n.
    double J[5];
    exp_moments(k, h, J);
    const double A = p2 + v2 * u1 * u1, B = 2 * v2 * u1, C = v2;
    return {w * J[0], w * (A * J[0] + B * J[1] + C * J[2]),
            w * (A * A * J[0] + 2 * A * B * J[1] + (B * B + 2 * A * C) * J[2] + 2 * B * C * J[3] +
                 C * C * J[4])};
  }
  // The means of u^2 and u^4 (u = tau - tm) over [u1, u2]: (u2^3 - u1^3) / 3h and
  // (u2^5 - u1^5) / 5h, factored so that nothing cancels when |u| >> h.
  const double u2 = e - tm, x = u1 * u1, y = u2 * u2, xy = u1 * u2;
  const double mu2 = (x + xy + y) * (1.0 / 3), mu4 = (x * x + y * y + xy * (x + y + xy)) * 0.2;
  const double energy = w * h;
  return {energy, energy * (p2 + v2 * mu2), energy * (p2 * p2 + 2 * p2 * v2 * mu2 + v2 * v2 * mu4)};
}
}  // namespace

PhotonTally::PhotonTally(const Grid& grid)
    : grid_(grid),
      layout_{grid.shells, grid.time.bins},
      shell_(static_cast<size_t>(grid.shells) + 1, 0.0) {}

// The current bin's entries are this photon's final values: add them and their squares. Zeros
// are added too (x + 0 = x), which costs less than testing for them.
void PhotonTally::finish_bin(TallySums& into) {
  if (bin_ < 0) return;
  double* p = into.sums.data() + 2 * layout_.slot(Quantity::Energy, bin_);
  for (int q = 0; q < 3; ++q) put(p + 2 * q, q_[q]), q_[q] = 0;  // energy, r^2, r^4
  if (low_order_) {
    for (int q = 3; q < kQuantities; ++q) put(p + 2 * q, q_[q]), q_[q] = 0;
    low_order_ = false;
  }
  double* c = p + 2 * kQuantities;  // the bin's cells follow its quantities
  const int top = std::min(i_hi_, grid_.shells - 1);
  for (int i = i_lo_; i <= top; ++i) {
    double& v = shell_[static_cast<size_t>(i)];
    put(c + 2 * i, v);
    v = 0;
  }
  shell_[static_cast<size_t>(grid_.shells)] = 0;
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

void PhotonTally::add(const Segment& s, TallySums& into) {
  ++segments_;
  const TimeAxis& ax = grid_.time;
  const double lo = std::max(s.t0, ax.t_start_ps), hi = std::min(s.t0 + s.duration, ax.t_end_ps());
  if (!(hi > lo)) return;
  const int j = std::clamp(static_cast<int>(std::floor((lo - ax.t_start_ps) / ax.bin_width_ps)), 0,
                           ax.bins - 1);
  if (s.k == 0)
    sweep<false>(s, lo - s.t0, hi - s.t0, j, into);
  else
    sweep<true>(s, lo - s.t0, hi - s.t0, j, into);
}

// One sweep along the part tau in [tau_lo, tau_hi] (time since the segment start) of a segment,
// bin by bin from bin j, over the times at which it crosses a shell radius; each piece between
// two such times or bin ends adds to one (shell, bin) cell. With the closest approach at tm and
// p its distance, r(tau)^2 = p^2 + v^2 u^2 with u = tau - tm: r falls until tm, then rises, so
// the crossing times of the radii i dr are explicit on each side. kWeighted: the weight decays
// as w0 exp(-k tau) (k > 0); otherwise it is w0 throughout.
// A bin that lies wholly inside the segment, where r is monotonic (most bins, when bins are
// shorter than flights), goes straight to the sums: each of its entries is final. The others
// pass through the current bin's buffers: the bin where the segment starts or ends (other
// segments of the photon add to it) and the one holding the closest approach (the photon may
// leave a shell there and come back).
template <bool kWeighted>
void PhotonTally::sweep(const Segment& s, double tau_lo, double tau_hi, int j, TallySums& into) {
  const TimeAxis& ax = grid_.time;
  const int n = grid_.shells, last = ax.bins - 1;
  const double dr = grid_.dr, v2 = s.v * s.v, inv_v = 1.0 / s.v;
  const double b = dot(s.x0, s.d), tm = -b * inv_v, p2 = std::max(0.0, dot(s.x0, s.x0) - b * b);
  const double u_lo = tau_lo - tm;
  const double i_lo = std::floor(std::sqrt(p2 + v2 * u_lo * u_lo) / dr);
  int i = i_lo >= n ? n : static_cast<int>(i_lo);  // n: beyond the last shell
  bool inward = u_lo < 0;
  // The time of the next shell crossing (inward: into shell i - 1; outward: into i + 1).
  auto next_crossing = [&]() -> double {
    if (inward) {
      const double R = i * dr, d2 = R * R - p2;
      if (i > 0 && d2 > 0) return tm - std::sqrt(d2) * inv_v;
      inward = false;  // the closest approach comes first: the photon turns inside shell i
    }
    if (i >= n) return kInf;
    const double R = (i + 1) * dr;
    return tm + std::sqrt(std::max(0.0, R * R - p2)) * inv_v;
  };
  const double k = s.k, inv_k = kWeighted ? 1 / k : 0.0;
  double w = kWeighted ? s.w0 * std::exp(-k * tau_lo) : s.w0;  // the weight at a
  const bool low = s.scatterings <= 1;
  const int low_q = static_cast<int>(s.scatterings == 0 ? Quantity::Unscattered : Quantity::Single);
  double a = tau_lo, next = next_crossing();
  // The integral of the weight over the piece [a, e]; a moves to e.
  auto piece = [&](double e) {
    double v;
    if (kWeighted) {
      const double m = one_minus_exp(k * (e - a));
      v = w * m * inv_k;
      w -= w * m;
    } else {
      v = w * (e - a);
    }
    a = e;
    return v;
  };
  // Adds [a, e] of the current bin to its buffers.
  double* shell = shell_.data();
  auto buffered = [&](double e) {
    const double a_bin = a, w_bin = w;
    auto to_shell = [&](double e_piece) {
      i_lo_ = std::min(i_lo_, i);
      i_hi_ = std::max(i_hi_, i);
      shell[i] += piece(e_piece);
    };
    while (next < e) {
      to_shell(std::max(next, a));
      i += inward ? -1 : 1;
      next = next_crossing();
    }
    to_shell(e);
    const BinMoments m = moments<kWeighted>(a_bin, e, w_bin, k, tm, p2, v2);
    q_[static_cast<int>(Quantity::Energy)] += m.energy;
    q_[static_cast<int>(Quantity::R2)] += m.r2;
    q_[static_cast<int>(Quantity::R4)] += m.r4;
    if (low) q_[low_q] += m.energy, low_order_ = true;
  };
  // Where bin jj ends (tau), not before a.
  auto bin_end = [&](int jj) {
    return jj == last ? tau_hi : std::max(a, std::min(tau_hi, ax.bin_start_ps(jj + 1) - s.t0));
  };

  if (j != bin_) {
    finish_bin(into);
    bin_ = j;
  }
  double e = bin_end(j);
  buffered(e);
  if (!(e < tau_hi)) return;
  finish_bin(into);  // the photon leaves bin j during this segment
  double* const sums = into.sums.data();
  const size_t stride = layout_.stride();
  while (++j <= last) {
    e = bin_end(j);
    const bool ends_here = !(e < tau_hi);
    // Buffered: a bin where the segment ends (later segments may add to it), or where the photon
    // passes its closest approach (it may leave a shell and come back).
    if (ends_here || (a < tm && tm < e)) {
      bin_ = j;
      buffered(e);
      if (ends_here) return;
      finish_bin(into);
      continue;
    }
    // Bin j lies inside this segment and r is monotonic in it, so no shell is visited twice:
    // every value is final.
    const BinMoments m = moments<kWeighted>(a, e, w, k, tm, p2, v2);
    double* p = sums + 2 * (static_cast<size_t>(j) * stride);
    put(p + 2 * static_cast<int>(Quantity::Energy), m.energy);
    put(p + 2 * static_cast<int>(Quantity::R2), m.r2);
    put(p + 2 * static_cast<int>(Quantity::R4), m.r4);
    if (low) put(p + 2 * low_q, m.energy);
    double* c = p + 2 * kQuantities;  // the bin's cells follow its quantities
    // No crossing: the whole bin in shell i.
    if (!(next < e)) {
      if (i < n) put(c + 2 * i, m.energy);
      if (kWeighted) w -= w * one_minus_exp(k * (e - a));
      a = e;
      continue;
    }
    while (next < e) {
      const double v = piece(std::max(next, a));
      if (i < n) put(c + 2 * i, v);
      i += inward ? -1 : 1;
      next = next_crossing();
    }
    const double v = piece(e);
    if (i < n) put(c + 2 * i, v);
  }
}

}  // namespace femto::diffusion
