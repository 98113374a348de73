#include "core/tissue/pulse.h"

#include <algorithm>
#include <cmath>

#include "core/constants.h"
#include "core/diffusion/analysis.h"

namespace femto::tissue {

namespace {
struct Shape {
  bool defined = false;
  double mean = 0, rms = 0, peak = 0, gauss = 0;
  int peak_gate = 0;
};

// Gate masses of a Gaussian pulse (mean, rms width sigma) over the axis; a pulse narrower than a
// millionth of a gate is all in the gate holding its mean.
std::vector<double> gaussian_gates(const TimeAxis& axis, double mean, double sigma) {
  std::vector<double> q(static_cast<size_t>(axis.bins), 0.0);
  if (!(sigma > 1e-6 * axis.bin_width_ps)) {
    const double u = std::floor((mean - axis.t_start_ps) / axis.bin_width_ps);
    if (u >= 0 && u < axis.bins) q[static_cast<size_t>(u)] = 1;
    return q;
  }
  const double k = 1 / (sigma * std::sqrt(2.0));
  for (int j = 0; j < axis.bins; ++j)
    q[static_cast<size_t>(j)] = 0.5 * (std::erf((axis.bin_start_ps(j + 1) - mean) * k) -
                                       std::erf((axis.bin_start_ps(j) - mean) * k));
  return q;
}

Shape shape_of(const TimeAxis& axis, const std::vector<double>& h) {
  Shape s;
  double w = 0, m1 = 0, m2 = 0;
  for (size_t j = 0; j < h.size(); ++j) {
    const double t = axis.bin_center_ps(static_cast<int>(j));
    w += h[j], m1 += h[j] * t, m2 += h[j] * t * t;
  }
  if (!(w > 0)) return s;
  s.defined = true;
  s.mean = m1 / w;
  const double bw = axis.bin_width_ps;
  s.rms = std::sqrt(std::max(0.0, m2 / w - s.mean * s.mean - bw * bw / 12));
  const size_t j = static_cast<size_t>(std::max_element(h.begin(), h.end()) - h.begin());
  s.peak_gate = static_cast<int>(j);
  s.peak = axis.bin_center_ps(static_cast<int>(j));
  if (j > 0 && j + 1 < h.size()) {
    const double a = h[j - 1], b = h[j], c = h[j + 1], den = a - 2 * b + c;
    if (den < 0) s.peak += 0.5 * bw * std::clamp((a - c) / den, -1.0, 1.0);
  }
  s.gauss = diffusion::tv_distance(h, gaussian_gates(axis, s.mean, s.rms));
  return s;
}
}  // namespace

PulseStats pulse_stats(const TimeAxis& axis, const std::vector<std::vector<double>>& batches) {
  PulseStats out;
  const size_t B = batches.size(), T = static_cast<size_t>(axis.bins);
  if (B == 0) return out;
  std::vector<double> all(T, 0.0);
  for (const auto& b : batches)
    for (size_t j = 0; j < T; ++j) all[j] += b[j];
  const Shape full = shape_of(axis, all);
  if (!full.defined) return out;
  out.defined = true;
  out.mean.value = full.mean, out.rms.value = full.rms, out.peak.value = full.peak;
  out.gaussian_distance.value = full.gauss;
  // Jackknife: leave one batch out.
  std::vector<Shape> rep;
  std::vector<double> rest(T);
  for (size_t b = 0; b < B && B > 1; ++b) {
    for (size_t j = 0; j < T; ++j) rest[j] = all[j] - batches[b][j];
    rep.push_back(shape_of(axis, rest));
  }
  const double q = diffusion::student_t95(static_cast<int>(B) - 1);
  auto finish = [&](PulseStat& st, double Shape::*field) {
    if (rep.size() < 2) {
      st.se = NAN, st.ci_lo = st.ci_hi = NAN;
      return;
    }
    double mean = 0;
    for (const Shape& r : rep) mean += r.*field;
    mean /= static_cast<double>(rep.size());
    double ss = 0;
    for (const Shape& r : rep) ss += (r.*field - mean) * (r.*field - mean);
    const double n = static_cast<double>(rep.size());
    st.se = std::sqrt((n - 1) / n * ss);
    st.ci_lo = st.value - q * st.se, st.ci_hi = st.value + q * st.se;
  };
  finish(out.mean, &Shape::mean);
  finish(out.rms, &Shape::rms);
  finish(out.peak, &Shape::peak);
  finish(out.gaussian_distance, &Shape::gauss);
  // Noise: the batch spread of the gate sums around the peak.
  const size_t j = static_cast<size_t>(full.peak_gate);
  auto gate_se = [&](size_t g) {
    double m = all[g] / static_cast<double>(B), ss = 0;
    for (const auto& b : batches) ss += (b[g] - m) * (b[g] - m);
    return B > 1 ? std::sqrt(ss / (static_cast<double>(B) - 1)) * std::sqrt(static_cast<double>(B))
                 : 0.0;
  };
  // The floor: E|N(0, se^2)| = se sqrt(2 / pi) per gate, halved as the distance is, over the
  // TPSF's total.
  double noise = 0, total = 0;
  for (size_t g = 0; g < T; ++g) noise += gate_se(g), total += all[g];
  out.gaussian_noise = 0.5 * std::sqrt(2 / kPi) * noise / total;
  out.gaussian_noise_limited = B < 2 || out.gaussian_noise >= 0.5 * out.gaussian_distance.value;
  const double neighbour = std::max(j > 0 ? all[j - 1] : 0.0, j + 1 < T ? all[j + 1] : 0.0);
  const double se_diff = std::hypot(gate_se(j), j > 0 && (j + 1 >= T || all[j - 1] >= all[j + 1])
                                                    ? gate_se(j - 1)
                                                    : (j + 1 < T ? gate_se(j + 1) : 0.0));
  // Decided by noise: the peak gate does not stand out from its larger neighbour by 2 standard
  // errors, or the replicates move the peak by more than a gate.
  out.peak_noise_limited =
      B < 2 || all[j] - neighbour < 2 * se_diff || !(q * out.peak.se <= axis.bin_width_ps);
  out.width_noise_limited = B < 2 || !(std::max(out.mean.se, out.rms.se) <= 0.1 * out.rms.value);
  return out;
}

}  // namespace femto::tissue
