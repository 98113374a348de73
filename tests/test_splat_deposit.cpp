// deposit_splats (core/integrators/splat_deposit.h): light-tracing splats from per-chunk lists
// into per-pixel sums, grouped by bands of rows and then by pixel. Checked against a plain loop
// over the splats in path order, to the last bit: values spread over 16 decades make each
// pixel's sum depend on the order of its additions, so a splat added out of path order (across
// chunks or within one), dropped, added twice, put in the wrong pixel (a band's first or last
// row, the film's last, partial band) or into a pixel `owns` rejects fails it; and the same
// bits with 1 and 4 threads. Mutants measured: a band's chunks taken in reverse order, 4 of the
// 4 checks fail; a band's sort by pixel that is not stable, 4; `owns` ignored, 2.
#include <catch2/catch.hpp>

#include <tbb/task_arena.h>

#include <cmath>
#include <vector>

#include "core/integrators/splat_deposit.h"
#include "core/rng.h"

using namespace femto;

namespace {

// Every splat has sigma 0 (one bin, or all before or after the window) and the scale is a power
// of two, so each addition is exact to the same rounding in any code: the comparison can be exact.
void reference(const std::vector<std::vector<Splat>>& lists, double scale, const TimeAxis& axis,
               size_t stride, size_t nb, bool (*owns)(size_t), std::vector<double>& sums) {
  for (const std::vector<Splat>& list : lists)
    for (const Splat& s : list) {
      if (!owns(s.pixel)) continue;
      double* px = sums.data() + s.pixel * stride;
      const int bin = axis.bin_of(s.t_ps);
      double* to = bin >= 0 ? px + 3 * bin : s.t_ps < axis.t_start_ps ? px + nb : px + nb + 3;
      for (int k = 0; k < 3; ++k) to[k] += s.value[k] * scale;
    }
}

bool every_pixel(size_t) {
  return true;
}
bool not_every_third_row(size_t p) {
  return (p / 37) % 3 != 1;
}  // a film 37 pixels wide

}  // namespace

TEST_CASE("splats reach their pixels in path order, the same with any thread count",
          "[light][splats]") {
  const int W = 37, H = 23;  // 23 rows: the last band of 4 rows has 3
  const size_t pixels = static_cast<size_t>(W) * H;
  TimeAxis axis;
  axis.t_start_ps = 100.0;
  axis.bin_width_ps = 10.0;
  axis.bins = 16;
  const size_t nb = static_cast<size_t>(axis.bins) * 3, stride = nb + 6;
  const TemporalFilter filter(axis, TemporalFilter::Kind::Histogram);
  Rng rng = Rng::for_sample(7, 0, 0);
  std::vector<std::vector<Splat>> lists(40);
  for (size_t c = 0; c < lists.size(); ++c) {
    if (c % 7 == 3) continue;  // empty chunks
    const int n = static_cast<int>(rng.uniform() * 600);
    for (int i = 0; i < n; ++i) {
      Splat s;
      // Half of them on a few pixels (band edges and the last pixel), where many meet.
      const size_t hot[] = {0, 4 * W - 1, 4 * W, 8 * W + 5, pixels - 1};
      const bool on_hot = rng.uniform() < 0.5;
      const double u = rng.uniform();
      s.pixel =
          static_cast<uint32_t>(on_hot ? hot[static_cast<int>(u * 5)]
                                       : static_cast<size_t>(u * static_cast<double>(pixels)));
      s.t_ps = 80.0 + rng.uniform() * 200.0;  // before, inside and after the window
      s.sigma_ps = 0.0;
      const double mag = std::pow(10.0, -8.0 + 16.0 * rng.uniform());
      s.value = RGB(mag * (rng.uniform() - 0.3), mag * rng.uniform(), -mag * rng.uniform());
      lists[c].push_back(s);
    }
  }
  const double scale = 0.25;
  for (bool (*owns)(size_t) : {every_pixel, not_every_third_row}) {
    // Two passes into the same sums, as two render passes.
    std::vector<double> want(pixels * stride, 0.0);
    for (int pass = 0; pass < 2; ++pass) reference(lists, scale, axis, stride, nb, owns, want);
    for (const int threads : {1, 4}) {
      std::vector<double> sums(pixels * stride, 0.0);
      SplatScratch scratch;
      size_t n = 0;
      tbb::task_arena(threads).execute([&] {
        // Twice with the same scratch, reused as across passes.
        for (int pass = 0; pass < 2; ++pass)
          n = deposit_splats(
              lists.size(), [&](size_t c) -> const std::vector<Splat>& { return lists[c]; }, scale,
              filter, W, H, stride, nb, sums.data(), owns, scratch);
      });
      size_t total = 0;
      for (const auto& l : lists) total += l.size();
      CHECK(n == total);
      size_t mismatches = 0;
      for (size_t i = 0; i < sums.size(); ++i)
        if (!(sums[i] == want[i])) ++mismatches;
      INFO("threads " << threads);
      CHECK(mismatches == 0);
    }
  }
}
