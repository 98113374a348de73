#include "core/lights.h"

#include <algorithm>
#include <cmath>

#include "core/constants.h"
#include "core/sampling.h"
#include "core/sincos_2pi.h"

namespace femto {

namespace {
double smoothstep(double a, double b, double x) {
  if (a == b) return x < a ? 0.0 : 1.0;
  const double t = std::clamp((x - a) / (b - a), 0.0, 1.0);
  return t * t * (3.0 - 2.0 * t);
}
}  // namespace

double spot_falloff(const Light& l, double cos_t) {
  return smoothstep(l.cos_cone, l.cos_falloff, cos_t);
}

LightSet::LightSet(const SceneDesc& scene) : scene_(&scene) {
  shape_light_.assign(scene.shapes.size(), -1);
  std::vector<double> power;
  for (const LightDesc& d : scene.lights) {
    Light l;
    l.position = d.position;
    l.direction = d.direction;
    l.pulse = d.pulse;
    switch (d.type) {
      case LightDesc::Type::Point:
        l.type = Light::Type::Point;
        l.intensity = d.intensity;
        power.push_back(4.0 * kPi * d.intensity.average());
        break;
      case LightDesc::Type::Spot: {
        l.type = Light::Type::Spot;
        l.intensity = d.intensity;
        l.cos_cone = std::cos(d.cone_angle_deg * kPi / 180.0);
        l.cos_falloff = std::cos(d.falloff_deg * kPi / 180.0);
        power.push_back(2.0 * kPi * (1.0 - 0.5 * (l.cos_cone + l.cos_falloff)) *
                        d.intensity.average());
        break;
      }
      case LightDesc::Type::Laser:
        l.type = Light::Type::Laser;
        l.power = d.power;
        l.radius = d.radius;
        power.push_back(d.power.average());
        break;
    }
    lights_.push_back(l);
  }
  for (size_t s = 0; s < scene.shapes.size(); ++s) {
    const ShapeDesc& sh = scene.shapes[s];
    if (!sh.emissive) continue;
    Light l;
    l.shape = static_cast<int>(s);
    l.emission = sh.emission;
    l.pulse = sh.pulse;
    if (sh.type == ShapeDesc::Type::Sphere) {
      l.type = Light::Type::AreaSphere;
      l.position = sh.center;
      l.radius = sh.radius;
      l.area = 4.0 * kPi * sh.radius * sh.radius;
    } else {
      l.type = Light::Type::AreaMesh;
      double acc = 0.0;
      for (const auto& t : sh.triangles) {
        acc += 0.5 * length(cross(sh.vertices[t[1]] - sh.vertices[t[0]],
                                  sh.vertices[t[2]] - sh.vertices[t[0]]));
        l.tri_cdf.push_back(acc);
      }
      l.area = acc;
      if (acc > 0)
        for (double& c : l.tri_cdf) c /= acc;
    }
    power.push_back(kPi * l.area * sh.emission.average());
    shape_light_[s] = static_cast<int>(lights_.size());
    lights_.push_back(std::move(l));
  }
  double total = 0.0;
  for (double p : power) total += p;
  double acc = 0.0;
  for (double p : power) {
    const double pm = total > 0 ? p / total : 1.0 / static_cast<double>(power.size());
    pmf_.push_back(pm);
    acc += pm;
    cdf_.push_back(acc);
  }
  if (!cdf_.empty()) cdf_.back() = 1.0;
  bool first = true;
  for (const Light& l : lights_) {
    min_offset_ = first ? l.pulse.offset_ps : std::min(min_offset_, l.pulse.offset_ps);
    max_sigma_ = std::max(max_sigma_, l.pulse.sigma_ps());
    first = false;
  }
}

int LightSet::pick(double u, double& pmf) const {
  if (cdf_.empty()) return -1;
  const auto it = std::upper_bound(cdf_.begin(), cdf_.end(), u);
  int i = static_cast<int>(it - cdf_.begin());
  i = std::min(i, static_cast<int>(cdf_.size()) - 1);
  pmf = pmf_[static_cast<size_t>(i)];
  return pmf > 0 ? i : -1;
}

bool LightSet::sample(int i, const Vec3& x, double u1, double u2, LightSample& ls) const {
  const Light& l = lights_[static_cast<size_t>(i)];
  switch (l.type) {
    case Light::Type::Point:
    case Light::Type::Spot: {
      const Vec3 v = l.position - x;
      const double d2 = length_squared(v);
      if (!(d2 > 0)) return false;
      ls.dist = std::sqrt(d2);
      ls.wi = v / ls.dist;
      ls.p = l.position;
      ls.pdf = 1.0;
      ls.is_delta = true;
      double falloff = 1.0;
      if (l.type == Light::Type::Spot) {
        falloff = spot_falloff(l, dot(-ls.wi, l.direction));
        if (falloff <= 0) return false;
      }
      ls.Li = l.intensity * (falloff / d2);
      return true;
    }
    case Light::Type::Laser: {
      // Collimated beam: x is lit only inside the cylinder, from the direction -direction.
      const Vec3 v = x - l.position;
      const double along = dot(v, l.direction);
      if (along <= 0) return false;
      const Vec3 perp = v - l.direction * along;
      if (length_squared(perp) > l.radius * l.radius) return false;
      ls.p = l.position + perp;
      ls.wi = -l.direction;
      ls.dist = along;
      ls.pdf = 1.0;
      ls.is_delta = true;
      ls.Li = l.power / (kPi * l.radius * l.radius);
      return true;
    }
    case Light::Type::AreaSphere: {
      const Vec3 n = sample_uniform_sphere(u1, u2);
      ls.p = l.position + n * l.radius;
      const Vec3 v = ls.p - x;
      const double d2 = length_squared(v);
      if (!(d2 > 0)) return false;
      ls.dist = std::sqrt(d2);
      ls.wi = v / ls.dist;
      const double cos_l = -dot(ls.wi, n);
      if (cos_l <= 0) return false;  // emits from the outside only
      ls.pdf = d2 / (cos_l * l.area);
      ls.Li = l.emission;
      ls.is_delta = false;
      return true;
    }
    case Light::Type::AreaMesh: {
      const ShapeDesc& sh = scene_->shapes[static_cast<size_t>(l.shape)];
      // Reuse u1: pick the triangle, then rescale u1 within it.
      const auto it = std::upper_bound(l.tri_cdf.begin(), l.tri_cdf.end(), u1);
      size_t t = std::min(static_cast<size_t>(it - l.tri_cdf.begin()), l.tri_cdf.size() - 1);
      const double c0 = t == 0 ? 0.0 : l.tri_cdf[t - 1];
      const double w = l.tri_cdf[t] - c0;
      const double uu = w > 0 ? std::clamp((u1 - c0) / w, 0.0, 1.0 - 1e-16) : 0.5;
      const auto& tri = sh.triangles[t];
      const Vec3 &a = sh.vertices[tri[0]], &b = sh.vertices[tri[1]], &c = sh.vertices[tri[2]];
      double b1, b2;
      sample_uniform_triangle(uu, u2, b1, b2);
      ls.p = a * (1 - b1 - b2) + b * b1 + c * b2;
      const Vec3 n = normalize(cross(b - a, c - a));
      const Vec3 v = ls.p - x;
      const double d2 = length_squared(v);
      if (!(d2 > 0)) return false;
      ls.dist = std::sqrt(d2);
      ls.wi = v / ls.dist;
      const double cos_l = -dot(ls.wi, n);
      if (cos_l <= 0) return false;  // one-sided: emits along the front normal
      ls.pdf = d2 / (cos_l * l.area);
      ls.Li = l.emission;
      ls.is_delta = false;
      return true;
    }
  }
  return false;
}

namespace {
/// Uniform point on an emitting mesh (triangle by area, then uniform in it) and its front normal.
void sample_mesh_point(const ShapeDesc& sh, const std::vector<double>& tri_cdf, double u1,
                       double u2, Vec3& p, Vec3& n) {
  const auto it = std::upper_bound(tri_cdf.begin(), tri_cdf.end(), u1);
  const size_t t = std::min(static_cast<size_t>(it - tri_cdf.begin()), tri_cdf.size() - 1);
  const double c0 = t == 0 ? 0.0 : tri_cdf[t - 1];
  const double w = tri_cdf[t] - c0;
  const double uu = w > 0 ? std::clamp((u1 - c0) / w, 0.0, 1.0 - 1e-16) : 0.5;
  const auto& tri = sh.triangles[t];
  const Vec3 &a = sh.vertices[tri[0]], &b = sh.vertices[tri[1]], &c = sh.vertices[tri[2]];
  double b1, b2;
  sample_uniform_triangle(uu, u2, b1, b2);
  p = a * (1 - b1 - b2) + b * b1 + c * b2;
  n = normalize(cross(b - a, c - a));
}
}  // namespace

bool LightSet::sample_emission(int i, double u1, double u2, double u3, double u4,
                               LightEmission& e) const {
  const Light& l = lights_[static_cast<size_t>(i)];
  e.area = false;
  switch (l.type) {
    case Light::Type::Point:
      e.ray = {l.position, sample_uniform_sphere(u1, u2)};
      e.beta = l.intensity * (4.0 * kPi);
      return true;
    case Light::Type::Spot: {
      // Uniform in the cone's solid angle, weighted by the smooth falloff.
      const double cos_t = 1.0 - u1 * (1.0 - l.cos_cone);
      const double sin_t = std::sqrt(std::fmax(0.0, 1.0 - cos_t * cos_t));
      const SinCos phi = sincos_2pi(u2);
      const Vec3 d =
          normalize(Frame(l.direction).to_world({sin_t * phi.cos, sin_t * phi.sin, cos_t}));
      const double falloff = spot_falloff(l, cos_t);
      if (!(falloff > 0)) return false;
      e.ray = {l.position, d};
      e.beta = l.intensity * (falloff * 2.0 * kPi * (1.0 - l.cos_cone));
      return true;
    }
    case Light::Type::Laser: {
      double x, y;
      sample_uniform_disc(u1, u2, x, y);
      const Frame f(l.direction);
      e.ray = {l.position + (f.s * x + f.t * y) * l.radius, l.direction};
      e.beta = l.power;  // total flux, spread uniformly over the beam's cross-section
      return true;
    }
    case Light::Type::AreaSphere:
    case Light::Type::AreaMesh: {
      Vec3 p, n;
      if (l.type == Light::Type::AreaSphere) {
        n = sample_uniform_sphere(u1, u2);
        p = l.position + n * l.radius;
      } else {
        sample_mesh_point(scene_->shapes[static_cast<size_t>(l.shape)], l.tri_cdf, u1, u2, p, n);
      }
      if (!(l.area > 0)) return false;
      const Vec3 local = sample_cosine_hemisphere(u3, u4);
      e.ray = {p, normalize(Frame(n).to_world(local))};
      e.n = n;
      e.area = true;
      e.Le_over_pdf_pos = l.emission * l.area;
      e.beta = l.emission * (kPi * l.area);  // Le cos / ((1 / A) (cos / pi))
      return true;
    }
  }
  return false;
}

double LightSet::pdf_area(int i, const Vec3& x, const Vec3& p, const Vec3& n) const {
  const Light& l = lights_[static_cast<size_t>(i)];
  const Vec3 v = p - x;
  const double d2 = length_squared(v);
  const double cos_l = std::abs(dot(v, n)) / std::sqrt(d2);
  if (!(cos_l > 0) || !(l.area > 0)) return 0.0;
  return d2 / (cos_l * l.area);
}

}  // namespace femto
