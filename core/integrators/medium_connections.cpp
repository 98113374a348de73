// Time-targeted sampling in media for the path tracer (seed 000 Sec. 5.2-5.3): segment
// connections to point and spot lights (equiangular, line-to-point, or both by MIS) and angular
// direction sampling mixed with phase sampling.
#include <algorithm>
#include <cmath>
#include <limits>

#include "core/constants.h"
#include "core/integrators/connection_choice.h"
#include "core/integrators/volpath.h"
#include "core/spot_cone.h"
#include "media/phase_hg.h"
#include "samplers/angular.h"
#include "samplers/distance.h"
#include "samplers/equiangular.h"
#include "samplers/line_to_point.h"

namespace femto {

namespace {
/// Connection-time window (ps) that keeps a contribution of light `L` inside the film window,
/// for a path that has used time t; pulse tails widen it by 8 sigma.
void connection_window(const TimeAxis& axis, const Light& L, double t, double& t_a, double& t_b) {
  const double spread = 8.0 * L.pulse.sigma_ps();
  t_a = axis.t_start_ps - t - L.pulse.offset_ps - spread;
  t_b = axis.t_end_ps() - t - L.pulse.offset_ps + spread;
}

/// Angular time sampling from x towards light L for a segment of length r, restricted to the
/// connection times that keep the contribution in the film window.
struct AngularTarget {
  Vec3 to;   ///< x -> light
  double l;  ///< |to|
  AngularTimeSampler sampler;
  AngularTimeSampler::Window win;
};
AngularTarget angular_target(const TimeAxis& axis, const Light& L, const Vec3& x, double r,
                             double eta, double t) {
  double t_a, t_b;
  connection_window(axis, L, t, t_a, t_b);
  const Vec3 to = L.position - x;
  const double l = length(to);
  const AngularTimeSampler sampler(r, l, eta);
  return {to, l, sampler, sampler.window(t_a, t_b)};
}
}  // namespace

double VolPathIntegrator::mixture_share(const Medium& med, const Vec3& x, double t,
                                        int depth) const {
  // Divided by the vertices so far: the weights 1 / (1 - q) then compound to a power of the
  // path length, not an exponential (dense media have many vertices per path).
  return mixture_tu_probability(spread_sigma_t(med, x), med.eta_at(x),
                                kSpeedOfLight * (t_cut_ - t)) /
         (1.0 + depth);
}

VolPathIntegrator::DirectionMix VolPathIntegrator::direction_mix(const Medium& med, const Vec3& x,
                                                                 double t, double u,
                                                                 int depth) const {
  DirectionMix mix;
  mix.u = u;
  mix.t = t;
  mix.eta = med.eta_at(x);
  // The segment length the next distance draw u gives at x's own coefficients (a mixture splits
  // u into its pick and the draw, as the tracker will).
  double u_dist = u;
  const bool tu = med.strategy.kind == DistanceSampling::Mixture
                      ? mixture_pick(u, mixture_share(med, x, t, depth), u_dist)
                      : med.strategy.kind == DistanceSampling::TimeUniform;
  const double e = unit_exponential(u_dist);  // the same draw as the tracker's
  if (tu) {
    mix.r_aux = e / (med.strategy.lambda * mix.eta);
  } else {
    const double sigma_t = med.sigma_t_at(x);
    mix.r_aux = sigma_t > 0 ? e / sigma_t : std::numeric_limits<double>::infinity();
  }
  if (!std::isfinite(mix.r_aux)) return mix;
  const LightSet& lights = scene_.lights();
  for (size_t k = 0; k < point_lights_.size(); ++k) {
    const Light& L = lights.light(point_lights_[k]);
    if (angular_target(filter_.axis(), L, x, mix.r_aux, mix.eta, t).win.valid)
      mix.valid_pmf += point_pmf_[k];
  }
  mix.active = mix.valid_pmf > 0;
  return mix;
}

double VolPathIntegrator::angular_pdf(const DirectionMix& mix, const Vec3& x, const Vec3& w) const {
  const LightSet& lights = scene_.lights();
  double pdf = 0;
  for (size_t k = 0; k < point_lights_.size(); ++k) {
    const AngularTarget a = angular_target(filter_.axis(), lights.light(point_lights_[k]), x,
                                           mix.r_aux, mix.eta, mix.t);
    if (!a.win.valid || !(a.l > 0)) continue;
    pdf += point_pmf_[k] / mix.valid_pmf *
           a.sampler.pdf_solid_angle(a.win, AngularTimeSampler::one_minus_cos(a.to / a.l, w));
  }
  return pdf;
}

double VolPathIntegrator::direction_pdf(const DirectionMix& mix, const Vec3& x, const Vec3& d,
                                        double g, const Vec3& w) const {
  const double phase = hg_eval(dot(d, w), g);
  return mix.active ? 0.5 * phase + 0.5 * angular_pdf(mix, x, w) : phase;
}

double VolPathIntegrator::sample_direction(const DirectionMix& mix, const Vec3& x, const Vec3& d,
                                           double g, Rng& rng, Vec3& w, double& pdf) const {
  if (!mix.active) {
    const double u2 = rng.uniform();  // the azimuth's first (a stated order, as GCC had it)
    const double u1 = rng.uniform();
    const PhaseSample ps = hg_sample(d, g, u1, u2);
    w = ps.dir;
    pdf = ps.value;
    return 1.0;  // HG is sampled exactly
  }
  const double u_pick = rng.uniform(), u1 = rng.uniform(), u2 = rng.uniform();
  if (u_pick < 0.5) {
    w = hg_sample(d, g, u1, u2).dir;
  } else {
    // A point light among those whose window is reachable, in proportion to power.
    const LightSet& lights = scene_.lights();
    double u = (u_pick - 0.5) * 2.0 * mix.valid_pmf;
    size_t chosen = point_lights_.size();
    for (size_t k = 0; k < point_lights_.size(); ++k) {
      if (!angular_target(filter_.axis(), lights.light(point_lights_[k]), x, mix.r_aux, mix.eta,
                          mix.t)
               .win.valid)
        continue;
      chosen = k;
      if (u < point_pmf_[k]) break;
      u -= point_pmf_[k];
    }
    const AngularTarget a = angular_target(filter_.axis(), lights.light(point_lights_[chosen]), x,
                                           mix.r_aux, mix.eta, mix.t);
    w = a.sampler.sample_direction(a.to / a.l, a.win, u1, u2);
  }
  pdf = direction_pdf(mix, x, d, g, w);
  return pdf > 0 ? hg_eval(dot(d, w), g) / pdf : 0.0;
}

VolPathIntegrator::LineToPointTarget VolPathIntegrator::line_to_point_target(
    const Medium& med, const ConnectedSegment& segment, const Light& L, bool narrow) const {
  const Ray& ray = segment.ray();
  const double t = segment.t, t_factor = segment.t_factor;
  LineToPointTarget target{
      false, 0.0, LineToPointSampler(ray.o, ray.d, L.position, med.eta_at(ray.o)), {}};
  // No vertex whose path passes the cut-off: with eta >= 1 the time of s and its connection is at
  // least (s + d) / c with d >= s - |p - o|; an unwarped camera segment counts only d.
  const double l = length(L.position - ray.o), budget = kSpeedOfLight * (t_cut_ - t);
  const double reach = t_factor > 0 ? 0.5 * (budget + l) : budget + l;
  target.s_end = std::min(segment.s_surf, reach);
  if (!(target.s_end > 0) || !narrow) return target;
  double t_a, t_b;
  connection_window(filter_.axis(), L, t, t_a, t_b);
  // Unwarped camera segment: the film time leaves out s, so cover every s whose connection can
  // land.
  if (!(t_factor > 0)) t_b += target.lp.eta() * target.s_end / kSpeedOfLight;
  target.win = target.lp.window(t_a, t_b, 0.0, target.s_end);
  target.valid = target.win.valid;
  return target;
}

EquiangularSampler VolPathIntegrator::near_equiangular(const Medium& med,
                                                       const ConnectedSegment& segment,
                                                       const Light& L) const {
  const Ray& ray = segment.ray();
  const double s_end = line_to_point_target(med, segment, L, false).s_end;
  return s_end > 0 ? EquiangularSampler(ray.o, ray.d, L.position, 0.0, s_end)
                   : EquiangularSampler();
}

void VolPathIntegrator::estimate_segment(const Medium& med, int m, const ConnectedSegment& segment,
                                         const RGB& beta, Rng& rng, PixelAccumulator& acc,
                                         PathStats& stats) const {
  const Ray& ray = segment.ray();
  const double t = segment.t, t_factor = segment.t_factor;
  const LightSet& lights = scene_.lights();
  double pmf = 0;
  const int li = lights.pick(rng.uniform(), pmf);
  const double u_e = rng.uniform(), u_l = rng.uniform(), u1 = rng.uniform(), u2 = rng.uniform();
  if (li < 0 || beta.is_black() || !med.interacts()) return;
  const Light& L = lights.light(li);
  if (!is_point_like(L)) return;  // area lights and lasers: next-event estimation at collisions
  const Vec3& p = L.position;
  const ConnectionSampling kind = med.connection;
  // The partition's share (connections alone), or on a time_mis segment the connection's half of
  // its MIS with the collisions.
  const bool partition = segment.covers(li, L);
  const bool eq_pair = !partition && segment.pairs_equiangular(li, L);
  const bool lp_pair = !partition && segment.mis_with_collisions(L);
  if (!partition && !eq_pair && !lp_pair) return;  // collision next-event estimation's share

  // auto connects by equiangular sampling where the light term peaks narrowly and by
  // line-to-point on time_mis segments, each by MIS with the collisions (both where both rules
  // hold).
  const bool use_eq = eq_pair || (partition && kind != ConnectionSampling::LineToPoint);
  const bool use_lp =
      lp_pair ||
      (partition && (kind == ConnectionSampling::LineToPoint || kind == ConnectionSampling::Mis));
  const LineToPointTarget target = !partition && segment.lp_target
                                       ? *segment.lp_target
                                       : line_to_point_target(med, segment, L, use_lp);
  const double s_end = target.s_end;
  if (!(s_end > 0)) return;
  // A spot lights only the stretch of the segment inside its cone (core/spot_cone.h). The
  // equiangular sampler (an atan2) is made only where it is used.
  double eq_a = 0.0, eq_b = s_end;
  const bool eq_lit =
      use_eq && (L.type != Light::Type::Spot || spot_cone_interval(L, ray, eq_a, eq_b));
  const EquiangularSampler eq = eq_pair && segment.eq_target ? *segment.eq_target
                                : eq_lit ? EquiangularSampler(ray.o, ray.d, p, eq_a, eq_b)
                                         : EquiangularSampler();
  const bool eq_ok = eq.valid(), lp_ok = use_lp && target.valid;

  auto contribute = [&](double s) {
    if (!(s < s_end)) return;
    const Vec3 y = ray.at(s);
    double tau, opl;
    tracker_.segment_integrals(m, ray, s, tau, opl);
    const double T = std::exp(-tau);
    const double sigma_t = med.sigma_t_at(y);
    // Multi-sample balance heuristic: f / (sum of the strategies' densities); the collisions'
    // density sigma_t T joins on time_mis segments.
    const double p_sum = (eq_ok ? eq.pdf(s) : 0.0) + (lp_ok ? target.lp.pdf(target.win, s) : 0.0) +
                         (partition ? 0.0 : sigma_t * T);
    if (!(p_sum > 0)) return;
    const double sigma_s =
        med.type == Medium::Type::Grid ? sigma_t * med.grid->albedo_at(y) : med.homogeneous.sigma_s;
    if (!(sigma_s > 0)) return;
    LightSample ls;
    if (!lights.sample(li, y, u1, u2, ls)) return;
    const double f = hg_eval(dot(ray.d, ls.wi), med.g());
    double Tr, dt;
    if (!(f > 0) || !tracker_.connect(y, m, ls.wi, ls.dist, Tr, dt, stats)) return;
    const double weight = sigma_s * T * f * Tr / (p_sum * pmf * ls.pdf);
    deposit(t + opl * t_factor + dt + L.pulse.offset_ps, L.pulse.sigma_ps(), beta * ls.Li * weight,
            acc, stats);
  };
  if (eq_ok) contribute(eq.sample(u_e));
  if (lp_ok) contribute(target.lp.sample(target.win, u_l));
}

}  // namespace femto
