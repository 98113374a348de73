#include "core/integrators/light_tracer.h"

#include <cmath>

#include "core/constants.h"

#include "media/phase_hg.h"
#include "samplers/equiangular_outside_ball.h"

namespace femto {

LightTracer::LightTracer(const Scene& scene, int max_depth, double t_cut_ps, Vertices vertices)
    : scene_(scene),
      tracker_(scene),
      max_depth_(max_depth),
      t_cut_(t_cut_ps),
      unwarp_(scene.desc().time_mode == TimeMode::Unwarp),
      vertices_(vertices),
      sensor_rays_(scene.camera().perspective()) {}

void LightTracer::splat(const Vec3& x, int m, const Vec3& w, double dist, const RGB& value,
                        double t_ps, double sigma_ps, double fx, double fy, std::vector<Splat>& out,
                        PathStats& stats) const {
  if (value.is_black()) return;
  double Tr, dt;
  if (!tracker_.connect(x, m, w, dist, Tr, dt, stats)) return;
  const RGB v = value * Tr;
  const double t = unwarp_ ? t_ps : t_ps + dt;
  if (!v.is_finite() || !std::isfinite(t)) {
    ++stats.nonfinite_dropped;
    return;
  }
  const Camera& cam = scene_.camera();
  const auto px = static_cast<uint32_t>(std::min(static_cast<int>(fx), cam.width() - 1));
  const auto py = static_cast<uint32_t>(std::min(static_cast<int>(fy), cam.height() - 1));
  out.push_back({py * static_cast<uint32_t>(cam.width()) + px, t, sigma_ps, v});
}

void LightTracer::trace(Rng& rng, std::vector<Splat>& out, PathStats& stats,
                        std::vector<Beam>* ball_beams) const {
  const Camera& cam = scene_.camera();
  const double eps = scene_.ray_epsilon();
  const bool indirect_only = vertices_ == Vertices::MediumIndirect;
  bool scattered = false;  // a diffuse surface or medium vertex so far
  bool surfaced = false;   // any surface vertex so far (caustic chains: light -> (S|G)+)
  // The latest non-specular vertex, and whether a specular surface came after it.
  enum class Last { Other, Medium, Diffuse } last = Last::Other;
  bool specular_since = false;
  // Only diffuse surfaces since a photon's vertex (light -> (S|G)+ -> D D*).
  bool caustic_chain = false;
  // Only diffuse surfaces since a laser's spot (laser -> D|G -> D*), no medium scattering.
  bool laser_chain = false;
  // Nothing but straight pieces so far (every light path of a laser shares its beam's).
  bool first_rays = true;
  // A delta light's path through non-diffuse surfaces only, the first of them specular
  // (light -> S (S|G)*): camera paths cannot reach the light from its glossy vertices (a shadow
  // ray does not pass the S) and photons are stored on diffuse surfaces only. An area light's
  // such paths stay the camera paths' (they hit the emitter past the S).
  bool area_light = false, specular_start = false;
  // The current medium ray piece's equiangular sensor connection (sensor_rays_).
  bool ray_active = false;
  int ray_connections = 1;
  Ray ray_piece;
  const bool ball = ball_.active() && indirect_only && sensor_rays_;
  const double r_ball = ball ? ball_.radius : 0.0;
  EquiangularOutsideBall eq(Vec3(), Vec3(0, 0, 1), Vec3(), 0.0, 0.0, 0.0);
  const auto& media = scene_.media();
  auto visit = [&](const LightVertex& v) {
    if (v.kind == LightVertex::Kind::Ray) {
      // The ray pieces whose collisions are splatted, under mean-free-path sampling (its
      // collision density sigma_t T is the other strategy of the MIS).
      ray_active = false;
      const Medium& med = media[static_cast<size_t>(v.medium)];
      // Direct light is the camera paths', but for a laser's beam (light -> M -> sensor), which
      // they find only where a point of the beam is on their segment.
      if (indirect_only && !scattered && !surfaced && !v.collimated) return true;
      // Up to the surface and the time cut-off (eta >= 1: time >= distance / c).
      double s0 = 0.0, s1 = std::fmin(v.length, (t_cut_ - v.t_ps) * kSpeedOfLight);
      Beam beam;
      // A laser's own beam. Inside the camera ball it is the camera paths' (laser chords, exact
      // there).
      const bool laser_beam = v.collimated && first_rays;
      if (ball && ball_beams && s1 > 0 && !laser_beam &&
          camera_ball_beam(tracker_, ball_, v, s1, beam))
        ball_beams->push_back(beam);
      if (med.strategy.kind != DistanceSampling::Mfp) return true;
      if (!(s1 > 0) || !cam.frustum_interval(v.p, v.d, s0, s1)) return true;
      eq = EquiangularOutsideBall(v.p, v.d, cam.position(), s0, s1, r_ball);
      if (!eq.valid()) return true;
      ray_active = true;
      ray_piece = {v.p, v.d};
      // A long streak gets several connections: one lands in one pixel, and a thin medium's
      // light seen across many pixels is otherwise made of sparse dots.
      // Not on a laser's own beam: every light path has (nearly) the same one, so one each
      // already covers its streak densely.
      ray_connections = 1;
      double ax, ay, bx, by;
      if (!laser_beam && cam.raster(ray_piece.at(s0), ax, ay) &&
          cam.raster(ray_piece.at(s1), bx, by)) {
        const double streak = std::hypot(bx - ax, by - ay) / streak_pixels_;
        if (streak >= 1)
          ray_connections =
              streak >= kMaxRayConnections - 1 ? kMaxRayConnections : 1 + static_cast<int>(streak);
      }
      const double u = rng.uniform();
      for (int k = 0; k < ray_connections; ++k) {
        const double s = eq.sample((k + u) / ray_connections);
        double tau, opl;
        tracker_.segment_integrals(v.medium, ray_piece, s, tau, opl);
        const double t_y = v.t_ps + opl / kSpeedOfLight;
        if (!(t_y <= t_cut_)) continue;  // as the walk, which ends past t_cut
        const Vec3 y = ray_piece.at(s);
        const double sigma_t = med.sigma_t_at(y);
        const double sigma_s = sigma_t * MediumTracker::albedo_at(med, y);
        double fx, fy, dist, W;
        Vec3 w;
        if (!(sigma_s > 0) || !cam.connect_to(y, fx, fy, w, dist, W)) continue;
        const double T = std::exp(-tau);
        // Balance heuristic with the collisions, each of the K points drawn from p_eq:
        // f / (K p_eq + sigma_t T).
        const double p_sum = ray_connections * eq.pdf(s) + sigma_t * T;
        if (p_sum > 0)
          splat(y, v.medium, w, dist,
                v.beta * (sigma_s * T * hg_eval(dot(v.d, w), v.g) * W / p_sum), t_y, v.sigma_ps, fx,
                fy, out, stats);
      }
      return true;
    }
    first_rays = first_rays && (v.kind == LightVertex::Kind::Segment || v.connection_only);
    if (indirect_only) {
      if (v.kind == LightVertex::Kind::Emitter) area_light = true;
      if (v.kind == LightVertex::Kind::Surface) {
        const bool diffuse = v.bsdf->is_diffuse();
        // That light on a glossy surface the camera sees: light -> S (S|G)* -> G -> sensor.
        const bool glossy_caustic = specular_start && !diffuse && !v.bsdf->is_delta();
        specular_start = !area_light && !diffuse &&
                         (surfaced ? specular_start : v.bsdf->is_delta()) && !scattered;
        // The light's own caustic seen directly, light -> (S|G)+ -> D -> sensor: the photons'
        // prefix, splatted exactly here where the camera sees D without a surface between.
        const bool caustic = diffuse && surfaced && !scattered;
        // A laser's spot on the surface the camera sees (laser -> D|G -> sensor), and what it
        // lights through diffuse bounces alone (laser -> D|G -> D+ -> sensor): camera paths find
        // the spot only where a pixel sample lands in it, or a bounce hits it.
        const bool laser_spot = v.collimated && !surfaced && !scattered && !v.bsdf->is_delta();
        const bool laser_lit = laser_spot || (laser_chain && diffuse);
        laser_chain = laser_lit;
        surfaced = true;
        scattered = scattered || diffuse;
        // Light scattered in a medium onto a diffuse surface, straight or through specular
        // surfaces (light -> X* M S* -> D -> sensor), and light from a diffuse surface through
        // specular ones (light -> X* D S+ -> D -> sensor): the caustics of what has scattered.
        // And the light of a caustic on a diffuse surface reaching the one the camera sees through
        // diffuse bounces only (light -> (S|G)+ -> D D* -> D -> sensor), which camera paths find
        // only by the directions of their bounces.
        const bool splat_here =
            caustic || glossy_caustic || laser_lit ||
            (diffuse &&
             (last == Last::Medium || (last == Last::Diffuse && specular_since) || caustic_chain));
        caustic_chain = diffuse && (caustic || caustic_chain);
        if (v.bsdf->is_delta()) {
          specular_since = true;
        } else {
          last = diffuse ? Last::Diffuse : Last::Other;
          specular_since = false;
        }
        if (!splat_here) return true;
      } else {
        if (v.kind != LightVertex::Kind::Medium) return true;
        const bool after_scattering = scattered || surfaced;
        if (!v.connection_only) {
          scattered = true;
          specular_start = false;
          last = Last::Medium;
          caustic_chain = false;
          laser_chain = false;
          specular_since = false;
        }
        // Direct light (light -> M) is the camera paths' share, but a laser's.
        if (!after_scattering && !v.collimated) return true;
      }
    }
    double fx, fy, dist, W;
    Vec3 w;
    if (!cam.connect_to(v.p, fx, fy, w, dist, W)) return true;
    // Medium points inside the camera ball are the camera paths' (through ball_beams).
    if (ball && v.kind == LightVertex::Kind::Medium && dist < r_ball) return !v.connection_only;
    switch (v.kind) {
      case LightVertex::Kind::Emitter: {
        const double cos_e = dot(v.n, w);
        if (cos_e > 0)
          splat(v.p + v.n * eps, v.medium, w, dist, v.beta * (cos_e * W), v.t_ps, v.sigma_ps, fx,
                fy, out, stats);
        return true;
      }
      case LightVertex::Kind::Segment:
        return true;
      case LightVertex::Kind::Medium: {
        double mis = 1.0;
        if (ray_active && !v.connection_only) {
          // The collision's half of the MIS with the ray piece's equiangular connection.
          const double s = dot(v.p - ray_piece.o, ray_piece.d);
          double tau, opl;
          tracker_.segment_integrals(v.medium, ray_piece, s, tau, opl);
          const double p_c = media[static_cast<size_t>(v.medium)].sigma_t_at(v.p) * std::exp(-tau);
          mis = p_c / (p_c + ray_connections * eq.pdf(s));
        }
        splat(v.p, v.medium, w, dist, v.beta * (hg_eval(dot(v.d, w), v.g) * W * mis), v.t_ps,
              v.sigma_ps, fx, fy, out, stats);
        return !v.connection_only;
      }
      case LightVertex::Kind::Ray:
        return true;
      case LightVertex::Kind::Surface: {
        if (v.bsdf->is_delta()) return true;
        const Vec3 wi = v.frame->to_local(w);
        const bool out_side = wi.z > 0;
        const RGB f = v.bsdf->f(v.wo, wi, TransportMode::Importance);
        if (f.is_black()) return true;
        const Vec3& ng = v.hit->ng;
        const int shape = v.hit->shape;
        const int m = out_side == (v.wo.z > 0)
                          ? v.medium
                          : out_side ? scene_.outside_medium(shape) : scene_.inside_medium(shape);
        splat(v.p + ng * (out_side ? eps : -eps), m, w, dist - eps,
              v.beta * f * (std::abs(wi.z) * W), v.t_ps, v.sigma_ps, fx, fy, out, stats);
        return true;
      }
    }
    return true;
  };
  walk_light_path(scene_, tracker_, rng, max_depth_, t_cut_, stats, visit, false, sensor_rays_);
}

}  // namespace femto
