#pragma once
// Tracking through the media of a scene, shared by camera paths, light paths and photon tracing:
// collision sampling on one ray segment, and transmittance plus time of flight of a straight
// connection (walking through index-matched boundaries).
#include "core/rng.h"
#include "core/scene.h"
#include "samplers/medium_distance.h"

namespace femto {

/// Counters of one render; integer sums, so merging per-thread copies is deterministic.
struct PathStats {
  uint64_t paths = 0;
  uint64_t medium_events = 0;      ///< real scattering events in media
  uint64_t surface_events = 0;     ///< reflections/refractions at surfaces
  uint64_t null_crossings = 0;     ///< passes through index-matched boundaries
  uint64_t max_depth_hits = 0;     ///< paths stopped by the max-depth safety bound
  uint64_t roulette_ends = 0;      ///< camera paths ended by Russian roulette
  uint64_t nonfinite_dropped = 0;  ///< contributions dropped for being NaN or infinite
  uint64_t light_paths = 0;        ///< light sub-paths (light tracing and photons)
  uint64_t photons_stored = 0;     ///< photons kept for gathering
  uint64_t photon_gathers = 0;     ///< camera vertices that gathered photons
  uint64_t beams_stored = 0;       ///< photon-beam segments kept for gathering
  uint64_t beam_gathers = 0;       ///< beam crossings that added to the image
  PathStats& operator+=(const PathStats& o);
};

/// Collision sampling on one ray segment: `main` continues the path; under MIS `extra` is the
/// time-uniform collision, used for connections (next-event estimation, camera splats) only.
struct MediumSample {
  DistanceEvent main;
  double main_nee_weight = 1.0;  ///< extra factor for connections made at `main`
  DistanceEvent extra;
  double extra_nee_weight = 0.0;
};

class MediumTracker {
 public:
  explicit MediumTracker(const Scene& scene) : scene_(scene) {}

  /// Next collision in `med` along `ray` before s_max (a surface, or infinity).
  /// `u_main` >= 0 replaces the main distance draw (angular direction sampling draws it early);
  /// `q_tu` is the time-uniform share of a `mixture` medium (0: mean free path, as light paths
  /// use).
  MediumSample sample(const Medium& med, const Ray& ray, double s_max, Rng& rng, double u_main = -1,
                      double q_tu = 0) const;
  /// Transmittance and time of flight of a straight connection x -> x + dist * w starting in
  /// medium m, passing through index-matched boundaries; false if a surface with a material
  /// blocks it.
  bool connect(const Vec3& x, int m, const Vec3& w, double dist, double& Tr, double& time_ps,
               PathStats& stats) const;
  /// Optical depth and optical path length of [0, s] along `ray` inside medium m.
  void segment_integrals(int m, const Ray& ray, double s, double& tau, double& opl) const;
  /// Single-scattering albedo of medium `med` at x.
  static double albedo_at(const Medium& med, const Vec3& x) {
    return med.type == Medium::Type::Grid ? med.grid->albedo_at(x) : med.homogeneous.albedo();
  }

 private:
  template <class Segments>
  MediumSample finish(Segments& segments, const DistanceStrategy& st, double u1, double q_tu,
                      Rng& rng) const;

  const Scene& scene_;
};

/// Guards against rays trapped between coincident index-matched faces.
constexpr int kMaxNullCrossings = 4096;

}  // namespace femto
