// Shapes: sphere, quad, box and mesh, with their material, interior medium and emission.
#include <cmath>
#include <filesystem>

#include "core/error.h"
#include "core/scene_json/loader.h"

namespace femto::scene_json {

namespace fs = std::filesystem;

// Every vertex Embree sees must stay far inside float range (transforms can scale them out).
void Loader::check_vertices(const ShapeDesc& s, const std::string& path) const {
  for (std::size_t i = 0; i < s.vertices.size(); ++i) {
    const Vec3& q = s.vertices[i];
    if (std::isfinite(q.x) && std::isfinite(q.y) && std::isfinite(q.z) &&
        max_abs_component(q) <= kMaxMagnitude)
      continue;
    fail(path, "vertex " + std::to_string(i + 1) + " lands at " + fmt(q) +
                   " mm, outside the bound of +-1e9 mm on every axis (docs/scene-format.md, "
                   "Bounds)");
  }
}

void Loader::shapes(const Json& v, SceneDesc& scene) const {
  if (!v.is_array()) fail("/shapes", "expected an array of shapes", v);
  for (std::size_t i = 0; i < v.size(); ++i)
    scene.shapes.push_back(shape(v[i], at("/shapes", i), scene));
}

ShapeDesc Loader::shape(const Json& v, const std::string& p, const SceneDesc& scene) const {
  const Json& o = object(v, p);
  const Keys types = {"sphere", "quad", "box", "mesh"};
  const Keys common = {"type", "transform", "material", "medium", "emission", "pulse"};
  const Keys specific = {"center", "radius", "corner", "edge1", "edge2", "min", "max", "file"};
  const std::string type = type_of(o, p, types, join(common, specific));
  ShapeDesc s;
  s.where = p;
  if (type == "sphere") {
    if (const Json* t = find(o, "transform"))
      fail(at(p, "transform"), "a sphere cannot be transformed; set 'center' and 'radius'", *t);
    check_keys(o, p, join(common, {"center", "radius"}), "a sphere", specific);
    s.type = ShapeDesc::Type::Sphere;
    s.center = vec3(require(o, p, "center"), at(p, "center"));
    const Json& jr = require(o, p, "radius");
    s.radius = not_tiny(number(jr, at(p, "radius"), above(0)), kMinLength, at(p, "radius"), jr);
  } else if (type == "quad") {
    check_keys(o, p, join(common, {"corner", "edge1", "edge2"}), "a quad", specific);
    s.type = ShapeDesc::Type::Quad;
    const Vec3 c = vec3(require(o, p, "corner"), at(p, "corner"));
    const Vec3 e1 = nonzero_vec3(require(o, p, "edge1"), at(p, "edge1"));
    const Json& je2 = require(o, p, "edge2");
    const Vec3 e2 = nonzero_vec3(je2, at(p, "edge2"));
    // Relative test: the sine of the angle between the edges must not vanish.
    if (length(cross(e1, e2)) <= 1e-9 * length(e1) * length(e2))
      fail(at(p, "edge2"), "parallel to edge1 " + fmt(e1) + ", so the quad is degenerate", je2);
    make_quad(c, e1, e2, s);
  } else if (type == "box") {
    check_keys(o, p, join(common, {"min", "max"}), "a box", specific);
    s.type = ShapeDesc::Type::Box;
    const Vec3 lo = vec3(require(o, p, "min"), at(p, "min"));
    const Json& jhi = require(o, p, "max");
    const Vec3 hi = vec3(jhi, at(p, "max"));
    if (!(hi.x > lo.x && hi.y > lo.y && hi.z > lo.z))
      fail(at(p, "max"), "must exceed 'min' " + fmt(lo) + " on every axis", jhi);
    make_box(lo, hi, s);
  } else {
    check_keys(o, p, join(common, {"file"}), "a mesh", specific);
    s.type = ShapeDesc::Type::Mesh;
    const std::string fp = at(p, "file");
    const Json& jf = require(o, p, "file");
    const std::string file = string(jf, fp);
    if (file.empty()) fail(fp, "must name an OBJ or PLY file", jf);
    const std::string path = resolve(file);
    std::error_code ec;
    if (!fs::is_regular_file(path, ec)) fail(fp, "mesh file not found: " + clip(path, 200), jf);
    try {
      load_mesh_file(path, s);
    } catch (const InputError& e) {
      fail(fp, e.what());
    }
  }

  if (const Json* m = find(o, "material")) s.material = material(*m, at(p, "material"));
  // Diffuse, mirror and rough conductor surfaces let no light in; dielectrics (smooth or rough)
  // bound a region of their own index.
  const bool opaque = s.material.type != MaterialDesc::Type::None && !s.material.is_transmissive();
  const std::string dielectric =
      s.material.type == MaterialDesc::Type::RoughDielectric ? "rough dielectric" : "dielectric";
  if (s.type == ShapeDesc::Type::Quad && s.material.is_transmissive())
    fail(at(p, "material"),
         "a " + dielectric + " needs a closed shape (sphere, box or mesh); a quad has no inside",
         o.at("material"));
  if (const Json* m = find(o, "medium")) {
    const std::string mp = at(p, "medium");
    if (s.type == ShapeDesc::Type::Quad)
      fail(mp, "a quad has no inside to fill; use a closed shape (sphere, box or mesh)", *m);
    if (opaque)
      fail(mp, "the shape's material is opaque, so its interior medium could never be reached", *m);
    s.interior_medium = medium_ref(*m, mp, scene);
    const MediumDesc& md = scene.media[static_cast<std::size_t>(s.interior_medium)];
    if (s.material.is_transmissive() && std::abs(md.medium.eta - s.material.eta) > 1e-12) {
      const Json& mat = o.at("material");
      const Json* e = find(mat, "eta");
      fail(e ? at(at(p, "material"), "eta") : at(p, "material"),
           dielectric + " eta " + fmt(s.material.eta) + (e ? "" : " (the default)") +
               " differs from eta " + fmt(md.medium.eta) + " of its interior medium '" +
               clip(md.name) + "'; they must be equal",
           e ? *e : mat);
    }
  }
  if (const Json* e = find(o, "emission")) {
    s.emission = bright_rgb(*e, at(p, "emission"));
    s.emissive = true;
  }
  if (const Json* pl = find(o, "pulse")) {
    if (!s.emissive) fail(at(p, "pulse"), "'pulse' needs 'emission' on the same shape", *pl);
    s.pulse = pulse(*pl, at(p, "pulse"));
  }
  if (s.material.type == MaterialDesc::Type::None && s.interior_medium < 0 && !s.emissive)
    fail(p, "shape has no 'material', 'medium' or 'emission', so it would be invisible");

  const Json* t = find(o, "transform");
  if (t) apply_transform(transform(*t, at(p, "transform")), s);
  check_vertices(s, at(p, t                                 ? "transform"
                          : s.type == ShapeDesc::Type::Mesh ? "file"
                          : s.type == ShapeDesc::Type::Box  ? "max"
                                                            : "corner"));
  if (s.type == ShapeDesc::Type::Mesh && (s.interior_medium >= 0 || s.material.is_transmissive())) {
    const std::string problem = closed_mesh_problem(s.vertices, s.triangles);
    if (!problem.empty())
      fail(at(p, "file"),
           "a mesh with a medium or a " + dielectric +
               " material must be closed and outward-facing, but " + problem,
           o.at("file"));
  }
  return s;
}

}  // namespace femto::scene_json
