// femto-bench-time_sampling: time-targeted connection sampling in media (seed 000 Fig. 8 in
// spirit). Single scattering along one pixel ray through a homogeneous medium lit by a pulsed
// (delta) point light, over a window many mean free times long. For each way of connecting the
// camera ray to the light (mfp: mean-free-path collision + next-event estimation; equiangular;
// line-to-point; MIS of the last two) at equal samples per pixel over independent runs: the
// relative RMS error per time bin against the exact bin-integrated answer (1-D quadrature),
// whether each strategy's mean agrees with it, equal-error sample and time ratios at late times,
// a CSV of every bin and a PNG plot of relative error over time.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <memory>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "core/constants.h"
#include "core/io/plot.h"
#include "core/render.h"
#include "core/scene.h"
#include "core/scene_desc.h"
#include "media/phase_hg.h"
#include "samplers/stats.h"
#include "tests/single_scatter.h"

using namespace femto;

namespace {

// The ray x(s) = (0, 0, s), s >= 0, seen by a 1 x 1 orthographic pixel at the origin looking
// down +z, in a homogeneous medium filling space, lit by a point light at (0, h, 0) emitting a
// delta pulse at t = 0. A vertex at s reaches the sensor at camera time
//   t(s) = eta (s + r(s)) / c,  r = sqrt(s^2 + h^2),
// and contributes sigma_s exp(-sigma_t s) f(cos) I exp(-sigma_t r) / r^2 per unit distance.
struct Setup : femto::test::SingleScatterSetup {
  Setup() {
    sigma_a = 0.002;
    sigma_s = 0.008;
    g = 0.3;
    eta = 1.0;
    h = 20.0;
    I = 1000.0;
    axis.t_start_ps = 0.0;
    axis.bin_width_ps = 80.0;
    axis.bins = 75;  // 6 ns: 1800 mm of light travel, 18 mean free paths (sigma_t = 0.01/mm)
  }
  double mean_free_time_ps() const { return eta / (sigma_t() * kSpeedOfLight); }
  SceneDesc scene(ConnectionSampling connection) const {
    SceneDesc d = SingleScatterSetup::scene();
    d.media[0].connection = connection;
    return d;
  }
};

struct Strategy {
  const char* name;
  ConnectionSampling kind;
  Rgb8 color;
};
const Strategy kStrategies[] = {
    {"mfp", ConnectionSampling::Collision, {20, 20, 20}},
    {"equiangular", ConnectionSampling::Equiangular, {31, 119, 180}},
    {"line_to_point", ConnectionSampling::LineToPoint, {214, 39, 40}},
    {"mis", ConnectionSampling::Mis, {255, 127, 14}},
};
constexpr size_t kCount = 4;

struct Options {
  int spp = 1024;
  int runs = 4000;
  uint64_t seed = 1;
  int threads = 2;
  std::string csv, png;
};

void usage(FILE* f) {
  std::fprintf(f,
               "usage: femto-bench-time_sampling [--spp N] [--runs N] [--seed N] [--threads N] [--csv FILE] "
               "[--png FILE]\n"
               "  --spp N      samples per pixel of every run, all strategies (default 1024)\n"
               "  --runs N     independent runs per strategy, seeds seed..seed+N-1 (default 4000, >= 2)\n"
               "  --seed N     first seed (default 1)\n"
               "  --threads N  runs rendered concurrently, one thread each (default 2)\n"
               "  --csv FILE   every bin: exact value, and per strategy relative RMS error, mean, SE\n"
               "  --png FILE   plot of relative RMS error over time, one curve per strategy (log y)\n");
}

bool parse(int argc, char** argv, Options& o) {
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--help" || a == "-h") {
      usage(stdout);
      std::exit(0);
    }
    if (i + 1 >= argc) return false;
    const char* v = argv[++i];
    char* end = nullptr;
    if (a == "--spp") o.spp = static_cast<int>(std::strtol(v, &end, 10));
    else if (a == "--runs") o.runs = static_cast<int>(std::strtol(v, &end, 10));
    else if (a == "--seed") o.seed = std::strtoull(v, &end, 10);
    else if (a == "--threads") o.threads = static_cast<int>(std::strtol(v, &end, 10));
    else if (a == "--csv") o.csv = v;
    else if (a == "--png") o.png = v;
    else return false;
    if (end && *end != '\0') return false;
  }
  return o.spp >= 1 && o.runs >= 2 && o.threads >= 1;
}

double now_s() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

/// Per strategy and bin: relative RMS error against the exact value, and mean and standard
/// error over the runs.
struct BinErrors {
  std::vector<double> rel, mean, se;
  std::vector<int> empty_runs;  ///< runs with no contribution in the bin
};

BinErrors analyse(const std::vector<std::vector<double>>& runs, const std::vector<double>& exact) {
  const size_t T = exact.size();
  const double R = static_cast<double>(runs.size());
  BinErrors e;
  for (size_t i = 0; i < T; ++i) {
    double sum = 0, sq_err = 0;
    int empty = 0;
    for (const auto& r : runs) {
      sum += r[i];
      sq_err += (r[i] - exact[i]) * (r[i] - exact[i]);
      empty += r[i] == 0.0;
    }
    const double mean = sum / R;
    double var = 0;
    for (const auto& r : runs) var += (r[i] - mean) * (r[i] - mean);
    var /= R - 1;
    e.mean.push_back(mean);
    e.se.push_back(std::sqrt(var / R));
    e.rel.push_back(exact[i] > 0 ? std::sqrt(sq_err / R) / exact[i] : NAN);
    e.empty_runs.push_back(empty);
  }
  return e;
}

/// RMS over bins [from, to) of the relative errors.
double rms_over(const std::vector<double>& rel, size_t from, size_t to) {
  double s = 0;
  for (size_t i = from; i < to; ++i) s += rel[i] * rel[i];
  return std::sqrt(s / static_cast<double>(to - from));
}

/// Equal-error sample ratio of strategy b against a over bins [from, to): error^2 ~ 1 / n, so
/// per bin n_a / n_b = (err_a / err_b)^2. `geo`: geometric mean of the per-bin ratios;
/// `pooled`: ratio of the bin-averaged squared errors (dominated by the worst bins).
struct Ratio {
  double geo, pooled;
};
Ratio sample_ratio(const std::vector<double>& a, const std::vector<double>& b, size_t from, size_t to) {
  double log_sum = 0, sa = 0, sb = 0;
  for (size_t i = from; i < to; ++i) {
    log_sum += 2.0 * std::log(a[i] / b[i]);
    sa += a[i] * a[i];
    sb += b[i] * b[i];
  }
  return {std::exp(log_sum / static_cast<double>(to - from)), sa / sb};
}

void write_csv(const std::string& path, const Setup& S, const std::vector<double>& exact,
               const std::vector<BinErrors>& err) {
  FILE* f = std::fopen(path.c_str(), "w");
  if (!f) throw std::runtime_error("cannot write " + path);
  std::fprintf(f, "bin,t_start_ps,t_center_ps,mean_free_times,exact");
  for (const Strategy& st : kStrategies)
    std::fprintf(f, ",rel_err_%s,mean_%s,se_%s,empty_runs_%s", st.name, st.name, st.name, st.name);
  std::fprintf(f, "\n");
  for (size_t i = 0; i < exact.size(); ++i) {
    const int b = static_cast<int>(i);
    std::fprintf(f, "%d,%.6g,%.6g,%.6g,%.10g", b, S.axis.bin_start_ps(b), S.axis.bin_center_ps(b),
                 S.axis.bin_center_ps(b) / S.mean_free_time_ps(), exact[i]);
    for (size_t k = 0; k < kCount; ++k)
      std::fprintf(f, ",%.6g,%.10g,%.6g,%d", err[k].rel[i], err[k].mean[i], err[k].se[i], err[k].empty_runs[i]);
    std::fprintf(f, "\n");
  }
  if (std::fclose(f) != 0) throw std::runtime_error("cannot write " + path);
}

void write_png(const std::string& path, const Setup& S, const Options& o, const std::vector<BinErrors>& err) {
  Plot p;
  p.log_y = true;
  p.x_label = "camera time t (ps)";
  p.y_label = "relative rms error";
  char title[200];
  std::snprintf(title, sizeof title, "single scattering, point light, sigma_t %.3g per mm: %d spp, %d runs",
                S.sigma_t(), o.spp, o.runs);
  p.title = title;
  p.x_min = S.axis.t_start_ps;
  p.x_max = S.axis.t_end_ps();
  p.legend = Plot::Legend::TopLeft;
  for (size_t k = 0; k < kCount; ++k) {
    PlotSeries s{kStrategies[k].name, {}, {}, kStrategies[k].color, PlotSeries::Style::Line};
    for (int i = 0; i < S.axis.bins; ++i) {
      s.x.push_back(S.axis.bin_center_ps(i));
      s.y.push_back(err[k].rel[static_cast<size_t>(i)]);
    }
    p.series.push_back(s);
  }
  Canvas canvas(1100, 640);
  draw_plot(canvas, 0, 0, canvas.width, canvas.height, p, 2);
  write_canvas_png(path, canvas);
}

int run(const Options& o) {
  const Setup S;
  const int T = S.axis.bins;
  std::vector<double> exact;
  for (int i = 0; i < T; ++i) exact.push_back(S.bin(i));
  const double s_far = S.s_of_time(S.axis.t_end_ps());
  std::printf("time_sampling: single scattering along one pixel ray, point light %.0f mm off the ray at its start,\n"
              "  delta pulse at t = 0; sigma_s %.3g, sigma_a %.3g /mm (mean free path %.0f mm, mean free time %.0f ps), "
              "g %.2f, eta %.2f\n"
              "  %d bins of %.0f ps from %.0f ps (window = %.1f mean free times; farthest vertex %.0f mm = %.1f mean "
              "free paths)\n"
              "  %d spp x %d runs per strategy (seeds %llu..), %d concurrent single-thread renders, max_depth 1\n",
              S.h, S.sigma_s, S.sigma_a, 1.0 / S.sigma_t(), S.mean_free_time_ps(), S.g, S.eta, T, S.axis.bin_width_ps,
              S.axis.t_start_ps, S.axis.t_end_ps() / S.mean_free_time_ps(), s_far, s_far * S.sigma_t(), o.spp,
              o.runs, static_cast<unsigned long long>(o.seed), o.threads);
  std::fflush(stdout);

  std::vector<std::unique_ptr<Scene>> scenes;
  for (const Strategy& st : kStrategies) scenes.push_back(std::make_unique<Scene>(S.scene(st.kind)));

  // Jobs interleave the strategies (run r: mfp, equiangular, line_to_point, mis), so machine
  // load affects each strategy's timing alike.
  const size_t R = static_cast<size_t>(o.runs);
  std::vector<std::vector<std::vector<double>>> films(kCount, std::vector<std::vector<double>>(R));
  std::vector<std::vector<double>> secs(kCount, std::vector<double>(R, 0.0));
  std::atomic<size_t> next{0};
  std::atomic<bool> failed{false};
  std::vector<std::string> errors(static_cast<size_t>(o.threads));
  const double t0 = now_s();
  auto worker = [&](size_t w) {
    try {
      for (size_t j = next++; j < R * kCount && !failed; j = next++) {
        const size_t r = j / kCount, k = j % kCount;
        RenderOptions ro;
        ro.spp = o.spp;
        ro.seed = o.seed + r;
        ro.threads = 1;
        ro.max_depth = 1;  // single scattering
        ro.quiet = true;
        const RenderResult res = render(*scenes[k], ro);
        std::vector<double>& v = films[k][r];
        for (int i = 0; i < T; ++i) v.push_back(res.film.transient()[3 * i]);
        secs[k][r] = res.wall_seconds;
        if (res.stats.nonfinite_dropped) {
          errors[w] = "non-finite contributions dropped";
          failed = true;
        }
      }
    } catch (const std::exception& e) {
      errors[w] = e.what();
      failed = true;
    }
  };
  std::vector<std::thread> pool;
  for (int w = 0; w < o.threads; ++w) pool.emplace_back(worker, static_cast<size_t>(w));
  for (std::thread& th : pool) th.join();
  for (const std::string& e : errors)
    if (!e.empty()) {
      std::fprintf(stderr, "femto-bench-time_sampling: %s\n", e.c_str());
      return 1;
    }
  const double elapsed = now_s() - t0;

  std::vector<BinErrors> err;
  for (size_t k = 0; k < kCount; ++k) err.push_back(analyse(films[k], exact));

  // Table: a subset of bins from the first to the last.
  std::printf("\n  relative RMS error per bin (RMS over runs of (estimate - exact) / exact)\n");
  std::printf("  bin  t_ps   t/mft  exact        ");
  for (const Strategy& st : kStrategies) std::printf(" %13s", st.name);
  std::printf("  mfp runs with 0\n");
  std::vector<int> shown;
  for (int i = 0; i < T; i += std::max(1, T / 12)) shown.push_back(i);
  if (shown.back() != T - 1) shown.push_back(T - 1);
  for (int i : shown) {
    const size_t b = static_cast<size_t>(i);
    std::printf("  %3d %6.0f %6.2f  %.4e", i, S.axis.bin_center_ps(i), S.axis.bin_center_ps(i) / S.mean_free_time_ps(),
                exact[b]);
    for (size_t k = 0; k < kCount; ++k) std::printf(" %13.4f", err[k].rel[b]);
    std::printf("  %5.1f%%\n", 100.0 * err[0].empty_runs[b] / static_cast<double>(R));
  }

  // Thirds of the window: RMS of the per-bin relative errors, and growth from the first third to
  // the last. Bin 0 is skipped: it holds the first arrival at h / c.
  const size_t N = exact.size(), third = N / 3;
  const size_t e0 = 1, e1 = third, m0 = third, m1 = N - third, l0 = N - third, l1 = N;
  std::printf("\n  RMS of the relative errors over the thirds of the window (early: bins %zu-%zu, mid %zu-%zu, "
              "late %zu-%zu = %.0f-%.0f ps)\n",
              e0, e1 - 1, m0, m1 - 1, l0, l1 - 1, S.axis.bin_start_ps(static_cast<int>(l0)), S.axis.t_end_ps());
  std::printf("  %-14s %9s %9s %9s %12s\n", "strategy", "early", "mid", "late", "late/early");
  for (size_t k = 0; k < kCount; ++k) {
    const double a = rms_over(err[k].rel, e0, e1), b = rms_over(err[k].rel, m0, m1), c = rms_over(err[k].rel, l0, l1);
    std::printf("  %-14s %9.4f %9.4f %9.4f %11.2fx\n", kStrategies[k].name, a, b, c, c / a);
  }

  // Cost per sample: a separate pass, one render at a time on one thread (the error runs share
  // the cores with each other), strategies interleaved, median over repetitions of a render of
  // at least 32768 samples (so per-render setup is negligible).
  const int reps = 7, timing_spp = std::max(o.spp, 32768);
  std::vector<std::vector<double>> ns(kCount);
  for (int rep = 0; rep < reps; ++rep)
    for (size_t k = 0; k < kCount; ++k) {
      RenderOptions ro;
      ro.spp = timing_spp;
      ro.seed = o.seed + 1000003 + static_cast<uint64_t>(rep);
      ro.threads = 1;
      ro.max_depth = 1;
      ro.quiet = true;
      ns[k].push_back(1e9 * render(*scenes[k], ro).wall_seconds / timing_spp);
    }
  std::vector<double> per_sample(kCount), per_run(kCount, 0.0);
  for (size_t k = 0; k < kCount; ++k) {
    std::vector<double>& v = ns[k];
    std::sort(v.begin(), v.end());
    per_sample[k] = v[v.size() / 2];
    for (double x : secs[k]) per_run[k] += x;
    per_run[k] /= static_cast<double>(R);
  }
  std::printf("\n  cost per sample: single thread, median of %d interleaved renders of %d spp (ratio to mfp); and the\n"
              "  mean wall time of the error runs' renders (%d spp, %d at a time, incl. per-render setup)\n",
              reps, timing_spp, o.spp, o.threads);
  for (size_t k = 0; k < kCount; ++k)
    std::printf("  %-14s %8.1f ns/sample  %.2fx   | %7.3f ms/run  %.2fx\n", kStrategies[k].name, per_sample[k],
                per_sample[k] / per_sample[0], 1e3 * per_run[k], per_run[k] / per_run[0]);

  std::printf("\n  equal-error ratios vs mfp: samples mfp needs / samples the strategy needs; per bin (err_mfp / err)^2\n"
              "  (error^2 ~ 1/n). 'geo' = geometric mean of the per-bin ratios, 'pooled' = mean err_mfp^2 / mean err^2\n"
              "  over the bins. Equal time = equal samples x (time per sample of mfp / of the strategy).\n");
  std::printf("  %-14s %10s %10s | %10s %10s | %10s %10s\n", "strategy", "early geo", "pooled", "late geo", "pooled",
              "late time", "pooled");
  for (size_t k = 1; k < kCount; ++k) {
    const Ratio re = sample_ratio(err[0].rel, err[k].rel, e0, e1), rl = sample_ratio(err[0].rel, err[k].rel, l0, l1);
    const double tr = per_sample[0] / per_sample[k];
    std::printf("  %-14s %9.3gx %9.3gx | %9.3gx %9.3gx | %9.3gx %9.3gx\n", kStrategies[k].name, re.geo, re.pooled,
                rl.geo, rl.pooled, rl.geo * tr, rl.pooled * tr);
  }

  // Agreement with the exact answer: the mean over runs within 4 standard errors in every bin.
  // A bin that fewer than 10 runs reached has no usable standard error (the estimate is a few
  // large values or none): it is counted as unresolved rather than tested.
  const int min_hits = 10;
  std::printf("\n  agreement with the exact answer: |mean - exact| <= 4 SE per bin (SE over runs); bins that fewer\n"
              "  than %d runs reached are unresolved, not tested\n", min_hits);
  int total_fail = 0;
  for (size_t k = 0; k < kCount; ++k) {
    int fail = 0, unresolved = 0;
    double worst = 0, sum_rel_bias = 0;
    int worst_bin = -1;
    for (size_t i = 0; i < N; ++i) {
      if (!(exact[i] > 0)) continue;
      const double diff = err[k].mean[i] - exact[i];
      sum_rel_bias += diff / exact[i];
      if (o.runs - err[k].empty_runs[i] < min_hits) {
        ++unresolved;
        continue;
      }
      const double z = diff / err[k].se[i];
      if (std::abs(diff) > 4.0 * err[k].se[i] + 1e-6 * exact[i]) ++fail;
      if (std::abs(z) > std::abs(worst)) worst = z, worst_bin = static_cast<int>(i);
    }
    total_fail += fail;
    std::printf("  %-14s failing bins %d of %zu, unresolved %d, worst z %+.2f (bin %d), "
                "mean relative deviation %+.4f\n",
                kStrategies[k].name, fail, N, unresolved, worst, worst_bin, sum_rel_bias / static_cast<double>(N));
  }
  std::printf("  %s\n", total_fail == 0 ? "all strategies agree with the exact answer"
                                          : "DISAGREEMENT: see the failing bins above (CSV: mean, se, exact)");
  std::printf("\n  total %.1f s (%.0f spp x %d runs x %zu strategies)\n", elapsed, static_cast<double>(o.spp), o.runs,
              kCount);

  if (!o.csv.empty()) {
    write_csv(o.csv, S, exact, err);
    std::printf("  wrote %s\n", o.csv.c_str());
  }
  if (!o.png.empty()) {
    write_png(o.png, S, o, err);
    std::printf("  wrote %s\n", o.png.c_str());
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  if (!parse(argc, argv, o)) {
    usage(stderr);
    return 2;
  }
  try {
    return run(o);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "femto-bench-time_sampling: %s\n", e.what());
    return 1;
  }
}
