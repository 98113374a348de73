#pragma once
// Collision-distance sampling along a ray through a medium given as a sequence of segments on
// which sigma_t(s) and eta(s) are cubic polynomials (one constant segment for a homogeneous
// medium, one per grid cell for a voxel medium). Strategies:
//  - mean free path: p(s) = sigma_t(s) exp(-tau(s)), tau = integral of sigma_t;
//  - time-uniform: optical path length O(s) = integral of eta is exponential with rate lambda,
//    p(s) = lambda eta(s) exp(-lambda O(s)), so vertex *times* O / c are exponential in time
//    whatever eta does (seed 000 Sec. 5.1, sampled in OPL rather than distance);
//  - MIS: both are sampled on every segment; the path continues from the mean-free-path
//    collision, and next-event estimation is done at both collisions with multi-sample MIS
//    weights (balance or power). Continuing with one strategy only avoids the variance that a
//    one-sample mixture compounds over many vertices (a factor 2 per vertex in dense media).
//    All pdfs are exact because tau and O are integrated exactly per segment.
#include <cmath>
#include <limits>

#include "core/scene_desc.h"
#include "media/grid_medium.h"
#include "media/poly3.h"
#include "samplers/distance.h"

namespace femto {

struct DistanceStrategy {
  DistanceSampling kind = DistanceSampling::Mfp;
  double lambda = 0.0;  ///< time-uniform rate, per mm of optical path length
  MisHeuristic heuristic = MisHeuristic::Balance;
};

struct DistanceEvent {
  bool collided = false;
  double s = 0;        ///< collision distance, or the end of the walked range
  double tau = 0;      ///< optical depth over [0, s]
  double opl = 0;      ///< optical path length over [0, s], mm
  double sigma_t = 0;  ///< at the collision
  double eta = 1;      ///< at the collision
  /// Throughput factor f / p without the albedo: exp(-tau) sigma_t / p(s) at a collision (the
  /// caller multiplies by the albedo at the point), exp(-tau) / P(no collision) otherwise.
  double weight = 1;
};

/// Integral of p over [0, L]; an infinite segment (the ray leaves to infinity) is constant.
inline double segment_integral(const Poly3& p, double L) {
  if (std::isfinite(L)) return p.integral(L);
  return p.c[0] > 0 ? std::numeric_limits<double>::infinity() : 0.0;
}

/// A homogeneous medium as a single segment [0, s_max].
class ConstantSegments {
 public:
  ConstantSegments(double sigma_t, double eta, double s_max) : sigma_t_(sigma_t), eta_(eta), s_max_(s_max) {}
  bool next(MediumSegment& seg) {
    if (done_) return false;
    done_ = true;
    seg = {0.0, s_max_, Poly3::constant(sigma_t_), Poly3::constant(eta_)};
    return true;
  }

 private:
  double sigma_t_, eta_, s_max_;
  bool done_ = false;
};

/// Samples a collision with a single strategy (kind Mfp or TimeUniform) along the segments,
/// which must cover [0, s_max] in order. Weight: f / p of the chosen strategy.
template <class Segments>
DistanceEvent sample_distance(Segments& segments, const DistanceStrategy& st, double u_dist) {
  const bool use_mfp = st.kind != DistanceSampling::TimeUniform;
  const double target = use_mfp ? unit_exponential(u_dist) : unit_exponential(u_dist) / st.lambda;
  DistanceEvent ev;
  MediumSegment seg;
  while (segments.next(seg)) {
    const double L = seg.s1 - seg.s0;
    const Poly3& driver = use_mfp ? seg.sigma_t : seg.eta;
    const double part = segment_integral(driver, L);
    if ((use_mfp ? ev.tau : ev.opl) + part >= target && part > 0) {
      const double t = invert_integral(driver, target - (use_mfp ? ev.tau : ev.opl), L);
      ev.collided = true;
      ev.s = seg.s0 + t;
      ev.tau += seg.sigma_t.integral(t);
      ev.opl += seg.eta.integral(t);
      ev.sigma_t = std::fmax(0.0, seg.sigma_t(t));
      ev.eta = seg.eta(t);
      // mfp: f / p = sigma_t T / (sigma_t T) = 1; time-uniform: sigma_t T / (lambda eta e^{-lambda O}).
      ev.weight = use_mfp ? 1.0 : ev.sigma_t * std::exp(-ev.tau) / (st.lambda * ev.eta * std::exp(-st.lambda * ev.opl));
      return ev;
    }
    ev.s = seg.s1;
    ev.tau += segment_integral(seg.sigma_t, L);
    ev.opl += segment_integral(seg.eta, L);
  }
  // Passed the whole range: T / P(pass).
  ev.weight = use_mfp ? 1.0 : std::exp(-ev.tau) / std::exp(-st.lambda * ev.opl);
  return ev;
}

/// The time-uniform share q of the `mixture` strategy on a segment that starts with budget_opl
/// mm of optical path left before the window closes, in a medium of extinction sigma_t and index
/// eta there. x = sigma_t budget / eta is how many mean free paths the remaining window spans:
/// mean-free-path vertices cover a window shorter than a mean free path about evenly (q -> 0),
/// and leave a window of many mean free paths empty beyond the first ones (q -> 1/2). Capping q
/// at 1/2 caps every weight at 1 / (1 - q) <= 2.
inline double mixture_tu_probability(double sigma_t, double eta, double budget_opl) {
  if (!(sigma_t > 0) || !(budget_opl > 0)) return 0.0;
  const double x = sigma_t * budget_opl / eta;
  return std::isfinite(x) ? 0.5 * x / (1.0 + x) : 0.5;
}

/// Splits the one uniform u of a mixture segment into the pick (time-uniform when u < q) and the
/// uniform of the picked strategy's draw (one uniform, so angular direction sampling can draw it
/// ahead).
inline bool mixture_pick(double u, double q, double& u_dist) {
  if (u < q) {
    u_dist = u / q;
    return true;
  }
  u_dist = (u - q) / (1.0 - q);
  return false;
}

/// Density of the mixture at a collision with optical depth tau, optical path opl, extinction
/// sigma_t and index eta, and its probability of passing a range of optical depth tau and path
/// opl.
inline double mixture_pdf(double q, double lambda, double tau, double opl, double sigma_t,
                          double eta) {
  return (1.0 - q) * sigma_t * std::exp(-tau) + q * lambda * eta * std::exp(-lambda * opl);
}
inline double mixture_pass(double q, double lambda, double tau, double opl) {
  return (1.0 - q) * std::exp(-tau) + q * std::exp(-lambda * opl);
}

/// One-sample MIS of the two strategies (kind Mixture): time-uniform with probability q_tu,
/// mean free path otherwise (mixture_pick splits u), and the path continues from the collision.
/// Weight f / (mixture density): sigma_t T / mixture_pdf at a collision (at most 1 / (1 - q),
/// so no heavy tail in dense media, unlike time-uniform alone), T / mixture_pass past the end.
template <class Segments>
DistanceEvent sample_distance_mixture(Segments& segments, const DistanceStrategy& st, double q_tu,
                                      double u) {
  double u_dist;
  const bool tu = mixture_pick(u, q_tu, u_dist);
  const double target = tu ? unit_exponential(u_dist) / st.lambda : unit_exponential(u_dist);
  DistanceEvent ev;
  MediumSegment seg;
  while (segments.next(seg)) {
    const double L = seg.s1 - seg.s0;
    const Poly3& driver = tu ? seg.eta : seg.sigma_t;
    const double part = segment_integral(driver, L);
    const double done = tu ? ev.opl : ev.tau;
    if (done + part >= target && part > 0) {
      const double x = invert_integral(driver, target - done, L);
      ev.collided = true;
      ev.s = seg.s0 + x;
      ev.tau += seg.sigma_t.integral(x);
      ev.opl += seg.eta.integral(x);
      ev.sigma_t = std::fmax(0.0, seg.sigma_t(x));
      ev.eta = seg.eta(x);
      const double p = mixture_pdf(q_tu, st.lambda, ev.tau, ev.opl, ev.sigma_t, ev.eta);
      ev.weight = p > 0 ? ev.sigma_t * std::exp(-ev.tau) / p : 0.0;
      return ev;
    }
    ev.s = seg.s1;
    ev.tau += segment_integral(seg.sigma_t, L);
    ev.opl += segment_integral(seg.eta, L);
  }
  const double P = mixture_pass(q_tu, st.lambda, ev.tau, ev.opl);
  ev.weight = P > 0 ? std::exp(-ev.tau) / P : 0.0;
  return ev;
}

/// Both strategies at once, for MIS (kind Mis): `mfp` continues the path (weight 1 as above),
/// `tu` is a second collision sampled uniformly in time. Each collision also gets `nee_weight`:
/// its MIS weight times f / p, to weight next-event estimation at that point (multi-sample MIS
/// of the two strategies, balance or power heuristic; densities evaluated exactly).
struct DistancePair {
  DistanceEvent mfp, tu;
  double mfp_nee_weight = 0, tu_nee_weight = 0;
};

template <class Segments>
DistancePair sample_distance_mis(Segments& segments, const DistanceStrategy& st, double u_mfp, double u_tu) {
  const double tau_target = unit_exponential(u_mfp);
  const double opl_target = unit_exponential(u_tu) / st.lambda;
  DistancePair out;
  double tau = 0, opl = 0;
  MediumSegment seg;
  while (!(out.mfp.collided && out.tu.collided) && segments.next(seg)) {
    const double L = seg.s1 - seg.s0;
    const double tau_seg = segment_integral(seg.sigma_t, L), opl_seg = segment_integral(seg.eta, L);
    auto record = [&](DistanceEvent& ev, const Poly3& driver, double remaining) {
      const double t = invert_integral(driver, remaining, L);
      ev.collided = true;
      ev.s = seg.s0 + t;
      ev.tau = tau + seg.sigma_t.integral(t);
      ev.opl = opl + seg.eta.integral(t);
      ev.sigma_t = std::fmax(0.0, seg.sigma_t(t));
      ev.eta = seg.eta(t);
    };
    if (!out.mfp.collided && tau_seg > 0 && tau + tau_seg >= tau_target) record(out.mfp, seg.sigma_t, tau_target - tau);
    if (!out.tu.collided && opl_seg > 0 && opl + opl_seg >= opl_target) record(out.tu, seg.eta, opl_target - opl);
    tau += tau_seg;
    opl += opl_seg;
    if (!out.mfp.collided) {
      out.mfp.s = seg.s1;
      out.mfp.tau = tau;
      out.mfp.opl = opl;
    }
  }
  const bool power = st.heuristic == MisHeuristic::Power;
  auto pdfs = [&](const DistanceEvent& ev, double& p_mfp, double& p_tu) {
    p_mfp = ev.sigma_t * std::exp(-ev.tau);
    p_tu = st.lambda * ev.eta * std::exp(-st.lambda * ev.opl);
  };
  if (out.mfp.collided) {
    double a, b;
    pdfs(out.mfp, a, b);
    out.mfp_nee_weight = power ? a * a / (a * a + b * b) : a / (a + b);  // w_mfp * (f / p_mfp = 1)
  }
  if (out.tu.collided) {
    double a, b;
    pdfs(out.tu, a, b);
    const double f = a;  // sigma_t T, the collision integrand without the albedo
    out.tu_nee_weight = a + b > 0 ? (power ? f * b / (a * a + b * b) : f / (a + b)) : 0.0;
  }
  out.mfp.weight = 1.0;
  return out;
}

/// Optical depth and optical path length over all segments (exact transmittance exp(-tau)).
template <class Segments>
void integrate_segments(Segments& segments, double& tau, double& opl) {
  tau = 0;
  opl = 0;
  MediumSegment seg;
  while (segments.next(seg)) {
    const double L = seg.s1 - seg.s0;
    tau += seg.sigma_t.integral(L);
    opl += seg.eta.integral(L);
  }
}

}  // namespace femto
