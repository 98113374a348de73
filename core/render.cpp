#include "core/render.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/info.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cmath>

#include "core/pixel_sampler.h"
#include "core/progress.h"
#include "core/reconstruction.h"

namespace femto {

namespace {
constexpr int kTile = 16;

/// The last sample's bandwidth at the median first-pass arrival inside the window (or at the
/// window centre), for kernel_bandwidth.exr.
double typical_bandwidth(const PixelAccumulator& acc, const TimeAxis& axis) {
  const auto lo = std::lower_bound(acc.times.begin(), acc.times.end(), axis.t_start_ps);
  const auto hi = std::lower_bound(acc.times.begin(), acc.times.end(), axis.t_end_ps());
  const double t = hi > lo ? *(lo + (hi - lo) / 2) : 0.5 * (axis.t_start_ps + axis.t_end_ps());
  return acc.bandwidth_at(t);
}
}  // namespace

void render_pixel(const Scene& scene, const VolPathIntegrator& integrator,
                  const TemporalFilter& filter, const RenderOptions& opt, int x, int y,
                  PixelAccumulator& acc, PathStats& st) {
  const Camera& camera = scene.camera();
  const TimeAxis& axis = filter.axis();
  const ReconstructionDesc& rec = scene.desc().reconstruction;
  acc.reset(axis.bins);
  const uint64_t pixel =
      static_cast<uint64_t>(y) * static_cast<uint64_t>(camera.width()) + static_cast<uint64_t>(x);
  auto trace_sample = [&](int s) {
    Rng rng = Rng::for_sample(opt.seed, pixel, static_cast<uint64_t>(s));
    double dx, dy;
    pixel_offset(opt.seed, pixel, static_cast<uint64_t>(s), dx, dy);
    const double fx = x + dx, fy = y + dy;
    acc.sample = s;
    integrator.trace(camera.generate_ray(fx, fy), rng, acc, st);
  };
  if (rec.type != TemporalFilter::Kind::Kernel) {
    for (int s = 0; s < opt.spp; ++s) trace_sample(s);
    return;
  }
  acc.kernel = true;
  acc.fixed_ps = rec.bandwidth_ps;
  acc.knn = rec.knn;
  acc.cap_ps = axis.t_end_ps() - axis.t_start_ps;
  acc.fallback_ps = axis.bin_width_ps;
  // First pass: its arrival times set the bandwidth, anchored (r_j / r_P) so that its last
  // sample uses the k-NN distance itself.
  const int first_pass = rec.bandwidth_ps <= 0.0 ? std::min(opt.spp, rec.first_pass_spp) : 0;
  const double ratio_P = BandwidthSchedule::ratio_at(rec.alpha, std::max(1, first_pass));
  const double norm = first_pass > 0 ? 1.0 / ratio_P : 1.0;
  BandwidthSchedule schedule(rec.alpha);
  if (first_pass > 0) {
    acc.hold = true;
    for (int s = 0; s < first_pass; ++s) trace_sample(s);
    acc.hold = false;
    for (const PixelAccumulator::Held& h : acc.held) acc.times.push_back(h.t_ps);
    std::sort(acc.times.begin(), acc.times.end());
    if (rec.onset_reflection && !acc.times.empty()) acc.floor_ps = acc.times.front();
    for (const PixelAccumulator::Held& h : acc.held) {  // in sample order
      while (schedule.j() < h.sample + 1) schedule.advance();
      acc.scale = norm * schedule.ratio();
      acc.add_now(filter, h.t_ps, h.sigma_ps, h.value, acc.bandwidth_at(h.t_ps));
    }
  }
  while (schedule.j() < first_pass + 1) schedule.advance();
  for (int s = first_pass; s < opt.spp; ++s) {
    acc.scale = norm * schedule.ratio();
    trace_sample(s);
    schedule.advance();
  }
  // For typical_bandwidth: the progressive loop left the last sample's scale; a pixel that was
  // all first pass ends at sample P.
  if (first_pass >= opt.spp) acc.scale = norm * ratio_P;
}

RenderResult render(const Scene& scene, const RenderOptions& opt) {
  if (opt.integrator == IntegratorKind::Light) return render_light(scene, opt);
  if (opt.integrator == IntegratorKind::Photons) return render_photons(scene, opt);
  const auto start = std::chrono::steady_clock::now();
  const Camera& camera = scene.camera();
  const int W = camera.width(), H = camera.height();
  const TimeAxis axis = scene.desc().time;
  RenderResult result{TransientFilm(W, H, axis), PathStats{}, 0.0, 0, {}, {}, 0};
  const ReconstructionDesc& rec = scene.desc().reconstruction;
  const bool kernel = rec.type == TemporalFilter::Kind::Kernel;
  const TemporalFilter filter(axis, rec.type, rec.kernel);
  if (kernel)
    result.final_bandwidth_ps.assign(static_cast<size_t>(W) * static_cast<size_t>(H), 0.0f);
  const VolPathIntegrator integrator(scene, filter, opt.max_depth);

  const int tiles_x = (W + kTile - 1) / kTile, tiles_y = (H + kTile - 1) / kTile;
  // oneTBB never runs more threads than the hardware has, so that is what gets recorded.
  const int hardware = tbb::info::default_concurrency();
  const int threads = opt.threads > 0 ? std::min(opt.threads, hardware) : hardware;
  result.threads = threads;
  Progress progress(
      static_cast<uint64_t>(W) * static_cast<uint64_t>(H) * static_cast<uint64_t>(opt.spp),
      "render", opt.quiet);
  tbb::enumerable_thread_specific<PixelAccumulator> accumulators;
  tbb::enumerable_thread_specific<PathStats> stats;
  tbb::task_arena arena(threads);
  arena.execute([&] {
    tbb::parallel_for(
        tbb::blocked_range<int>(0, tiles_x * tiles_y, 1), [&](const tbb::blocked_range<int>& r) {
          PixelAccumulator& acc = accumulators.local();
          PathStats& st = stats.local();
          for (int tile = r.begin(); tile != r.end(); ++tile) {
            const int x0 = (tile % tiles_x) * kTile, y0 = (tile / tiles_x) * kTile;
            const int x1 = std::min(x0 + kTile, W), y1 = std::min(y0 + kTile, H);
            for (int y = y0; y < y1; ++y) {
              for (int x = x0; x < x1; ++x) {
                render_pixel(scene, integrator, filter, opt, x, y, acc, st);
                if (kernel)
                  result.final_bandwidth_ps[static_cast<size_t>(y) * static_cast<size_t>(W) +
                                            static_cast<size_t>(x)] =
                      static_cast<float>(typical_bandwidth(acc, axis));
                result.film.set_pixel(x, y, acc.bins.data(), acc.before, acc.after, opt.spp);
              }
              progress.add(static_cast<uint64_t>(x1 - x0) * static_cast<uint64_t>(opt.spp));
            }
          }
        });
  });
  progress.finish();
  for (const PathStats& s : stats) result.stats += s;
  result.wall_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace femto
