// Shape geometry: transforms read and applied, the triangles of a quad and a box, mesh files, the
// closed-mesh check.
#include <cmath>
#include <filesystem>
#include <map>

#include "core/constants.h"
#include "core/error.h"
#include "core/io/ply.h"
#include "core/obj_loader.h"
#include "core/scene_json/loader.h"

namespace femto::scene_json {

Vec3 Transform::apply(const Vec3& p) const {
  Vec3 q{p.x * scale.x, p.y * scale.y, p.z * scale.z};
  for (int axis = 0; axis < 3; ++axis) {
    const double a = rotate_deg[axis] * kPi / 180.0;
    if (a == 0.0) continue;
    const double c = std::cos(a), s = std::sin(a);
    const int i = (axis + 1) % 3, j = (axis + 2) % 3;  // rotates the (i, j) plane, right-handed
    const double qi = q[i], qj = q[j];
    q[i] = c * qi - s * qj;
    q[j] = s * qi + c * qj;
  }
  return q + translate;
}

void apply_transform(const Transform& tf, ShapeDesc& s) {
  for (auto& v : s.vertices) v = tf.apply(v);
  // Swapping two corners restores the winding, so normals keep pointing to the same side
  // (outward for closed shapes) after mirroring.
  if (tf.mirrors())
    for (auto& t : s.triangles) std::swap(t[1], t[2]);
}

namespace {

Vec3 face_normal(const std::vector<Vec3>& v, const std::array<uint32_t, 3>& t) {
  return cross(v[t[1]] - v[t[0]], v[t[2]] - v[t[0]]);
}

}  // namespace

void make_quad(const Vec3& corner, const Vec3& e1, const Vec3& e2, ShapeDesc& s) {
  s.vertices = {corner, corner + e1, corner + e1 + e2, corner + e2};
  s.triangles = {{0, 1, 2}, {0, 2, 3}};  // both have normal along e1 x e2
}

void load_mesh_file(const std::string& path, ShapeDesc& s) {
  if (std::filesystem::path(path).extension() == ".ply")
    load_ply(path, s.vertices, s.triangles);
  else
    load_obj(path, s.vertices, s.triangles);
}

void make_box(const Vec3& lo, const Vec3& hi, ShapeDesc& s) {
  s.vertices.clear();
  for (int i = 0; i < 8; ++i)  // bit 0 picks x, bit 1 y, bit 2 z
    s.vertices.push_back({(i & 1) ? hi.x : lo.x, (i & 2) ? hi.y : lo.y, (i & 4) ? hi.z : lo.z});
  // Faces as corner cycles; the box is convex, so each triangle is oriented against the centre.
  static const uint32_t kFaces[6][4] = {{0, 2, 6, 4}, {1, 3, 7, 5}, {0, 1, 5, 4},
                                        {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 5, 7, 6}};
  const Vec3 centre = (lo + hi) * 0.5;
  s.triangles.clear();
  for (const auto& f : kFaces) {
    for (const std::array<uint32_t, 3> t0 :
         {std::array<uint32_t, 3>{f[0], f[1], f[2]}, std::array<uint32_t, 3>{f[0], f[2], f[3]}}) {
      std::array<uint32_t, 3> t = t0;
      const Vec3 c = (s.vertices[t[0]] + s.vertices[t[1]] + s.vertices[t[2]]) / 3.0;
      if (dot(face_normal(s.vertices, t), c - centre) < 0) std::swap(t[1], t[2]);
      s.triangles.push_back(t);
    }
  }
}

// Empty when the mesh is a closed, consistently wound, outward-facing surface; else the problem.
// Vertices are welded by position first, since OBJ exporters often duplicate seam vertices.
std::string closed_mesh_problem(const std::vector<Vec3>& v,
                                const std::vector<std::array<uint32_t, 3>>& tris) {
  std::map<std::array<double, 3>, uint32_t> weld;
  std::vector<uint32_t> id(v.size());
  std::vector<std::size_t> number;  // welded id -> 1-based OBJ number of its first vertex
  for (std::size_t i = 0; i < v.size(); ++i) {
    const auto [it, added] = weld.emplace(std::array<double, 3>{v[i].x, v[i].y, v[i].z},
                                          static_cast<uint32_t>(number.size()));
    if (added) number.push_back(i + 1);
    id[i] = it->second;
  }
  std::map<std::pair<uint32_t, uint32_t>, int> edges;  // directed edge -> use count
  for (const auto& t : tris) {
    const uint32_t a = id[t[0]], b = id[t[1]], c = id[t[2]];
    if (a == b || b == c || a == c) continue;  // zero-area sliver: no edges of its own
    ++edges[{a, b}];
    ++edges[{b, c}];
    ++edges[{c, a}];
  }
  for (const auto& [e, count] : edges) {
    const std::string which = "the edge between vertices " + std::to_string(number[e.first]) +
                              " and " + std::to_string(number[e.second]);
    if (count > 1)
      return "faces are not consistently oriented, or more than two faces share " + which;
    if (!edges.count({e.second, e.first})) return "it is not closed: " + which + " has one face";
  }
  double volume6 = 0;  // six times the signed enclosed volume
  for (const auto& t : tris) volume6 += dot(v[t[0]], cross(v[t[1]], v[t[2]]));
  if (volume6 < 0) return "its faces point inward (reverse the winding of every face)";
  if (!(volume6 > 0)) return "it encloses no volume";
  return "";
}

Transform Loader::transform(const Json& v, const std::string& p) const {
  const Json& o = object(v, p);
  check_keys(o, p, {"translate", "rotate", "scale"});
  Transform tf;
  if (const Json* t = find(o, "translate")) tf.translate = vec3(*t, at(p, "translate"));
  if (const Json* r = find(o, "rotate")) tf.rotate_deg = vec3(*r, at(p, "rotate"));
  if (const Json* s = find(o, "scale")) {
    const std::string sp = at(p, "scale");
    if (s->is_number()) {
      tf.scale = Vec3(number(*s, sp));
      check_scale(tf.scale.x, sp, *s);
    } else {
      if (!s->is_array()) fail(sp, "expected a number or an array of 3 numbers", *s);
      tf.scale = vec3(*s, sp);
      for (int i = 0; i < 3; ++i)
        check_scale(tf.scale[i], at(sp, i), (*s)[static_cast<std::size_t>(i)]);
    }
  }
  return tf;
}

void Loader::check_scale(double x, const std::string& path, const Json& v) const {
  if (x == 0) fail(path, "must be non-zero", v);
  if (std::abs(x) < kMinScale || std::abs(x) > kMaxScale)
    fail(path, "magnitude must be in [1e-6, 1e6] (docs/scene-format.md, Bounds)", v);
}

}  // namespace femto::scene_json
