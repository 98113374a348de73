#pragma once
// Surface scattering at a path vertex: one value type over the BSDF families, dispatched by a
// switch. All directions are in the local frame: z = the shape's geometric normal (outside of
// closed shapes, front of quads); wo points towards the previous path vertex, wi towards the next.
#include <algorithm>

#include "core/bsdf/bsdf_sample.h"
#include "core/bsdf/dielectric.h"
#include "core/bsdf/diffuse.h"
#include "core/bsdf/microfacet.h"
#include "core/bsdf/mirror.h"
#include "core/bsdf/rough_conductor.h"
#include "core/bsdf/rough_dielectric.h"
#include "core/scene_desc.h"

namespace femto {

class Bsdf {
 public:
  /// Surface scattering of material m at a point whose outside medium has refractive index
  /// eta_outside (> 0; dielectrics use eta_rel = m.eta / eta_outside). Material None (an
  /// index-matched boundary) and a rough dielectric with eta_rel = 1 pass light straight through
  /// like a smooth dielectric of relative index 1: without an index step nothing refracts.
  static Bsdf from_material(const MaterialDesc& m, double eta_outside) {
    Bsdf b;
    b.type_ = m.type;
    const double eta_rel = eta_outside > 0.0 ? m.eta / eta_outside : m.eta;
    const Ggx ggx{std::max(m.roughness, kMinAlpha)};
    switch (m.type) {
      case MaterialDesc::Type::Diffuse:
        b.family_ = Family::Diffuse;
        b.diffuse_ = Diffuse{m.albedo};
        break;
      case MaterialDesc::Type::Mirror:
        b.family_ = Family::Mirror;
        b.mirror_ = Mirror{m.reflectance};
        break;
      case MaterialDesc::Type::RoughConductor:
        b.family_ = Family::RoughConductor;
        b.conductor_ = RoughConductor{m.reflectance, ggx};
        break;
      case MaterialDesc::Type::RoughDielectric:
        if (eta_rel != 1.0) {
          b.family_ = Family::RoughDielectric;
          b.rough_dielectric_ = RoughDielectric{eta_rel, ggx};
          break;
        }
        b.family_ = Family::Dielectric;
        b.dielectric_ = SmoothDielectric{1.0};
        break;
      case MaterialDesc::Type::Dielectric:
        b.family_ = Family::Dielectric;
        b.dielectric_ = SmoothDielectric{eta_rel};
        break;
      case MaterialDesc::Type::None:
        b.family_ = Family::Dielectric;
        b.dielectric_ = SmoothDielectric{1.0};
        break;
    }
    return b;
  }

  /// BSDF value (no cosine); 0 for delta BSDFs.
  RGB f(const Vec3& wo, const Vec3& wi, TransportMode mode) const {
    switch (family_) {
      case Family::Diffuse:
        return diffuse_.f(wo, wi);
      case Family::RoughConductor:
        return conductor_.f(wo, wi);
      case Family::RoughDielectric:
        return rough_dielectric_.f(wo, wi, mode);
      case Family::Mirror:
      case Family::Dielectric:
        break;
    }
    return {};
  }

  /// Solid-angle pdf of sample(); 0 for delta BSDFs.
  double pdf(const Vec3& wo, const Vec3& wi) const {
    switch (family_) {
      case Family::Diffuse:
        return diffuse_.pdf(wo, wi);
      case Family::RoughConductor:
        return conductor_.pdf(wo, wi);
      case Family::RoughDielectric:
        return rough_dielectric_.pdf(wo, wi);
      case Family::Mirror:
      case Family::Dielectric:
        break;
    }
    return 0.0;
  }

  /// Draws wi: u_lobe picks a lobe (reflection or refraction), u1 and u2 the direction in it.
  /// False when no direction results (wo on the surface, a microfacet reflection into the
  /// surface); s is then unspecified.
  bool sample(const Vec3& wo, double u_lobe, double u1, double u2, TransportMode mode,
              BsdfSample& s) const {
    switch (family_) {
      case Family::Diffuse:
        return diffuse_.sample(wo, u1, u2, s);
      case Family::Mirror:
        return mirror_.sample(wo, s);
      case Family::Dielectric:
        return dielectric_.sample(wo, u_lobe, mode, s);
      case Family::RoughConductor:
        return conductor_.sample(wo, u1, u2, s);
      case Family::RoughDielectric:
        return rough_dielectric_.sample(wo, u_lobe, u1, u2, mode, s);
    }
    return false;
  }

  /// Mirror, smooth dielectric (and the index-matched pass-through).
  bool is_delta() const { return family_ == Family::Mirror || family_ == Family::Dielectric; }
  /// Lambertian.
  bool is_diffuse() const { return family_ == Family::Diffuse; }
  /// Dielectric, rough dielectric (and the index-matched pass-through).
  bool transmits() const {
    return family_ == Family::Dielectric || family_ == Family::RoughDielectric;
  }
  MaterialDesc::Type type() const { return type_; }

 private:
  /// Smallest GGX alpha used: keeps D's 1 / alpha^2 finite; the loader requires alpha > 0.
  static constexpr double kMinAlpha = 1e-4;

  enum class Family { Diffuse, Mirror, Dielectric, RoughConductor, RoughDielectric };
  MaterialDesc::Type type_ = MaterialDesc::Type::None;
  Family family_ = Family::Dielectric;
  // One member per family (all small and trivially copyable); only family_'s is used.
  Diffuse diffuse_;
  Mirror mirror_;
  SmoothDielectric dielectric_{1.0};
  RoughConductor conductor_;
  RoughDielectric rough_dielectric_;
};

}  // namespace femto
