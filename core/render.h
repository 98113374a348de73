#pragma once
// Renders a scene into a transient film with oneTBB over image tiles.
#include <cstdint>
#include <string>
#include <vector>

#include "core/film.h"
#include "core/integrators/volpath.h"
#include "core/scene.h"

namespace femto {

struct RenderOptions {
  IntegratorKind integrator = IntegratorKind::Path;  ///< resolved (never Auto here)
  int64_t light_paths = 0;  ///< light tracing: paths in all; 0 = spp x pixels
  PhotonDesc photons;       ///< photon mapping: per-pass photons, initial radius/bandwidth, schedule
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
  /// Photon mapping: what was used (radius and bandwidth at the first and last pass, mm and ps).
  struct PhotonReport {
    int passes = 0;
    int64_t per_pass = 0;
    double radius_first = 0, radius_last = 0, bandwidth_first_ps = 0, bandwidth_last_ps = 0;
    uint64_t max_stored_per_pass = 0;
    uint64_t peak_photon_bytes = 0;  ///< largest photon list + grid of one pass
  } photons;
  int64_t light_paths = 0;  ///< light tracing: paths traced
};

/// The integrator `kind` stands for in this scene: Auto becomes Photons when the scene has
/// delta lights (point, spot, laser) and non-diffuse surfaces and the film is a histogram, else
/// Path. `why` says which rule decided.
IntegratorKind resolve_integrator(const SceneDesc& scene, IntegratorKind kind, std::string& why);
const char* integrator_name(IntegratorKind kind);

/// Default initial photon gather radius: 0.5% of the scene's bounding-box diagonal, mm.
double default_photon_radius(const Scene& scene);
/// Default initial temporal bandwidth: one time bin, ps.
double default_photon_bandwidth(const SceneDesc& scene);

/// Traces the spp samples of pixel (x, y) into `acc` (reset first) with the scene's temporal
/// reconstruction: the whole per-pixel estimator, in double precision, before the film's float.
void render_pixel(const Scene& scene, const VolPathIntegrator& integrator, const TemporalFilter& filter,
                  const RenderOptions& opt, int x, int y, PixelAccumulator& acc, PathStats& stats);

/// Traces spp paths per pixel and reconstructs time with the scene's `reconstruction`. The result is bit-identical for a given seed whatever the thread
/// count: every sample has its own random stream and each pixel sums its samples in order.
/// Dispatches on options.integrator: camera paths, light tracing (render_light) or camera paths
/// plus photons (render_photons).
RenderResult render(const Scene& scene, const RenderOptions& options);
/// Light tracing: options.light_paths paths (or spp x pixels) splatted to the sensor.
/// Bit-identical for any thread count: paths are traced in fixed chunks and each pixel sums its
/// splats in path order.
RenderResult render_light(const Scene& scene, const RenderOptions& options);
/// Transient progressive photon mapping: spp passes, each of options.photons.per_pass photons and
/// one camera sample per pixel that gathers them at diffuse surfaces with that pass's radius and
/// bandwidth (core/integrators/ppm_schedule.h).
RenderResult render_photons(const Scene& scene, const RenderOptions& options);

}  // namespace femto
