#pragma once
// Transient volumetric path tracer: camera paths through media and surfaces (core/bsdf),
// next-event estimation through media and index-matched boundaries, and MIS between light
// sampling and phase/BSDF sampling for area lights. Each contribution is stamped with its path's
// time of flight (sum of eta * length / c over segments, plus the light's emission time) and
// deposited into the pixel's time bins. With a photon pass (core/integrators/photon_map.h) the
// tracer gathers caustic photons at diffuse surfaces and leaves those paths to them.
#include <cstdint>
#include <optional>
#include <vector>

#include "core/bsdf/bsdf.h"
#include "core/pixel_accumulator.h"
#include "core/rng.h"
#include "core/scene.h"
#include "core/temporal_filter.h"
#include "core/transport/tracker.h"
#include "samplers/equiangular.h"
#include "samplers/line_to_point.h"
#include "samplers/medium_distance.h"

namespace femto {

struct PhotonGather;
struct BeamGather;

class VolPathIntegrator {
 public:
  VolPathIntegrator(const Scene& scene, const TemporalFilter& filter, int max_depth,
                    const RouletteDesc& roulette = {0, 1.0});

  /// Traces one camera path starting on `ray` (in the outside medium) and adds its
  /// contributions to `acc`. With `photons`, caustic paths (light -> non-diffuse surfaces ->
  /// diffuse surface) come from the photons gathered at diffuse vertices, not from this path.
  /// With `beams`, light scattered in a medium before the path's first non-specular surface
  /// comes from photon beams gathered along those segments. With `light_indirect`, when the
  /// path's first vertex is a medium vertex x_c, only light arriving there directly (next-event
  /// estimation, emission hit) comes from this path: light that scattered or passed a surface
  /// before reaching x_c comes from light tracing (LightTracer::Vertices::MediumIndirect), and
  /// no caustic beams are gathered on the camera's own segment; a laser's light there (its beam)
  /// and at a first surface vertex (its spot) is light tracing's too. When x_c is a diffuse
  /// surface, light tracing gives the light reaching it from a medium scattering (on the segments
  /// leaving x_c through specular surfaces this path takes no medium light), from a diffuse surface
  /// through specular ones, and from the light through non-diffuse surfaces only (no photons
  /// are gathered at x_c).
  void trace(Ray ray, Rng& rng, PixelAccumulator& acc, PathStats& stats,
             const PhotonGather* photons = nullptr, const BeamGather* beams = nullptr,
             bool light_indirect = false) const;

  /// Path time beyond which no contribution can reach the window, ps.
  double time_cutoff_ps() const { return t_cut_; }

 private:
  /// Angular direction sampling at a collision (one-sample MIS of phase and angular sampling):
  /// `u` is drawn before the direction and is also the next segment's raw distance draw, so
  /// r_aux (the segment length angular sampling assumes) is shared by every strategy's weights.
  struct DirectionMix {
    bool active = false;
    double u = 0;          ///< raw uniform of the next segment's main distance draw
    double r_aux = 0;      ///< segment length implied by u at the vertex, mm
    double eta = 1;        ///< index at the vertex
    double t = 0;          ///< path time at the vertex, ps
    double valid_pmf = 0;  ///< total pick probability of the point lights whose window is reachable
  };
  /// `depth`: the vertices before the next segment (for a mixture's share).
  DirectionMix direction_mix(const Medium& med, const Vec3& x, double t, double u, int depth) const;
  /// Time-uniform share of a `mixture` medium's distance draw on a segment from x at path time t
  /// after `depth` vertices.
  double mixture_share(const Medium& med, const Vec3& x, double t, int depth) const;
  /// Density (per steradian) of direction w at x: phase alone, or the phase/angular mixture.
  double direction_pdf(const DirectionMix& mix, const Vec3& x, const Vec3& d, double g,
                       const Vec3& w) const;
  double angular_pdf(const DirectionMix& mix, const Vec3& x, const Vec3& w) const;
  /// Samples the next direction; returns f / pdf (1 for phase sampling alone) and the pdf.
  double sample_direction(const DirectionMix& mix, const Vec3& x, const Vec3& d, double g, Rng& rng,
                          Vec3& w, double& pdf) const;
  /// A segment's line-to-point connection to light L: the sampler, its window and the end of the
  /// reachable part. The connection and the collisions' MIS weights both use it.
  struct LineToPointTarget {
    bool valid = false;  ///< some s in [0, s_end) connects inside the window
    double s_end = 0;    ///< beyond it no connection can reach the window, mm
    LineToPointSampler lp;
    LineToPointSampler::Window win;
  };
  /// The segment a medium vertex lies on, as far as segment connections are concerned: which
  /// point and spot lights estimate_segment has already gathered along it.
  struct ConnectedSegment {
    bool active = false;   ///< some point or spot light is gathered by connections on this segment
    bool all = false;      ///< every point light (an explicit strategy), else connection_choice.h
    bool decided = false;  ///< auto with a single point light: active says it all
    /// auto on a camera segment whose window spans many mean free paths: point lights that
    /// `covers` leaves to the collisions also get one line-to-point connection, and the two
    /// strategies share that light by the balance heuristic (connection_choice.h).
    bool time_mis = false;
    /// time_mis on an optically thin segment with every point light outside the scattering
    /// media (connection_choice.h, third rule): for every such light, not only those behind the
    /// segment's start.
    bool thin = false;
    /// auto with mean-free-path distances: a point light near the segment (connect_segment_to)
    /// is shared between one equiangular connection and the collisions' next-event estimation by
    /// the balance heuristic instead of left to the connection alone.
    bool near_mis = false;
    // Set by plan_segment when a flag is: not initialised here, so a path's plan costs no
    // zeroing.
    const Ray* ray_ptr;
    double s_surf;
    double sigma_t;  ///< spread_sigma_t at ray.o: set only where a rule reads it (needs_spread)
    /// The medium's row of light_sigma_t_ (by light index): the first rule's extinction per light.
    const double* light_sigma_t;
    double t, t_factor;  ///< path time at ray.o (ps) and the OPL -> time factor
    const Ray& ray() const { return *ray_ptr; }
    /// No connections: every flag down.
    void reset() {
      active = all = decided = time_mis = thin = near_mis = false;
      lp_target.reset();
      eq_target.reset();
    }
    /// The extinction the first rule (connect_segment_to) uses for light li.
    double near_sigma_t(int li) const {
      return light_sigma_t[li] > 0 ? light_sigma_t[li] : sigma_t;
    }
    bool covers(int li, const Light& light) const;
    /// time_mis for this light: the light lies behind the segment's start (lights_from_start).
    bool mis_with_collisions(const Light& light) const;
    /// near_mis for light li: a point light near the segment.
    bool pairs_equiangular(int li, const Light& light) const;
    /// With a single point light that mis_with_collisions: its target, made once per segment.
    std::optional<LineToPointTarget> lp_target;
    /// With a single point light that pairs_equiangular: its sampler (near_equiangular), made
    /// once per segment for the connection and the collisions' weights.
    std::optional<EquiangularSampler> eq_target;
  };
  /// The segment's connection plan, decided once per segment (and without random draws, so a
  /// segment that connects nothing costs a few flops). m: the index of `med` in the scene's
  /// media. t, t_factor: as for estimate_segment.
  /// Fills the path's one `segment`, resetting only its flags: the rest is read only when a flag
  /// is set, and zeroing the whole struct per segment cost 6% of a render.
  void plan_segment(const Medium& med, int m, const Ray& ray, double s_surf, double t,
                    double t_factor, bool camera_segment, ConnectedSegment& segment) const;
  /// A segment's line-to-point connection to light L (narrow: with its window).
  LineToPointTarget line_to_point_target(const Medium& med, const ConnectedSegment& segment,
                                         const Light& L, bool narrow_window) const;
  /// A segment's equiangular connection to point light L over the stretch whose vertices can
  /// reach the film window.
  EquiangularSampler near_equiangular(const Medium& med, const ConnectedSegment& segment,
                                      const Light& L) const;
  /// Next-event estimation from a medium point x reached along direction d with throughput beta.
  /// `mix` (may be null) gives the direction density for MIS with area lights; point and spot
  /// lights that `segment` covers are left to estimate_segment. collision: the segment's
  /// mean-free-path collision when x is it (else null): its density sigma_t exp(-tau) weighs it
  /// against the segment's connections.
  void estimate_direct_medium(const Vec3& x, int m, const Vec3& d, double g, const RGB& beta,
                              double t, const DirectionMix* mix, const ConnectedSegment& segment,
                              const DistanceEvent* collision, Rng& rng, PixelAccumulator& acc,
                              PathStats& stats) const;
  /// Direct light from a point or spot light scattered anywhere on [0, s_surf) of the segment's
  /// ray in medium m (equiangular, line-to-point, or both by MIS; on time_mis segments also
  /// line-to-point with the collisions by MIS).
  void estimate_segment(const Medium& med, int m, const ConnectedSegment& segment, const RGB& beta,
                        Rng& rng, PixelAccumulator& acc, PathStats& stats) const;
  /// Direct light from every laser scattered anywhere on [0, s_surf) of the segment's ray in
  /// medium m: one point on the stretch inside each beam (core/laser_cylinder.h), drawn with the
  /// decay of both transmittances along it (core/integrators/laser_chords.cpp). Collision
  /// next-event estimation leaves lasers to it.
  void estimate_laser_chords(const Medium& med, int m, const Ray& ray, double s_surf, double t,
                             double t_factor, const RGB& beta, Rng& rng, PixelAccumulator& acc,
                             PathStats& stats) const;
  void deposit(double t_ps, double sigma_ps, const RGB& value, PixelAccumulator& acc,
               PathStats& stats) const;
  /// Russian roulette after the vertex at `depth`: false ends the path; a survivor's beta is
  /// divided by its probability.
  bool survives_roulette(int depth, RGB& beta, Rng& rng, PathStats& stats) const {
    if (roulette_.depth <= 0 || depth < roulette_.depth) return true;
    const double q = beta.max_component() / roulette_.threshold;
    if (q >= 1.0) return true;
    if (rng.uniform() >= q) {
      ++stats.roulette_ends;
      return false;
    }
    beta *= 1.0 / q;
    return true;
  }
  /// Next-event estimation at a surface vertex with a non-delta BSDF (local frame z = ng); m_wo
  /// is the medium on the side of wo (the path's). Without `lasers` a laser picked gives nothing
  /// (light tracing's share).
  void estimate_direct_surface(const Bsdf& bsdf, const SurfaceHit& hit, const Frame& frame,
                               const Vec3& wo, bool wo_outside, int m_wo, const RGB& beta, double t,
                               bool lasers, Rng& rng, PixelAccumulator& acc,
                               PathStats& stats) const;

  const Scene& scene_;
  MediumTracker tracker_;
  TemporalFilter filter_;
  int max_depth_;
  RouletteDesc roulette_;
  bool unwarp_;
  double t_cut_;
  std::vector<int> point_lights_;  ///< point and spot lights: targets of angular sampling
  /// Per medium: connection_choice.h's third rule applies (thin_media_lit_from_outside).
  std::vector<char> thin_media_;
  /// Per medium: no point light can ever connect on its segments under the first rule
  /// (media_far_from_lights), so plan_segment skips the rules where no other one applies.
  std::vector<char> far_media_;
  /// Per medium and light (m * lights + li): the extinction at a point light inside a voxel
  /// medium, which sets the collisions' density at the peak of its direct term on every segment
  /// that passes near it (connection_choice.h's first rule); 0 where the segment's own
  /// spread_sigma_t stands in (homogeneous media, lights in empty voxels or outside the grid).
  std::vector<double> light_sigma_t_;
  /// Per medium: some point light's first rule reads the segment's spread_sigma_t.
  std::vector<char> needs_spread_;
  std::vector<double> point_pmf_;  ///< their pick probabilities, proportional to power
  std::vector<int> lasers_;        ///< lasers: targets of laser chords
};

}  // namespace femto
