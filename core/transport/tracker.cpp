#include "core/transport/tracker.h"

#include <cmath>
#include <limits>

#include "core/constants.h"
#include "samplers/distance.h"

namespace femto {

namespace {
}

PathStats& PathStats::operator+=(const PathStats& o) {
  paths += o.paths;
  medium_events += o.medium_events;
  surface_events += o.surface_events;
  null_crossings += o.null_crossings;
  max_depth_hits += o.max_depth_hits;
  roulette_ends += o.roulette_ends;
  nonfinite_dropped += o.nonfinite_dropped;
  light_paths += o.light_paths;
  photons_stored += o.photons_stored;
  photon_gathers += o.photon_gathers;
  beams_stored += o.beams_stored;
  beam_gathers += o.beam_gathers;
  return *this;
}

MediumSample MediumTracker::sample(const Medium& med, const Ray& ray, double s_max, Rng& rng,
                                   double u_main, double q_tu) const {
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
    // A mixture with no time-uniform share is mean-free-path sampling (mixture_pick keeps u).
    const bool mfp = med.strategy.kind == DistanceSampling::Mfp ||
                     (med.strategy.kind == DistanceSampling::Mixture && !(q_tu > 0));
    if (mfp || !(h.sigma_s > 0)) {
      // Closed form; a purely absorbing medium is integrated exactly instead of sampled.
      const double s = h.sigma_s > 0 ? sample_exponential(h.sigma_t(), u1) : kInf;
      ev.collided = s < s_max;
      ev.s = ev.collided ? s : s_max;
      ev.opl = h.eta * ev.s;
      ev.tau = h.sigma_t() * ev.s;
      ev.sigma_t = h.sigma_t();
      ev.eta = h.eta;
      ev.weight = h.sigma_s > 0 ? 1.0 : std::exp(-h.sigma_t() * s_max);
      return out;
    }
    ConstantSegments segments(h.sigma_t(), h.eta, s_max);
    return finish(segments, med.strategy, u1, q_tu, rng);
  }
  GridMedium::Walker walker(*med.grid, ray, s_max);
  return finish(walker, med.strategy, u1, q_tu, rng);
}

template <class Segments>
MediumSample MediumTracker::finish(Segments& segments, const DistanceStrategy& st, double u1,
                                   double q_tu, Rng& rng) const {
  MediumSample out;
  if (st.kind == DistanceSampling::Mixture) {
    out.main = sample_distance_mixture(segments, st, q_tu, u1);
    return out;
  }
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

void MediumTracker::segment_integrals(int m, const Ray& ray, double s, double& tau,
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

bool MediumTracker::connect(const Vec3& x, int m, const Vec3& w, double dist, double& Tr,
                            double& time_ps, PathStats& stats) const {
  const double eps = scene_.ray_epsilon();
  if (!scene_.has_null_boundaries()) {
    // Every surface blocks: one occlusion query, and the segment stays in medium m.
    if (dist > 2 * eps && scene_.geometry().occluded({x, w}, 0.0, dist - eps)) return false;
    double tau, opl;
    segment_integrals(m, {x, w}, dist, tau, opl);
    Tr = std::exp(-tau);
    time_ps = opl / kSpeedOfLight;
    return true;
  }
  double optical_depth = 0.0, opl = 0.0;
  Ray ray{x, w};
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
    m = scene_.medium_beyond(hit.shape, w, hit.ng);
    ray.o = hit.p + w * eps;
    remaining -= s + eps;
  }
  return false;
}

}  // namespace femto
