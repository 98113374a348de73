// femto-bench-speed: camera-path throughput of the transient path tracer on a small dense fog
// scene (a homogeneous box, sigma_t = 1/mm, albedo 0.8, g = 0.3, a point light inside it,
// 32 x 32 pixels, 150 time bins) for the sampling configurations users choose between. The
// configurations run interleaved, repeated, and their medians are reported, so the ratios come
// from one run on one (noisy, shared) machine.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "core/render.h"
#include "core/scene_loader.h"

using namespace femto;

namespace {

const char* kScene = R"({
  "camera": { "type": "perspective", "position": [0, 0, 60], "look_at": [0, 0, 0], "fov": 30,
              "resolution": [32, 32] },
  "time": { "t_start": 0, "bin_width": 2, "bins": 150 },
  "media": { "fog": { "type": "homogeneous", "sigma_a": 0.2, "sigma_s": 0.8, "g": 0.3 } },
  "shapes": [ { "type": "box", "min": [-10, -10, -10], "max": [10, 10, 10], "medium": "fog" } ],
  "lights": [ { "type": "point", "position": [2, 3, 1], "intensity": 100 } ]
})";

std::string cpu_model() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("model name", 0) == 0) return line.substr(line.find(':') + 2);
  return "unknown";
}

struct Config {
  const char* name;
  DistanceSampling distance;
  ConnectionSampling connection;
  DirectionSampling direction;
};

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
  int spp = 64, reps = 8;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if ((a == "--spp" || a == "--reps") && i + 1 < argc) {
      (a == "--spp" ? spp : reps) = std::atoi(argv[++i]);
    } else {
      std::fprintf(stderr, "usage: femto-bench-speed [--spp N] [--reps N (seeds, >= 2)]\n");
      return 2;
    }
  }
  if (spp < 1 || reps < 2) {
    std::fprintf(stderr, "femto-bench-speed: --spp must be positive and --reps at least 2\n");
    return 2;
  }
  const SceneDesc base = load_scene_string(kScene, "<bench fog box>", ".");
  const Config configs[] = {
      {"default (mis + mis, phase)", base.media[0].sampling, base.media[0].connection,
       base.media[0].direction},
      {"mfp + mis", DistanceSampling::Mfp, ConnectionSampling::Mis, DirectionSampling::Phase},
      {"mis + equiangular", DistanceSampling::Mis, ConnectionSampling::Equiangular,
       DirectionSampling::Phase},
      {"mfp + line_to_point", DistanceSampling::Mfp, ConnectionSampling::LineToPoint,
       DirectionSampling::Phase},
      {"mfp + equiangular", DistanceSampling::Mfp, ConnectionSampling::Equiangular,
       DirectionSampling::Phase},
      {"mfp + collision", DistanceSampling::Mfp, ConnectionSampling::Collision,
       DirectionSampling::Phase},
  };
  const int n = static_cast<int>(sizeof(configs) / sizeof(configs[0]));
  std::vector<std::unique_ptr<Scene>> scenes;
  for (const Config& c : configs) {
    SceneDesc d = base;
    d.media[0].sampling = c.distance;
    d.media[0].connection = c.connection;
    d.media[0].direction = c.direction;
    scenes.push_back(std::make_unique<Scene>(d));
  }
  std::printf(
      "femto-bench-speed: CPU %s; fog box 32 x 32, 150 bins, %d spp, %d seeds per configuration, "
      "interleaved\n",
      cpu_model().c_str(), spp, reps);
  // Per configuration: wall times with 1 and 2 threads, and each seed's film (2 threads) for the
  // per-cell variance across seeds.
  std::vector<std::vector<double>> secs(static_cast<size_t>(2 * n));
  std::vector<PathStats> stats(static_cast<size_t>(n));
  std::vector<std::vector<std::vector<float>>> films(static_cast<size_t>(n));
  for (int r = 0; r < reps; ++r)
    for (int threads : {1, 2})
      for (int k = 0; k < n; ++k) {
        RenderOptions opt;
        opt.spp = spp;
        opt.threads = threads;
        opt.quiet = true;
        opt.seed = 1 + static_cast<uint64_t>(r);
        const RenderResult res = render(*scenes[static_cast<size_t>(k)], opt);
        secs[static_cast<size_t>(2 * k + threads - 1)].push_back(res.wall_seconds);
        stats[static_cast<size_t>(k)] = res.stats;
        if (threads == 2) {
          // Cells: pixel x bin, the three channels summed.
          const TransientFilm& f = res.film;
          const size_t cells = static_cast<size_t>(f.width() * f.height() * f.bins());
          std::vector<float> c(cells);
          for (size_t i = 0; i < cells; ++i)
            c[i] = f.transient()[3 * i] + f.transient()[3 * i + 1] + f.transient()[3 * i + 2];
          films[static_cast<size_t>(k)].push_back(std::move(c));
        }
      }
  // Error of each configuration against a reference made of all the others (they estimate the
  // same light; leaving the configuration itself out keeps its error uncorrelated with the
  // reference). Per cell (pixel x bin): the mean squared error of one seed's film, times the
  // 1-thread render time; efficiency = that of mfp + collision over that of the configuration.
  // A squared error, not a variance: an estimator whose rare large values are missed by most
  // runs shows up as a shortfall in every run.
  const size_t cells = films[0][0].size();
  std::vector<std::vector<double>> mean(static_cast<size_t>(n), std::vector<double>(cells, 0.0));
  for (int k = 0; k < n; ++k)
    for (const auto& f : films[static_cast<size_t>(k)])
      for (size_t i = 0; i < cells; ++i) mean[static_cast<size_t>(k)][i] += static_cast<double>(f[i]) / reps;
  std::vector<double> pooled(cells, 0.0);
  for (int k = 0; k < n; ++k)
    for (size_t i = 0; i < cells; ++i) pooled[i] += mean[static_cast<size_t>(k)][i] / n;
  // Cells with signal: pooled mean above 1% of its 99.9th percentile (a robust peak).
  std::vector<double> sorted = pooled;
  std::sort(sorted.begin(), sorted.end());
  const double peak = sorted[sorted.size() - 1 - sorted.size() / 1000];
  auto mse_of = [&](int k) {
    std::vector<double> mse(cells, 0.0);
    for (size_t i = 0; i < cells; ++i) {
      const double ref = (pooled[i] * n - mean[static_cast<size_t>(k)][i]) / (n - 1);
      for (const auto& f : films[static_cast<size_t>(k)])
        mse[i] += (f[i] - ref) * (f[i] - ref) / reps;
    }
    return mse;
  };
  const std::vector<double> mse_c = mse_of(n - 1);
  const double time_c = median(secs[static_cast<size_t>(2 * (n - 1))]);
  double pooled_total = 0;
  for (size_t i = 0; i < cells; ++i) pooled_total += pooled[i];
  std::printf("%-28s %13s %13s %14s %11s  %s\n", "configuration", "paths/s 1 thr",
              "paths/s 2 thr", "events/s 2 thr", "events/path",
              "equal-time efficiency vs mfp + collision (median / 1% worst cells), film total");
  for (int k = 0; k < n; ++k) {
    const double paths = static_cast<double>(stats[static_cast<size_t>(k)].paths);
    const double events = static_cast<double>(stats[static_cast<size_t>(k)].medium_events);
    const double t1 = median(secs[static_cast<size_t>(2 * k)]);
    const double t2 = median(secs[static_cast<size_t>(2 * k + 1)]);
    const std::vector<double> mse = mse_of(k);
    std::vector<double> eff;
    for (size_t i = 0; i < cells; ++i)
      if (pooled[i] > 0.01 * peak && mse[i] > 0 && mse_c[i] > 0)
        eff.push_back((mse_c[i] * time_c) / (mse[i] * t1));
    std::sort(eff.begin(), eff.end());
    const double med = eff.empty() ? 0 : eff[eff.size() / 2];
    const double worst = eff.empty() ? 0 : eff[eff.size() / 100];
    // The film total per seed, relative to the pooled total: mean and standard error.
    std::vector<double> totals;
    for (const auto& f : films[static_cast<size_t>(k)]) {
      double sum = 0;
      for (size_t i = 0; i < cells; ++i) sum += f[i];
      totals.push_back(sum / pooled_total);
    }
    double tm = 0, tv = 0;
    for (double x : totals) tm += x / reps;
    for (double x : totals) tv += (x - tm) * (x - tm) / (reps - 1);
    std::printf("%-28s %13.3g %13.3g %14.3g %11.2f  %6.2fx / %.3fx, total %.3f +- %.3f\n",
                configs[k].name, paths / t1, paths / t2, events / t2, events / paths, med, worst,
                tm, std::sqrt(tv / reps));
  }
  std::printf(
      "efficiency: per pixel-bin cell (channels summed; cells above 1%% of the robust peak), mean "
      "squared error of one render against the mean of all other configurations, times the "
      "1-thread time; mfp + collision's over the configuration's (> 1: better). 1%% worst: the "
      "1st percentile over cells. total: the film's sum over the pooled mean's, +- its standard "
      "error over seeds\n");
  return 0;
}
