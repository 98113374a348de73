// femto render --integrator light: light paths splatted to the sensor.
#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/info.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include "core/distributed/bytes.h"
#include "core/distributed/render_gather.h"
#include "core/integrators/light_tracer.h"
#include "core/integrators/splat_deposit.h"
#include "core/progress.h"
#include "core/render.h"
#include "core/render_passes.h"

namespace femto {

namespace {
constexpr int64_t kChunk = 4096;         // light paths per task: the unit of deterministic order
constexpr int64_t kChunksPerBatch = 16;  // splats are binned into the film after each batch
constexpr uint64_t kLightStream = 0x4000000000000000ULL;  // apart from camera pixel keys
}  // namespace

uint64_t light_batch_bytes(uint64_t pixels) {
  // A batch's splats and their sort, and at most a film's worth of per-pixel offsets.
  return splat_bytes(static_cast<uint64_t>(kChunk * kChunksPerBatch)) +
         (pixels + 1) * sizeof(uint32_t);
}

RenderResult render_light(const Scene& scene, const RenderOptions& opt) {
  const Camera& camera = scene.camera();
  const int W = camera.width(), H = camera.height();
  const TimeAxis axis = scene.desc().time;
  const TemporalFilter filter(axis, TemporalFilter::Kind::Histogram);
  const size_t pixels = static_cast<size_t>(W) * static_cast<size_t>(H);
  const int64_t total =
      opt.light_paths > 0 ? opt.light_paths : static_cast<int64_t>(pixels) * opt.spp;
  // Light-path times include the emission offset: the window end plus the widest pulse spread.
  const double t_cut = axis.t_end_ps() + 8.0 * scene.lights().max_sigma_ps();
  const LightTracer tracer(scene, opt.max_depth, t_cut);

  const int64_t chunks = (total + kChunk - 1) / kChunk;
  // A pass is one batch of chunks: the unit of checkpoints.
  const int64_t batches = (chunks + kChunksPerBatch - 1) / kChunksPerBatch;
  RenderState state =
      passes::start_state(opt, IntegratorKind::Light, false, pixels, axis.bins, batches);
  const size_t stride = static_cast<size_t>(state.stride);
  const size_t nb = static_cast<size_t>(axis.bins) * 3;
  std::vector<std::vector<Splat>> per_chunk(static_cast<size_t>(std::min(chunks, kChunksPerBatch)));
  SplatScratch scratch;

  const int threads = opt.threads > 0 ? opt.threads : tbb::info::default_concurrency();
  // Across ranks, chunk c is traced by rank c % ranks; after each batch, rank 0 receives the
  // other ranks' splats by chunk and bins the whole batch in path order as a single process does.
  const distributed::Comm& comm = opt.comm ? *opt.comm : distributed::alone();
  uint64_t own_paths = 0;
  for (int64_t c = 0; c < chunks; ++c)
    if (comm.owns(c)) own_paths += static_cast<uint64_t>(std::min(total, (c + 1) * kChunk) - c * kChunk);
  Progress progress(own_paths, "light paths", opt.quiet);
  progress.add(static_cast<uint64_t>(std::min(total, state.units_done * kChunksPerBatch * kChunk)));
  tbb::enumerable_thread_specific<PathStats> stats;
  tbb::task_arena arena(threads);
  arena.execute([&] {
    while (state.units_done < batches) {
      const auto pass_start = std::chrono::steady_clock::now();
      const int64_t c0 = state.units_done * kChunksPerBatch;
      const int64_t c1 = std::min(chunks, c0 + kChunksPerBatch);
      tbb::parallel_for(
          tbb::blocked_range<int64_t>(c0, c1, 1), [&](const tbb::blocked_range<int64_t>& r) {
            PathStats& st = stats.local();
            for (int64_t c = r.begin(); c != r.end(); ++c) {
              if (!comm.owns(c)) continue;
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
      if (!comm.single()) {
        distributed::ByteWriter mine;
        if (!comm.root())
          for (int64_t c = c0; c < c1; ++c)
            if (comm.owns(c)) mine.put_vector(per_chunk[static_cast<size_t>(c - c0)]);
        comm.gather(mine.bytes(), [&](int rank, const std::vector<char>& bytes) {
          if (rank == 0) return;
          distributed::ByteReader in(bytes);
          for (int64_t c = c0; c < c1; ++c)
            if (c % comm.size() == rank)
              per_chunk[static_cast<size_t>(c - c0)] = in.get_vector<Splat>();
        });
        if (!comm.root()) {  // rank 0 bins the batch
          ++state.units_done;
          passes::end_pass(state, stats, pass_start, opt, batches);
          continue;
        }
      }
      // Bin the batch: every pixel sums its splats in path order whatever the thread count.
      deposit_splats(
          static_cast<size_t>(c1 - c0),
          [&](size_t c) -> const std::vector<Splat>& { return per_chunk[c]; }, 1.0, filter, W, H,
          stride, nb, state.sums.data(), [](size_t) { return true; }, scratch);
      ++state.units_done;
      if (passes::end_pass(state, stats, pass_start, opt, batches)) break;
    }
  });
  progress.finish();
  distributed::sum_stats(comm, state.stats);
  per_chunk.clear();
  per_chunk.shrink_to_fit();
  scratch.by_band = {};
  scratch.by_pixel = {};
#if defined(__GLIBC__)
  // The splat lists grew in the heap, whose freed pages stay resident: hand them back before
  // the film is built (the memory estimate counts film and sums, not the splats, at that point).
  malloc_trim(0);
#endif
  RenderResult result{TransientFilm(W, H, axis), state.stats, state.seconds, threads, {}, {}, 0};
  const int64_t done = std::min(total, state.units_done * kChunksPerBatch * kChunk);
  result.light_paths = done;
  result.complete = state.units_done == batches;
  result.units_done = state.units_done;
  result.units_total = batches;
  result.unit = "batches of 65536 light paths";
  result.spp_done = state.units_done == batches ? opt.spp : 0;
  result.sessions = state.sessions;
  // Each pixel's mean radiance is its splat sum over all light paths.
  if (done > 0)
    passes::film_from_sums(result.film, state, axis.bins, 1.0 / static_cast<double>(done), 1);
  return result;
}

}  // namespace femto
