#pragma once
// Renders a scene into a transient film with oneTBB over image tiles.
#include <algorithm>
#include <atomic>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "core/film.h"
#include "core/integrators/volpath.h"
#include "core/scene.h"

namespace femto {

namespace distributed {
class Comm;
}
struct RenderState;

struct RenderOptions {
  IntegratorKind integrator = IntegratorKind::Path;  ///< resolved (never Auto here)
  /// Light tracing: paths in all; 0 = spp x pixels. Hybrid: its light-traced share in all (spread
  /// over the passes); 0 = hybrid_light_paths_per_pass's default.
  int64_t light_paths = 0;
  /// Hybrid: the camera ball's radius, mm; < 0: camera_ball's default rule, 0: none.
  double camera_ball_mm = -1;
  PhotonDesc photons;       ///< photon mapping: per-pass photons, initial radius/bandwidth, schedule
  int spp = 16;
  uint64_t seed = 1;
  int threads = 0;       ///< 0: all hardware threads
  int max_depth = 1000;
  /// Russian roulette on camera paths: off unless set (`femto render` sets the scene's,
  /// through RenderSetup; benchmarks and tests choose it explicitly).
  RouletteDesc roulette{0, 1.0};
  bool quiet = false;    ///< no progress on stderr

  // Passes, interruption and resume. A render runs in passes (camera paths, histogram film: a
  // block of samples for every pixel; kernel film: a band of tile rows with all their samples;
  // light tracing: a batch of chunks; photons: one photon pass). The result does not depend on
  // how the work is cut into passes, so a resumed render gives the same bits.
  /// Checked after every pass: when set, the render stops there and returns what it has
  /// (RenderResult::complete = false). At least one pass always runs.
  const std::atomic<bool>* stop = nullptr;
  /// Called after every pass with the state a resumed render would continue from; `last` is true
  /// for the final pass (the render is complete or stopping).
  std::function<void(const RenderState& state, bool last)> after_pass;
  /// Continue from this state (moved from); it must come from a render with the same scene and
  /// options (the caller checks that: core/checkpoint.h).
  RenderState* resume = nullptr;
  /// Work units per pass (samples, tile rows, chunks); 0: sized so that a pass takes about
  /// `pass_seconds`. Photon passes are always one photon pass.
  int64_t units_per_pass = 0;
  double pass_seconds = 1.0;
  /// The processes sharing this render (core/distributed/comm.h; nullptr: this one alone). Each
  /// renders its share; rank 0 gets the result, bit-identical to a single process's. Not with
  /// stop, after_pass or resume.
  const distributed::Comm* comm = nullptr;
};

/// Everything a render continues from between passes (and in a checkpoint).
struct RenderState {
  IntegratorKind integrator = IntegratorKind::Path;
  bool kernel = false;         ///< camera paths with the kernel film (units are tile rows)
  int64_t units_done = 0;      ///< samples per pixel, tile rows, light chunks or photon passes done
  int64_t units_total = 0;
  int stride = 0;              ///< doubles per pixel: (bins + 2) x 3
  /// Per pixel: bins x RGB sums over the samples done, then before-window and after-window RGB.
  std::vector<double> sums;
  std::vector<float> bandwidth_ps;  ///< kernel film: each finished pixel's final bandwidth
  PathStats stats;
  double seconds = 0;          ///< render time so far (all sessions)
  int sessions = 0;            ///< runs that contributed (1 + resumes)
  // Photon mapping report so far.
  double photon_radius_last = 0, photon_bandwidth_last_ps = 0;
  uint64_t photon_max_stored = 0, photon_peak_bytes = 0;
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
    double alpha = 0, beta_t = 0;
    /// Hybrid: the caustic beams' settings (the fields above are the photons').
    bool hybrid_beams = false;
    double beam_radius_first = 0, beam_radius_last = 0, beam_bandwidth_first_ps = 0, beam_bandwidth_last_ps = 0;
    double beam_alpha = 0, beam_beta_t = 0;
    int64_t beam_paths = 0;
    int64_t hybrid_light_paths = 0;  ///< hybrid: light paths per pass for light tracing's share
    /// Photons and caustic beams: whether /render/photons/aim was on for paths that could use it,
    /// and per light the aimed cones' share of its emission (-1: not aimed;
    /// core/transport/caustic_aim.h).
    bool aim = false;
    std::vector<double> aim_share;
    double aim_paths_scale = 1;  ///< default paths per pass multiplied by this (aimed, unset)
    /// Hybrid, camera in a scattering medium: the camera ball (core/integrators/camera_ball.h),
    /// its gather kernel's slope and smallest radius at the first and after the last pass, and
    /// the most beams one pass kept in it.
    double camera_ball_radius = 0, camera_ball_slope_first = 0, camera_ball_slope_last = 0,
           camera_ball_r_min_first = 0, camera_ball_r_min_last = 0;
    uint64_t camera_ball_beams_max = 0;
    double radius_first = 0, radius_last = 0, bandwidth_first_ps = 0, bandwidth_last_ps = 0;
    uint64_t max_stored_per_pass = 0;
    uint64_t peak_photon_bytes = 0;  ///< largest photon list + grid of one pass
    /// Wall-clock seconds of this session's passes by part: tracing and building the beams, the
    /// photons, the hybrid's light paths splatted to the film, and the camera paths (gathers).
    double seconds_beams = 0, seconds_photons = 0, seconds_light_paths = 0, seconds_camera = 0;
  } photons;
  int64_t light_paths = 0;  ///< light tracing: paths traced
  /// False when the render stopped early (RenderOptions::stop): the film holds the samples done.
  bool complete = true;
  int64_t units_done = 0, units_total = 0;
  const char* unit = "samples per pixel";  ///< what the units count
  int64_t spp_done = 0;  ///< samples per pixel done (kernel film: in the finished rows)
  int sessions = 1;
};

/// Memory of the buffers a render allocates on top of the loaded scene, bytes.
struct RenderMemory {
  uint64_t film = 0;          ///< the float32 film (built at the end)
  uint64_t sums = 0;          ///< per-pixel double sums kept between passes
  uint64_t per_thread = 0;    ///< per-thread pixel accumulators, all threads
  uint64_t integrator = 0;    ///< photon pass or light-splat batch
  uint64_t outputs = 0;       ///< buffers while the outputs are written
  /// The largest of: rendering (sums, per-thread and integrator buffers), building the film from
  /// the sums, writing the outputs from the film (the sums are freed by then).
  uint64_t peak() const {
    const uint64_t rendering = sums + per_thread + integrator, building = sums + per_thread + film,
                   writing = film + outputs;
    return std::max(rendering, std::max(building, writing));
  }
};
RenderMemory render_memory(int width, int height, int bins, const RenderOptions& options,
                           int threads, bool kernel, int first_pass_spp, bool multipart_frames,
                           bool scattering_medium);

/// The integrator `kind` stands for in this scene: Auto becomes Hybrid when the scene has delta
/// lights (point, spot, laser) and non-diffuse surfaces and the film is a histogram (Beams when
/// a scattering medium lies behind specular surfaces only), else Path. `why` says which rule
/// decided.
IntegratorKind resolve_integrator(const SceneDesc& scene, IntegratorKind kind, std::string& why);
/// Whether a medium of the scene scatters (a voxel medium, or sigma_s > 0).
bool has_scattering_medium(const SceneDesc& scene);
const char* integrator_name(IntegratorKind kind);

/// Beam light paths per pass when the scene sets none: half the film's pixels, within
/// [1000, 20000].
int64_t default_beam_paths_per_pass(int64_t pixels);

/// The hybrid's caustic beam light paths per pass when the scene sets none: one per 128 pixels
/// of the film, within [500, 20000].
int64_t default_caustic_beam_paths_per_pass(int64_t pixels);

/// The hybrid's photons per pass when the scene sets none: one per two pixels of the film,
/// within [10000, 200000] (the photons integrator keeps 200000).
int64_t default_hybrid_photons_per_pass(int64_t pixels);

/// The hybrid's light paths per pass for light tracing's share (docs/ARCHITECTURE.md, "Path-space
/// partition"): one per four pixels of the film.
int64_t default_hybrid_light_paths_per_pass(int64_t pixels);

/// The hybrid's light paths per pass: options.light_paths (paths in all, the scene's
/// `light_paths` or --light-paths) spread evenly over its spp passes, at least one a pass; when
/// unset, default_hybrid_light_paths_per_pass.
int64_t hybrid_light_paths_per_pass(const RenderOptions& opt, int64_t pixels);

/// Width of one pixel at the camera's look-at distance (perspective) or of the film (orthographic).
double pixel_footprint_mm(const CameraDesc& cam);

/// `p` with its automatic values filled in for `kind`: Photons, Beams, or Hybrid for the
/// hybrid's caustic beams. Photons: 200000 per pass, R_1 = 0.5% of the scene's bounding-box
/// diagonal, alpha = 4/7, beta_t = 1/3. Beams: default_beam_paths_per_pass light paths per
/// pass, R_1 = 1% of the diagonal, alpha = 2/3, beta_t = 1/2. Caustic beams: as beams, but
/// default_caustic_beam_paths_per_pass paths and R_1 = one pixel's footprint (at most 1% of the
/// diagonal). All: T_1 = one time bin.
PhotonDesc progressive_settings(const Scene& scene, IntegratorKind kind, PhotonDesc p);

/// Traces the spp samples of pixel (x, y) into `acc` (reset first) with the scene's temporal
/// reconstruction: the whole per-pixel estimator, in double precision, before the film's float.
void render_pixel(const Scene& scene, const VolPathIntegrator& integrator, const TemporalFilter& filter,
                  const RenderOptions& opt, int x, int y, PixelAccumulator& acc, PathStats& stats);

/// Traces samples [s0, s1) of pixel (x, y) into `acc`, continuing its sums (histogram film).
void trace_samples(const Scene& scene, const VolPathIntegrator& integrator, const RenderOptions& opt, int x,
                   int y, int s0, int s1, PixelAccumulator& acc, PathStats& stats);

/// Bytes of one light-tracing batch of splats (an estimate: a few splats per light path).
uint64_t light_batch_bytes(uint64_t pixels);

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
