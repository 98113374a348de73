#pragma once
// The transient film: H x W x T x RGB float32 (bin-integrated radiance: summing over the bins of
// a pixel gives its steady radiance within the window), plus per-pixel steady and
// outside-the-window images.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/spectrum.h"
#include "core/temporal_filter.h"
#include "core/time_axis.h"

namespace femto {

class TransientFilm {
 public:
  TransientFilm(int width, int height, const TimeAxis& axis);

  /// Bytes the film will allocate for these dimensions (checked before allocating).
  static uint64_t memory_bytes(int width, int height, int bins);

  int width() const { return width_; }
  int height() const { return height_; }
  int bins() const { return axis_.bins; }
  const TimeAxis& axis() const { return axis_; }

  /// Sets every NaN or infinite value (transient, steady, before, after) to 0 and returns how many
  /// there were: a finite contribution can still overflow float32, and outputs must stay finite.
  uint64_t zero_nonfinite();

  /// Stores a finished pixel: `bins` holds T x 3 sums over samples, divided here by `spp`.
  void set_pixel(int x, int y, const double* bins, const RGB& before, const RGB& after, int spp);

  /// Layout (H, W, T, 3), C order.
  const float* transient() const { return transient_.data(); }
  const float* steady() const { return steady_.data(); }        ///< (H, W, 3)
  const float* before() const { return before_.data(); }        ///< (H, W, 3)
  const float* after() const { return after_.data(); }          ///< (H, W, 3)
  /// Time (ps, bin centre) of each pixel's brightest bin by luminance; NaN where all bins are 0.
  std::vector<float> peak_time() const;
  /// Frame t as (H, W, 3).
  std::vector<float> frame(int t) const;
  /// Sums over all pixels, in a fixed order (so they are deterministic).
  RGB total_steady() const;
  RGB total_before() const;
  RGB total_after() const;

 private:
  int width_, height_;
  TimeAxis axis_;
  std::vector<float> transient_, steady_, before_, after_;
};

}  // namespace femto
