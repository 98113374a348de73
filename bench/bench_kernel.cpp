// femto-bench-kernel: the progressive kernel film (seed 000 Sec. 4 / Supp. B) against the
// histogram film and against rendering every frame on its own.
//  convergence and cost are described in docs/PERFORMANCE.md; `--help` lists the options.
//  convergence  seed 000 Fig. 4 in spirit: single scattering along one pixel ray (a point light
//               4 mm beside the ray: a step onset followed by a 1/r^2 peak and a long tail), 256
//               bins of 1 ps; RMSE over the bins against the exact bin integrals (1-D quadrature)
//               versus the sample count n, averaged over independent runs; fitted log-log slopes
//               next to the theoretical ones; equal-error sample ratio kernel vs histogram; the
//               kernel film's energy against the histogram's for the same paths.
//  cost         time of the kernel film relative to the histogram film at equal samples on the
//               built-in default scene at reduced resolution, 1 and N threads.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <exception>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "bench/bench_util.h"
#include "core/constants.h"
#include "core/default_scene.h"
#include "core/integrators/volpath.h"
#include "core/io/plot.h"
#include "core/pixel_accumulator.h"
#include "core/reconstruction.h"
#include "core/render.h"
#include "core/rng.h"
#include "core/scene_loader.h"
#include "samplers/stats.h"
#include "tests/single_scatter.h"

using namespace femto;
using femto::bench::now_s;
using femto::bench::process_cpu_s;

namespace {

/// CPU time of the calling thread, s (a render with 1 thread runs on the calling thread).
double thread_cpu_s() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

uint64_t mix(uint64_t x) {  // splitmix64 finaliser
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

// ---------------------------------------------------------------------------------------------
// The single-scattering pixel and its exact answer.
//
// Camera ray x(s) = (0, 0, s), s >= 0, in an infinite homogeneous medium; point light of
// intensity I at (0, h, 0). A scattering vertex at s is seen at camera time
// t(s) = eta (s + r(s)) / c, r = sqrt(s^2 + h^2), and contributes per unit length
//   L(s) = sigma_s exp(-sigma_t s) p_HG(cos) I exp(-sigma_t r) / r^2,  cos = -s / r
// (cosine between the light's propagation direction (x - L) / r and the direction to the camera
// -z). The pixel's bin-integrated radiance over [t0, t1) is the integral of L over
// [s(t0), s(t1)], with s(t) = (tau^2 - h^2) / (2 tau), tau = c t / eta >= h.
// The time response jumps from 0 to its maximum at t = eta h / c (a step), falls like the 1/r^2
// peak over ~eta h / c, then decays slowly (exp(-sigma_t c t / eta) / t^2) over the window.
struct Pixel : femto::test::SingleScatterSetup {
  Pixel() {
    sigma_a = 0.01;
    sigma_s = 0.04;
    g = 0.4;
    eta = 1.33;
    h = 4.0;
    I = 1000.0;
    axis.t_start_ps = 8.0;  // onset at eta h / c = 17.7 ps
    axis.bin_width_ps = 1.0;
    axis.bins = 256;
  }
  std::vector<double> exact_bins() const {
    std::vector<double> v;
    for (int i = 0; i < axis.bins; ++i) v.push_back(bin(i));
    return v;
  }
  /// Everything the pixel receives, in and out of the window (the tail to 60 mean free paths).
  double exact_total() const { return integral(0.0, 60.0 / sigma_t()); }
  SceneDesc scene(const ReconstructionDesc& rec) const {
    SceneDesc d = SingleScatterSetup::scene();
    d.reconstruction = rec;
    return d;
  }
};

// ---------------------------------------------------------------------------------------------
// Methods compared at equal sample counts n.
struct Method {
  const char* name;
  const char* label;
  bool no_reuse;          ///< every frame its own histogram render with n / bins samples
  ReconstructionDesc rec;
  double theory_slope;    ///< asymptotic log-log slope of the RMSE against bin integrals
  const char* theory;
};

std::vector<Method> methods() {
  ReconstructionDesc hist;
  ReconstructionDesc kern;
  kern.type = TemporalFilter::Kind::Kernel;
  ReconstructionDesc fixed = kern;
  fixed.alpha = 1.0;
  ReconstructionDesc epan = kern;
  epan.kernel = TemporalKernel::Epanechnikov;
  ReconstructionDesc k10 = kern;
  k10.knn = 10;
  return {
      {"no_reuse", "no path reuse", true, hist, -0.5, "-1/2 (unbiased, bins x the histogram's variance)"},
      {"histogram", "histogram", false, hist, -0.5, "-1/2 (unbiased for bin integrals)"},
      {"kernel", "kernel a=0.8 perlin", false, kern, -0.4, "-2/5 (AMSE n^-4/5, smooth signal)"},
      {"kernel_epan", "kernel a=0.8 epan.", false, epan, -0.4, "-2/5 (AMSE n^-4/5, smooth signal)"},
      {"kernel_a1", "kernel a=1 (fixed)", false, fixed, 0.0, "0 (bandwidth never shrinks: bias floor)"},
      {"kernel_k10", "kernel a=0.8 k=10", false, k10, -0.4, "-2/5 (AMSE n^-4/5, smooth signal)"},
  };
}

// Single scattering, one thread (the caller runs renders in parallel).
RenderOptions pixel_options(int spp, uint64_t seed) {
  RenderOptions o;
  o.spp = spp;
  o.seed = seed;
  o.threads = 1;
  o.max_depth = 1;
  o.quiet = true;
  return o;
}

// One render of the pixel.
std::vector<double> render_one(const Scene& scene, int spp, uint64_t seed, double& total) {
  const RenderResult r = render(scene, pixel_options(spp, seed));
  const TransientFilm& f = r.film;
  std::vector<double> v(static_cast<size_t>(f.bins()));
  for (int i = 0; i < f.bins(); ++i) v[static_cast<size_t>(i)] = f.transient()[3 * i];
  total = static_cast<double>(f.steady()[0]) + f.before()[0] + f.after()[0];
  return v;
}

// The same pixel through render_pixel(), keeping the double-precision sums the film rounds to
// float. Bit-identical float bins against render() show that these sums are render()'s own.
struct MirrorPixel {
  PixelAccumulator acc;
  double total = 0.0;  ///< (bins + before + after) / spp, red channel, in double
};
MirrorPixel mirror_pixel(const Scene& scene, int spp, uint64_t seed) {
  const ReconstructionDesc& rec = scene.desc().reconstruction;
  const TimeAxis axis = scene.desc().time;
  const TemporalFilter filter(axis, rec.type, rec.kernel);
  const VolPathIntegrator integrator(scene, filter, 1);
  PathStats st;
  MirrorPixel m;
  render_pixel(scene, integrator, filter, pixel_options(spp, seed), 0, 0, m.acc, st);
  double sum = m.acc.before.r + m.acc.after.r;
  for (int i = 0; i < axis.bins; ++i) sum += m.acc.bins[3 * static_cast<size_t>(i)];
  m.total = sum / spp;
  return m;
}

bool same_as_film(const MirrorPixel& m, const Scene& scene, int spp, uint64_t seed) {
  const RenderResult r = render(scene, pixel_options(spp, seed));
  const double inv = 1.0 / spp;
  for (int i = 0; i < r.film.bins() * 3; ++i)
    if (static_cast<float>(m.acc.bins[static_cast<size_t>(i)] * inv) != r.film.transient()[i]) return false;
  return static_cast<float>(m.acc.before.r * inv) == r.film.before()[0] &&
         static_cast<float>(m.acc.after.r * inv) == r.film.after()[0];
}

// Least-squares line through (log n, log e): slope and intercept.
struct Fit {
  double slope = NAN, intercept = NAN;
  double at(double n) const { return std::exp(intercept + slope * std::log(n)); }
};
Fit fit_loglog(const std::vector<double>& n, const std::vector<double>& e) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  int m = 0;
  for (size_t i = 0; i < n.size(); ++i) {
    if (!(e[i] > 0)) continue;
    const double x = std::log(n[i]), y = std::log(e[i]);
    sx += x, sy += y, sxx += x * x, sxy += x * y, ++m;
  }
  Fit f;
  if (m < 2) return f;
  f.slope = (m * sxy - sx * sy) / (m * sxx - sx * sx);
  f.intercept = (sy - f.slope * sx) / m;
  return f;
}

struct Cell {                // one method at one n
  std::vector<double> mse;   ///< per run: mean over bins of (estimate - exact)^2
  std::vector<double> total;      ///< per run: film energy (bins + before + after)
  std::vector<double> cpu;        ///< per run: CPU time of the task's renders, s
  bool valid = false;
};

// Error statistics of every (method, n) cell over the bins [i0, i1).
struct Region {
  std::string name, title;
  int i0 = 0, i1 = 0;
  double mean_signal = 0;
  std::vector<double> rmse, rel, spread, bias;  ///< (method, n), relative ones over mean_signal
  double n_split = 0;                           ///< slopes are fitted over n >= n_split
  std::vector<Fit> fits, fits_all;
};

void analyse(Region& rg, const std::vector<Method>& ms, const std::vector<int>& ns,
             const std::vector<std::vector<Cell>>& cells,
             const std::vector<std::vector<std::vector<double>>>& estimates, const std::vector<double>& exact,
             int runs) {
  const size_t R = static_cast<size_t>(runs), cnt = ms.size() * ns.size();
  const double nb = rg.i1 - rg.i0;
  rg.mean_signal = 0;
  for (int i = rg.i0; i < rg.i1; ++i) rg.mean_signal += exact[static_cast<size_t>(i)] / nb;
  rg.rmse.assign(cnt, NAN), rg.rel.assign(cnt, NAN), rg.spread.assign(cnt, NAN), rg.bias.assign(cnt, NAN);
  for (size_t k = 0; k < ms.size(); ++k)
    for (size_t j = 0; j < ns.size(); ++j) {
      if (!cells[k][j].valid) continue;
      const size_t id = k * ns.size() + j;
      const auto& est = estimates[id];
      double m = 0, s1 = 0, s2 = 0;
      for (size_t r = 0; r < R; ++r) {
        double e2 = 0;
        for (int i = rg.i0; i < rg.i1; ++i)
          e2 += std::pow(est[r][static_cast<size_t>(i)] - exact[static_cast<size_t>(i)], 2);
        e2 /= nb;
        m += e2, s1 += std::sqrt(e2), s2 += e2;
      }
      m /= static_cast<double>(R);
      const double mean_rmse = s1 / static_cast<double>(R);
      rg.rmse[id] = std::sqrt(m);
      rg.rel[id] = rg.rmse[id] / rg.mean_signal;
      rg.spread[id] = std::sqrt(std::max(0.0, s2 / static_cast<double>(R) - mean_rmse * mean_rmse) *
                                static_cast<double>(R) / static_cast<double>(R - 1)) / rg.mean_signal;
      double b2 = 0;
      for (int i = rg.i0; i < rg.i1; ++i) {
        double sum = 0, sum2 = 0;
        for (size_t r = 0; r < R; ++r) {
          const double v = est[r][static_cast<size_t>(i)];
          sum += v, sum2 += v * v;
        }
        const double mean = sum / static_cast<double>(R);
        const double var = (sum2 - sum * mean) / static_cast<double>(R - 1);
        b2 += std::pow(mean - exact[static_cast<size_t>(i)], 2) - var / static_cast<double>(R);
      }
      rg.bias[id] = std::sqrt(std::max(0.0, b2 / nb)) / rg.mean_signal;
    }
  // Slopes: least squares over the larger half of the n values (n >= sqrt(n_min * n_max)).
  rg.n_split = std::sqrt(static_cast<double>(ns.front()) * ns.back());
  rg.fits.assign(ms.size(), Fit{});
  rg.fits_all.assign(ms.size(), Fit{});
  for (size_t k = 0; k < ms.size(); ++k) {
    std::vector<double> x, y, xa, ya;
    for (size_t j = 0; j < ns.size(); ++j) {
      if (!cells[k][j].valid) continue;
      xa.push_back(ns[j]), ya.push_back(rg.rmse[k * ns.size() + j]);
      if (ns[j] >= rg.n_split) x.push_back(ns[j]), y.push_back(rg.rmse[k * ns.size() + j]);
    }
    rg.fits[k] = fit_loglog(x, y);
    rg.fits_all[k] = fit_loglog(xa, ya);
  }
}

// Runs `tasks` on `threads` workers (each task does its own renders with 1 thread).
template <class F>
void parallel_tasks(int count, int threads, F f) {
  std::atomic<int> next{0};
  auto worker = [&] {
    for (int t; (t = next.fetch_add(1)) < count;) f(t);
  };
  std::vector<std::thread> pool;
  for (int k = 1; k < threads; ++k) pool.emplace_back(worker);
  worker();
  for (std::thread& th : pool) th.join();
}

void write_png(const std::string& path, const std::vector<Method>& ms, const std::vector<int>& ns,
               const std::vector<std::vector<Cell>>& cells, const std::vector<double>& rel_rmse_of,
               const Pixel& px, const std::vector<double>& exact, const std::vector<std::vector<double>>& example,
               int example_n) {
  const Rgb8 colors[] = {{44, 160, 44}, {214, 39, 40}, {31, 119, 180}, {148, 103, 189}, {255, 127, 14}, {140, 86, 75}};
  Canvas canvas(1400, 560);
  Plot p;
  p.title = "1 ps bins: RMSE / mean bin vs samples";
  p.x_label = "log2 n (samples per pixel)";
  p.y_label = "RMSE / mean signal";
  p.log_y = true;
  p.legend = Plot::Legend::BottomLeft;
  for (size_t k = 0; k < ms.size(); ++k) {
    PlotSeries s{ms[k].label, {}, {}, colors[k % 6], PlotSeries::Style::Line};
    for (size_t j = 0; j < ns.size(); ++j)
      if (cells[k][j].valid) {
        s.x.push_back(std::log2(ns[j]));
        s.y.push_back(rel_rmse_of[k * ns.size() + j]);
      }
    p.series.push_back(s);
  }
  draw_plot(canvas, 0, 0, 700, 560, p, 2);
  Plot q;
  q.title = "one run at n = " + std::to_string(example_n) + " (zero bins not drawn)";
  q.x_label = "t (ps)";
  q.y_label = "bin-integrated radiance";
  q.log_y = true;
  PlotSeries ex{"exact", {}, {}, {20, 20, 20}, PlotSeries::Style::Line};
  for (int i = 0; i < px.axis.bins; ++i) {
    ex.x.push_back(px.axis.bin_center_ps(i));
    ex.y.push_back(exact[static_cast<size_t>(i)]);
  }
  for (size_t k = 0; k < example.size() && k < 3; ++k) {
    if (example[k].size() != static_cast<size_t>(px.axis.bins)) continue;  // no path reuse needs n >= bins
    PlotSeries s{ms[k].label, {}, {}, colors[k], k == 0 ? PlotSeries::Style::Markers : PlotSeries::Style::Line};
    for (int i = 0; i < px.axis.bins; ++i) {
      s.x.push_back(px.axis.bin_center_ps(i));
      s.y.push_back(example[k][static_cast<size_t>(i)]);
    }
    q.series.push_back(s);
  }
  q.series.push_back(ex);
  double ymax = 0;
  for (double v : exact) ymax = std::max(ymax, v);
  q.y_max = 3 * ymax;
  q.y_min = ymax * 1e-4;
  draw_plot(canvas, 700, 0, 700, 560, q, 2);
  write_canvas_png(path, canvas);
}

struct Options {
  int runs = 16, max_n = 1 << 19, threads = 2, reps = 3, width = 64, spp = 256;
  uint64_t seed = 1;
  std::string csv, png;
};

int convergence(const Options& opt) {
  const Pixel px;
  const std::vector<double> exact = px.exact_bins();
  double in_window = 0;
  for (double v : exact) in_window += v;
  const double mean_bin = in_window / static_cast<double>(exact.size());
  const double total_exact = px.exact_total();
  const int bins = px.axis.bins;
  std::vector<int> ns;
  for (int n = 16; n <= opt.max_n; n *= 2) ns.push_back(n);
  const std::vector<Method> ms = methods();
  std::vector<std::unique_ptr<Scene>> scenes;
  for (const Method& m : ms) scenes.push_back(std::make_unique<Scene>(px.scene(m.rec)));

  std::printf("convergence: single scattering along one pixel ray, point light %.0f mm beside it\n", px.h);
  std::printf("  medium sigma_a %.3g sigma_s %.3g /mm, g %.2g, eta %.3g; onset (step) at %.2f ps\n", px.sigma_a,
              px.sigma_s, px.g, px.eta, px.onset_ps());
  std::printf("  %d bins of %.3g ps from %.3g ps; exact bin integrals by adaptive Simpson; peak bin %.4g, mean bin %.4g\n",
              bins, px.axis.bin_width_ps, px.axis.t_start_ps, *std::max_element(exact.begin(), exact.end()),
              mean_bin);
  std::printf("  exact energy %.6g (in window %.6g); n = 16 .. %d, %d runs each, %d worker threads\n", total_exact,
              in_window, opt.max_n, opt.runs, opt.threads);
  std::printf("  no path reuse: frame i is bin i of its own histogram render of n / %d samples (own seed), so\n"
              "  the n samples are spread over %d one-frame renders; defined for n >= %d.\n",
              bins, bins, bins);

  // Cells and tasks: (method, n, run). Histogram and kernel variants share the seed of (n, run):
  // the same paths, reconstructed differently.
  std::vector<std::vector<Cell>> cells(ms.size(), std::vector<Cell>(ns.size()));
  struct Task {
    int m, j, run;
    double cost;
  };
  std::vector<Task> tasks;
  for (size_t k = 0; k < ms.size(); ++k)
    for (size_t j = 0; j < ns.size(); ++j) {
      Cell& c = cells[k][j];
      c.valid = !ms[k].no_reuse || ns[j] >= bins;
      if (!c.valid) continue;
      c.mse.assign(static_cast<size_t>(opt.runs), 0.0);
      c.total.assign(static_cast<size_t>(opt.runs), 0.0);
      c.cpu.assign(static_cast<size_t>(opt.runs), 0.0);
      for (int r = 0; r < opt.runs; ++r)
        tasks.push_back({static_cast<int>(k), static_cast<int>(j), r, static_cast<double>(ns[j])});
    }
  std::stable_sort(tasks.begin(), tasks.end(), [](const Task& a, const Task& b) { return a.cost > b.cost; });
  const int example_j = static_cast<int>(std::min<size_t>(ns.size() - 1, 8));  // n = 4096 by default
  std::vector<std::vector<double>> example(3);
  std::vector<std::vector<std::vector<double>>> estimates(ms.size() * ns.size());
  for (auto& e : estimates) e.resize(static_cast<size_t>(opt.runs));

  const double t0 = now_s();
  parallel_tasks(static_cast<int>(tasks.size()), opt.threads, [&](int ti) {
    const Task& t = tasks[static_cast<size_t>(ti)];
    const int n = ns[static_cast<size_t>(t.j)];
    const uint64_t seed = mix(opt.seed * 0x100000001b3ULL + static_cast<uint64_t>(t.j) * 1000003ULL +
                              static_cast<uint64_t>(t.run));
    const double start = thread_cpu_s();
    std::vector<double> est;
    double total = 0;
    if (ms[static_cast<size_t>(t.m)].no_reuse) {
      est.assign(static_cast<size_t>(bins), 0.0);
      for (int i = 0; i < bins; ++i) {
        double frame_total = 0;
        const std::vector<double> f = render_one(*scenes[static_cast<size_t>(t.m)], n / bins,
                                                   mix(seed ^ mix(static_cast<uint64_t>(i) + 77)), frame_total);
        est[static_cast<size_t>(i)] = f[static_cast<size_t>(i)];
        total += frame_total / bins;
      }
    } else {
      est = render_one(*scenes[static_cast<size_t>(t.m)], n, seed, total);
    }
    const double secs = thread_cpu_s() - start;
    double e2 = 0;
    for (int i = 0; i < bins; ++i) e2 += std::pow(est[static_cast<size_t>(i)] - exact[static_cast<size_t>(i)], 2);
    Cell& c = cells[static_cast<size_t>(t.m)][static_cast<size_t>(t.j)];
    c.mse[static_cast<size_t>(t.run)] = e2 / bins;
    c.total[static_cast<size_t>(t.run)] = total;
    estimates[static_cast<size_t>(t.m) * ns.size() + static_cast<size_t>(t.j)][static_cast<size_t>(t.run)] = est;
    c.cpu[static_cast<size_t>(t.run)] = secs;
  });
  const double elapsed = now_s() - t0;

  // Per region and cell: RMSE = sqrt(mean over runs of the per-run MSE over the region's bins);
  // run-to-run sd of the per-run RMSE; bias part = sqrt(bin-averaged unbiased estimate of bias^2).
  const double onset = px.onset_ps();
  std::vector<Region> regions(3);
  regions[0].name = "all", regions[0].title = "all bins", regions[0].i0 = 0, regions[0].i1 = bins;
  regions[1].name = "onset", regions[1].i0 = px.axis.bin_of(onset - 8.0), regions[1].i1 = px.axis.bin_of(onset + 30.0);
  regions[2].name = "tail", regions[2].i0 = regions[1].i1, regions[2].i1 = bins;
  char name_buf[2][96];
  std::snprintf(name_buf[0], sizeof name_buf[0], "onset region, bins at %.0f-%.0f ps (step, 1/r^2 peak)",
                px.axis.bin_start_ps(regions[1].i0), px.axis.bin_start_ps(regions[1].i1));
  std::snprintf(name_buf[1], sizeof name_buf[1], "tail, bins at %.0f-%.0f ps (smooth, few samples per bin)",
                px.axis.bin_start_ps(regions[2].i0), px.axis.t_end_ps());
  regions[1].title = name_buf[0];
  regions[2].title = name_buf[1];
  for (Region& rg : regions) analyse(rg, ms, ns, cells, estimates, exact, opt.runs);
  const size_t R = static_cast<size_t>(opt.runs);

  for (const Region& rg : regions) {
    const bool main_region = &rg == &regions[0];
    std::printf("\n  === %s: mean bin %.4g ===\n", rg.title.c_str(), rg.mean_signal);
    std::printf("  relative RMSE (RMSE / mean bin of the region), over %d runs; +- = run-to-run sd of the\n"
                "  per-run value; [b] = bias part (sqrt of the bin-averaged squared bias, noise removed)\n",
                opt.runs);
    std::printf("  %8s", "n");
    for (const Method& m : ms) std::printf(" | %-27s", m.label);
    std::printf("\n");
    for (size_t j = 0; j < ns.size(); ++j) {
      std::printf("  %8d", ns[j]);
      for (size_t k = 0; k < ms.size(); ++k) {
        const size_t id = k * ns.size() + j;
        if (!cells[k][j].valid) {
          std::printf(" | %-27s", "   -");
          continue;
        }
        char buf[64];
        if (k < 2)
          std::snprintf(buf, sizeof buf, "%.4f +- %.4f", rg.rel[id], rg.spread[id]);
        else
          std::snprintf(buf, sizeof buf, "%.4f +- %.4f [b %.4f]", rg.rel[id], rg.spread[id], rg.bias[id]);
        std::printf(" | %-27s", buf);
      }
      std::printf("\n");
    }
    if (main_region) std::printf("  absolute RMSE = relative x mean bin %.6g\n", rg.mean_signal);

    std::printf("\n  fitted log-log slope of the RMSE vs n (least squares over n >= %.0f; over all n in brackets)\n",
                rg.n_split);
    for (size_t k = 0; k < ms.size(); ++k) {
      char a[16] = "   n/a", b[16] = "   n/a";
      if (std::isfinite(rg.fits[k].slope)) std::snprintf(a, sizeof a, "%+.3f", rg.fits[k].slope);
      if (std::isfinite(rg.fits_all[k].slope)) std::snprintf(b, sizeof b, "%+.3f", rg.fits_all[k].slope);
      std::printf("    %-22s %s  [%s]   %s%s\n", ms[k].label, a, b, main_region ? "theory " : "",
                  main_region ? ms[k].theory : "");
    }
    if (main_region) {
      std::printf("    (the -2/5 of seed 000 Supp. B assumes a smooth signal. This one jumps at the onset: the\n"
                  "    kernel moves O(J w) into or out of each of the ~T/w bins next to the jump J, so the\n"
                  "    squared bias summed over the bins is ~J^2 w T and the RMSE falls like T^(1/2) ~\n"
                  "    n^(-(1-alpha)/2) = n^-0.1 while T >> w (n^-0.2 once T << w), until it dominates.)\n");
      double lr = 0;
      int cnt = 0;
      for (size_t j = 0; j < ns.size(); ++j)
        if (cells[0][j].valid) lr += std::log(rg.rmse[j] / rg.rmse[ns.size() + j]), ++cnt;
      if (cnt > 0)
        std::printf("    no path reuse / histogram RMSE, geometric mean over n >= %d: %.2f (theory sqrt(%d) = %.0f)\n",
                    bins, std::exp(lr / cnt), bins, std::sqrt(static_cast<double>(bins)));
    }

    // Equal-error sample ratio: histogram samples needed to reach the kernel's RMSE at n, from the
    // histogram's fitted line (all n: it is unbiased, its slope holds throughout), and pointwise
    // from the theoretical -1/2 slope: (e_hist(n) / e_kernel(n))^2.
    const Fit& hfit = rg.fits_all[1];
    std::printf("\n  equal-error sample ratio = (histogram samples reaching the kernel's RMSE at n) / n; > 1: the\n"
                "  kernel is better. 'fit' inverts the histogram's fitted line (slope %+.3f), 'pw' (pointwise)\n"
                "  = (rmse_histogram / rmse_kernel)^2 at the same n\n",
                hfit.slope);
    std::printf("  %8s", "n");
    for (size_t k = 2; k < ms.size(); ++k) std::printf(" %-20s", ms[k].label);
    std::printf("\n  %8s", "");
    for (size_t k = 2; k < ms.size(); ++k) std::printf(" %-20s", "      fit /       pw");
    std::printf("\n");
    for (size_t j = 0; j < ns.size(); ++j) {
      std::printf("  %8d", ns[j]);
      for (size_t k = 2; k < ms.size(); ++k) {
        const double e = rg.rmse[k * ns.size() + j];
        const double nh = std::exp((std::log(e) - hfit.intercept) / hfit.slope);
        const double pw = std::pow(rg.rmse[1 * ns.size() + j] / e, 2);
        char buf[64];
        std::snprintf(buf, sizeof buf, "%8.3gx /%8.3gx", nh / ns[j], pw);
        std::printf(" %-20s", buf);
      }
      std::printf("\n");
    }
    // Where each kernel's measured curve crosses the histogram's, and where the fitted lines would.
    for (size_t k = 2; k < ms.size(); ++k) {
      std::string where;
      for (size_t j = 1; j < ns.size(); ++j) {
        const double a = std::log(rg.rmse[ns.size() + j - 1] / rg.rmse[k * ns.size() + j - 1]);
        const double b = std::log(rg.rmse[ns.size() + j] / rg.rmse[k * ns.size() + j]);
        if ((a > 0) != (b > 0)) {
          const double f = a / (a - b);
          char buf[96];
          std::snprintf(buf, sizeof buf, "%s n ~ %.0f (kernel %s above)", where.empty() ? "" : ",",
                        std::exp(std::log(ns[j - 1]) + f * (std::log(ns[j]) - std::log(ns[j - 1]))),
                        b > 0 ? "better" : "worse");
          where += buf;
        }
      }
      const size_t last = ns.size() - 1;
      const bool better_now = rg.rmse[k * ns.size() + last] < rg.rmse[ns.size() + last];
      if (where.empty())
        where = std::string(" none: kernel ") + (better_now ? "better" : "worse") + " at every n";
      const Fit& kf = rg.fits[k];
      const Fit& hf = rg.fits[1];
      std::string extra;
      if (kf.slope != hf.slope) {
        const double nx = std::exp((kf.intercept - hf.intercept) / (hf.slope - kf.slope));
        if (nx > ns.back() && (kf.slope > hf.slope) == better_now) {
          char buf[96];
          std::snprintf(buf, sizeof buf, "; fitted lines extrapolate to cross at n ~ %.2g", nx);
          extra = buf;
        }
      }
      std::printf("  %-22s crossing with the histogram:%s%s\n", ms[k].label, where.c_str(), extra.c_str());
    }
  }

  // The histogram against the exact answer (it is unbiased): z = (mean over runs - exact) / standard
  // error per bin at the largest n. The per-run values are skewed (1/r^2 connections), so the
  // standard error from the runs is itself noisy and |z| has heavier tails than a Gaussian.
  {
    const size_t id = ns.size() + ns.size() - 1;
    int off = 0, nonzero = 0, worst_bin = -1, early = 0;
    double worst = 0, z2 = 0;
    for (int i = 0; i < bins; ++i) {
      double sum = 0, sum2 = 0;
      for (size_t r = 0; r < R; ++r) {
        const double v = estimates[id][r][static_cast<size_t>(i)];
        sum += v, sum2 += v * v;
      }
      const double mean = sum / static_cast<double>(R);
      const double se = std::sqrt(std::max(0.0, (sum2 - sum * mean) / static_cast<double>(R - 1)) / static_cast<double>(R));
      if (exact[static_cast<size_t>(i)] == 0.0) {
        early += mean != 0.0;
        continue;
      }
      ++nonzero;
      const double z = (mean - exact[static_cast<size_t>(i)]) / (se + 1e-300);
      z2 += z * z;
      if (std::abs(z) > worst) worst = std::abs(z), worst_bin = i;
      off += std::abs(z) > 3.5;
    }
    char expect[48] = "no finite expectation";
    if (opt.runs > 3) std::snprintf(expect, sizeof expect, "about %.2f expected", (opt.runs - 1.0) / (opt.runs - 3.0));
    std::printf("\n  check of the exact answer: histogram at n = %d, mean over runs vs quadrature per bin:\n"
                "  mean z^2 %.2f over %d bins with signal (%s for %d runs), %d bins with |z| > 3.5,\n"
                "  largest |z| %.2f (bin at %.0f ps); bins before the onset hold %s\n",
                ns.back(), z2 / nonzero, nonzero, expect, opt.runs, off, worst,
                px.axis.bin_start_ps(std::max(0, worst_bin)), early > 0 ? "energy (wrong)" : "nothing, as they should");
  }

  // Energy: kernel films against the histogram film of the same seed (same paths). The films
  // store float32, so they agree to float rounding; the double sums (mirror) to ~1e-12.
  double worst_film = 0, worst_round = 0;
  for (size_t k = 2; k < ms.size(); ++k)
    for (size_t j = 0; j < ns.size(); ++j)
      for (size_t r = 0; r < R; ++r) {
        const double h = cells[1][j].total[r], kk = cells[k][j].total[r];
        worst_film = std::max(worst_film, std::abs(kk - h) / h);
      }
  worst_round = 3.0 * std::ldexp(1.0, -24);
  std::printf("\n  energy (bins + before + after), kernel films vs the histogram film with the same seed:\n");
  std::printf("    film (float32 storage), all n, runs and kernel variants: max relative difference %.2e\n"
              "    (float rounding of the three stored sums allows up to ~%.1e)\n",
              worst_film, worst_round);
  double hist_mean = 0, hist_m2 = 0;
  for (double v : cells[1].back().total) hist_mean += v, hist_m2 += v * v;
  hist_mean /= static_cast<double>(R);
  const double hist_se = std::sqrt(std::max(0.0, hist_m2 / static_cast<double>(R) - hist_mean * hist_mean) /
                                   static_cast<double>(R - 1));
  std::printf("    histogram energy at n = %d, mean over runs %.6g +- %.2g; exact %.6g (%+.1f standard errors)\n",
              ns.back(), hist_mean, hist_se, total_exact, (hist_mean - total_exact) / hist_se);
  const int mirror_ns[] = {16, 100, 160, 1000, std::min(ns.back(), 16384)};
  double worst_double = 0;
  bool all_identical = true;
  for (int n : mirror_ns) {
    const uint64_t seed = mix(opt.seed + 4242u + static_cast<uint64_t>(n));
    const MirrorPixel h = mirror_pixel(*scenes[1], n, seed);
    all_identical = all_identical && same_as_film(h, *scenes[1], n, seed);
    for (size_t k = 2; k < ms.size(); ++k) {
      const MirrorPixel m = mirror_pixel(*scenes[k], n, seed);
      all_identical = all_identical && same_as_film(m, *scenes[k], n, seed);
      const double d = std::abs(m.total - h.total) / h.total;
      worst_double = std::max(worst_double, d);
      if (k == 2)
        std::printf("    n = %6d: double sums, histogram %.15g, kernel %.15g, relative difference %.2e\n", n, h.total,
                    m.total, d);
    }
  }
  std::printf("    double sums before storage (n in {16, 100, 160, 1000, 16384}, all kernel variants): max relative\n"
              "    difference %.2e (%s); the traced pixel matches render()'s film bit for bit: %s\n",
              worst_double, worst_double < 1e-9 ? "OK, < 1e-9" : "MISMATCH", all_identical ? "yes" : "NO");

  // The default kernel's bandwidth after its last sample, at a few times (from the mirror).
  {
    const int n = ns.back();
    const MirrorPixel m = mirror_pixel(*scenes[2], n, mix(opt.seed + 4242u + static_cast<uint64_t>(n)));
    const MirrorPixel f = mirror_pixel(*scenes[2], 160, mix(opt.seed + 4242u + 160u));
    const MirrorPixel f16 = mirror_pixel(*scenes[2], 16, mix(opt.seed + 4242u + 16u));
    std::printf("\n  default kernel: bandwidth of the last sample at time t (k = %d of %d first-pass arrivals,\n"
                "  %zu of them arrived before the window end); first-pass arrivals within 10 ps after onset: %d\n",
                ms[2].rec.knn, ms[2].rec.first_pass_spp,
                static_cast<size_t>(std::lower_bound(f.acc.times.begin(), f.acc.times.end(), px.axis.t_end_ps()) -
                                    f.acc.times.begin()),
                static_cast<int>(std::lower_bound(f.acc.times.begin(), f.acc.times.end(), px.onset_ps() + 10) -
                                 std::lower_bound(f.acc.times.begin(), f.acc.times.end(), px.onset_ps())));
    std::printf("    %10s", "t (ps)");
    const double ts[] = {px.onset_ps() - 2, px.onset_ps() + 2, px.onset_ps() + 10, 60, 120, 200, 260};
    for (double t : ts) std::printf(" %8.1f", t);
    std::printf("\n    %10s", "n = 16");
    for (double t : ts) std::printf(" %8.2f", f16.acc.bandwidth_at(t));
    std::printf("\n    %10s", "n = 160");
    for (double t : ts) std::printf(" %8.2f", f.acc.bandwidth_at(t));
    std::printf("\n    n = %-6d", n);
    for (double t : ts) std::printf(" %8.2f", m.acc.bandwidth_at(t));
    std::printf("\n");
  }
  const int n_cpu = std::min(4096, ns.back());
  std::printf("\n  CPU time per sample on this pixel (n >= %d, all runs; 1 ps bins, so a kernel deposit\n"
              "  covers 2 T / 1 ps bins):", n_cpu);
  for (size_t k = 0; k < ms.size(); ++k) {
    double secs = 0, samples = 0;
    for (size_t j = 0; j < ns.size(); ++j)
      if (cells[k][j].valid && ns[j] >= n_cpu)
        for (double v : cells[k][j].cpu) secs += v, samples += ns[j];
    if (samples > 0) std::printf("%s %s %.3g us", k == 0 ? "" : ",", ms[k].name, 1e6 * secs / samples);
  }
  std::printf("\n  time: %.1f s for all renders (%d threads)\n", elapsed, opt.threads);

  if (!opt.csv.empty()) {
    FILE* f = std::fopen(opt.csv.c_str(), "w");
    if (!f) {
      std::fprintf(stderr, "cannot write %s\n", opt.csv.c_str());
      return 1;
    }
    std::fprintf(f, "n,method,region,rmse,rel_rmse,rel_rmse_run_sd,rel_bias,runs\n");
    for (const Region& rg : regions)
      for (size_t j = 0; j < ns.size(); ++j)
        for (size_t k = 0; k < ms.size(); ++k) {
          const size_t id = k * ns.size() + j;
          if (cells[k][j].valid)
            std::fprintf(f, "%d,%s,%s,%.6e,%.6e,%.6e,%.6e,%d\n", ns[j], ms[k].name, rg.name.c_str(), rg.rmse[id],
                         rg.rel[id], rg.spread[id], rg.bias[id], opt.runs);
        }
    std::fclose(f);
    std::printf("  wrote %s\n", opt.csv.c_str());
  }
  if (!opt.png.empty()) {
    for (size_t k = 0; k < 3; ++k)
      example[k] = estimates[k * ns.size() + static_cast<size_t>(example_j)][0];
    write_png(opt.png, ms, ns, cells, regions[0].rel, px, exact, example, ns[static_cast<size_t>(example_j)]);
    std::printf("  wrote %s\n", opt.png.c_str());
  }
  return 0;
}

// ---------------------------------------------------------------------------------------------
int cost(const Options& opt) {
  SceneDesc base = load_scene_string(default_scene_json(), "<default scene>", "");
  const int w0 = base.camera.width, h0 = base.camera.height;
  base.camera.width = opt.width;
  base.camera.height = std::max(1, opt.width * h0 / w0);
  SceneDesc kd = base;
  kd.reconstruction = ReconstructionDesc{};
  kd.reconstruction.type = TemporalFilter::Kind::Kernel;
  base.reconstruction = ReconstructionDesc{};
  const Scene hist(base), kern(kd);
  std::printf("cost: built-in default scene at %d x %d, %d spp, %d bins of %.3g ps; kernel film with default\n"
              "  settings (perlin, alpha %.2g, k %d, first pass %d spp); min of %d reps, order alternating\n",
              base.camera.width, base.camera.height, opt.spp, base.time.bins, base.time.bin_width_ps,
              kd.reconstruction.alpha, kd.reconstruction.knn, kd.reconstruction.first_pass_spp, opt.reps);
  std::vector<int> thread_counts = {1};
  if (opt.threads > 1) thread_counts.push_back(opt.threads);
  double ratio_wall[2] = {0, 0}, ratio_cpu[2] = {0, 0};
  for (size_t tc = 0; tc < thread_counts.size(); ++tc) {
    const int threads = thread_counts[tc];
    double wall_h = 1e30, wall_k = 1e30, cpu_h = 1e30, cpu_k = 1e30;
    uint64_t paths = 0;
    for (int rep = 0; rep < opt.reps; ++rep) {
      for (int order = 0; order < 2; ++order) {
        const bool kernel_now = (order == 0) == (rep % 2 == 1);
        RenderOptions o;
        o.spp = opt.spp;
        o.seed = opt.seed;
        o.threads = threads;
        o.quiet = true;
        const double t = now_s(), c = process_cpu_s();
        const RenderResult r = render(kernel_now ? kern : hist, o);
        const double dt = now_s() - t, dc = process_cpu_s() - c;
        paths = r.stats.paths;
        double& w = kernel_now ? wall_k : wall_h;
        double& cp = kernel_now ? cpu_k : cpu_h;
        w = std::min(w, dt);
        cp = std::min(cp, dc);
      }
    }
    ratio_wall[tc] = wall_k / wall_h;
    ratio_cpu[tc] = cpu_k / cpu_h;
    std::printf("  %d thread%s: wall histogram %.3f s (%.3g paths/s), kernel %.3f s -> %.3fx;"
                " cpu histogram %.3f s, kernel %.3f s -> %.3fx\n",
                threads, threads > 1 ? "s" : " ", wall_h, static_cast<double>(paths) / wall_h, wall_k, wall_k / wall_h,
                cpu_h, cpu_k, cpu_k / cpu_h);
  }
  std::printf("  kernel / histogram at equal samples (target <= 1.2x): wall %.3fx (1 thread)", ratio_wall[0]);
  if (thread_counts.size() > 1) std::printf(", %.3fx (%d threads)", ratio_wall[1], thread_counts[1]);
  std::printf("; cpu %.3fx (1 thread)", ratio_cpu[0]);
  if (thread_counts.size() > 1) std::printf(", %.3fx (%d threads)", ratio_cpu[1], thread_counts[1]);
  std::printf("\n");
  return 0;
}

void usage(FILE* f) {
  std::fprintf(f,
               "usage: femto-bench-kernel [convergence|cost|all] [options]\n"
               "  convergence: RMSE vs samples of no path reuse, histogram and kernel films against the\n"
               "               exact single-scattering answer; slopes, equal-error ratios, energy check\n"
               "  cost:        kernel vs histogram film time at equal samples on the default scene\n"
               "options:\n"
               "  --runs N     independent runs per sample count (default 16, >= 2)\n"
               "  --max-n N    largest sample count (16, 32, ... up to N; default 524288)\n"
               "  --seed N     base seed (default 1)\n"
               "  --reps N     cost: repetitions, the minimum time is kept (default 3)\n"
               "  --threads N  convergence: worker threads; cost: times 1 and N threads (default 2)\n"
               "  --width N    cost: image width, height from the scene's aspect (default 64)\n"
               "  --spp N      cost: samples per pixel (default 256)\n"
               "  --csv FILE   convergence: write n, method, rmse, rel_rmse, run spread, bias\n"
               "  --png FILE   convergence: write a log-log plot of the relative RMSE and one time response\n"
               "  --help       this text\n");
}

}  // namespace

int main(int argc, char** argv) {
  std::string what = "all";
  Options opt;
  int i = 1;
  if (argc > 1 && argv[1][0] != '-') what = argv[i++];
  for (; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--help" || a == "-h") {
      usage(stdout);
      return 0;
    }
    if (i + 1 >= argc) {
      std::fprintf(stderr, "missing value after %s\n", a.c_str());
      usage(stderr);
      return 2;
    }
    const char* v = argv[++i];
    if (a == "--runs") opt.runs = std::atoi(v);
    else if (a == "--max-n") opt.max_n = std::atoi(v);
    else if (a == "--seed") opt.seed = std::strtoull(v, nullptr, 10);
    else if (a == "--reps") opt.reps = std::atoi(v);
    else if (a == "--threads") opt.threads = std::atoi(v);
    else if (a == "--width") opt.width = std::atoi(v);
    else if (a == "--spp") opt.spp = std::atoi(v);
    else if (a == "--csv") opt.csv = v;
    else if (a == "--png") opt.png = v;
    else {
      std::fprintf(stderr, "unknown option %s\n", a.c_str());
      usage(stderr);
      return 2;
    }
  }
  if ((what != "all" && what != "convergence" && what != "cost") || opt.runs < 2 || opt.max_n < 32 ||
      opt.reps < 1 || opt.threads < 1 || opt.width < 1 || opt.spp < 1) {
    usage(stderr);
    return 2;
  }
  try {
    if (what != "cost" && convergence(opt) != 0) return 1;
    if (what == "all") std::printf("\n");
    if (what != "convergence") return cost(opt);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
  return 0;
}
