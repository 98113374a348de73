#include "core/render.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/info.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>

#include "core/progress.h"

namespace femto {

namespace {
constexpr int kTile = 16;
}

RenderResult render(const Scene& scene, const RenderOptions& opt) {
  const auto start = std::chrono::steady_clock::now();
  const Camera& camera = scene.camera();
  const int W = camera.width(), H = camera.height();
  const TimeAxis axis = scene.desc().time;
  RenderResult result{TransientFilm(W, H, axis), PathStats{}, 0.0, 0};
  const TemporalFilter filter(axis, TemporalFilter::Kind::Histogram);
  const VolPathIntegrator integrator(scene, filter, opt.max_depth);

  const int tiles_x = (W + kTile - 1) / kTile, tiles_y = (H + kTile - 1) / kTile;
  const int threads = opt.threads > 0 ? opt.threads : tbb::info::default_concurrency();
  result.threads = threads;
  Progress progress(static_cast<uint64_t>(W) * static_cast<uint64_t>(H) * static_cast<uint64_t>(opt.spp),
                    "render", opt.quiet);
  tbb::enumerable_thread_specific<PixelAccumulator> accumulators;
  tbb::enumerable_thread_specific<PathStats> stats;
  tbb::task_arena arena(threads);
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<int>(0, tiles_x * tiles_y, 1), [&](const tbb::blocked_range<int>& r) {
      PixelAccumulator& acc = accumulators.local();
      PathStats& st = stats.local();
      for (int tile = r.begin(); tile != r.end(); ++tile) {
        const int x0 = (tile % tiles_x) * kTile, y0 = (tile / tiles_x) * kTile;
        const int x1 = std::min(x0 + kTile, W), y1 = std::min(y0 + kTile, H);
        for (int y = y0; y < y1; ++y) {
          for (int x = x0; x < x1; ++x) {
            acc.reset(axis.bins);
            const uint64_t pixel = static_cast<uint64_t>(y) * static_cast<uint64_t>(W) + static_cast<uint64_t>(x);
            for (int s = 0; s < opt.spp; ++s) {
              Rng rng = Rng::for_sample(opt.seed, pixel, static_cast<uint64_t>(s));
              const double fx = x + rng.uniform(), fy = y + rng.uniform();
              integrator.trace(camera.generate_ray(fx, fy), rng, acc, st);
            }
            result.film.set_pixel(x, y, acc.bins.data(), acc.before, acc.after, opt.spp);
          }
          progress.add(static_cast<uint64_t>(x1 - x0) * static_cast<uint64_t>(opt.spp));
        }
      }
    });
  });
  progress.finish();
  for (const PathStats& s : stats) result.stats += s;
  result.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace femto
