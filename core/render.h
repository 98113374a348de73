#pragma once
// Renders a scene into a transient film with oneTBB over image tiles.
#include <cstdint>
#include <vector>

#include "core/film.h"
#include "core/integrators/volpath.h"
#include "core/scene.h"

namespace femto {

struct RenderOptions {
  int spp = 16;
  uint64_t seed = 1;
  int threads = 0;       ///< 0: all hardware threads
  int max_depth = 1000;
  bool quiet = false;    ///< no progress on stderr
};

struct RenderResult {
  TransientFilm film;
  PathStats stats;
  double wall_seconds = 0;
  int threads = 0;  ///< threads used: the requested count, at most the hardware's
  /// Kernel film: bandwidth (ps) of each pixel's last sample, (H, W); empty for the histogram.
  std::vector<float> final_bandwidth_ps;
};

/// Traces the spp samples of pixel (x, y) into `acc` (reset first) with the scene's temporal
/// reconstruction: the whole per-pixel estimator, in double precision, before the film's float.
void render_pixel(const Scene& scene, const VolPathIntegrator& integrator, const TemporalFilter& filter,
                  const RenderOptions& opt, int x, int y, PixelAccumulator& acc, PathStats& stats);

/// Traces spp paths per pixel and reconstructs time with the scene's `reconstruction`. The result is bit-identical for a given seed whatever the thread
/// count: every sample has its own random stream and each pixel sums its samples in order.
RenderResult render(const Scene& scene, const RenderOptions& options);

}  // namespace femto
