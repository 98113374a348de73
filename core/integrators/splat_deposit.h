#pragma once
// Light-tracing splats binned into per-pixel double sums in a fixed order: a stable counting sort
// by pixel keeps path order within each pixel, so every pixel adds its splats in the same order
// whatever the thread count.
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cstdint>
#include <vector>

#include "core/integrators/light_tracer.h"
#include "core/render_passes.h"
#include "core/temporal_filter.h"

namespace femto {

/// Adds scale x every splat of `splats` whose pixel `owns(pixel)` accepts to `sums` (per pixel:
/// `stride` doubles, the bins then before- and after-window RGB at offset nb). `offsets` and
/// `sorted` are scratch space kept across calls.
template <class Owns>
void deposit_splats(const std::vector<Splat>& splats, double scale, const TemporalFilter& filter,
                    size_t pixels, size_t stride, size_t nb, double* sums, Owns&& owns,
                    std::vector<uint32_t>& offsets, std::vector<const Splat*>& sorted) {
  offsets.assign(pixels + 1, 0u);
  for (const Splat& s : splats) ++offsets[s.pixel + 1];
  for (size_t p = 0; p < pixels; ++p) offsets[p + 1] += offsets[p];
  sorted.resize(splats.size());
  {
    std::vector<uint32_t> next(offsets.begin(), offsets.end() - 1);
    for (const Splat& s : splats) sorted[next[s.pixel]++] = &s;
  }
  tbb::parallel_for(
      tbb::blocked_range<size_t>(0, pixels, 256), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t p = r.begin(); p != r.end(); ++p) {
          if (offsets[p] == offsets[p + 1] || !owns(p)) continue;
          double* px = sums + p * stride;
          RGB before = passes::load_rgb(px + nb), after = passes::load_rgb(px + nb + 3);
          for (uint32_t k = offsets[p]; k < offsets[p + 1]; ++k) {
            const Splat& s = *sorted[k];
            const RGB v = s.value * scale;
            const DepositSplit split = filter.deposit(s.t_ps, s.sigma_ps, v, px);
            if (split.before > 0) before += v * split.before;
            if (split.after > 0) after += v * split.after;
          }
          passes::store_rgb(px + nb, before);
          passes::store_rgb(px + nb + 3, after);
        }
      });
}

}  // namespace femto
