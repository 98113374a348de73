#include "core/distributed/render_gather.h"

#include <algorithm>
#include <cstring>
#include <stdexcept>
#include <string>

#include "core/distributed/bytes.h"

namespace femto::distributed {

namespace {
constexpr size_t kCounters = sizeof(PathStats) / sizeof(uint64_t);
static_assert(sizeof(PathStats) == kCounters * sizeof(uint64_t), "PathStats holds uint64 counters");

std::vector<uint64_t> counters(const PathStats& s) {
  std::vector<uint64_t> v(kCounters);
  std::memcpy(v.data(), &s, sizeof(PathStats));
  return v;
}
}  // namespace

void sum_stats(const Comm& comm, PathStats& stats) {
  if (comm.single()) return;
  std::vector<uint64_t> v = counters(stats);
  comm.sum_to_root(v);
  if (comm.root()) std::memcpy(static_cast<void*>(&stats), v.data(), sizeof(PathStats));
}

uint64_t own_band_pixels(const Comm& comm, int width, int height, int band_rows) {
  uint64_t n = 0;
  for (int b = 0, y0 = 0; y0 < height; ++b, y0 += band_rows)
    if (comm.owns(b)) n += static_cast<uint64_t>(std::min(band_rows, height - y0)) * width;
  return n;
}

void gather_bands(const Comm& comm, RenderState& state, int width, int height, int band_rows) {
  if (comm.single()) return;
  sum_stats(comm, state.stats);
  const size_t stride = static_cast<size_t>(state.stride), W = static_cast<size_t>(width);
  const bool kernel = !state.bandwidth_ps.empty();
  // Visits the bands of rank r: first pixel and pixel count of each.
  auto for_bands = [&](int r, auto&& f) {
    for (int b = 0, y0 = 0; y0 < height; ++b, y0 += band_rows)
      if (b % comm.size() == r)
        f(static_cast<size_t>(y0) * W, static_cast<size_t>(std::min(band_rows, height - y0)) * W);
  };
  ByteWriter out;
  if (!comm.root())
    for_bands(comm.rank(), [&](size_t p0, size_t n) {
      out.put_array(state.sums.data() + p0 * stride, n * stride);
      if (kernel) out.put_array(state.bandwidth_ps.data() + p0, n);
    });
  comm.gather(out.bytes(), [&](int r, const std::vector<char>& bytes) {
    if (r == 0) return;
    ByteReader in(bytes);
    for_bands(r, [&](size_t p0, size_t n) {
      in.get_array(state.sums.data() + p0 * stride, n * stride);
      if (kernel) in.get_array(state.bandwidth_ps.data() + p0, n);
    });
    if (!in.done())
      throw std::runtime_error("distributed: rank " + std::to_string(r) +
                               " sent a film of another size");
  });
}

}  // namespace femto::distributed
