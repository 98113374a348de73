// The kernel film (progressive kernel density estimation in time): deposits, the k-nearest-
// arrival bandwidth, agreement with its exact expectation, consistency, and its error against the
// histogram on single scattering, whose time-resolved answer is a 1-D integral.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

#include "core/pixel_accumulator.h"
#include "core/reconstruction.h"
#include "core/rng.h"
#include "core/temporal_filter.h"
#include "scene_builders.h"
#include "single_scatter.h"

using namespace femto;
using namespace femto::test;

namespace {

double bins_sum(const std::vector<double>& bins, int channel) {
  double s = 0;
  for (size_t i = static_cast<size_t>(channel); i < bins.size(); i += 3) s += bins[i];
  return s;
}

SingleScatterSetup narrow_setup(double bin_width_ps, int bins) {
  SingleScatterSetup p;
  p.axis.t_start_ps = 110;
  p.axis.bin_width_ps = bin_width_ps;
  p.axis.bins = bins;
  return p;
}

SceneDesc with_reconstruction(SceneDesc d, TemporalFilter::Kind kind, double bandwidth_ps = 0.0) {
  d.reconstruction.type = kind;
  d.reconstruction.bandwidth_ps = bandwidth_ps;
  return d;
}

}  // namespace

// Catches: kernel deposits that gain or lose energy (bins + before + after != 1), also across
// the window edges and for Gaussian pulses; a kernel shape that differs from kernel_bin_weight;
// a widened Gaussian whose variance is not the pulse's plus the kernel's; T = 0 unlike the
// histogram.
TEST_CASE("kernel deposits keep their energy bin by bin", "[kernel_film]") {
  TimeAxis axis;
  axis.t_start_ps = 100;
  axis.bin_width_ps = 2.5;
  axis.bins = 40;
  Rng rng(7, 3);
  for (TemporalKernel k : {TemporalKernel::Perlin, TemporalKernel::Epanechnikov}) {
    const TemporalFilter kernel(axis, TemporalFilter::Kind::Kernel, k);
    const TemporalFilter histogram(axis, TemporalFilter::Kind::Histogram);
    for (int trial = 0; trial < 400; ++trial) {
      const double t = 40 + 220 * rng.uniform();
      const double T =
          std::exp(std::log(0.05) + std::log(2000.0) * rng.uniform());  // 0.05 .. 100 ps
      const double sigma = trial % 3 == 0 ? 0.5 + 4 * rng.uniform() : 0.0;
      std::vector<double> bins(static_cast<size_t>(axis.bins) * 3, 0.0);
      const DepositSplit sp = kernel.deposit(t, sigma, RGB(1.0, 2.0, 3.0), bins.data(), T);
      INFO("t " << t << " T " << T << " sigma " << sigma);
      CHECK(std::abs(sp.before + sp.inside + sp.after - 1.0) < 1e-12);
      CHECK(std::abs(bins_sum(bins, 0) - sp.inside) < 1e-12);
      CHECK(std::abs(bins_sum(bins, 2) - 3.0 * sp.inside) < 1e-11);
      if (sigma == 0.0) {
        for (int i = 0; i < axis.bins; ++i)
          CHECK(std::abs(bins[3 * static_cast<size_t>(i)] -
                         kernel_bin_weight(k, t, T, axis.bin_start_ps(i),
                                           axis.bin_start_ps(i + 1))) < 1e-12);
      } else if (sp.inside > 1.0 - 1e-9 && sigma * sigma + kernel_variance(k) * T * T >
                                               4 * axis.bin_width_ps * axis.bin_width_ps) {
        // Fully inside and wider than 2 bins: the bin-centre variance is sigma^2 + var_k T^2
        // plus the bins' w^2 / 12 (Sheppard's correction, exact to ~1e-8 for such a Gaussian).
        double mean = 0, m2 = 0;
        for (int i = 0; i < axis.bins; ++i)
          mean += bins[3 * static_cast<size_t>(i)] * axis.bin_center_ps(i);
        for (int i = 0; i < axis.bins; ++i)
          m2 += bins[3 * static_cast<size_t>(i)] * std::pow(axis.bin_center_ps(i) - mean, 2);
        const double expected =
            sigma * sigma + kernel_variance(k) * T * T + axis.bin_width_ps * axis.bin_width_ps / 12;
        CHECK(std::abs(mean - t) < 1e-6);
        CHECK(std::abs(m2 - expected) < 1e-4 * expected);
      }
    }
    // T = 0 deposits exactly like the histogram.
    std::vector<double> a(static_cast<size_t>(axis.bins) * 3, 0.0), b = a;
    kernel.deposit(123.4, 0.0, RGB(1.0), a.data(), 0.0);
    histogram.deposit(123.4, 0.0, RGB(1.0), b.data());
    CHECK(a == b);
  }
}

// Catches: onset reflection that loses or gains energy, leaves mass before the floor, mirrors
// about the wrong point, or moves an arrival earlier than the floor (it must reflect about the
// arrival itself then, so the shift vanishes with T).
TEST_CASE("kernel deposits reflect at the pixel's onset", "[kernel_film]") {
  TimeAxis axis;
  axis.t_start_ps = 100;
  axis.bin_width_ps = 2.5;
  axis.bins = 40;
  Rng rng(5, 9);
  for (TemporalKernel k : {TemporalKernel::Perlin, TemporalKernel::Epanechnikov}) {
    const TemporalFilter filter(axis, TemporalFilter::Kind::Kernel, k);
    for (int trial = 0; trial < 300; ++trial) {
      const double tf = 110 + 60 * rng.uniform();
      const double t = tf - 5 + 20 * rng.uniform(), T = 0.5 + 20 * rng.uniform();
      const double floor = std::fmin(tf, t);
      std::vector<double> bins(static_cast<size_t>(axis.bins) * 3, 0.0);
      const DepositSplit sp = filter.deposit(t, 0.0, RGB(1.0), bins.data(), T, tf);
      INFO("t " << t << " T " << T << " floor " << tf);
      CHECK(std::abs(sp.before + sp.inside + sp.after - 1.0) < 1e-12);
      CHECK(sp.before == 0.0);
      for (int i = 0; i < axis.bins; ++i) {
        const double b0 = axis.bin_start_ps(i), b1 = axis.bin_start_ps(i + 1);
        // The reflected kernel: K_T(x - t) + K_T(2 floor - x - t) on [floor, inf).
        double expected = 0;
        if (b1 > floor) {
          const double lo = std::fmax(b0, floor);
          expected = kernel_bin_weight(k, t, T, lo, b1) +
                     kernel_bin_weight(k, t, T, 2 * floor - b1, 2 * floor - lo);
        }
        CHECK(std::abs(bins[3 * static_cast<size_t>(i)] - expected) < 1e-12);
      }
    }
  }
}

// Catches: an off-by-one k (k-th vs (k+1)-th neighbour), wrong handling of t outside the arrivals
// or of fewer arrivals than k.
TEST_CASE("k-th nearest arrival distance matches brute force", "[kernel_film]") {
  Rng rng(11, 1);
  for (int n : {1, 2, 7, 100}) {
    std::vector<double> times;
    for (int i = 0; i < n; ++i)
      times.push_back(std::floor(1000 * rng.uniform()) * 0.5);  // with ties
    std::sort(times.begin(), times.end());
    for (int k : {1, 3, 40}) {
      for (int trial = 0; trial < 50; ++trial) {
        const double t = trial < 5 ? times[static_cast<size_t>(trial) % times.size()]
                                   : -100 + 800 * rng.uniform();
        std::vector<double> d;
        for (double x : times) d.push_back(std::abs(x - t));
        std::sort(d.begin(), d.end());
        const double expected = d[static_cast<size_t>(std::min(k, n)) - 1];
        CHECK(kth_nearest_distance(times, t, k) == expected);
      }
    }
  }
  CHECK(kth_nearest_distance({}, 1.0, 3) == -1.0);
}

// Catches: the film not being the estimator it claims: a bandwidth schedule applied to the wrong
// samples (e.g. per pass instead of per sample), a wrong kernel in the film, a lost or doubled
// deposit. With a fixed initial bandwidth the film's expectation is an exact 1-D integral:
// E[bin i] = integral over s of L(s) (1/N) sum_j w_i(t(s), T_1 r_j) ds.
TEST_CASE("kernel film equals its exact expectation on single scattering", "[kernel_film]") {
  const SingleScatterSetup p = narrow_setup(5.0, 40);
  const double T1 = 30.0, alpha = 0.8;
  const int spp = 128, batches = 48;
  SceneDesc d = with_reconstruction(p.scene(), TemporalFilter::Kind::Kernel, T1);
  d.reconstruction.alpha = alpha;
  const auto films = render_batches(d, spp, batches, /*max_depth=*/1);

  std::vector<double> T;  // T_j, j = 1..spp
  for (BandwidthSchedule s(alpha); s.j() <= spp; s.advance()) T.push_back(T1 * s.ratio());
  int resolved = 0;
  for (int i = 0; i < p.axis.bins; ++i) {
    const double b0 = p.axis.bin_start_ps(i), b1 = p.axis.bin_start_ps(i + 1);
    auto integrand = [&](double s) {
      const double t = p.time_of(s);
      double w = 0;
      for (double Tj : T) w += kernel_bin_weight(TemporalKernel::Perlin, t, Tj, b0, b1);
      return p.density(s) * w / static_cast<double>(T.size());
    };
    const double s0 = p.s_of_time(b0 - T1), s1 = p.s_of_time(b1 + T1);
    const double expected = s1 > s0 ? stats::adaptive_simpson(integrand, s0, s1, 1e-11) : 0.0;
    const MeanSE m = bin_mean_se(films, i);
    INFO("bin " << i << ": " << m.mean << " +- " << m.se << ", expected " << expected
                << ", histogram answer " << p.bin(i));
    CHECK(std::abs(m.mean - expected) < 4.0 * m.se + 1e-9 * expected);
    // The test can tell the kernel from the histogram where the smoothing matters.
    if (std::abs(expected - p.bin(i)) > 8.0 * m.se) ++resolved;
  }
  CHECK(resolved >= 3);
}

// Catches: a schedule that does not shrink the bandwidth (bias that never vanishes) and a
// k-nearest-arrival bandwidth that ignores the sample count. The bias (mean over batches minus
// the exact answer, noise removed) must fall as samples grow.
TEST_CASE("progressive kernel bias shrinks as samples grow", "[kernel_film]") {
  const SingleScatterSetup p = narrow_setup(2.0, 60);
  const SceneDesc d = with_reconstruction(p.scene(), TemporalFilter::Kind::Kernel);
  auto bias2 = [&](int spp, int batches) {
    const auto films = render_batches(d, spp, batches, /*max_depth=*/1);
    double b2 = 0, norm = 0;
    for (int i = 0; i < p.axis.bins; ++i) {
      const MeanSE m = bin_mean_se(films, i);
      const double e = p.bin(i);
      b2 += (m.mean - e) * (m.mean - e) - m.se * m.se;  // unbiased estimate of bias^2
      norm += e * e;
    }
    return b2 / norm;
  };
  const double early = bias2(64, 64), late = bias2(4096, 16);
  INFO("relative squared bias: 64 spp " << early << ", 4096 spp " << late);
  CHECK(early > 1e-3);        // there is bias to remove at 64 spp
  CHECK(late < 0.5 * early);  // and it shrinks
}

// Catches: kernel mass spilling ahead of the first light (light seen before it can arrive):
// with onset reflection every bin that ends before the single-scattering onset stays exactly
// empty, and without it (the power check) those bins receive light.
TEST_CASE("kernel film puts no light before the pixel's onset", "[kernel_film]") {
  const SingleScatterSetup p =
      narrow_setup(1.0, 60);  // onset eta h / c = 120.1 ps, window from 110 ps
  for (bool reflect : {true, false}) {
    SceneDesc d = with_reconstruction(p.scene(), TemporalFilter::Kind::Kernel);
    d.reconstruction.onset_reflection = reflect;
    const auto films = render_batches(d, 200, 2, /*max_depth=*/1);
    double early = 0, total = 0;
    for (const auto& f : films)
      for (int i = 0; i < p.axis.bins; ++i) {
        total += f.transient()[3 * i];
        if (p.axis.bin_start_ps(i + 1) <= p.onset_ps()) early += f.transient()[3 * i];
      }
    INFO("reflection " << reflect << ": before the onset " << early << " of " << total);
    CHECK(total > 0);
    if (reflect)
      CHECK(early == 0.0);
    else
      CHECK(early > 1e-3 * total);
  }
}

// Catches: a kernel film that is no better than the histogram (the reason it exists): with 1 ps
// bins and 256 samples its error against the exact answer must be well below the histogram's
// (measured: 0.16x with onset reflection, 0.32x without).
TEST_CASE("kernel film beats the histogram at equal samples", "[kernel_film]") {
  const SingleScatterSetup p = narrow_setup(1.0, 150);
  std::vector<double> exact;
  for (int i = 0; i < p.axis.bins; ++i) exact.push_back(p.bin(i));
  auto mse = [&](TemporalFilter::Kind kind) {
    const auto films =
        render_batches(with_reconstruction(p.scene(), kind), 256, 8, /*max_depth=*/1);
    double e2 = 0;
    for (const auto& f : films)
      for (int i = 0; i < p.axis.bins; ++i)
        e2 += std::pow(f.transient()[3 * i] - exact[static_cast<size_t>(i)], 2);
    return e2 / static_cast<double>(films.size());
  };
  const double kernel = mse(TemporalFilter::Kind::Kernel),
               histogram = mse(TemporalFilter::Kind::Histogram);
  INFO("summed squared error per render: kernel " << kernel << ", histogram " << histogram);
  CHECK(kernel < 0.5 * histogram);
}

// Catches: energy created or lost by the kernel film (it sees the same paths as the histogram
// for the same seed, so bins + before + after must agree), thread-count dependence of the
// first pass or of the schedule, and the unwarp time mode breaking either.
TEST_CASE("kernel film keeps the histogram's energy and is deterministic", "[kernel_film]") {
  for (TimeMode mode : {TimeMode::Camera, TimeMode::Unwarp}) {
    SceneDesc d;
    d.source = "fog box";
    d.camera = ortho_camera({0, 0, 50}, {0, 0, 0}, 40, 19, 17);
    d.time.t_start_ps = 50;
    d.time.bin_width_ps = 20;
    d.time.bins = 30;
    d.time_mode = mode;
    d.media.push_back(medium("fog", 0.002, 0.03, 0.3, 1.3));
    d.global_medium = 0;
    d.shapes.push_back(quad({-30, -30, -20}, {60, 0, 0}, {0, 60, 0}, diffuse(0.6)));
    LightDesc l;
    l.position = {5, 10, 30};
    l.intensity = RGB(500.0);
    l.pulse.fwhm_ps = mode == TimeMode::Camera ? 0.0 : 15.0;  // Gaussian pulses too
    d.lights.push_back(l);
    const Scene hist_scene(d);
    d.reconstruction.type = TemporalFilter::Kind::Kernel;
    d.reconstruction.first_pass_spp = 5;  // first pass and progressive samples both used
    const Scene kern_scene(d);
    RenderOptions opt;
    opt.spp = 12;
    opt.seed = 5;
    opt.quiet = true;
    opt.threads = 1;
    const RenderResult h = render(hist_scene, opt), k1 = render(kern_scene, opt);
    opt.threads = 2;
    const RenderResult k2 = render(kern_scene, opt);
    const size_t n = static_cast<size_t>(19) * 17 * 30 * 3;
    CHECK(std::memcmp(k1.film.transient(), k2.film.transient(), n * sizeof(float)) == 0);
    CHECK(k1.final_bandwidth_ps == k2.final_bandwidth_ps);
    const RGB hs = h.film.total_steady() + h.film.total_before() + h.film.total_after();
    const RGB ks = k1.film.total_steady() + k1.film.total_before() + k1.film.total_after();
    INFO("mode " << static_cast<int>(mode) << ": histogram " << hs.g << ", kernel " << ks.g);
    CHECK(hs.g > 0);
    CHECK(std::abs(ks.g - hs.g) < 1e-5 * hs.g);
    CHECK(std::memcmp(k1.film.transient(), h.film.transient(), n * sizeof(float)) != 0);
  }
}

// Catches: a touched range that misses a bin a deposit wrote (histogram, Gaussian pulse or
// kernel), which would leave light from one sample in the next (the hybrid's camera loop zeroes
// and reads only that range), or a reset that leaves bins non-zero.
TEST_CASE("a pixel accumulator knows which bins its deposits wrote", "[kernel_film]") {
  const TimeAxis axis{100.0, 10.0, 40};
  Rng rng(7, 3);
  PixelAccumulator acc;
  acc.reset(axis.bins);
  for (int sample = 0; sample < 300; ++sample) {
    const int kind = sample % 3;  // histogram delta, Gaussian pulse, Epanechnikov kernel
    const TemporalFilter filter(
        axis, kind == 2 ? TemporalFilter::Kind::Kernel : TemporalFilter::Kind::Histogram,
        TemporalKernel::Epanechnikov);
    const int deposits = 1 + static_cast<int>(4 * rng.uniform());
    for (int k = 0; k < deposits; ++k) {
      const double t = 60.0 + 420.0 * rng.uniform();  // some before or after the window
      const double sigma = kind == 1 ? 25.0 * rng.uniform() : 0.0;
      acc.add_now(filter, t, sigma, RGB(1.0, 2.0, 3.0), kind == 2 ? 30.0 * rng.uniform() : 0.0);
    }
    for (int i = 0; i < axis.bins; ++i) {
      const bool inside = i >= acc.touched_first && i <= acc.touched_last;
      if (!inside && acc.bins[3 * static_cast<size_t>(i)] != 0.0)
        FAIL("sample " << sample << ": bin " << i << " written outside the touched range");
    }
    acc.reset_touched(axis.bins);
    CHECK(std::all_of(acc.bins.begin(), acc.bins.end(), [](double v) { return v == 0.0; }));
    CHECK(acc.touched_last < acc.touched_first);
  }
}
