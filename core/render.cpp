#include "core/render.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/info.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cmath>

#include "core/distributed/render_gather.h"
#include "core/integrators/light_tracer.h"
#include "core/integrators/photon_beams.h"
#include "core/integrators/photon_map.h"
#include "core/integrators/splat_deposit.h"
#include "core/pixel_sampler.h"
#include "core/progress.h"
#include "core/reconstruction.h"
#include "core/render_passes.h"

namespace femto {

namespace {
using passes::kTile;

/// The last sample's bandwidth at the median first-pass arrival inside the window (or at the
/// window centre), for kernel_bandwidth.exr.
double typical_bandwidth(const PixelAccumulator& acc, const TimeAxis& axis) {
  const auto lo = std::lower_bound(acc.times.begin(), acc.times.end(), axis.t_start_ps);
  const auto hi = std::lower_bound(acc.times.begin(), acc.times.end(), axis.t_end_ps());
  const double t = hi > lo ? *(lo + (hi - lo) / 2) : 0.5 * (axis.t_start_ps + axis.t_end_ps());
  return acc.bandwidth_at(t);
}
}  // namespace

void trace_samples(const Scene& scene, const VolPathIntegrator& integrator,
                   const RenderOptions& opt, int x, int y, int s0, int s1, PixelAccumulator& acc,
                   PathStats& st) {
  const Camera& camera = scene.camera();
  const uint64_t pixel =
      static_cast<uint64_t>(y) * static_cast<uint64_t>(camera.width()) + static_cast<uint64_t>(x);
  for (int s = s0; s < s1; ++s) {
    Rng rng = Rng::for_sample(opt.seed, pixel, static_cast<uint64_t>(s));
    double dx, dy;
    pixel_offset(opt.seed, pixel, static_cast<uint64_t>(s), dx, dy);
    acc.sample = s;
    integrator.trace(camera.generate_ray(x + dx, y + dy), rng, acc, st);
  }
}

void render_pixel(const Scene& scene, const VolPathIntegrator& integrator,
                  const TemporalFilter& filter, const RenderOptions& opt, int x, int y,
                  PixelAccumulator& acc, PathStats& st) {
  const TimeAxis& axis = filter.axis();
  const ReconstructionDesc& rec = scene.desc().reconstruction;
  acc.reset(axis.bins);
  auto trace_sample = [&](int s) {
    trace_samples(scene, integrator, opt, x, y, s, s + 1, acc, st);
  };
  if (rec.type != TemporalFilter::Kind::Kernel) {
    trace_samples(scene, integrator, opt, x, y, 0, opt.spp, acc, st);
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
  if (opt.integrator == IntegratorKind::Photons || opt.integrator == IntegratorKind::Beams ||
      opt.integrator == IntegratorKind::Hybrid)
    return render_photons(scene, opt);
  const auto start = std::chrono::steady_clock::now();
  const Camera& camera = scene.camera();
  const int W = camera.width(), H = camera.height();
  const TimeAxis axis = scene.desc().time;
  const ReconstructionDesc& rec = scene.desc().reconstruction;
  const bool kernel = rec.type == TemporalFilter::Kind::Kernel;
  const TemporalFilter filter(axis, rec.type, rec.kernel);
  const VolPathIntegrator integrator(scene, filter, opt.max_depth, opt.roulette);
  const size_t pixels = static_cast<size_t>(W) * static_cast<size_t>(H);

  const int tiles_x = (W + kTile - 1) / kTile, tiles_y = (H + kTile - 1) / kTile;
  // Histogram film: a pass is a block of samples for every pixel, added to the pixel's double
  // sums in sample order, so the sums do not depend on where passes start. Kernel film: a pixel's
  // first pass sets its bandwidths for all later samples, so a pass is a band of tile rows with
  // all their samples.
  const int64_t total = kernel ? tiles_y : opt.spp;
  RenderState state =
      passes::start_state(opt, IntegratorKind::Path, kernel, pixels, axis.bins, total);
  const size_t S = static_cast<size_t>(state.stride);
  const size_t nb = static_cast<size_t>(axis.bins) * 3;

  // oneTBB never runs more threads than the hardware has, so that is what gets recorded.
  const int hardware = tbb::info::default_concurrency();
  const int threads = opt.threads > 0 ? std::min(opt.threads, hardware) : hardware;
  const uint64_t per_pixel_spp = static_cast<uint64_t>(opt.spp);
  // Across ranks, band b of tile rows is rendered by rank b % ranks; progress shows this rank's.
  const distributed::Comm& comm = opt.comm ? *opt.comm : distributed::alone();
  Progress progress(distributed::own_band_pixels(comm, W, H, kTile) * per_pixel_spp, "render",
                    opt.quiet);
  auto pixels_in_rows = [&](int64_t tile_rows) {
    return static_cast<uint64_t>(std::min<int64_t>(H, tile_rows * kTile)) *
           static_cast<uint64_t>(W);
  };
  progress.add(kernel ? pixels_in_rows(state.units_done) * per_pixel_spp
                      : static_cast<uint64_t>(pixels) * static_cast<uint64_t>(state.units_done));
  tbb::enumerable_thread_specific<PixelAccumulator> accumulators;
  tbb::enumerable_thread_specific<PathStats> stats;
  passes::Planner planner(opt);
  tbb::task_arena arena(threads);
  arena.execute([&] {
    while (state.units_done < total) {
      const auto pass_start = std::chrono::steady_clock::now();
      const int64_t u0 = state.units_done, u1 = u0 + planner.next(u0, total);
      const int tile0 = kernel ? static_cast<int>(u0) * tiles_x : 0;
      const int tile1 = kernel ? static_cast<int>(u1) * tiles_x : tiles_x * tiles_y;
      tbb::parallel_for(
          tbb::blocked_range<int>(tile0, tile1, 1), [&](const tbb::blocked_range<int>& r) {
            PixelAccumulator& acc = accumulators.local();
            PathStats& st = stats.local();
            for (int tile = r.begin(); tile != r.end(); ++tile) {
              if (!comm.owns(tile / tiles_x)) continue;
              const int x0 = (tile % tiles_x) * kTile, y0 = (tile / tiles_x) * kTile;
              const int x1 = std::min(x0 + kTile, W), y1 = std::min(y0 + kTile, H);
              for (int y = y0; y < y1; ++y) {
                for (int x = x0; x < x1; ++x) {
                  const size_t p =
                      static_cast<size_t>(y) * static_cast<size_t>(W) + static_cast<size_t>(x);
                  double* sums = state.sums.data() + p * S;
                  if (kernel) {
                    render_pixel(scene, integrator, filter, opt, x, y, acc, st);
                    state.bandwidth_ps[p] = static_cast<float>(typical_bandwidth(acc, axis));
                  } else {
                    // Continue the pixel's sums with samples [u0, u1).
                    acc.reset(axis.bins);
                    std::copy(sums, sums + nb, acc.bins.begin());
                    acc.before = passes::load_rgb(sums + nb);
                    acc.after = passes::load_rgb(sums + nb + 3);
                    trace_samples(scene, integrator, opt, x, y, static_cast<int>(u0),
                                  static_cast<int>(u1), acc, st);
                  }
                  std::copy(acc.bins.begin(), acc.bins.end(), sums);
                  passes::store_rgb(sums + nb, acc.before);
                  passes::store_rgb(sums + nb + 3, acc.after);
                }
                progress.add(static_cast<uint64_t>(x1 - x0) *
                             (kernel ? per_pixel_spp : static_cast<uint64_t>(u1 - u0)));
              }
            }
          });
      planner.done();
      state.units_done = u1;
      if (passes::end_pass(state, stats, pass_start, opt, total)) break;
    }
  });
  progress.finish();
  distributed::gather_bands(comm, state, W, H, kTile);

  RenderResult result{TransientFilm(W, H, axis), state.stats, state.seconds, threads, {}, {}, 0};
  result.complete = state.units_done == total;
  result.units_done = state.units_done;
  result.units_total = total;
  result.sessions = state.sessions;
  if (kernel) {
    result.unit = "tile rows of 16 pixels (all samples)";
    std::vector<char> rows(static_cast<size_t>(H), 0);
    for (int y = 0; y < H && y < state.units_done * kTile; ++y) rows[static_cast<size_t>(y)] = 1;
    passes::film_from_sums(result.film, state, axis.bins, 1.0, opt.spp, &rows);
    result.spp_done = state.units_done > 0 ? opt.spp : 0;
    result.final_bandwidth_ps = std::move(state.bandwidth_ps);
  } else {
    result.unit = "samples per pixel";
    passes::film_from_sums(result.film, state, axis.bins, 1.0, static_cast<int>(state.units_done));
    result.spp_done = state.units_done;
  }
  (void)start;
  return result;
}

RenderMemory render_memory(int width, int height, int bins, const RenderOptions& opt, int threads,
                           bool kernel, int first_pass_spp, bool multipart_frames,
                           bool scattering_medium) {
  RenderMemory m;
  const uint64_t pixels = static_cast<uint64_t>(width) * static_cast<uint64_t>(height);
  const uint64_t B = static_cast<uint64_t>(bins);
  m.film = TransientFilm::memory_bytes(width, height, bins);
  m.sums = pixels * (B + 2) * 3 * sizeof(double) + (kernel ? pixels * sizeof(float) : 0);
  // A pixel accumulator per thread; the kernel film's first pass holds its deposits (a few per
  // sample) and their arrival times.
  const uint64_t held = kernel ? static_cast<uint64_t>(first_pass_spp) * 8 *
                                     (sizeof(PixelAccumulator::Held) + sizeof(double))
                               : 0;
  m.per_thread = static_cast<uint64_t>(std::max(1, threads)) * (B * 3 * sizeof(double) + held);
  if (opt.integrator == IntegratorKind::Photons || opt.integrator == IntegratorKind::Hybrid)
    m.integrator =
        photon_pass_bytes(opt.photons.per_pass > 0 ? opt.photons.per_pass
                          : opt.integrator == IntegratorKind::Hybrid
                              ? default_hybrid_photons_per_pass(static_cast<int64_t>(pixels))
                              : 200000);
  // Beams: an estimate (the beams a light path leaves depend on the scene), about 8 per path
  // for all beams; the hybrid's caustic beams end at the path's first scattering, about 2, and
  // without a scattering medium it traces none.
  if (opt.integrator == IntegratorKind::Beams ||
      (opt.integrator == IntegratorKind::Hybrid && scattering_medium))
    m.integrator += beam_pass_bytes(
        (opt.integrator == IntegratorKind::Beams ? 8 : 2) *
        static_cast<uint64_t>(
            opt.photons.per_pass > 0 ? opt.photons.per_pass
            : opt.integrator == IntegratorKind::Beams
                ? default_beam_paths_per_pass(static_cast<int64_t>(pixels))
                : default_caustic_beam_paths_per_pass(static_cast<int64_t>(pixels))));
  // The hybrid's light-traced share: its splats and their sort.
  if (opt.integrator == IntegratorKind::Hybrid)
    m.integrator += splat_bytes(static_cast<uint64_t>(
                        hybrid_light_paths_per_pass(opt, static_cast<int64_t>(pixels)))) +
                    (pixels + 1) * sizeof(uint32_t);
  if (opt.integrator == IntegratorKind::Light) m.integrator = light_batch_bytes(pixels);
  // Writing: a frame, the peak-time image, the contact sheet's 16 frames and its 8-bit image,
  // the 8-bit preview; a multipart EXR is written from the film itself.
  const uint64_t frame = pixels * 3 * sizeof(float);
  m.outputs = frame + pixels * sizeof(float) + 16 * frame + 16 * pixels * 3 + pixels * 3;
  (void)multipart_frames;
  return m;
}

}  // namespace femto
