#pragma once
// Rough dielectric interface (Walter et al. 2007): GGX microfacets, each a smooth dielectric,
// Smith height-correlated masking-shadowing, sampled by the normals visible from wo (Heitz 2018).
// z > 0 is outside (relative index 1), z < 0 inside (index eta); eta != 1 (an index-matched
// interface does not refract, so it has no rough transmission lobe: see Bsdf::from_material).
//
// With eta_p = eta_wi_side / eta_wo_side and the generalised half vector
// m = +-normalize(wo + eta_p wi), m.z > 0 (for reflection eta_p = 1):
//   reflection:   f = R D G / (4 |wo.z| |wi.z|)
//   transmission: f = T D G |wi.m| |wo.m| / (|wo.z| |wi.z| (wi.m + wo.m / eta_p)^2),
//                 times 1 / eta_p^2 in Radiance mode
//   pdf = D_wo(m) * (R / (4 |wo.m|)  or  T |wi.m| / (wi.m + wo.m / eta_p)^2)
// where R and T = 1 - R are the exact Fresnel coefficients at the microfacet, and the last
// factors are the Jacobians dm/dwi of reflection and refraction.
#include <cmath>

#include "core/bsdf/bsdf_sample.h"
#include "core/bsdf/fresnel.h"
#include "core/bsdf/microfacet.h"

namespace femto {

struct RoughDielectric {
  double eta = 1.5;  ///< index inside / index outside
  Ggx ggx;

  RGB f(const Vec3& wo, const Vec3& wi, TransportMode mode) const {
    Pair p;
    return connect(wo, wi, p) ? RGB(value(wo, wi, p, mode)) : RGB();
  }

  double pdf(const Vec3& wo, const Vec3& wi) const {
    Pair p;
    return connect(wo, wi, p) ? density(wo, p) : 0.0;
  }

  /// Draws a normal visible from wo, then reflects (probability R at that normal) or refracts.
  bool sample(const Vec3& wo, double u_lobe, double u1, double u2, TransportMode mode,
              BsdfSample& s) const {
    if (wo.z == 0.0 || !std::isfinite(wo.z)) return false;
    const bool outside = wo.z > 0.0;
    // The distribution is symmetric under m -> -m, so wo below samples as -wo above.
    const Vec3 m = ggx.sample_visible(outside ? wo : -wo, u1, u2);
    const double cos_up = std::abs(dot(wo, m));  // cosine on wo's side of the facet
    if (!(m.z > 0.0) || !same_sign(dot(wo, m), wo.z)) return false;
    const double eta_t = eta_across(wo);
    const Fresnel fr = fresnel_dielectric(cos_up, eta_t);
    const bool reflect_lobe = u_lobe < fr.R;
    const Vec3 wi =
        reflect_lobe ? reflect(wo, m) : refract(wo, outside ? m : -m, cos_up, fr.cos_t, eta_t);
    // f and pdf of the result through the same code as f() and pdf(), so that weight and pdf
    // agree with them to rounding even where the refraction is ill-conditioned (near grazing).
    Pair p;
    if (!connect(wo, wi, p) || p.reflected != reflect_lobe) return false;
    s.pdf = density(wo, p);
    const double value_cos = value(wo, wi, p, mode) * std::abs(wi.z);
    if (!(s.pdf > 0.0) || !std::isfinite(s.pdf) || !std::isfinite(value_cos)) return false;
    s.wi = wi;
    s.weight = RGB(value_cos / s.pdf);  // = G / G1(wo), times 1 / eta_p^2 for Radiance refraction
    s.delta = false;
    s.transmitted = !p.reflected;
    return true;
  }

 private:
  /// A direction pair joined through one microfacet.
  struct Pair {
    Vec3 m;  ///< microfacet normal, m.z > 0
    bool reflected = true;
    double eta_p = 1.0;           ///< eta_wi_side / eta_wo_side (1 for reflection)
    double cos_om = 0.0;          ///< wo.m
    double cos_im = 0.0;          ///< wi.m
    double coefficient = 0.0;     ///< Fresnel R (reflection) or T (transmission) at m
    double jacobian_denom = 0.0;  ///< (wi.m + wo.m / eta_p)^2, transmission only
  };

  /// Index of the far side / index of wo's side.
  double eta_across(const Vec3& wo) const { return wo.z > 0.0 ? eta : 1.0 / eta; }

  /// The microfacet normal that scatters wo into wi; false if there is none: a direction on the
  /// surface, a degenerate half vector, or a facet that wo or wi sees from behind.
  bool connect(const Vec3& wo, const Vec3& wi, Pair& p) const {
    if (wo.z == 0.0 || wi.z == 0.0 || !std::isfinite(wo.z) || !std::isfinite(wi.z)) return false;
    p.reflected = same_side(wo, wi);
    p.eta_p = p.reflected ? 1.0 : eta_across(wo);
    const Vec3 h = wo + wi * p.eta_p;
    const double len2 = length_squared(h);
    if (!(len2 > 0.0)) return false;
    p.m = h / std::sqrt(len2);
    if (p.m.z < 0.0) p.m = -p.m;
    if (!(p.m.z > 0.0)) return false;
    p.cos_om = dot(wo, p.m);
    p.cos_im = dot(wi, p.m);
    if (!same_sign(p.cos_om, wo.z) || !same_sign(p.cos_im, wi.z)) return false;  // backfacing
    if (p.reflected) {
      p.coefficient = fresnel_dielectric(std::abs(p.cos_om), eta_across(wo)).R;
    } else {
      // Both cosines are known: the symmetric form keeps f reciprocal near total reflection.
      p.coefficient = fresnel_transmittance(std::abs(p.cos_om), std::abs(p.cos_im), p.eta_p);
      const double d = p.cos_im + p.cos_om / p.eta_p;
      p.jacobian_denom = d * d;
    }
    return true;
  }

  /// f(wo, wi) of a connected pair.
  double value(const Vec3& wo, const Vec3& wi, const Pair& p, TransportMode mode) const {
    const double DG = ggx.D(p.m) * ggx.G(wo, wi);
    const double cosines = std::abs(wo.z) * std::abs(wi.z);
    if (p.reflected) {
      const double denom = 4.0 * cosines;
      return denom > 0.0 ? p.coefficient * DG / denom : 0.0;
    }
    const double denom = cosines * p.jacobian_denom;
    if (!(denom > 0.0)) return 0.0;
    const double ft = p.coefficient * DG * std::abs(p.cos_im * p.cos_om) / denom;
    // Radiance / eta^2 is what is conserved across the interface.
    return mode == TransportMode::Radiance ? ft / (p.eta_p * p.eta_p) : ft;
  }

  /// pdf(wo, wi) of a connected pair: the visible-normal density times the lobe's probability
  /// and its Jacobian dm/dwi.
  double density(const Vec3& wo, const Pair& p) const {
    const double cos_o = std::abs(wo.z);
    if (!(cos_o > 0.0)) return 0.0;
    const double g1_d = ggx.G1(wo) * ggx.D(p.m);  // D_wo(m) = g1_d |wo.m| / |wo.z|
    if (p.reflected) return p.coefficient * g1_d / (4.0 * cos_o);
    if (!(p.jacobian_denom > 0.0)) return 0.0;
    return p.coefficient * g1_d * std::abs(p.cos_om) * std::abs(p.cos_im) /
           (cos_o * p.jacobian_denom);
  }
};

}  // namespace femto
