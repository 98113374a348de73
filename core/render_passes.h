#pragma once
// Shared by the renderers: the per-pixel double sums kept between passes (RenderState), the film
// built from them, and how large a pass is.
#include <algorithm>
#include <chrono>
#include <cmath>

#include "core/error.h"
#include "core/render.h"
#include "core/zeroed_array.h"

namespace femto::passes {

/// Square image tiles of kTile pixels: the unit of a pass's work and of the MPI ranks' bands.
constexpr int kTile = 16;

inline RGB load_rgb(const double* p) {
  return {p[0], p[1], p[2]};
}
inline void store_rgb(double* p, const RGB& c) {
  p[0] = c.r;
  p[1] = c.g;
  p[2] = c.b;
}

/// A fresh state, or the one to resume (checked against this render's shape).
inline RenderState start_state(const RenderOptions& opt, IntegratorKind kind, bool kernel,
                               size_t pixels, int bins, int64_t units_total) {
  RenderState s;
  const int stride = (bins + 2) * 3;
  if (opt.resume) {
    s = std::move(*opt.resume);
    if (s.integrator != kind || s.kernel != kernel || s.stride != stride ||
        s.sums.size() != pixels * static_cast<size_t>(stride) || s.units_total != units_total ||
        s.units_done < 0 || s.units_done > units_total ||
        (kernel && s.bandwidth_ps.size() != pixels))
      throw InputError(
          "the checkpoint's render state does not fit this render (film, integrator or length "
          "differ)");
  } else {
    s.integrator = kind;
    s.kernel = kernel;
    s.units_total = units_total;
    s.stride = stride;
    resize_in_huge_pages(s.sums, pixels * static_cast<size_t>(stride));  // few page faults
    if (kernel) s.bandwidth_ps.assign(pixels, 0.0f);
  }
  s.sessions += 1;
  return s;
}

/// Ends a pass: folds the per-thread counters into the state, adds the pass's time, hands the
/// state to after_pass (checkpoints), and says whether a stop was requested.
template <class ThreadStats>
bool end_pass(RenderState& state, ThreadStats& stats,
              std::chrono::steady_clock::time_point pass_start, const RenderOptions& opt,
              int64_t units_total) {
  for (PathStats& s : stats) {
    state.stats += s;
    s = PathStats{};
  }
  state.seconds +=
      std::chrono::duration<double>(std::chrono::steady_clock::now() - pass_start).count();
  const bool stopping = opt.stop && opt.stop->load();
  if (opt.after_pass) opt.after_pass(state, stopping || state.units_done == units_total);
  return stopping;
}

/// Sizes passes so that each takes about `seconds` (the first is one unit), or uses a fixed size.
class Planner {
 public:
  Planner(const RenderOptions& opt) : fixed_(opt.units_per_pass), seconds_(opt.pass_seconds) {}
  int64_t next(int64_t done, int64_t total) {
    int64_t n = fixed_ > 0 ? fixed_ : size_;
    start_ = std::chrono::steady_clock::now();
    last_ = std::max<int64_t>(1, std::min(n, total - done));
    return last_;
  }
  /// After the pass: the time it took sets the next size (at most 4 times larger).
  void done() {
    const double s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    const double want =
        s > 0 ? seconds_ / s * static_cast<double>(last_) : 4.0 * static_cast<double>(last_);
    size_ = std::max<int64_t>(
        1, static_cast<int64_t>(std::min(want, 4.0 * static_cast<double>(last_))));
  }

 private:
  int64_t fixed_;
  double seconds_;
  int64_t size_ = 1, last_ = 1;
  std::chrono::steady_clock::time_point start_;
};

/// Sets every pixel of `film` from the sums, divided by `n` (after multiplying by `scale`).
inline void film_from_sums(TransientFilm& film, const RenderState& s, int bins, double scale, int n,
                           const std::vector<char>* rows_done = nullptr) {
  const int W = film.width(), H = film.height();
  std::vector<double> tmp(static_cast<size_t>(bins) * 3);
  for (int y = 0; y < H; ++y) {
    if (rows_done && !(*rows_done)[static_cast<size_t>(y)]) continue;
    for (int x = 0; x < W; ++x) {
      const size_t p = static_cast<size_t>(y) * static_cast<size_t>(W) + static_cast<size_t>(x);
      const double* src = s.sums.data() + p * static_cast<size_t>(s.stride);
      const double* b = src;
      RGB before = load_rgb(src + bins * 3), after = load_rgb(src + bins * 3 + 3);
      if (scale != 1.0) {
        for (size_t i = 0; i < tmp.size(); ++i) tmp[i] = src[i] * scale;
        before *= scale;
        after *= scale;
        b = tmp.data();
      }
      film.set_pixel(x, y, b, before, after, n);
    }
  }
}

}  // namespace femto::passes
