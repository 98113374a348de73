#pragma once
// Rough conductor, two-sided: GGX microfacets that are perfect mirrors with Schlick Fresnel,
// Smith height-correlated masking-shadowing, sampled by visible normals.
//   f = F(wo.h) D(h) G(wo, wi) / (4 |wo.z| |wi.z|),  h = normalize(wo + wi)
//   pdf = D_wo(h) / (4 |wo.h|) = G1(wo) D(h) / (4 |wo.z|)
#include <cmath>

#include "core/bsdf/bsdf_sample.h"
#include "core/bsdf/fresnel.h"
#include "core/bsdf/microfacet.h"

namespace femto {

struct RoughConductor {
  RGB f0{1.0};  ///< reflectance at normal incidence (Schlick's F0)
  Ggx ggx;

  RGB f(const Vec3& wo, const Vec3& wi) const {
    if (!same_side(wo, wi)) return {};
    const Vec3 o = wo.z > 0.0 ? wo : mirror_z(wo), i = wo.z > 0.0 ? wi : mirror_z(wi);
    const double denom = 4.0 * o.z * i.z;
    const Vec3 h = o + i;  // h.z > 0: both directions are above
    if (!(denom > 0.0)) return {};
    const Vec3 m = normalize(h);
    return fresnel_schlick(f0, dot(o, m)) * (ggx.D(m) * ggx.G(o, i) / denom);
  }

  double pdf(const Vec3& wo, const Vec3& wi) const {
    if (!same_side(wo, wi)) return 0.0;
    const Vec3 o = wo.z > 0.0 ? wo : mirror_z(wo), i = wo.z > 0.0 ? wi : mirror_z(wi);
    return pdf_up(o, normalize(o + i));
  }

  /// Reflects wo about a visible normal; fails when the reflection points into the surface
  /// (the energy single scattering loses).
  bool sample(const Vec3& wo, double u1, double u2, BsdfSample& s) const {
    if (wo.z == 0.0 || !std::isfinite(wo.z)) return false;
    const Vec3 o = wo.z > 0.0 ? wo : mirror_z(wo);
    const Vec3 m = ggx.sample_visible(o, u1, u2);
    const double cos_om = dot(o, m);
    const Vec3 i = reflect(o, m);
    if (!(cos_om > 0.0) || !(i.z > 0.0)) return false;
    s.pdf = pdf_up(o, m);
    if (!(s.pdf > 0.0) || !std::isfinite(s.pdf)) return false;
    // f |cos i| / pdf: D and the cosines cancel, leaving F G / G1.
    s.weight = fresnel_schlick(f0, cos_om) * (ggx.G(o, i) / ggx.G1(o));
    s.wi = wo.z > 0.0 ? i : mirror_z(i);
    s.delta = false;
    s.transmitted = false;
    return true;
  }

 private:
  /// pdf of reflection about m for o.z > 0; the Jacobian 1 / (4 o.m) cancels D_visible's o.m.
  double pdf_up(const Vec3& o, const Vec3& m) const {
    const double denom = 4.0 * o.z;
    if (!(denom > 0.0)) return 0.0;
    return ggx.G1(o) * ggx.D(m) / denom;
  }
};

}  // namespace femto
