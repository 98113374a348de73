#pragma once
// The scenes of femto-bench-caustics (bench/bench_caustics.cpp): the default scene's spot light
// replaced by an emitter that camera paths can reach, and which pixels and blocks see the glass.
#include <cmath>
#include <utility>
#include <vector>

#include "core/scene.h"
#include "core/scene_desc.h"

namespace femto::bench {

/// The default scene with its spot light replaced by an emissive sphere of radius r at the same
/// place, of the same radiant intensity I: a Lambertian sphere has I = Le pi r^2 in every
/// direction.
inline SceneDesc sphere_emitter_scene(const SceneDesc& spot, double r) {
  SceneDesc d = spot;
  const LightDesc l = d.lights.front();
  d.lights.clear();
  ShapeDesc s;
  s.type = ShapeDesc::Type::Sphere;
  s.center = l.position;
  s.radius = r;
  s.emissive = true;
  s.emission = l.intensity / (3.14159265358979323846 * r * r);
  s.pulse = l.pulse;
  s.material.type = MaterialDesc::Type::Diffuse;
  s.material.albedo = RGB(0.0);
  d.shapes.push_back(s);
  return d;
}

/// The same emitter inside a black cone (albedo 0) of the spot's half-angle about its axis, open
/// towards the scene: it lights the spot's cone only (a hard edge at cone_angle instead of the
/// spot's falloff from falloff_start), so camera paths face the spot's light, not a lamp that
/// lights the whole room.
inline SceneDesc housed_emitter_scene(const SceneDesc& spot, double r) {
  SceneDesc d = sphere_emitter_scene(spot, r);
  const LightDesc& l = spot.lights.front();
  const Vec3 axis = normalize(l.direction);
  const double half = l.cone_angle_deg * 3.14159265358979323846 / 180.0;
  // Apex behind the sphere so that the cone clears it by 5%; 60 mm long.
  const Vec3 apex = l.position - axis * (1.05 * r / std::sin(half));
  const double len = 60.0, rim = len * std::tan(half);
  const Vec3 u = normalize(cross(axis, std::abs(axis.x) < 0.9 ? Vec3(1, 0, 0) : Vec3(0, 1, 0)));
  const Vec3 v = cross(axis, u);
  ShapeDesc cone;
  cone.type = ShapeDesc::Type::Mesh;
  cone.material.type = MaterialDesc::Type::Diffuse;
  cone.material.albedo = RGB(0.0);
  const int n = 64;
  cone.vertices.push_back(apex);
  for (int k = 0; k < n; ++k) {
    const double phi = 2.0 * 3.14159265358979323846 * k / n;
    cone.vertices.push_back(apex + axis * len + (u * std::cos(phi) + v * std::sin(phi)) * rim);
  }
  for (uint32_t k = 0; k < static_cast<uint32_t>(n); ++k)
    cone.triangles.push_back({0, 1 + k, 1 + (k + 1) % static_cast<uint32_t>(n)});
  d.shapes.push_back(cone);
  return d;
}

/// Whether the camera ray of pixel (x, y) through its centre or a corner meets `sphere`.
inline bool pixel_sees_sphere(const Camera& cam, int x, int y, const ShapeDesc& sphere) {
  for (const auto& c : {std::pair<double, double>{0.5, 0.5}, {0, 0}, {1, 0}, {0, 1}, {1, 1}}) {
    const Ray r = cam.generate_ray(x + c.first, y + c.second);
    const Vec3 oc = r.o - sphere.center;
    const double b = dot(oc, r.d), cc = dot(oc, oc) - sphere.radius * sphere.radius;
    if (b * b - cc > 0 && -b + std::sqrt(b * b - cc) > 0) return true;
  }
  return false;
}

/// Blocks of B x B pixels holding a pixel whose camera ray (centre or a corner) meets a
/// dielectric sphere: through glass the camera sees the light itself (a small emitter's image in
/// the sphere, which no estimator here samples well), not the medium.
inline std::vector<bool> glass_blocks(const Scene& scene, int B) {
  const Camera& cam = scene.camera();
  const int bw = (cam.width() + B - 1) / B, bh = (cam.height() + B - 1) / B;
  std::vector<bool> out(static_cast<size_t>(bw * bh), false);
  for (const ShapeDesc& g : scene.desc().shapes) {
    if (g.type != ShapeDesc::Type::Sphere || g.material.type != MaterialDesc::Type::Dielectric)
      continue;
    for (int y = 0; y < cam.height(); ++y)
      for (int x = 0; x < cam.width(); ++x)
        if (pixel_sees_sphere(cam, x, y, g)) out[static_cast<size_t>((y / B) * bw + x / B)] = true;
  }
  return out;
}

}  // namespace femto::bench
