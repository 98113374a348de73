#include "core/integrators/volpath.h"

#include <cmath>
#include <limits>

#include "core/constants.h"
#include "core/sampling.h"
#include "media/phase_hg.h"
#include "samplers/distance.h"

namespace femto {

namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr int kMaxNullCrossings = 4096;  // guards against rays trapped between coincident faces

// Unpolarised Fresnel reflectance of a smooth dielectric; eta = eta_t / eta_i.
double fresnel_dielectric(double cos_i, double eta, double& cos_t) {
  const double sin2_t = (1.0 - cos_i * cos_i) / (eta * eta);
  if (sin2_t >= 1.0) {
    cos_t = 0.0;
    return 1.0;  // total internal reflection
  }
  cos_t = std::sqrt(1.0 - sin2_t);
  const double r_par = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
  const double r_perp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
  return 0.5 * (r_par * r_par + r_perp * r_perp);
}
}  // namespace

PathStats& PathStats::operator+=(const PathStats& o) {
  paths += o.paths;
  medium_events += o.medium_events;
  surface_events += o.surface_events;
  null_crossings += o.null_crossings;
  max_depth_hits += o.max_depth_hits;
  nonfinite_dropped += o.nonfinite_dropped;
  return *this;
}

VolPathIntegrator::VolPathIntegrator(const Scene& scene, const TemporalFilter& filter,
                                     int max_depth)
    : scene_(scene),
      filter_(filter),
      max_depth_(max_depth),
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

VolPathIntegrator::MediumSample VolPathIntegrator::sample_medium(const Medium& med, const Ray& ray, double s_max,
                                              Rng& rng, double u_main) const {
  MediumSample out;
  DistanceEvent& ev = out.main;
  if (!med.interacts()) {
    ev.s = s_max;
    ev.opl = med.homogeneous.eta * s_max;
    return out;
  }
  const double u1 = u_main >= 0.0 ? u_main : rng.uniform();
  if (med.type == Medium::Type::Homogeneous) {
    const HomogeneousMedium& h = med.homogeneous;
    if (med.strategy.kind == DistanceSampling::Mfp || !(h.sigma_s > 0)) {
      // Closed form; a purely absorbing medium is integrated exactly instead of sampled.
      const double s = h.sigma_s > 0 ? sample_exponential(h.sigma_t(), u1) : kInf;
      ev.collided = s < s_max;
      ev.s = ev.collided ? s : s_max;
      ev.opl = h.eta * ev.s;
      ev.sigma_t = h.sigma_t();
      ev.eta = h.eta;
      ev.weight = h.sigma_s > 0 ? 1.0 : std::exp(-h.sigma_t() * s_max);
      return out;
    }
    ConstantSegments segments(h.sigma_t(), h.eta, s_max);
    return finish_sample(segments, med.strategy, u1, rng);
  }
  GridMedium::Walker walker(*med.grid, ray, s_max);
  return finish_sample(walker, med.strategy, u1, rng);
}

template <class Segments>
VolPathIntegrator::MediumSample VolPathIntegrator::finish_sample(Segments& segments, const DistanceStrategy& st, double u1,
                                              Rng& rng) const {
  MediumSample out;
  if (st.kind != DistanceSampling::Mis) {
    out.main = sample_distance(segments, st, u1);
    return out;
  }
  const DistancePair pair = sample_distance_mis(segments, st, u1, rng.uniform());
  out.main = pair.mfp;
  out.main_nee_weight = pair.mfp_nee_weight;
  out.extra = pair.tu;
  out.extra_nee_weight = pair.tu_nee_weight;
  return out;
}

void VolPathIntegrator::estimate_direct_medium(const Vec3& x, int m, const Vec3& d, double g,
                                               const RGB& beta, double t, const DirectionMix* mix,
                                               bool skip_point_lights, Rng& rng, PixelAccumulator& acc,
                                               PathStats& stats) const {
  const LightSet& lights = scene_.lights();
  double pmf = 0;
  const int li = lights.pick(rng.uniform(), pmf);
  const double u1 = rng.uniform(), u2 = rng.uniform();
  LightSample ls;
  if (li < 0 || beta.is_black()) return;
  if (skip_point_lights && is_point_like(lights.light(li))) return;  // estimate_segment's share
  if (!lights.sample(li, x, u1, u2, ls)) return;
  const double f = hg_eval(dot(d, ls.wi), g);
  double Tr, dt;
  if (!(f > 0) || !connect(x, m, ls.wi, ls.dist, Tr, dt, stats)) return;
  const double p_dir = ls.is_delta ? 0.0 : mix ? direction_pdf(*mix, x, d, g, ls.wi) : f;
  const double w = ls.is_delta ? 1.0 : power_heuristic(pmf * ls.pdf, p_dir);
  const Light& L = lights.light(li);
  deposit(t + dt + L.pulse.offset_ps, L.pulse.sigma_ps(), beta * ls.Li * (f * Tr * w / (pmf * ls.pdf)), acc,
          stats);
}

void VolPathIntegrator::segment_integrals(int m, const Ray& ray, double s, double& tau,
                                          double& opl) const {
  const Medium& med = scene_.media()[static_cast<size_t>(m)];
  if (med.type == Medium::Type::Homogeneous) {
    tau = med.homogeneous.sigma_t() * s;
    opl = med.homogeneous.eta * s;
    return;
  }
  GridMedium::Walker walker(*med.grid, ray, s);
  integrate_segments(walker, tau, opl);
}

bool VolPathIntegrator::connect(const Vec3& x, int m, const Vec3& wi, double dist, double& Tr,
                                double& time_ps, PathStats& stats) const {
  const double eps = scene_.ray_epsilon();
  if (!scene_.has_null_boundaries()) {
    // Every surface blocks: one occlusion query, and the segment stays in medium m.
    if (dist > 2 * eps && scene_.geometry().occluded({x, wi}, 0.0, dist - eps)) return false;
    double tau, opl;
    segment_integrals(m, {x, wi}, dist, tau, opl);
    Tr = std::exp(-tau);
    time_ps = opl / kSpeedOfLight;
    return true;
  }
  double optical_depth = 0.0, opl = 0.0;
  Ray ray{x, wi};
  double remaining = dist;
  for (int k = 0; k < kMaxNullCrossings; ++k) {
    SurfaceHit hit;
    const double s_max = remaining - eps;
    const bool found = s_max > eps && scene_.geometry().intersect(ray, 0.0, s_max, hit);
    const double s = found ? hit.s : remaining;
    double tau_k, opl_k;
    segment_integrals(m, ray, s, tau_k, opl_k);
    optical_depth += tau_k;
    opl += opl_k;
    if (!found) {
      Tr = std::exp(-optical_depth);
      time_ps = opl / kSpeedOfLight;
      return true;
    }
    if (scene_.desc().shapes[static_cast<size_t>(hit.shape)].material.type !=
        MaterialDesc::Type::None)
      return false;
    ++stats.null_crossings;
    m = dot(wi, hit.ng) < 0 ? scene_.inside_medium(hit.shape) : scene_.outside_medium();
    ray.o = hit.p + wi * eps;
    remaining -= s + eps;
  }
  return false;
}

void VolPathIntegrator::trace(Ray ray, Rng& rng, PixelAccumulator& acc, PathStats& stats) const {
  const auto& media = scene_.media();
  const auto& shapes = scene_.desc().shapes;
  const LightSet& lights = scene_.lights();
  const double eps = scene_.ray_epsilon();
  ++stats.paths;

  int m = scene_.outside_medium();
  RGB beta(1.0);
  double t = 0.0;             // time of flight from the sensor to the current vertex, ps
  bool on_camera_segment = true;  // unwarp mode drops the time of the sensor's own segment
  bool specular = true;       // previous vertex was the sensor or a specular surface
  double prev_pdf = 0.0;      // solid-angle pdf of the direction sampled at the previous vertex
  Vec3 prev_p = ray.o;
  int depth = 0;
  int null_crossings = 0;
  double u_next = -1.0;       // pre-drawn distance uniform for the next segment (angular sampling)

  for (;;) {
    SurfaceHit hit;
    const bool found = scene_.geometry().intersect(ray, 0.0, kInf, hit);
    const double s_surf = found ? hit.s : kInf;
    const Medium& med = media[static_cast<size_t>(m)];
    const MediumSample ms = sample_medium(med, ray, s_surf, rng, u_next);
    const double t_dropped = unwarp_ && on_camera_segment ? 0.0 : 1.0 / kSpeedOfLight;
    const bool segment_connections = med.connection != ConnectionSampling::Collision && !point_lights_.empty();
    if (segment_connections && depth < max_depth_)
      estimate_segment(med, m, ray, s_surf, beta, t, t_dropped, rng, acc, stats);
    // Angular direction sampling: the next segment's distance draw is made now so that every
    // strategy's MIS weight at this segment's vertices sees the same r_aux.
    const bool angular = med.direction == DirectionSampling::Angular && !point_lights_.empty() &&
                         ms.main.collided && depth < max_depth_;
    u_next = angular ? rng.uniform() : -1.0;
    const double t_main = t + ms.main.opl * t_dropped;
    const DirectionMix mix_main = angular ? direction_mix(med, ray.at(ms.main.s), t_main, u_next) : DirectionMix{};
    if (ms.extra.collided && depth < max_depth_) {
      // The time-uniform collision of MIS: next-event estimation only (the path goes on from
      // the mean-free-path collision).
      const Vec3 x2 = ray.at(ms.extra.s);
      const double albedo2 = med.type == Medium::Type::Grid ? med.grid->albedo_at(x2) : med.homogeneous.albedo();
      const double t2 = t + ms.extra.opl * t_dropped;
      const DirectionMix mix2 = angular ? direction_mix(med, x2, t2, u_next) : DirectionMix{};
      estimate_direct_medium(x2, m, ray.d, med.g(), beta * (albedo2 * ms.extra_nee_weight), t2,
                             angular ? &mix2 : nullptr, segment_connections, rng, acc, stats);
    }
    const DistanceEvent& ev = ms.main;
    if (!ev.collided && !found) break;  // escaped to infinity
    beta *= ev.weight;
    t += ev.opl * t_dropped;
    if (t > t_cut_) break;

    if (ev.collided) {
      // Real collision: absorb by weighting with the single-scattering albedo.
      on_camera_segment = false;
      ++stats.medium_events;
      if (depth >= max_depth_) {
        ++stats.max_depth_hits;
        break;
      }
      ++depth;
      const Vec3 x = ray.at(ev.s);
      beta *= med.type == Medium::Type::Grid ? med.grid->albedo_at(x) : med.homogeneous.albedo();
      if (beta.is_black()) break;
      estimate_direct_medium(x, m, ray.d, med.g(), beta * ms.main_nee_weight, t, angular ? &mix_main : nullptr,
                             segment_connections, rng, acc, stats);
      Vec3 wi;
      beta *= sample_direction(mix_main, x, ray.d, med.g(), rng, wi, prev_pdf);  // 1 for phase alone
      if (beta.is_black()) break;
      specular = false;
      prev_p = x;
      ray = {x, wi};
      continue;
    }

    // Surface interaction.
    const ShapeDesc& sh = shapes[static_cast<size_t>(hit.shape)];
    const bool front = dot(ray.d, hit.ng) < 0;
    if (sh.emissive && front) {
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
      m = front ? scene_.inside_medium(hit.shape) : scene_.outside_medium();
      ray.o = hit.p + ray.d * eps;
      continue;
    }
    on_camera_segment = false;
    ++stats.surface_events;
    if (depth >= max_depth_) {
      ++stats.max_depth_hits;
      break;
    }
    ++depth;
    const Vec3 ns = front ? hit.ng : -hit.ng;  // normal on the side the ray came from
    const Vec3 wo = -ray.d;

    switch (sh.material.type) {
      case MaterialDesc::Type::Diffuse: {
        const RGB& albedo = sh.material.albedo;
        double pmf = 0;
        const int li = lights.pick(rng.uniform(), pmf);
        const double u1 = rng.uniform(), u2 = rng.uniform();
        LightSample ls;
        const Vec3 x = hit.p + ns * eps;
        if (li >= 0 && lights.sample(li, x, u1, u2, ls)) {
          const double cos_i = dot(ns, ls.wi);
          double Tr, dt;
          if (cos_i > 0 && connect(x, m, ls.wi, ls.dist, Tr, dt, stats)) {
            const double bsdf_pdf = cos_i * kInvPi;
            const double w = ls.is_delta ? 1.0 : power_heuristic(pmf * ls.pdf, bsdf_pdf);
            const Light& L = lights.light(li);
            deposit(t + dt + L.pulse.offset_ps, L.pulse.sigma_ps(),
                    beta * albedo * ls.Li * (kInvPi * cos_i * Tr * w / (pmf * ls.pdf)), acc, stats);
          }
        }
        const Vec3 local = sample_cosine_hemisphere(rng.uniform(), rng.uniform());
        const Vec3 wi = normalize(Frame(ns).to_world(local));
        beta *= albedo;  // (albedo / pi) cos / (cos / pi)
        prev_pdf = cosine_hemisphere_pdf(local.z);
        specular = false;
        prev_p = hit.p;
        ray = {x, wi};
        break;
      }
      case MaterialDesc::Type::Mirror: {
        beta *= sh.material.reflectance;
        specular = true;
        prev_p = hit.p;
        ray = {hit.p + ns * eps, normalize(ray.d - ns * (2.0 * dot(ray.d, ns)))};
        break;
      }
      case MaterialDesc::Type::Dielectric: {
        const double eta_out = media[static_cast<size_t>(scene_.outside_medium())].eta_at(hit.p);
        const double eta_in = sh.material.eta;
        const double eta = front ? eta_in / eta_out : eta_out / eta_in;  // eta_t / eta_i
        const double cos_i = dot(wo, ns);
        double cos_t;
        const double F = fresnel_dielectric(cos_i, eta, cos_t);
        specular = true;
        prev_p = hit.p;
        if (rng.uniform() < F) {
          ray = {hit.p + ns * eps, normalize(ray.d + ns * (2.0 * cos_i))};
        } else {
          const Vec3 dir = normalize(ray.d / eta + ns * (cos_i / eta - cos_t));
          beta *= 1.0 / (eta * eta);  // radiance scales with 1 / eta^2 across the interface
          m = front ? scene_.inside_medium(hit.shape) : scene_.outside_medium();
          ray = {hit.p - ns * eps, dir};
        }
        break;
      }
      case MaterialDesc::Type::None:
        break;
    }
  }
}

}  // namespace femto
