#include "core/tissue/launch.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/bsdf/fresnel.h"
#include "core/sampling.h"
#include "core/scene_json/shape_builders.h"
#include "core/sincos_2pi.h"
#include "core/transport/voxel_space.h"
#include "media/grid_medium.h"  // clamped_floor

namespace femto::tissue {

namespace {
double standard_normal(Rng& rng) {
  const double u1 = rng.uniform(), u2 = rng.uniform();
  return std::sqrt(-2.0 * std::log1p(-u1)) * sincos_2pi(u2).cos;
}
}  // namespace

Emitter::Emitter(const Source& src) {
  if (is_surface(src.type)) {
    // The camera scenes' emissive shapes: uniform over the area, cosine-weighted about the
    // normal (a Lambertian emitter), from the light code's sample_emission.
    ShapeDesc sh;
    sh.emissive = true;
    sh.emission = RGB(1.0);
    if (src.type == Source::Type::Sphere) {
      sh.type = ShapeDesc::Type::Sphere;
      sh.center = src.position;
      sh.radius = src.radius;
    } else if (src.type == Source::Type::Quad) {
      sh.type = ShapeDesc::Type::Quad;
      scene_json::make_quad(src.position, src.edge1, src.edge2, sh);
    } else if (src.type == Source::Type::Box) {
      sh.type = ShapeDesc::Type::Box;
      scene_json::make_box(src.box_min, src.box_max, sh);
    } else {
      sh.type = ShapeDesc::Type::Mesh;
      sh.vertices = src.mesh_vertices;
      sh.triangles = src.mesh_triangles;
    }
    scene.shapes = {sh};
    lights = std::make_unique<LightSet>(scene);
    LightEmission e;  // beta = Le pi A for every ray: weight 1 after this
    if (lights->sample_emission(0, 0.5, 0.5, 0.5, 0.5, e) && e.beta.r > 0)
      inv_mean_beta = 1 / e.beta.r;
    return;
  }
  if (src.type != Source::Type::Spot) return;
  LightDesc d;
  d.type = LightDesc::Type::Spot;
  d.position = src.position;
  d.direction = src.direction;
  d.intensity = RGB(1.0);
  d.cone_angle_deg = src.cone_angle_deg;
  d.falloff_deg = src.falloff_start_deg;
  scene.lights = {d};
  lights = std::make_unique<LightSet>(scene);
  // E[beta] over u1 (the cone's cosine is linear in u1, the falloff smooth): midpoint rule,
  // relative error ~1e-10.
  const int m = 200000;
  double sum = 0, carry = 0;  // compensated: a constant weight comes out 1 to rounding
  for (int i = 0; i < m; ++i) {
    LightEmission e;
    if (!lights->sample_emission(0, (i + 0.5) / m, 0.25, 0.5, 0.5, e)) continue;
    const double y = e.beta.r - carry, t = sum + y;
    carry = (t - sum) - y;
    sum = t;
  }
  inv_mean_beta = sum > 0 ? m / sum : 0.0;
  // The largest beta: falloff 1 over the cone's solid angle (unit intensity).
  max_weight = inv_mean_beta * 2 * kPi * (1 - std::cos(src.cone_angle_deg * kPi / 180));
}

template <class Space>
bool launch(const Setup& s, const Space& space, const Emitter& emitter, Rng& rng, Photon& p,
            double& specular) {
  const Source& src = s.source;
  const LabelVolume& vol = space.volume();
  specular = 0;
  p = Photon{};
  p.t = src.offset_ps + (src.fwhm_ps > 0 ? src.sigma_ps() * standard_normal(rng) : 0.0);
  p.x = src.position;
  p.d = src.direction;
  if (src.type == Source::Type::Gaussian || src.type == Source::Type::Disk) {
    const double u = rng.uniform();
    const SinCos phi = sincos_2pi(rng.uniform());  // exact at quarter turns, as elsewhere
    // Gaussian: intensity exp(-2 r^2 / w^2) (w: 1/e^2 radius); disk: uniform in area.
    const double r = src.type == Source::Type::Gaussian
                         ? src.waist * std::sqrt(-0.5 * std::log1p(-u))
                         : src.radius * std::sqrt(u);
    p.x += Frame(src.direction).to_world({r * phi.cos, r * phi.sin, 0.0});
  } else if (src.type == Source::Type::Isotropic) {
    const double u1 = rng.uniform(), u2 = rng.uniform();
    p.d = sample_uniform_sphere(u1, u2);
  } else if (src.type == Source::Type::Spot) {
    const double u1 = rng.uniform(), u2 = rng.uniform();
    LightEmission e;
    if (!emitter.lights->sample_emission(0, u1, u2, 0.5, 0.5, e)) {
      p.w = 0;  // outside the falloff: no energy (never for u1 < 1)
      return false;
    }
    p.d = e.ray.d;
    p.w = e.beta.r * emitter.inv_mean_beta;
  } else if (is_surface(src.type)) {
    // Two draws for the point, two for the direction, in this order.
    const double u1 = rng.uniform(), u2 = rng.uniform(), u3 = rng.uniform(), u4 = rng.uniform();
    LightEmission e;
    if (!emitter.lights->sample_emission(0, u1, u2, u3, u4, e)) return false;
    p.x = e.ray.o;
    p.d = e.ray.d;
    p.w = e.beta.r * emitter.inv_mean_beta;
  }
  // Into the grid's box (slab test); `axis` is the face it enters through, -1 if inside.
  double s_in = 0, s_out = std::numeric_limits<double>::infinity();
  int axis = -1;
  const Vec3 hi = vol.upper();
  for (int a = 0; a < 3; ++a) {
    const double x = p.x[a], d = p.d[a];
    if (d == 0) {
      if (x < vol.origin[a] || x > hi[a]) return false;
      continue;
    }
    const double ta = (vol.origin[a] - x) / d, tb = (hi[a] - x) / d;
    const double near = std::min(ta, tb), far = std::max(ta, tb);
    if (near >= s_in) s_in = near, axis = a;
    s_out = std::min(s_out, far);
  }
  if (!(s_out > s_in)) return false;
  double travelled = s_in;
  p.x += p.d * s_in;
  for (int a = 0; a < 3; ++a)
    p.cell[a] = std::clamp(clamped_floor((p.x[a] - vol.origin[a]) / vol.voxel), 0, vol.n[a] - 1);
  if (axis >= 0) p.x[axis] = vol.origin[axis] + (p.d[axis] > 0 ? 0 : vol.n[axis]) * vol.voxel;
  // Through label-0 voxels to the first tissue voxel.
  if (vol.label_at(p.cell[0], p.cell[1], p.cell[2]) == 0) {
    VoxelDda dda(p.x, p.d, p.cell, vol.origin, Vec3(vol.voxel));
    double s_entry = 0;
    while (vol.label_at(dda.cell[0], dda.cell[1], dda.cell[2]) == 0) {
      axis = dda.axis();
      s_entry = dda.t_max[axis];
      dda.advance(axis);
      if (dda.cell[axis] < 0 || dda.cell[axis] >= vol.n[axis]) return false;
    }
    travelled += s_entry;
    p.x += p.d * s_entry;
    for (int a = 0; a < 3; ++a) p.cell[a] = dda.cell[a];
    p.x[axis] = vol.origin[axis] + (p.cell[axis] + (p.d[axis] > 0 ? 0 : 1)) * vol.voxel;
  }
  p.label = vol.label_at(p.cell[0], p.cell[1], p.cell[2]);
  const double n1 = space.outside_n(), n2 = space.optics_at(p).n;
  p.t += travelled * n1 / kSpeedOfLight;
  if (axis >= 0 && s.fresnel && n1 != n2) {
    const Fresnel fr = fresnel_dielectric(std::abs(p.d[axis]), n2 / n1);
    if (src.specular) {
      specular = p.w * fr.R;
      p.w -= specular;
    }
    if (fr.R < 1.0) {  // Snell at the entry surface
      const double sign = p.d[axis] > 0 ? 1.0 : -1.0;
      Vec3 d = p.d * (n1 / n2);
      d[axis] = sign * fr.cos_t;
      p.d = normalize(d);
    }
  }
  return true;
}

template bool launch(const Setup&, const LabelSpace&, const Emitter&, Rng&, Photon&, double&);
template bool launch(const Setup&, const VoxelSpace&, const Emitter&, Rng&, Photon&, double&);

}  // namespace femto::tissue
