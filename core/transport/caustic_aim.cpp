#include "core/transport/caustic_aim.h"

#include <algorithm>
#include <cmath>

#include "core/constants.h"
#include "core/sincos_2pi.h"

namespace femto {

namespace {
// Mirrors, glass and rough surfaces start a caustic chain; diffuse ones end it and index-matched
// boundaries (no material) are passed straight.
bool starts_chain(const MaterialDesc& m) {
  return m.type != MaterialDesc::Type::None && m.type != MaterialDesc::Type::Diffuse;
}

// A sphere holding every point of the shape.
void bounding_sphere(const ShapeDesc& sh, Vec3& c, double& r) {
  if (sh.type == ShapeDesc::Type::Sphere) {
    c = sh.center;
    r = sh.radius;
    return;
  }
  Vec3 lo(INFINITY), hi(-INFINITY);
  for (const Vec3& v : sh.vertices) {
    lo = Vec3(std::min(lo.x, v.x), std::min(lo.y, v.y), std::min(lo.z, v.z));
    hi = Vec3(std::max(hi.x, v.x), std::max(hi.y, v.y), std::max(hi.z, v.z));
  }
  c = (lo + hi) * 0.5;
  r = 0;
  for (const Vec3& v : sh.vertices) r = std::max(r, length(v - c));
}

// Whether unit direction d lies in the cone: by the sine, which keeps narrow cones exact.
bool in_cone(const CausticAim::Cone& k, const Vec3& d) {
  return dot(d, k.axis) > 0 && length_squared(cross(d, k.axis)) <= k.sin2_max;
}
}  // namespace

CausticAim::CausticAim(const SceneDesc& desc, const LightSet& lights) {
  per_light_.resize(static_cast<size_t>(lights.count()));
  for (int i = 0; i < lights.count(); ++i) {
    const Light& l = lights.light(i);
    if (!is_point_like(l)) continue;
    PerLight& pl = per_light_[static_cast<size_t>(i)];
    const double light_solid_angle =
        l.type == Light::Type::Point ? 4 * kPi : 2 * kPi * (1 - l.cos_cone);
    const double spot_angle = l.type == Light::Type::Spot ? std::acos(l.cos_cone) : kPi;
    bool inside = false;
    for (const ShapeDesc& sh : desc.shapes) {
      if (!starts_chain(sh.material)) continue;
      Vec3 c;
      double r;
      bounding_sphere(sh, c, r);
      r *= 1 + 1e-6;  // rounding must not put a hit outside every cone
      const Vec3 v = c - l.position;
      const double dist = length(v);
      if (!(dist > r)) {
        inside = true;
        break;
      }
      Cone k;
      k.axis = v / dist;
      const double sin2 = (r / dist) * (r / dist);
      k.cos_max = std::sqrt(1 - sin2);
      k.one_minus = sin2 / (1 + k.cos_max);
      k.sin2_max = k.one_minus * (1 + k.cos_max);
      k.solid_angle = 2 * kPi * k.one_minus;
      // A spot never emits into a cone wholly outside its own.
      const double apart = std::acos(std::clamp(dot(k.axis, l.direction), -1.0, 1.0));
      if (apart - std::asin(r / dist) >= spot_angle) continue;
      pl.cones.push_back(k);
      pl.total += k.solid_angle;
    }
    // Aim only where it pays: cones covering more than half the light waste less by plain
    // emission than by their overlaps and the parts outside a spot's cone.
    if (inside || !(pl.total <= 0.5 * light_solid_angle)) {
      pl = PerLight{};
      continue;
    }
    pl.aimed = true;
    pl.ratio = pl.total / light_solid_angle;
    double sum = 0;
    for (const Cone& k : pl.cones) pl.cdf.push_back(sum += k.solid_angle / pl.total);
    if (!pl.cdf.empty()) pl.cdf.back() = 1;
  }
}

bool CausticAim::any() const {
  return std::any_of(per_light_.begin(), per_light_.end(),
                     [](const PerLight& p) { return p.aimed; });
}

double CausticAim::path_share(const LightSet& lights) const {
  double share = 0;
  for (int i = 0; i < lights.count(); ++i)
    share += lights.pmf(i) * (aims(i) ? per_light_[static_cast<size_t>(i)].ratio : 1.0);
  return share;
}

double CausticAim::pdf(int i, const Vec3& d) const {
  const PerLight& pl = per_light_[static_cast<size_t>(i)];
  int count = 0;
  for (const Cone& k : pl.cones) count += in_cone(k, d);
  return count > 0 ? count / pl.total : 0.0;
}

bool CausticAim::sample_emission(const Light& l, int i, double u_cone, double u1, double u2,
                                 LightEmission& e) const {
  const PerLight& pl = per_light_[static_cast<size_t>(i)];
  if (pl.cones.empty()) return false;  // nothing non-diffuse in reach: no caustic light
  const size_t c = std::min<size_t>(
      static_cast<size_t>(std::upper_bound(pl.cdf.begin(), pl.cdf.end(), u_cone) - pl.cdf.begin()),
      pl.cones.size() - 1);
  const Cone& k = pl.cones[c];
  // Uniform in the cone: 1 - cos = u1 (1 - cos_max); sin from (1 - cos)(1 + cos), exact when
  // narrow.
  const double one_minus = u1 * k.one_minus, cos_t = 1 - one_minus;
  const double sin_t = std::sqrt(std::fmax(0.0, one_minus * (1 + cos_t)));
  const SinCos phi = sincos_2pi(u2);
  const Vec3 d = normalize(Frame(k.axis).to_world({sin_t * phi.cos, sin_t * phi.sin, cos_t}));
  // The mixture's pdf: the drawn cone always counts (rounding at its rim must not drop it).
  int count = 1;
  for (size_t j = 0; j < pl.cones.size(); ++j)
    if (j != c) count += in_cone(pl.cones[j], d);
  double falloff = 1;
  if (l.type == Light::Type::Spot) {
    falloff = spot_falloff(l, dot(d, l.direction));
    if (!(falloff > 0)) return false;
  }
  e.area = false;
  e.ray = {l.position, d};
  e.beta = l.intensity * (falloff * pl.total / count);
  return true;
}

}  // namespace femto
