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

#include "bench/bench_util.h"
#include "core/render.h"
#include "core/scene_loader.h"

using namespace femto;
using femto::bench::cpu_model;
using femto::bench::median;

namespace {

const char* kScene = R"({
  "camera": { "type": "perspective", "position": [0, 0, 60], "look_at": [0, 0, 0], "fov": 30,
              "resolution": [32, 32] },
  "time": { "t_start": 0, "bin_width": 2, "bins": 150 },
  "media": { "fog": { "type": "homogeneous", "sigma_a": 0.2, "sigma_s": 0.8, "g": 0.3 } },
  "shapes": [ { "type": "box", "min": [-10, -10, -10], "max": [10, 10, 10], "medium": "fog" } ],
  "lights": [ { "type": "point", "position": [2, 3, 1], "intensity": 100 } ]
})";

struct Config {
  const char* name;
  DistanceSampling distance;
  ConnectionSampling connection;
  DirectionSampling direction;
};

}  // namespace

int main(int argc, char** argv) {
  int spp = 64, reps = 5;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if ((a == "--spp" || a == "--reps") && i + 1 < argc) {
      (a == "--spp" ? spp : reps) = std::atoi(argv[++i]);
    } else {
      std::fprintf(stderr, "usage: femto-bench-speed [--spp N] [--reps N]\n");
      return 2;
    }
  }
  if (spp < 1 || reps < 1) {
    std::fprintf(stderr, "femto-bench-speed: --spp and --reps must be positive\n");
    return 2;
  }
  const SceneDesc base = load_scene_string(kScene, "<bench fog box>", ".");
  const Config configs[] = {
      {"default (mfp + auto)", base.media[0].sampling, base.media[0].connection,
       base.media[0].direction},
      {"mis + mis (old default)", DistanceSampling::Mis, ConnectionSampling::Mis,
       DirectionSampling::Phase},
      {"mfp + mis", DistanceSampling::Mfp, ConnectionSampling::Mis, DirectionSampling::Phase},
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
      "femto-bench-speed: CPU %s; fog box 32 x 32, 150 bins, %d spp, medians of %d runs, "
      "interleaved\n",
      cpu_model().c_str(), spp, reps);
  // Per configuration: wall times with 1 and 2 threads.
  std::vector<std::vector<double>> secs(static_cast<size_t>(2 * n));
  std::vector<PathStats> stats(static_cast<size_t>(n));
  for (int r = 0; r < reps; ++r)
    for (int threads : {1, 2})
      for (int k = 0; k < n; ++k) {
        RenderOptions opt;
        opt.spp = spp;
        opt.threads = threads;
        opt.quiet = true;
        opt.seed = 1;
        const RenderResult res = render(*scenes[static_cast<size_t>(k)], opt);
        secs[static_cast<size_t>(2 * k + threads - 1)].push_back(res.wall_seconds);
        stats[static_cast<size_t>(k)] = res.stats;
      }
  std::printf("%-28s %13s %13s %14s %11s\n", "configuration", "paths/s 1 thr", "paths/s 2 thr",
              "events/s 2 thr", "events/path");
  for (int k = 0; k < n; ++k) {
    const double paths = static_cast<double>(stats[static_cast<size_t>(k)].paths);
    const double events = static_cast<double>(stats[static_cast<size_t>(k)].medium_events);
    const double t1 = median(secs[static_cast<size_t>(2 * k)]);
    const double t2 = median(secs[static_cast<size_t>(2 * k + 1)]);
    std::printf("%-28s %13.3g %13.3g %14.3g %11.2f\n", configs[k].name, paths / t1, paths / t2,
                events / t2, events / paths);
  }
  std::printf("(equal-time errors of these configurations: femto-bench-sampling)\n");
  return 0;
}
