#pragma once
// Small scene-building helpers shared by the tracer tests.
#include <string>
#include <vector>

#include "core/render.h"
#include "core/scene_desc.h"

namespace femto::test {

/// A parallelogram corner + e1, e2 as a two-triangle shape; front normal along e1 x e2.
inline ShapeDesc quad(const Vec3& corner, const Vec3& e1, const Vec3& e2, const MaterialDesc& mat) {
  ShapeDesc s;
  s.type = ShapeDesc::Type::Quad;
  s.vertices = {corner, corner + e1, corner + e1 + e2, corner + e2};
  s.triangles = {{0, 1, 2}, {0, 2, 3}};
  s.material = mat;
  return s;
}

/// A perspective camera at pos looking at `look_at`, vertical field of view fov degrees.
inline CameraDesc perspective(const Vec3& pos, const Vec3& look_at, double fov, int w, int h) {
  CameraDesc c;
  c.type = CameraDesc::Type::Perspective;
  c.position = pos;
  c.look_at = look_at;
  c.fov_deg = fov;
  c.width = w;
  c.height = h;
  return c;
}

inline LightDesc point_light(const Vec3& p, double intensity) {
  LightDesc l;
  l.type = LightDesc::Type::Point;
  l.position = p;
  l.intensity = RGB(intensity);
  return l;
}

inline MaterialDesc diffuse(double albedo) {
  MaterialDesc m;
  m.type = MaterialDesc::Type::Diffuse;
  m.albedo = RGB(albedo);
  return m;
}

inline CameraDesc ortho_camera(const Vec3& pos, const Vec3& look_at, double width_mm, int w, int h) {
  CameraDesc c;
  c.type = CameraDesc::Type::Orthographic;
  c.position = pos;
  c.look_at = look_at;
  c.up = std::abs(look_at.y - pos.y) > 0.9 * length(look_at - pos) ? Vec3(0, 0, 1) : Vec3(0, 1, 0);
  c.ortho_width = width_mm;
  c.width = w;
  c.height = h;
  return c;
}

inline MediumDesc medium(const char* name, double sigma_a, double sigma_s, double g, double eta) {
  MediumDesc m;
  m.name = name;
  m.medium = HomogeneousMedium{sigma_a, sigma_s, g, eta};
  return m;
}

/// A voxel medium read from `file` (grid "density", sigma_t = density / mm), constant albedo.
inline MediumDesc vdb_medium(const char* name, const std::string& file, double albedo, double g) {
  MediumDesc m;
  m.name = name;
  m.type = MediumDesc::Type::Vdb;
  m.vdb.file = file;
  m.vdb.albedo = albedo;
  m.medium.g = g;
  return m;
}

/// A laser at the origin along +x: radius R (mm), power P.
inline LightDesc laser_along_x(double R, double P) {
  LightDesc l;
  l.type = LightDesc::Type::Laser;
  l.position = {0, 0, 0};
  l.direction = {1, 0, 0};
  l.radius = R;
  l.power = RGB(P);
  return l;
}

/// Renders `desc` once per seed (seeds base..base+batches-1) and returns each batch's film.
inline std::vector<TransientFilm> render_batches(const SceneDesc& desc, int spp, int batches,
                                                 int max_depth = 1000, int threads = 2) {
  const Scene scene(desc);
  std::vector<TransientFilm> films;
  for (int b = 0; b < batches; ++b) {
    RenderOptions opt;
    opt.spp = spp;
    opt.seed = 1000 + static_cast<uint64_t>(b);
    opt.threads = threads;
    opt.max_depth = max_depth;
    opt.quiet = true;
    films.push_back(render(scene, opt).film);
  }
  return films;
}

/// Mean and standard error over batch values.
struct MeanSE {
  double mean = 0, se = 0;
};
inline MeanSE mean_se(const std::vector<double>& v) {
  double m = 0;
  for (double x : v) m += x;
  m /= static_cast<double>(v.size());
  double var = 0;
  for (double x : v) var += (x - m) * (x - m);
  var /= static_cast<double>(v.size() - 1);
  return {m, std::sqrt(var / static_cast<double>(v.size()))};
}

/// Mean and standard error over batches of bin i of the first pixel (red channel).
inline MeanSE bin_mean_se(const std::vector<TransientFilm>& films, int i) {
  std::vector<double> v;
  for (const auto& f : films) v.push_back(f.transient()[3 * static_cast<size_t>(i)]);
  return mean_se(v);
}

}  // namespace femto::test
