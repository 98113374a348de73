#pragma once
// Light-tracing splats binned into per-pixel double sums in a fixed order: every pixel adds its
// splats in path order whatever the thread count. The splats arrive as per-chunk lists in path
// order; they are grouped into bands of film rows (in parallel over chunks), then each band is
// sorted by pixel and deposited on its own (in parallel over bands), so nothing is copied and
// no step runs serially over all splats.
#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cstdint>
#include <vector>

#include "core/integrators/light_tracer.h"
#include "core/render_passes.h"
#include "core/temporal_filter.h"

namespace femto {

/// Memory of the splats of `light_paths` light paths and of their sort, for the estimate made
/// before a render: about 16 splats per path (one per splatted vertex and up to four per medium
/// ray piece the camera sees; measured 16.2 in the default scene, 12.5 in laser_fog.json), lists
/// grown by doubling (on average 1.5x their size) and two pointers per splat.
inline uint64_t splat_bytes(uint64_t light_paths) {
  return light_paths * 16 * (sizeof(Splat) * 3 / 2 + 2 * sizeof(const Splat*));
}

/// Scratch space of deposit_splats, kept across passes so that its memory is reused.
struct SplatScratch {
  std::vector<uint32_t> slots;         ///< chunks x bands: counts, then each chunk's next slot
  std::vector<size_t> band_start;      ///< bands + 1
  std::vector<const Splat*> by_band;   ///< grouped by band, path order within
  std::vector<const Splat*> by_pixel;  ///< within each band's range, grouped by pixel
  tbb::enumerable_thread_specific<std::vector<uint32_t>> pixel_offsets;  ///< one band's pixels
};

/// Adds scale x every splat of the lists list(0), ..., list(chunks - 1) (path order: chunk by
/// chunk) whose pixel `owns(pixel)` accepts to `sums` (per pixel: `stride` doubles, the bins then
/// before- and after-window RGB at offset nb). Returns the number of splats.
template <class ListOf, class Owns>
size_t deposit_splats(size_t chunks, ListOf&& list, double scale, const TemporalFilter& filter,
                      int width, int height, size_t stride, size_t nb, double* sums, Owns&& owns,
                      SplatScratch& scratch) {
  constexpr int kBandRows = 4;  // a band's sums (4 rows of pixels) stay in cache while binned
  const size_t band_px = static_cast<size_t>(width) * kBandRows;
  const size_t pixels = static_cast<size_t>(width) * static_cast<size_t>(height);
  const size_t bands = (pixels + band_px - 1) / band_px;
  std::vector<uint32_t>& slots = scratch.slots;
  slots.assign(chunks * bands, 0u);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, chunks, 1),
                    [&](const tbb::blocked_range<size_t>& r) {
                      for (size_t c = r.begin(); c != r.end(); ++c)
                        for (const Splat& s : list(c)) ++slots[c * bands + s.pixel / band_px];
                    });
  // Slots band by band, chunk by chunk within a band: path order within every band.
  scratch.band_start.resize(bands + 1);
  size_t total = 0;
  for (size_t b = 0; b < bands; ++b) {
    scratch.band_start[b] = total;
    for (size_t c = 0; c < chunks; ++c) {
      const uint32_t n = slots[c * bands + b];
      slots[c * bands + b] = static_cast<uint32_t>(total);
      total += n;
    }
  }
  scratch.band_start[bands] = total;
  scratch.by_band.resize(total);
  scratch.by_pixel.resize(total);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, chunks, 1),
                    [&](const tbb::blocked_range<size_t>& r) {
                      for (size_t c = r.begin(); c != r.end(); ++c) {
                        uint32_t* next = slots.data() + c * bands;
                        for (const Splat& s : list(c))
                          scratch.by_band[next[s.pixel / band_px]++] = &s;
                      }
                    });
  tbb::parallel_for(
      tbb::blocked_range<size_t>(0, bands, 1), [&](const tbb::blocked_range<size_t>& r) {
        std::vector<uint32_t>& offsets = scratch.pixel_offsets.local();
        for (size_t b = r.begin(); b != r.end(); ++b) {
          const size_t i0 = scratch.band_start[b], i1 = scratch.band_start[b + 1];
          if (i0 == i1) continue;
          const size_t p0 = b * band_px, n_px = std::min(band_px, pixels - p0);
          // A stable counting sort of the band's splats by pixel.
          offsets.assign(n_px + 1, 0u);
          for (size_t i = i0; i < i1; ++i) ++offsets[scratch.by_band[i]->pixel - p0 + 1];
          for (size_t p = 0; p < n_px; ++p) offsets[p + 1] += offsets[p];
          for (size_t i = i0; i < i1; ++i) {
            const Splat* s = scratch.by_band[i];
            scratch.by_pixel[i0 + offsets[s->pixel - p0]++] = s;
          }
          // offsets[p] now ends pixel p's run (and starts pixel p + 1's).
          size_t k = i0;
          for (size_t q = 0; q < n_px; ++q) {
            const size_t k_end = i0 + offsets[q];
            const size_t p = p0 + q;
            if (k == k_end || !owns(p)) {
              k = k_end;
              continue;
            }
            double* px = sums + p * stride;
            RGB before = passes::load_rgb(px + nb), after = passes::load_rgb(px + nb + 3);
            for (; k < k_end; ++k) {
              const Splat& s = *scratch.by_pixel[k];
              const RGB v = s.value * scale;
              const DepositSplit split = filter.deposit(s.t_ps, s.sigma_ps, v, px);
              if (split.before > 0) before += v * split.before;
              if (split.after > 0) after += v * split.after;
            }
            passes::store_rgb(px + nb, before);
            passes::store_rgb(px + nb + 3, after);
          }
        }
      });
  return total;
}

}  // namespace femto
