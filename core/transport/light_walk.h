#pragma once
// The random walk of light sub-paths, written once: emission from any light (with its pulse),
// distance sampling and per-voxel OPL timing in media, index-matched boundaries, and surface
// scattering through the BSDF module in importance (flux) transport. What to record is the
// caller's visitor: a splat to the camera (light tracing), a photon store, later beams and
// tallies. The visitor is a template parameter, so the walk has no per-step virtual call.
#include <cmath>
#include <limits>

#include "core/bsdf/bsdf.h"
#include "core/constants.h"
#include "core/rng.h"
#include "core/scene.h"
#include "core/transport/caustic_aim.h"
#include "core/transport/tracker.h"
#include "media/phase_hg.h"

namespace femto {

/// One vertex of a light sub-path, as handed to the visitor.
struct LightVertex {
  enum class Kind { Emitter, Surface, Medium, Segment, Ray };
  Kind kind = Kind::Medium;
  Vec3 p;                           ///< position
  Vec3 d;                           ///< propagation direction of the path arriving at p
  Vec3 n;                           ///< emitter: unit emitting normal
  int medium = 0;                   ///< medium the path arrived through
  const SurfaceHit* hit = nullptr;  ///< surface vertices
  const Bsdf* bsdf = nullptr;       ///< surface vertices
  const Frame* frame = nullptr;     ///< surface vertices: local frame, z = hit->ng
  Vec3 wo;                          ///< surface vertices: -d in the local frame
  double g = 0;                     ///< medium vertices: HG asymmetry
  RGB beta;                         ///< flux weight arriving at p (emitter: Le / pdf_pos)
  double t_ps = 0;                  ///< emission time (pulse centre) + flight time to p
  double sigma_ps = 0;              ///< the light's pulse std
  /// Non-diffuse surfaces met since emission, or -1 once the path has scattered in a medium or
  /// off a diffuse surface (the caustic-path test of the photon partition).
  int chain = 0;
  /// Segment (photon beams): the straight piece of path in a scattering medium that starts at p
  /// along d, up to the next collision sampled by mean free path or the next surface (infinite if
  /// it escapes); beta and t_ps are at its start. Mean-free-path sampling makes the chance of the
  /// segment reaching s exactly the transmittance to s, so a beam needs no transmittance of its
  /// own.
  /// Ray (light tracing's sensor connections): the straight piece of path in a scattering medium
  /// that starts at p along d, up to the next surface (length; infinite if none), visited before
  /// its distance is sampled.
  double length = 0;
  /// A medium vertex for connections only (the time-uniform collision of MIS distance sampling):
  /// the path does not continue from it.
  bool connection_only = false;
  /// The path's light is a laser (its first medium rays are the beam itself).
  bool collimated = false;
};

/// Medium a ray starts in: the interior of the first medium boundary it leaves, else the
/// outside of the first it enters, else the global medium. Surfaces that bound no medium are
/// passed: one may cross a medium's boundary (a mirror standing half in a fog box), so its single
/// outside medium does not say which side of that boundary the origin is on.
inline int medium_at_origin(const Scene& scene, Ray ray) {
  for (int passed = 0; passed < 64; ++passed) {
    SurfaceHit hit;
    if (!scene.geometry().intersect(ray, 0.0, std::numeric_limits<double>::infinity(), hit))
      return scene.global_medium();
    if (scene.bounds_medium(hit.shape))
      return dot(ray.d, hit.ng) > 0 ? scene.inside_medium(hit.shape)
                                    : scene.outside_medium(hit.shape);
    ray.o = hit.p + ray.d * scene.ray_epsilon();
  }
  return scene.medium_at(ray.o);
}

/// Traces one light sub-path from a light picked by power. `visit(const LightVertex&)` returns
/// whether the path goes on. Paths stop at t_cut_ps, at max_depth scattering vertices (counted),
/// or when the visitor stops them. With `segments`, distances in media are sampled by mean free
/// path whatever the medium's strategy, and every segment in a scattering medium is visited too.
/// With `rays`, every straight piece in a scattering medium that may still hold a scattering
/// vertex (depth below max_depth) is visited as a Ray before its distance is sampled.
/// With `aim`, the lights it aims emit only towards the non-diffuse shapes: for visitors that
/// store nothing unless the path meets one of those before anything else (core/transport/
/// caustic_aim.h).
template <class Visitor>
void walk_light_path(const Scene& scene, const MediumTracker& tracker, Rng& rng, int max_depth,
                     double t_cut_ps, PathStats& stats, Visitor&& visit, bool segments = false,
                     bool rays = false, const CausticAim* aim = nullptr) {
  const LightSet& lights = scene.lights();
  const auto& media = scene.media();
  const auto& shapes = scene.desc().shapes;
  const double eps = scene.ray_epsilon();
  ++stats.light_paths;
  double pmf = 0;
  const int li = lights.pick(rng.uniform(), pmf);
  const double u1 = rng.uniform(), u2 = rng.uniform(), u3 = rng.uniform(), u4 = rng.uniform();
  LightEmission e;
  if (li < 0) return;
  const Light& L = lights.light(li);
  // An aimed light draws its cone with u3, which point and spot emission leave unused.
  if (aim && aim->aims(li) ? !aim->sample_emission(L, li, u3, u1, u2, e)
                           : !lights.sample_emission(li, u1, u2, u3, u4, e))
    return;

  LightVertex v;
  const bool collimated = L.type == Light::Type::Laser;
  v.t_ps = L.pulse.offset_ps;
  v.sigma_ps = L.pulse.sigma_ps();
  Ray ray = e.ray;
  if (e.area) {
    ray.o = ray.o + e.n * eps;
    v.kind = LightVertex::Kind::Emitter;
    v.p = e.ray.o;
    v.n = e.n;
    v.medium = medium_at_origin(scene, {ray.o, e.n});
    v.beta = e.Le_over_pdf_pos / pmf;
    if (!visit(static_cast<const LightVertex&>(v))) return;
  }
  RGB beta = e.beta / pmf;
  double t = L.pulse.offset_ps;
  int m = medium_at_origin(scene, ray);
  int depth = 0, null_crossings = 0, chain = 0;

  for (;;) {
    SurfaceHit hit;
    const bool found =
        scene.geometry().intersect(ray, 0.0, std::numeric_limits<double>::infinity(), hit);
    const double s_surf = found ? hit.s : std::numeric_limits<double>::infinity();
    const Medium& region = media[static_cast<size_t>(m)];
    // A straight piece of the path from ray.o (a Ray or a beam Segment).
    auto visit_piece = [&](LightVertex::Kind kind, double length) {
      LightVertex piece;
      piece.kind = kind;
      piece.p = ray.o;
      piece.d = ray.d;
      piece.medium = m;
      piece.g = region.g();
      piece.beta = beta;
      piece.t_ps = t;
      piece.sigma_ps = v.sigma_ps;
      piece.chain = chain;
      piece.collimated = collimated;
      piece.length = length;
      visit(static_cast<const LightVertex&>(piece));
    };
    if (rays && depth < max_depth && region.interacts())
      visit_piece(LightVertex::Kind::Ray, s_surf);
    Medium mfp_copy;
    if (segments) {
      mfp_copy = region;
      mfp_copy.strategy.kind = DistanceSampling::Mfp;
    }
    const Medium& med = segments ? mfp_copy : region;
    const MediumSample ms = tracker.sample(med, ray, s_surf, rng);
    const bool scatters = med.type == Medium::Type::Grid || med.homogeneous.sigma_s > 0;
    if (segments && scatters) visit_piece(LightVertex::Kind::Segment, ms.main.s);
    if (ms.extra.collided && depth < max_depth) {
      const Vec3 x2 = ray.at(ms.extra.s);
      LightVertex c;
      c.kind = LightVertex::Kind::Medium;
      c.p = x2;
      c.d = ray.d;
      c.medium = m;
      c.g = med.g();
      c.beta = beta * (MediumTracker::albedo_at(med, x2) * ms.extra_nee_weight);
      c.t_ps = t + ms.extra.opl / kSpeedOfLight;
      c.sigma_ps = v.sigma_ps;
      c.chain = -1;
      c.connection_only = true;
      c.collimated = collimated;
      visit(static_cast<const LightVertex&>(c));
    }
    const DistanceEvent& ev = ms.main;
    if (!ev.collided && !found) return;  // escaped
    beta *= ev.weight;
    t += ev.opl / kSpeedOfLight;
    if (t > t_cut_ps || beta.is_black()) return;

    if (ev.collided) {
      ++stats.medium_events;
      if (depth >= max_depth) {
        ++stats.max_depth_hits;
        return;
      }
      ++depth;
      const Vec3 x = ray.at(ev.s);
      beta *= MediumTracker::albedo_at(med, x);
      if (beta.is_black()) return;
      chain = -1;
      v = LightVertex{};
      v.kind = LightVertex::Kind::Medium;
      v.p = x;
      v.d = ray.d;
      v.medium = m;
      v.g = med.g();
      v.beta = beta * ms.main_nee_weight;
      v.t_ps = t;
      v.sigma_ps = L.pulse.sigma_ps();
      v.chain = chain;
      v.collimated = collimated;
      if (!visit(static_cast<const LightVertex&>(v))) return;
      const double u_phi = rng.uniform();  // the azimuth's first (a stated order, as GCC had it)
      const double u_cos = rng.uniform();
      ray = {x, hg_sample(ray.d, med.g(), u_cos, u_phi).dir};
      continue;
    }

    const ShapeDesc& sh = shapes[static_cast<size_t>(hit.shape)];
    const bool front = dot(ray.d, hit.ng) < 0;
    if (sh.material.type == MaterialDesc::Type::None) {
      ++stats.null_crossings;
      if (++null_crossings > kMaxNullCrossings) return;
      m = front ? scene.inside_medium(hit.shape) : scene.outside_medium(hit.shape);
      ray.o = hit.p + ray.d * eps;
      continue;
    }
    ++stats.surface_events;
    if (depth >= max_depth) {
      ++stats.max_depth_hits;
      return;
    }
    ++depth;
    const Bsdf bsdf = Bsdf::from_material(
        sh.material, media[static_cast<size_t>(scene.outside_medium(hit.shape))].eta_at(hit.p));
    const Frame frame(hit.ng);
    v = LightVertex{};
    v.kind = LightVertex::Kind::Surface;
    v.p = hit.p;
    v.d = ray.d;
    v.medium = m;
    v.hit = &hit;
    v.bsdf = &bsdf;
    v.frame = &frame;
    v.wo = frame.to_local(-ray.d);
    v.beta = beta;
    v.t_ps = t;
    v.sigma_ps = L.pulse.sigma_ps();
    v.chain = chain;
    v.collimated = collimated;
    if (!visit(static_cast<const LightVertex&>(v))) return;
    chain = bsdf.is_diffuse() || chain < 0 ? -1 : chain + 1;
    BsdfSample bs;
    const double ul = rng.uniform(), b1 = rng.uniform(), b2 = rng.uniform();
    if (!bsdf.sample(v.wo, ul, b1, b2, TransportMode::Importance, bs)) return;
    beta *= bs.weight;
    if (beta.is_black()) return;
    const bool out = bs.wi.z > 0;
    if (bs.transmitted) m = out ? scene.outside_medium(hit.shape) : scene.inside_medium(hit.shape);
    ray = {hit.p + hit.ng * (out ? eps : -eps), normalize(frame.to_world(bs.wi))};
  }
}

}  // namespace femto
