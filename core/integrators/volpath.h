#pragma once
// Transient volumetric path tracer: camera paths with mean-free-path distance sampling in
// homogeneous media, next-event estimation through media and index-matched boundaries, and MIS
// between light sampling and phase/BSDF sampling for area lights. Each contribution is stamped
// with its path's time of flight (sum of eta * length / c over segments, plus the light's
// emission time) and deposited into the pixel's time bins.
#include <cstdint>
#include <vector>

#include "core/pixel_accumulator.h"
#include "core/rng.h"
#include "core/scene.h"
#include "core/temporal_filter.h"
#include "samplers/medium_distance.h"

namespace femto {

/// Counters of one render; integer sums, so merging per-thread copies is deterministic.
struct PathStats {
  uint64_t paths = 0;
  uint64_t medium_events = 0;      ///< real scattering events in media
  uint64_t surface_events = 0;     ///< reflections/refractions at surfaces
  uint64_t null_crossings = 0;     ///< passes through index-matched boundaries
  uint64_t max_depth_hits = 0;     ///< paths stopped by the max-depth safety bound
  uint64_t nonfinite_dropped = 0;  ///< contributions dropped for being NaN or infinite
  PathStats& operator+=(const PathStats& o);
};

class VolPathIntegrator {
 public:
  VolPathIntegrator(const Scene& scene, const TemporalFilter& filter, int max_depth);

  /// Traces one camera path starting on `ray` (in the outside medium) and adds its
  /// contributions to `acc`.
  void trace(Ray ray, Rng& rng, PixelAccumulator& acc, PathStats& stats) const;

  /// Path time beyond which no contribution can reach the window, ps.
  double time_cutoff_ps() const { return t_cut_; }

 private:
  /// Transmittance and time of flight of a straight connection x -> x + dist * wi starting in
  /// medium m, passing through index-matched boundaries; false if an opaque or refracting
  /// surface blocks it.
  bool connect(const Vec3& x, int m, const Vec3& wi, double dist, double& Tr, double& time_ps,
               PathStats& stats) const;
  /// Collision sampling on one ray segment: `main` continues the path; under MIS `extra` is the
  /// time-uniform collision, used for next-event estimation only.
  struct MediumSample {
    DistanceEvent main;
    double main_nee_weight = 1.0;  ///< extra factor for next-event estimation at `main`
    DistanceEvent extra;
    double extra_nee_weight = 0.0;
  };
  /// Next collision in `med` along `ray` before s_max (a surface, or infinity).
  MediumSample sample_medium(const Medium& med, const Ray& ray, double s_max, Rng& rng) const;
  template <class Segments>
  MediumSample finish_sample(Segments& segments, const DistanceStrategy& st, double u1, Rng& rng) const;
  /// Next-event estimation from a medium point x reached along direction d with throughput beta.
  void estimate_direct_medium(const Vec3& x, int m, const Vec3& d, double g, const RGB& beta, double t,
                              Rng& rng, PixelAccumulator& acc, PathStats& stats) const;
  /// Optical depth and optical path length of [0, s] along `ray` inside medium m.
  void segment_integrals(int m, const Ray& ray, double s, double& tau, double& opl) const;
  void deposit(double t_ps, double sigma_ps, const RGB& value, PixelAccumulator& acc,
               PathStats& stats) const;

  const Scene& scene_;
  TemporalFilter filter_;
  int max_depth_;
  bool unwarp_;
  double t_cut_;
};

}  // namespace femto
