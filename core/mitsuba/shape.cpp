// Shapes: sphere, rectangle, cube, obj and ply, with their bsdf, interior medium and area emitter.
#include <cctype>
#include <cmath>
#include <filesystem>

#include "core/error.h"
#include "core/mitsuba/importer.h"

namespace femto::mitsuba {

void Importer::shape(Node n) {
  const std::string type = plugin_type(n);
  const std::string path = "/shapes/" + std::to_string(out_["shapes"].size());
  origin(path, n);
  Props p = props(n);
  Json s = Json::object();
  const Placement place = get_transform(p, "to_world");
  const Affine& m = place.m;
  const Node tw = p.by_name.count("to_world") ? p.by_name.at("to_world") : n;
  if (p.by_name.count("to_world") && !(m.det() > 0))
    fail(tw, "a mirroring or degenerate to_world (determinant <= 0) is not supported");
  const bool flip = get_bool(p, "flip_normals", false);
  if (flip && type != "rectangle")
    fail(p.by_name.at("flip_normals"), "flip_normals is supported on rectangles only");

  const auto femto_transform = [&](Json& shape_json) {
    SplitTransform st;
    if (!mitsuba::split(m, st))
      fail(tw, "to_world must be rotation, positive scale and translation only (no shear)");
    Json t = Json::object();
    if (st.scale.x != 1 || st.scale.y != 1 || st.scale.z != 1) t["scale"] = vec_json(st.scale);
    if (st.rotates()) t["rotate"] = vec_json(st.rotate_deg);
    if (st.translate.x != 0 || st.translate.y != 0 || st.translate.z != 0)
      t["translate"] = vec_json(st.translate);
    if (!t.empty()) shape_json["transform"] = t;
  };

  if (type == "sphere") {
    const Vec3 c = get_point(p, "center", Vec3(0, 0, 0));
    const Node rn = p.by_name.count("radius") ? p.by_name.at("radius") : Node();
    const double r = get_float(p, "radius", 1.0);
    if (!(r > 0)) fail(rn ? rn : n, "radius must be > 0 (got " + fmt(r) + ")");
    const double sx = length(m.column(0)), sy = length(m.column(1)), sz = length(m.column(2));
    const bool uniform = std::abs(sx - sz) <= 1e-9 * sz && std::abs(sy - sz) <= 1e-9 * sz &&
                         std::abs(dot(m.column(0), m.column(1))) <= 1e-9 * sz * sz &&
                         std::abs(dot(m.column(0), m.column(2))) <= 1e-9 * sz * sz &&
                         std::abs(dot(m.column(1), m.column(2))) <= 1e-9 * sz * sz;
    if (!uniform) fail(tw, "a sphere's to_world must scale uniformly (femto spheres stay round)");
    s["type"] = "sphere";
    s["center"] = vec_json(m.point(c));
    s["radius"] = r * sz;
  } else if (type == "rectangle") {
    // Mitsuba's rectangle is [-1, 1]^2 at z = 0 facing +z.
    s["type"] = "quad";
    Vec3 e1 = m.vector(Vec3(2, 0, 0)), e2 = m.vector(Vec3(0, 2, 0));
    if (flip) std::swap(e1, e2);
    s["corner"] = vec_json(m.point(Vec3(-1, -1, 0)));
    s["edge1"] = vec_json(e1);
    s["edge2"] = vec_json(e2);
  } else if (type == "cube") {
    // Mitsuba's cube is [-1, 1]^3.
    s["type"] = "box";
    if (m.is_diagonal() && m.m[0][0] > 0 && m.m[1][1] > 0 && m.m[2][2] > 0) {
      s["min"] = vec_json(m.point(Vec3(-1, -1, -1)));
      s["max"] = vec_json(m.point(Vec3(1, 1, 1)));
    } else {
      s["min"] = vec_json(Vec3(-1, -1, -1));
      s["max"] = vec_json(Vec3(1, 1, 1));
      femto_transform(s);
    }
  } else if (type == "obj" || type == "ply") {
    const Node fn = p.by_name.count("filename") ? p.by_name.at("filename") : Node();
    if (!fn) fail(n, "missing <string name=\"filename\" .../>");
    const std::string file = get_string(p, "filename", "");
    const std::string ext = std::filesystem::path(file).extension().string();
    std::string lower;
    for (char ch : ext) lower += static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
    if (lower != "." + type)
      fail(fn, "a " + type + " shape needs a ." + type + " file (got \"" + clip(file) + "\")");
    s["type"] = "mesh";
    s["file"] = file;
    origin(path + "/file", fn);
    // femto always shades with the triangles' own (face) normals and has no textures.
    for (const char* unused : {"face_normals", "flip_tex_coords"}) (void)take(p, unused);
    femto_transform(s);
  } else {
    fail(n, "unsupported shape \"" + clip(type) + "\" (sphere, rectangle, cube, obj and ply are)");
  }
  if (p.by_name.count("to_world")) origin(path + "/transform", tw);
  check_all_used(p);

  // Nested BSDF, area emitter and media.
  Material mat;
  Node bsdf_node, interior, exterior, emitter_node;
  for (Node c : p.objects) {
    const std::string tag = std::string(c.name()) == "ref" ? ref_tag(c) : std::string(c.name());
    if (tag == "bsdf") {
      if (bsdf_node) fail(c, "a second bsdf for the shape");
      bsdf_node = c;
    } else if (tag == "medium") {
      const std::string role = c.attribute("name") ? attr(c, "name") : "";
      if (role == "interior") {
        if (interior) fail(c, "a second interior medium");
        interior = resolve(c, 0);
      } else if (role == "exterior") {
        if (exterior) fail(c, "a second exterior medium");
        exterior = resolve(c, 0);
      } else {
        fail(c, "a shape's medium needs name=\"interior\" or name=\"exterior\"");
      }
    } else if (tag == "emitter") {
      if (emitter_node) fail(c, "a second emitter for the shape");
      emitter_node = c;
    } else {
      fail(c, "unsupported element inside <shape> (a bsdf, an area emitter and media are)");
    }
  }
  if (exterior && exterior != global_medium_)
    fail(exterior, "a shape's exterior medium must be the sensor's medium (femto's global medium)" +
                       std::string(global_medium_ ? "" : "; the sensor has none"));
  if (bsdf_node) {
    mat = bsdf(bsdf_node, 0);
    origin(path + "/material", resolve(bsdf_node, 0));
  } else {
    // Mitsuba's default BSDF is a 0.5 diffuse.
    mat.json = {{"type", "diffuse"}, {"albedo", Json::array({0.5, 0.5, 0.5})}};
    if (interior)
      fail(n,
           "a shape with an interior medium needs <bsdf type=\"null\"/> or a dielectric "
           "(Mitsuba's "
           "default bsdf is an opaque diffuse)");
  }
  if (!mat.null) s["material"] = mat.json;
  if (interior) {
    if (!mat.null && !mat.transmissive)
      fail(interior, "the shape's bsdf is opaque, so its interior medium could never be reached");
    medium_check(interior);
    s["medium"] = medium_name(interior, mat.transmissive ? mat.eta : 1.0);
    origin(path + "/medium", interior);
  }
  if (emitter_node) {
    const Node e = resolve(emitter_node, 0);
    if (plugin_type(e) != "area") fail(e, "a shape's emitter must be of type \"area\"");
    Props ep = props(e);
    const RGB L = get_rgb(ep, "radiance", RGB(1.0));
    check_all_used(ep);
    if (!ep.objects.empty())
      fail(ep.objects.front(), "textures are not supported (docs/mitsuba.md)");
    s["emission"] = Json::array({L.r, L.g, L.b});
    origin(path + "/emission", e);
  }
  if (mat.null && !interior && !emitter_node)
    fail(n, "a shape with a null bsdf and no interior medium or area emitter is invisible");
  out_["shapes"].push_back(s);
}

}  // namespace femto::mitsuba
