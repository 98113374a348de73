#include "core/integrators/volpath.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/constants.h"
#include "core/integrators/connection_choice.h"
#include "core/integrators/photon_beams.h"
#include "core/integrators/photon_map.h"
#include "core/medium_nesting.h"
#include "core/sampling.h"
#include "media/phase_hg.h"

namespace femto {

namespace {

// Per medium: the bounding box of the shapes that bound it (lo > hi where none does; the global
// medium is unbounded).
void medium_bounds(const Scene& scene, std::vector<Vec3>& lo, std::vector<Vec3>& hi) {
  lo.assign(scene.media().size(), Vec3(kInf));
  hi.assign(scene.media().size(), Vec3(-kInf));
  const std::vector<ShapeDesc>& shapes = scene.desc().shapes;
  for (size_t i = 0; i < shapes.size(); ++i) {
    if (!bounds_a_medium(shapes[i])) continue;
    const size_t m = static_cast<size_t>(scene.inside_medium(static_cast<int>(i)));
    Vec3 a, b;
    shape_bounds(shapes[i], a, b);
    lo[m] = vmin(lo[m], a), hi[m] = vmax(hi[m], b);
  }
}

bool bounded(const Scene& scene, size_t m, const std::vector<Vec3>& lo,
             const std::vector<Vec3>& hi) {
  return static_cast<int>(m) != scene.global_medium() && lo[m].x <= hi[m].x;
}

// connection_choice.h, third rule, per medium: every point and spot light sits in a medium that
// does not scatter, and the medium is thinner than kThinDepth across the bounding box of the
// shapes that bound it (the global medium, unbounded, never is).
std::vector<char> thin_media_lit_from_outside(const Scene& scene, const std::vector<int>& lights,
                                              const std::vector<Vec3>& lo,
                                              const std::vector<Vec3>& hi) {
  const std::vector<Medium>& media = scene.media();
  std::vector<char> thin(media.size(), 0);
  if (lights.empty()) return thin;
  for (int i : lights)
    if (media[static_cast<size_t>(scene.medium_at(scene.lights().light(i).position))].interacts())
      return thin;
  for (size_t m = 0; m < media.size(); ++m) {
    const Medium& med = media[m];
    if (!med.interacts() || !bounded(scene, m, lo, hi)) continue;
    const double width = std::min({hi[m].x - lo[m].x, hi[m].y - lo[m].y, hi[m].z - lo[m].z});
    const double sigma_t =
        med.type == Medium::Type::Grid ? med.grid->mean_sigma_t() : med.homogeneous.sigma_t();
    thin[m] = sigma_t * width < kThinDepth;
  }
  return thin;
}

// connection_choice.h, first rule, per medium: every point light (spots always connect) is
// box_far_from_light of the bounding box of the medium's shapes, which its segments stay in.
std::vector<char> media_far_from_lights(const Scene& scene, const std::vector<int>& lights,
                                        const std::vector<Vec3>& lo, const std::vector<Vec3>& hi) {
  const std::vector<Medium>& media = scene.media();
  std::vector<char> far(media.size(), 0);
  for (size_t m = 0; m < media.size(); ++m) {
    const Medium& med = media[m];
    if (!med.interacts() || !bounded(scene, m, lo, hi)) continue;
    const double sigma_t = med.type == Medium::Type::Homogeneous ? med.homogeneous.sigma_t() : 0.0;
    bool all_far = true;
    for (int i : lights) {
      const Light& L = scene.lights().light(i);
      all_far = all_far && L.type != Light::Type::Spot &&
                box_far_from_light(lo[m], hi[m], sigma_t, L.position);
    }
    far[m] = all_far;
  }
  return far;
}

}  // namespace

VolPathIntegrator::VolPathIntegrator(const Scene& scene, const TemporalFilter& filter,
                                     int max_depth, const RouletteDesc& roulette)
    : scene_(scene),
      tracker_(scene),
      filter_(filter),
      max_depth_(max_depth),
      roulette_(roulette),
      unwarp_(scene.desc().time_mode == TimeMode::Unwarp) {
  // Contributions are deposited with up to 8 sigma of pulse spread (see TemporalFilter).
  t_cut_ = filter.axis().t_end_ps() - scene.lights().min_offset_ps() +
           8.0 * scene.lights().max_sigma_ps();
  const LightSet& lights = scene.lights();
  double total = 0;
  for (int i = 0; i < lights.count(); ++i)
    if (is_point_like(lights.light(i))) {
      point_lights_.push_back(i);
      point_pmf_.push_back(lights.pmf(i));
      total += lights.pmf(i);
    }
  for (double& p : point_pmf_) p /= total;
  for (int i = 0; i < lights.count(); ++i)
    if (lights.light(i).type == Light::Type::Laser) lasers_.push_back(i);
  std::vector<Vec3> lo, hi;
  medium_bounds(scene, lo, hi);
  thin_media_ = thin_media_lit_from_outside(scene, point_lights_, lo, hi);
  far_media_ = media_far_from_lights(scene, point_lights_, lo, hi);
  const std::vector<Medium>& media = scene.media();
  const size_t n_lights = static_cast<size_t>(lights.count());
  light_sigma_t_.assign(media.size() * n_lights, 0.0);
  needs_spread_.assign(media.size(), 0);
  for (size_t m = 0; m < media.size(); ++m)
    for (int li : point_lights_) {
      double& s = light_sigma_t_[m * n_lights + static_cast<size_t>(li)];
      if (media[m].type == Medium::Type::Grid)
        s = media[m].grid->sigma_t_at(lights.light(li).position);
      needs_spread_[m] = needs_spread_[m] || !(s > 0);
    }
}

void VolPathIntegrator::deposit(double t_ps, double sigma_ps, const RGB& value,
                                PixelAccumulator& acc, PathStats& stats) const {
  if (!value.is_finite() || !std::isfinite(t_ps)) {
    ++stats.nonfinite_dropped;
    return;
  }
  if (value.is_black()) return;
  acc.add(filter_, t_ps, sigma_ps, value);
}

bool VolPathIntegrator::ConnectedSegment::covers(int li, const Light& light) const {
  if (!active) return false;
  if (all) return true;
  if (near_mis && light.type == Light::Type::Point) return false;  // pairs_equiangular's
  return decided || auto_connects(light, ray_ptr->o, ray_ptr->d, s_surf, near_sigma_t(li));
}

bool VolPathIntegrator::ConnectedSegment::pairs_equiangular(int li, const Light& light) const {
  return active && near_mis && !all && light.type == Light::Type::Point &&
         !mis_with_collisions(light) &&
         (decided || connect_segment_to(ray_ptr->o, ray_ptr->d, s_surf, near_sigma_t(li),
                                        light.position, kNearPairFraction));
}

bool VolPathIntegrator::ConnectedSegment::mis_with_collisions(const Light& light) const {
  return time_mis && (thin || lights_from_start(ray_ptr->o, ray_ptr->d, light.position));
}

void VolPathIntegrator::plan_segment(const Medium& med, int m, const Ray& ray, double s_surf,
                                     double t, double t_factor, bool camera_segment,
                                     ConnectedSegment& segment) const {
  segment.reset();
  if (med.connection == ConnectionSampling::Collision || point_lights_.empty() || !med.interacts())
    return;
  segment.ray_ptr = &ray;  // the loop's ray, unchanged while the plan is used
  segment.s_surf = s_surf;
  segment.t = t;
  segment.t_factor = t_factor;
  segment.all = med.connection != ConnectionSampling::Auto;
  if (segment.all) {
    segment.active = true;
    return;
  }
  const bool mfp = med.strategy.kind == DistanceSampling::Mfp;
  const size_t mi = static_cast<size_t>(m);
  if (far_media_[mi] && !(mfp && (camera_segment || thin_media_[mi]))) {
    segment.decided = point_lights_.size() == 1;  // and no rule applies
    return;
  }
  // The lookup (a voxel fetch in a grid) only where a rule reads it: the time rules, or a light
  // whose first rule has no extinction of its own.
  const bool time_rules = mfp && (camera_segment || thin_media_[mi]);
  segment.sigma_t = time_rules || needs_spread_[mi] ? spread_sigma_t(med, ray.o) : 0.0;
  const LightSet& lights = scene_.lights();
  segment.light_sigma_t = &light_sigma_t_[mi * static_cast<size_t>(lights.count())];
  const double budget = kSpeedOfLight * (t_cut_ - t);
  segment.time_mis = camera_segment && mfp && starved_segment(s_surf, budget, segment.sigma_t);
  segment.thin =
      !segment.time_mis && mfp && thin_media_[mi] && thin_segment(s_surf, budget, segment.sigma_t);
  segment.time_mis = segment.time_mis || segment.thin;
  const double fraction = mfp ? kNearPairFraction : kConnectionPeakFraction;
  for (int li : point_lights_)
    if (auto_connects(lights.light(li), ray.o, ray.d, s_surf, segment.near_sigma_t(li), fraction)) {
      segment.active = true;
      break;
    }
  segment.decided = point_lights_.size() == 1;
  segment.near_mis = mfp;
  if (segment.decided && (segment.active || segment.time_mis)) {
    const int li = point_lights_[0];
    const Light& L = lights.light(li);
    if (!segment.covers(li, L) && segment.mis_with_collisions(L))
      segment.lp_target = line_to_point_target(med, segment, L, true);
    else if (segment.pairs_equiangular(li, L))
      segment.eq_target = near_equiangular(med, segment, L);
  }
}

void VolPathIntegrator::estimate_direct_medium(const Vec3& x, int m, const Vec3& d, double g,
                                               const RGB& beta, double t, const DirectionMix* mix,
                                               const ConnectedSegment& segment,
                                               const DistanceEvent* collision, Rng& rng,
                                               PixelAccumulator& acc, PathStats& stats) const {
  const LightSet& lights = scene_.lights();
  double pmf = 0;
  const int li = lights.pick(rng.uniform(), pmf);
  const double u1 = rng.uniform(), u2 = rng.uniform();
  LightSample ls;
  if (li < 0 || beta.is_black()) return;
  const Light& L = lights.light(li);
  double w_seg = 1.0;  // the collisions' balance-heuristic weight against the segment's connections
  if (L.type == Light::Type::Laser) return;  // estimate_laser_chords' share
  // A segment without connections (most) leaves every point light to the collisions.
  if (is_point_like(L) && (segment.active || segment.time_mis)) {
    if (segment.covers(li, L)) return;  // estimate_segment's share
    const bool eq_pair = segment.pairs_equiangular(li, L), lp_pair = segment.mis_with_collisions(L);
    if (collision && (eq_pair || lp_pair)) {
      const Medium& med = scene_.media()[static_cast<size_t>(m)];
      const double s_seg = collision->s;
      double p_other = !eq_pair            ? 0.0
                       : segment.eq_target ? segment.eq_target->pdf(s_seg)
                                           : near_equiangular(med, segment, L).pdf(s_seg);
      if (lp_pair) {
        const LineToPointTarget target =
            segment.lp_target ? *segment.lp_target : line_to_point_target(med, segment, L, true);
        if (target.valid && s_seg < target.s_end) p_other += target.lp.pdf(target.win, s_seg);
      }
      if (p_other > 0) {
        const double p_c = collision->sigma_t * std::exp(-collision->tau);
        w_seg = p_c / (p_c + p_other);
      }
    }
  }
  if (!lights.sample(li, x, u1, u2, ls)) return;
  const double f = hg_eval(dot(d, ls.wi), g);
  double Tr, dt;
  if (!(f > 0) || !tracker_.connect(x, m, ls.wi, ls.dist, Tr, dt, stats)) return;
  const double p_dir = ls.is_delta ? 0.0 : mix ? direction_pdf(*mix, x, d, g, ls.wi) : f;
  const double w = ls.is_delta ? w_seg : power_heuristic(pmf * ls.pdf, p_dir);
  deposit(t + dt + L.pulse.offset_ps, L.pulse.sigma_ps(),
          beta * ls.Li * (f * Tr * w / (pmf * ls.pdf)), acc, stats);
}

void VolPathIntegrator::estimate_direct_surface(const Bsdf& bsdf, const SurfaceHit& hit,
                                                const Frame& frame, const Vec3& wo, bool wo_outside,
                                                int m_wo, const RGB& beta, double t, bool lasers,
                                                Rng& rng, PixelAccumulator& acc,
                                                PathStats& stats) const {
  const LightSet& lights = scene_.lights();
  double pmf = 0;
  const int li = lights.pick(rng.uniform(), pmf);
  const double u1 = rng.uniform(), u2 = rng.uniform();
  if (li < 0 || (!lasers && lights.light(li).type == Light::Type::Laser)) return;
  const double eps = scene_.ray_epsilon();
  // Probe point for the light sample: the side of wo; a transmitted sample leaves from the other
  // side.
  LightSample ls;
  const Vec3 x_wo = hit.p + hit.ng * (wo_outside ? eps : -eps);
  if (!lights.sample(li, x_wo, u1, u2, ls)) return;
  const Vec3 wi = frame.to_local(ls.wi);
  const bool wi_outside = wi.z > 0;
  if (wi_outside != wo_outside && !bsdf.transmits()) return;
  const RGB f = bsdf.f(wo, wi, TransportMode::Radiance);
  if (f.is_black()) return;
  const Vec3 x = wi_outside == wo_outside ? x_wo : hit.p + hit.ng * (wi_outside ? eps : -eps);
  // A reflected sample stays in the path's medium; a transmitted one is beyond the surface.
  const int m = wi_outside == wo_outside ? m_wo
                : wi_outside             ? scene_.outside_medium(hit.shape)
                                         : scene_.inside_medium(hit.shape);
  // From the other side the light is nearer by the offset's projection (else the occlusion
  // test would reach the light's own surface).
  const double dist = ls.dist - dot(x - x_wo, ls.wi);
  double Tr, dt;
  if (!tracker_.connect(x, m, ls.wi, dist, Tr, dt, stats)) return;
  const double w = ls.is_delta ? 1.0 : power_heuristic(pmf * ls.pdf, bsdf.pdf(wo, wi));
  const Light& L = lights.light(li);
  deposit(t + dt + L.pulse.offset_ps, L.pulse.sigma_ps(),
          beta * f * ls.Li * (std::abs(wi.z) * Tr * w / (pmf * ls.pdf)), acc, stats);
}

void VolPathIntegrator::trace(Ray ray, Rng& rng, PixelAccumulator& acc, PathStats& stats,
                              const PhotonGather* photons, const BeamGather* beams,
                              bool light_indirect) const {
  const auto& media = scene_.media();
  const auto& shapes = scene_.desc().shapes;
  const LightSet& lights = scene_.lights();
  const double eps = scene_.ray_epsilon();
  ++stats.paths;

  int m = scene_.camera_medium();
  RGB beta(1.0);
  double t = 0.0;                 // time of flight from the sensor to the current vertex, ps
  bool on_camera_segment = true;  // unwarp mode drops the time of the sensor's own segment
  bool specular = true;           // previous vertex was the sensor or a specular surface
  double prev_pdf = 0.0;          // solid-angle pdf of the direction sampled at the previous vertex
  Vec3 prev_p = ray.o;
  int depth = 0;
  int null_crossings = 0;
  double u_next = -1.0;  // pre-drawn distance uniform for the next segment (angular sampling)
  // Path-space partition (docs/ARCHITECTURE.md): light that reaches a diffuse vertex through one
  // or more non-diffuse surfaces belongs to the photons, and light that reaches a medium point
  // that way to the caustic beams. `last` is the latest non-specular vertex (diffuse surface or
  // medium) and `since` counts the non-diffuse surfaces met after it.
  enum class Last { Camera, Diffuse, Medium } last = Last::Camera;
  int since = 0;
  const bool caustic_beams = beams && beams->caustic_only;
  auto owned = [&](Last l) {
    return (l == Last::Diffuse && photons) || (l == Last::Medium && caustic_beams);
  };
  // All beams: they own the paths whose first non-specular vertex from the camera is in a medium.
  bool beam_prefix = beams != nullptr && !caustic_beams;
  // Light tracing owns light -> X+ -> x_c -> camera, x_c the path's first vertex when it is a
  // medium vertex (any point of the camera's own segment, so no caustic beams there): past x_c the
  // path only looks for an emitter hit (the other half of x_c's next-event MIS) and ends at its
  // next vertex.
  bool past_xc = false;
  // It also owns light -> X* M S* -> x_c -> camera with x_c a diffuse surface: on the segments
  // leaving such an x_c through specular surfaces the path takes no light scattered in a medium
  // and ends at a collision. And light -> X* D S+ -> x_c: the first diffuse surface reached from
  // x_c through specular surfaces ends the path.
  bool from_xd = false, from_xd_specular = false;
  // And light -> (S|G)+ -> D D* -> x_c (a caustic on a diffuse surface lighting, through diffuse
  // bounces only, the one the camera sees): no photon gathers along a diffuse chain from x_c.
  bool diffuse_chain = false;
  ConnectedSegment segment;  // the current segment's connection plan (plan_segment)

  for (;;) {
    SurfaceHit hit;
    const bool found = scene_.geometry().intersect(ray, 0.0, kInf, hit);
    const double s_surf = found ? hit.s : kInf;
    const Medium& med = media[static_cast<size_t>(m)];
    const bool medium_light = depth < max_depth_ && !past_xc && !from_xd;  // light tracing's else
    // On the camera's own segment caustic light comes from light tracing (light_indirect).
    if (caustic_beams && med.interacts() && medium_light && !(light_indirect && on_camera_segment))
      beams->gather(m, ray, s_surf, beta, t,
                    unwarp_ && on_camera_segment ? 0.0 : 1.0 / kSpeedOfLight, acc, stats);
    // Inside the camera ball, light tracing's share comes from the light pieces through it (the
    // ray still starts at the pinhole: no boundary crossed yet).
    if (light_indirect && on_camera_segment && null_crossings == 0 && beams && beams->ball &&
        med.interacts())
      beams->ball->gather(m, ray, std::fmin(s_surf, beams->ball_radius), beta, t,
                          unwarp_ ? 0.0 : 1.0 / kSpeedOfLight, acc, stats);
    if (beam_prefix && med.interacts()) {
      // Before the first non-specular surface, light scattered in a medium comes from the beams:
      // the camera path passes through with the segment's exact transmittance.
      const double t_seg = unwarp_ && on_camera_segment ? 0.0 : 1.0 / kSpeedOfLight;
      beams->gather(m, ray, s_surf, beta, t, t_seg, acc, stats);
      if (!found) break;
      double tau, opl;
      tracker_.segment_integrals(m, ray, s_surf, tau, opl);
      beta *= std::exp(-tau);
      t += opl * t_seg;
      if (t > t_cut_ || beta.is_black()) break;
    } else {
      const double q_tu = med.strategy.kind == DistanceSampling::Mixture && med.interacts()
                              ? mixture_share(med, ray.o, t, depth)
                              : 0.0;
      const MediumSample ms = tracker_.sample(med, ray, s_surf, rng, u_next, q_tu);
      const double t_dropped = unwarp_ && on_camera_segment ? 0.0 : 1.0 / kSpeedOfLight;
      // Passed without meeting any extinction (a camera ray beside a cloud): no connection
      // along it can gather light, so it gets no plan.
      const bool clear =
          med.strategy.kind == DistanceSampling::Mfp && !ms.main.collided && !(ms.main.tau > 0);
      if (clear)
        segment.reset();
      else
        plan_segment(med, m, ray, s_surf, t, t_dropped, on_camera_segment, segment);
      if ((segment.active || segment.time_mis) && medium_light)
        estimate_segment(med, m, segment, beta, rng, acc, stats);
      // On the camera's own segment a laser's beam is light tracing's (light_indirect), but
      // inside the camera ball, where chords are exact and light tracing would need the ball's
      // kernel.
      if (!lasers_.empty() && medium_light && med.interacts()) {
        const bool ball = null_crossings == 0 && beams && beams->ball;
        const double s_chords = !(light_indirect && on_camera_segment) ? s_surf
                                : ball ? std::fmin(s_surf, beams->ball_radius)
                                       : 0.0;
        if (s_chords > 0)
          estimate_laser_chords(med, m, ray, s_chords, t, t_dropped, beta, rng, acc, stats);
      }
      // Angular direction sampling: the next segment's distance draw is made now so that every
      // strategy's MIS weight at this segment's vertices sees the same r_aux.
      const bool angular = med.direction == DirectionSampling::Angular && !point_lights_.empty() &&
                           ms.main.collided && depth < max_depth_;
      u_next = angular ? rng.uniform() : -1.0;
      const double t_main = t + ms.main.opl * t_dropped;
      const DirectionMix mix_main =
          angular ? direction_mix(med, ray.at(ms.main.s), t_main, u_next, depth + 1)
                  : DirectionMix{};
      if (ms.extra.collided && medium_light) {
        // The time-uniform collision of MIS: next-event estimation only (the path goes on from
        // the mean-free-path collision).
        const Vec3 x2 = ray.at(ms.extra.s);
        const double t2 = t + ms.extra.opl * t_dropped;
        const DirectionMix mix2 =
            angular ? direction_mix(med, x2, t2, u_next, depth + 1) : DirectionMix{};
        estimate_direct_medium(x2, m, ray.d, med.g(),
                               beta * (MediumTracker::albedo_at(med, x2) * ms.extra_nee_weight), t2,
                               angular ? &mix2 : nullptr, segment, nullptr, rng, acc, stats);
      }
      const DistanceEvent& ev = ms.main;
      if (!ev.collided && !found) break;  // escaped to infinity
      beta *= ev.weight;
      t += ev.opl * t_dropped;
      if (t > t_cut_) break;

      if (ev.collided) {
        // Real collision: absorb by weighting with the single-scattering albedo.
        if (past_xc || from_xd) break;
        past_xc = light_indirect && on_camera_segment;
        on_camera_segment = false;
        last = Last::Medium;
        since = 0;
        diffuse_chain = false;
        ++stats.medium_events;
        if (depth >= max_depth_) {
          ++stats.max_depth_hits;
          break;
        }
        ++depth;
        const Vec3 x = ray.at(ev.s);
        beta *= MediumTracker::albedo_at(med, x);
        if (beta.is_black()) break;
        estimate_direct_medium(x, m, ray.d, med.g(), beta * ms.main_nee_weight, t,
                               angular ? &mix_main : nullptr, segment, &ev, rng, acc, stats);
        Vec3 wi;
        beta *=
            sample_direction(mix_main, x, ray.d, med.g(), rng, wi, prev_pdf);  // 1 for phase alone
        if (beta.is_black() || !survives_roulette(depth, beta, rng, stats)) break;
        specular = false;
        prev_p = x;
        ray = {x, wi};
        continue;
      }
    }

    // Surface interaction.
    const ShapeDesc& sh = shapes[static_cast<size_t>(hit.shape)];
    const bool front = dot(ray.d, hit.ng) < 0;
    if (sh.emissive && front && !(since > 0 && owned(last))) {
      const int li = lights.light_of_shape(hit.shape);
      double w = 1.0;
      if (!specular) {
        const double p_light = lights.pmf(li) * lights.pdf_area(li, prev_p, hit.p, hit.ng);
        w = power_heuristic(prev_pdf, p_light);
      }
      deposit(t + sh.pulse.offset_ps, sh.pulse.sigma_ps(), beta * sh.emission * w, acc, stats);
    }
    if (sh.material.type == MaterialDesc::Type::None) {
      // Index-matched boundary: change medium, keep going straight.
      ++stats.null_crossings;
      if (++null_crossings > kMaxNullCrossings) break;
      m = front ? scene_.inside_medium(hit.shape) : scene_.outside_medium(hit.shape);
      ray.o = hit.p + ray.d * eps;
      continue;
    }
    if (past_xc) break;
    const bool first_vertex = on_camera_segment;
    on_camera_segment = false;
    ++stats.surface_events;
    if (depth >= max_depth_) {
      ++stats.max_depth_hits;
      break;
    }
    ++depth;
    const Bsdf bsdf = Bsdf::from_material(
        sh.material, media[static_cast<size_t>(scene_.outside_medium(hit.shape))].eta_at(hit.p));
    if (from_xd_specular && bsdf.is_diffuse()) break;  // light tracing's (emission above stays)
    const Frame frame(hit.ng);
    const Vec3 wo = frame.to_local(-ray.d);
    const bool wo_outside = front;
    // At x_c a diffuse surface light tracing owns the photons' light -> (S|G)+ -> x_c too, and
    // along a diffuse chain from it light -> (S|G)+ -> D D* -> x_c (a bright caustic lighting what
    // the camera sees, which camera paths find only by the directions of their bounces).
    if (photons && bsdf.is_diffuse() && !(light_indirect && (first_vertex || diffuse_chain)))
      photons->gather(bsdf, hit, frame, wo, beta, t, acc, stats);
    // Next-event estimation, except where a photon owns the path (light -> glossy -> diffuse).
    if (!bsdf.is_delta() && !(!bsdf.is_diffuse() && owned(last)))
      // A laser's spot on the surface the camera sees, and on those lighting it through diffuse
      // bounces alone, is light tracing's (light_indirect).
      estimate_direct_surface(bsdf, hit, frame, wo, wo_outside, m, beta, t,
                              !(light_indirect && (first_vertex || diffuse_chain)), rng, acc,
                              stats);
    if (bsdf.is_diffuse()) {
      last = Last::Diffuse;
      since = 0;
    } else if (last != Last::Camera) {
      ++since;
    }
    if (!bsdf.is_delta()) beam_prefix = false;
    diffuse_chain = light_indirect && bsdf.is_diffuse() && (first_vertex || diffuse_chain);
    from_xd_specular = from_xd && bsdf.is_delta();
    from_xd =
        light_indirect && ((first_vertex && bsdf.is_diffuse()) || (from_xd && bsdf.is_delta()));

    BsdfSample bs;
    const double u_lobe = rng.uniform(), u1 = rng.uniform(), u2 = rng.uniform();
    if (!bsdf.sample(wo, u_lobe, u1, u2, TransportMode::Radiance, bs)) break;
    beta *= bs.weight;
    if (beta.is_black() || !survives_roulette(depth, beta, rng, stats)) break;
    const bool wi_outside = bs.wi.z > 0;
    if (bs.transmitted)
      m = wi_outside ? scene_.outside_medium(hit.shape) : scene_.inside_medium(hit.shape);
    specular = bs.delta;
    prev_pdf = bs.pdf;
    prev_p = hit.p;
    ray = {hit.p + hit.ng * (wi_outside ? eps : -eps), normalize(frame.to_world(bs.wi))};
  }
}

}  // namespace femto
