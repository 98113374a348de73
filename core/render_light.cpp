// femto render --integrator light: light paths splatted to the sensor.
#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/info.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>

#include "core/integrators/light_tracer.h"
#include "core/progress.h"
#include "core/render.h"

namespace femto {

namespace {
constexpr int64_t kChunk = 4096;            // light paths per task: the unit of deterministic order
constexpr int64_t kChunksPerBatch = 16;     // splats are binned into the film after each batch
constexpr uint64_t kLightStream = 0x4000000000000000ULL;  // apart from camera pixel keys
}  // namespace

RenderResult render_light(const Scene& scene, const RenderOptions& opt) {
  const auto start = std::chrono::steady_clock::now();
  const Camera& camera = scene.camera();
  const int W = camera.width(), H = camera.height();
  const TimeAxis axis = scene.desc().time;
  const TemporalFilter filter(axis, TemporalFilter::Kind::Histogram);
  RenderResult result{TransientFilm(W, H, axis), PathStats{}, 0.0, 0, {}, {}, 0};
  const size_t pixels = static_cast<size_t>(W) * static_cast<size_t>(H);
  const int64_t total = opt.light_paths > 0 ? opt.light_paths : static_cast<int64_t>(pixels) * opt.spp;
  result.light_paths = total;
  // Light-path times include the emission offset: the window end plus the widest pulse spread.
  const double t_cut = axis.t_end_ps() + 8.0 * scene.lights().max_sigma_ps();
  const LightTracer tracer(scene, opt.max_depth, t_cut);

  const size_t stride = static_cast<size_t>(axis.bins) * 3;
  std::vector<double> bins(pixels * stride, 0.0);
  std::vector<RGB> before(pixels), after(pixels);
  const int64_t chunks = (total + kChunk - 1) / kChunk;
  std::vector<std::vector<Splat>> per_chunk(static_cast<size_t>(std::min(chunks, kChunksPerBatch)));
  std::vector<uint32_t> offsets(pixels + 1);
  std::vector<const Splat*> sorted;

  const int threads = opt.threads > 0 ? opt.threads : tbb::info::default_concurrency();
  result.threads = threads;
  Progress progress(static_cast<uint64_t>(total), "light paths", opt.quiet);
  tbb::enumerable_thread_specific<PathStats> stats;
  tbb::task_arena arena(threads);
  arena.execute([&] {
    for (int64_t c0 = 0; c0 < chunks; c0 += kChunksPerBatch) {
      const int64_t c1 = std::min(chunks, c0 + kChunksPerBatch);
      tbb::parallel_for(tbb::blocked_range<int64_t>(c0, c1, 1), [&](const tbb::blocked_range<int64_t>& r) {
        PathStats& st = stats.local();
        for (int64_t c = r.begin(); c != r.end(); ++c) {
          std::vector<Splat>& out = per_chunk[static_cast<size_t>(c - c0)];
          out.clear();
          const int64_t end = std::min(total, (c + 1) * kChunk);
          for (int64_t i = c * kChunk; i < end; ++i) {
            Rng rng = Rng::for_sample(opt.seed, kLightStream, static_cast<uint64_t>(i));
            tracer.trace(rng, out, st);
          }
          progress.add(static_cast<uint64_t>(end - c * kChunk));
        }
      });
      // Bin the batch: a stable counting sort by pixel keeps path order within each pixel, so
      // every pixel sums its splats in the same order whatever the thread count.
      std::fill(offsets.begin(), offsets.end(), 0u);
      size_t n = 0;
      for (int64_t c = c0; c < c1; ++c)
        for (const Splat& s : per_chunk[static_cast<size_t>(c - c0)]) {
          ++offsets[s.pixel + 1];
          ++n;
        }
      for (size_t p = 0; p < pixels; ++p) offsets[p + 1] += offsets[p];
      sorted.resize(n);
      {
        std::vector<uint32_t> next(offsets.begin(), offsets.end() - 1);
        for (int64_t c = c0; c < c1; ++c)
          for (const Splat& s : per_chunk[static_cast<size_t>(c - c0)]) sorted[next[s.pixel]++] = &s;
      }
      tbb::parallel_for(tbb::blocked_range<size_t>(0, pixels, 256), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t p = r.begin(); p != r.end(); ++p)
          for (uint32_t k = offsets[p]; k < offsets[p + 1]; ++k) {
            const Splat& s = *sorted[k];
            const DepositSplit split = filter.deposit(s.t_ps, s.sigma_ps, s.value, bins.data() + p * stride);
            if (split.before > 0) before[p] += s.value * split.before;
            if (split.after > 0) after[p] += s.value * split.after;
          }
      });
    }
  });
  progress.finish();
  for (const PathStats& s : stats) result.stats += s;
  // Each pixel's mean radiance is its splat sum over all light paths.
  const double inv = 1.0 / static_cast<double>(total);
  for (double& b : bins) b *= inv;
  for (size_t p = 0; p < pixels; ++p) {
    before[p] *= inv;
    after[p] *= inv;
    result.film.set_pixel(static_cast<int>(p % static_cast<size_t>(W)), static_cast<int>(p / static_cast<size_t>(W)),
                          bins.data() + p * stride, before[p], after[p], 1);
  }
  result.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace femto
