#pragma once
// The error measures of femto-bench-caustics (bench/bench_caustics.cpp): references as means of
// independent films, relative RMSE over a crop, sums over blocks of pixels and bins.
#include <algorithm>
#include <cmath>
#include <vector>

#include "core/film.h"

namespace femto::bench {

/// Median, the mean of the middle two for an even count (bench::median takes the upper one; the
/// figures in docs/PERFORMANCE.md were made with this one).
inline double median_of(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

struct Errors {
  double steady = 0, transient = 0;  ///< relative RMSE: RMSE over the crop / mean of the reference
};

/// A reference as the mean of two independent films (their difference bounds its own error).
struct Reference {
  std::vector<double> steady, transient;
  int bins = 0;
  Errors own;  ///< its own relative RMSE, from its two halves (default mode)
};

inline Reference mean_of(const TransientFilm& a, const TransientFilm& b) {
  Reference r;
  r.bins = a.bins();
  const size_t ns = static_cast<size_t>(a.width()) * static_cast<size_t>(a.height()) * 3;
  const size_t nt = ns * static_cast<size_t>(a.bins());
  for (size_t i = 0; i < ns; ++i)
    r.steady.push_back(0.5 * (static_cast<double>(a.steady()[i]) + b.steady()[i]));
  for (size_t i = 0; i < nt; ++i)
    r.transient.push_back(0.5 * (static_cast<double>(a.transient()[i]) + b.transient()[i]));
  return r;
}

/// Relative errors of a film (float) or a block sum (double) against ref.
template <class V>
inline Errors errors(const V* steady, const V* transient, const Reference& ref,
                     const std::vector<int>& px, double scale = 1.0) {
  const int T = ref.bins;
  double se_s = 0, se_t = 0, m_s = 0, m_t = 0;
  for (int p : px)
    for (int c = 0; c < 3; ++c) {
      const size_t i = static_cast<size_t>(p) * 3 + static_cast<size_t>(c);
      const double d = scale * steady[i] - ref.steady[i];
      se_s += d * d;
      m_s += ref.steady[i];
      for (int t = 0; t < T; ++t) {
        const size_t k =
            (static_cast<size_t>(p) * static_cast<size_t>(T) + static_cast<size_t>(t)) * 3 +
            static_cast<size_t>(c);
        const double e = scale * transient[k] - ref.transient[k];
        se_t += e * e;
        m_t += ref.transient[k];
      }
    }
  const double n = 3.0 * static_cast<double>(px.size());
  return {std::sqrt(se_s / n) / (m_s / n), std::sqrt(se_t / (n * T)) / (m_t / (n * T))};
}

/// Sums of a film (or reference) over blocks of B x B pixels and G bins, channels kept: the
/// tissue example's light is a small bright spot and a dim glow, and a per-pixel, per-bin
/// reference would need hours; the blocks are what is compared there.
inline Reference blocks(const std::vector<double>& steady, const std::vector<double>& transient,
                        int W, int H, int T, int B, int G) {
  const int bw = (W + B - 1) / B, bh = (H + B - 1) / B, bt = (T + G - 1) / G;
  Reference r;
  r.bins = bt;
  r.steady.assign(static_cast<size_t>(bw * bh) * 3, 0.0);
  r.transient.assign(static_cast<size_t>(bw * bh * bt) * 3, 0.0);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const size_t p = static_cast<size_t>(y) * static_cast<size_t>(W) + static_cast<size_t>(x);
      const size_t q = static_cast<size_t>((y / B) * bw + x / B);
      for (int c = 0; c < 3; ++c) {
        r.steady[q * 3 + static_cast<size_t>(c)] += steady[p * 3 + static_cast<size_t>(c)];
        for (int t = 0; t < T; ++t)
          r.transient[(q * static_cast<size_t>(bt) + static_cast<size_t>(t / G)) * 3 +
                      static_cast<size_t>(c)] +=
              transient[(p * static_cast<size_t>(T) + static_cast<size_t>(t)) * 3 +
                        static_cast<size_t>(c)];
      }
    }
  return r;
}

inline Reference blocks(const TransientFilm& f, int B, int G) {
  const size_t ns = static_cast<size_t>(f.width()) * static_cast<size_t>(f.height()) * 3;
  const std::vector<double> s(f.steady(), f.steady() + ns);
  const std::vector<double> t(f.transient(), f.transient() + ns * static_cast<size_t>(f.bins()));
  return blocks(s, t, f.width(), f.height(), f.bins(), B, G);
}

/// The mean of two references of the same layout.
inline Reference average(const Reference& a, const Reference& b) {
  Reference r = a;
  for (size_t i = 0; i < r.steady.size(); ++i) r.steady[i] = 0.5 * (a.steady[i] + b.steady[i]);
  for (size_t i = 0; i < r.transient.size(); ++i)
    r.transient[i] = 0.5 * (a.transient[i] + b.transient[i]);
  return r;
}

}  // namespace femto::bench
