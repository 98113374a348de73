#include "core/scene_loader.h"

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <utility>

#include "core/constants.h"
#include "core/error.h"
#include "core/io/ply.h"
#include "core/medium_nesting.h"
#include "core/mitsuba/mitsuba_xml.h"
#include "core/obj_loader.h"

namespace femto {
namespace {

// Ordered so that media keep the order of the file (their indices are used by the tracer).
using Json = nlohmann::ordered_json;
namespace fs = std::filesystem;
using Keys = std::vector<std::string>;

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr std::uint64_t kMaxFilmBytes = 64ull << 30;  // guards against typos like 1e6 bins
// Bounds of docs/scene-format.md ("Bounds"): values become floats (Embree, the film) or ints.
constexpr double kMaxMagnitude = 1e9;    // any number, in its unit
constexpr double kMinLength = 1e-6;      // mm: radii and widths that are inverted
constexpr double kMinBinWidth = 1e-6;    // ps (or mm of OPL)
constexpr double kMaxWindowEnd = 1e10;   // ps
constexpr double kMinRate = 1e-9;        // per mm of OPL
constexpr double kMinScale = 1e-6, kMaxScale = 1e6;
constexpr int kMaxNesting = 64;          // JSON depth; scenes need fewer than 10 levels
constexpr std::uint64_t kMaxSceneBytes = 64ull << 20;

// ---------------------------------------------------------------------------------------------
// Text helpers

std::string fmt(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

std::string fmt(const Vec3& v) { return "[" + fmt(v.x) + ", " + fmt(v.y) + ", " + fmt(v.z) + "]"; }

// JSON pointer escaping (RFC 6901), so a medium named "a/b" still yields a usable path.
std::string escape_key(const std::string& key) {
  std::string out;
  for (char ch : clip(key, 40)) {  // a path is for messages: keep each step short
    if (ch == '~')
      out += "~0";
    else if (ch == '/')
      out += "~1";
    else
      out += ch;
  }
  return out;
}

std::string at(const std::string& path, const std::string& key) {
  return path + "/" + escape_key(key);
}
std::string at(const std::string& path, std::size_t index) {
  return path + "/" + std::to_string(index);
}

// A value as shown after "got": compact, and short so the message stays readable on one line.
// Values are at most kMaxNesting deep (checked while parsing), so dump() cannot recurse far.
std::string show(const Json& v) {
  if (v.is_string()) return clip(Json(clip(v.get<std::string>(), 200)).dump());
  return clip(v.dump());
}

std::size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diag = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (a[i - 1] == b[j - 1] ? 0u : 1u)});
      diag = up;
    }
  }
  return row[b.size()];
}

// " (did you mean 'x'?)" for the closest option within edit distance 2, else "".
std::string suggest(const std::string& got, const Keys& options) {
  constexpr std::size_t kMaxLen = 64;  // edit distance is quadratic: long names get no hint
  if (got.size() > kMaxLen) return "";
  std::size_t best = 3;
  std::string pick;
  for (const auto& o : options) {
    if (o.size() > kMaxLen || o.size() + 2 < got.size() || got.size() + 2 < o.size()) continue;
    const std::size_t d = edit_distance(got, o);
    if (d < best) {
      best = d;
      pick = o;
    }
  }
  return pick.empty() ? "" : " (did you mean '" + pick + "'?)";
}

// At most 10 entries, each clipped: the list is user data when it names media.
std::string quoted_list(const Keys& options) {
  std::string s;
  const std::size_t n = std::min<std::size_t>(options.size(), 10);
  for (std::size_t i = 0; i < n; ++i) s += (i ? ", \"" : "\"") + clip(options[i], 40) + "\"";
  if (options.size() > n) s += " and " + std::to_string(options.size() - n) + " more";
  return s;
}

// 1-based line and column of the byte before `byte` (nlohmann reports bytes read so far).
std::string line_col(const std::string& text, std::size_t byte) {
  const std::size_t idx = std::min(byte > 0 ? byte - 1 : 0, text.size());
  std::size_t line = 1, col = 1;
  for (std::size_t i = 0; i < idx; ++i) {
    if (text[i] == '\n') {
      ++line;
      col = 1;
    } else {
      ++col;
    }
  }
  return "line " + std::to_string(line) + ", column " + std::to_string(col);
}

// Allowed-range check with a message built from the bounds.
struct Range {
  double lo = -kInf, hi = kInf;
  bool lo_open = false, hi_open = false;
  bool contains(double x) const {
    return (lo_open ? x > lo : x >= lo) && (hi_open ? x < hi : x <= hi);
  }
  std::string text() const {
    if (hi == kInf) return std::string(lo_open ? "must be > " : "must be >= ") + fmt(lo);
    if (lo == -kInf) return std::string(hi_open ? "must be < " : "must be <= ") + fmt(hi);
    return std::string("must be in ") + (lo_open ? "(" : "[") + fmt(lo) + ", " + fmt(hi) +
           (hi_open ? ")" : "]");
  }
};
Range at_least(double x) { return {x, kInf, false, false}; }
Range above(double x) { return {x, kInf, true, false}; }
Range within(double lo, double hi, bool lo_open = false, bool hi_open = false) {
  return {lo, hi, lo_open, hi_open};
}

// ---------------------------------------------------------------------------------------------
// Geometry helpers

/// Shape transform: scale, then rotate about x, y, z (degrees, in that order), then translate.
struct Transform {
  Vec3 scale{1, 1, 1}, rotate_deg{0, 0, 0}, translate{0, 0, 0};

  Vec3 apply(const Vec3& p) const {
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
  /// A mirroring transform turns counter-clockwise triangles clockwise.
  bool mirrors() const { return scale.x * scale.y * scale.z < 0; }
};

void apply_transform(const Transform& tf, ShapeDesc& s) {
  for (auto& v : s.vertices) v = tf.apply(v);
  // Swapping two corners restores the winding, so normals keep pointing to the same side
  // (outward for closed shapes) after mirroring.
  if (tf.mirrors())
    for (auto& t : s.triangles) std::swap(t[1], t[2]);
}

Vec3 face_normal(const std::vector<Vec3>& v, const std::array<uint32_t, 3>& t) {
  return cross(v[t[1]] - v[t[0]], v[t[2]] - v[t[0]]);
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

// ---------------------------------------------------------------------------------------------
// The loader

class Loader {
 public:
  Loader(std::string source, std::string base_dir)
      : source_(std::move(source)), base_dir_(std::move(base_dir)) {}

  SceneDesc load(const std::string& text) {
    const Json root = parse(text);
    SceneDesc scene;
    scene.source = source_;
    if (!root.is_object()) fail("/", "the scene must be a JSON object", root);
    if (root.contains("tissue"))  // a tissue-optics run, not a camera scene
      fail("/tissue", "a tissue-optics scene (docs/tissue.md): run it with femto render or femto tissue; "
                      "it cannot be used as a camera scene here");
    check_keys(root, "", {"camera", "time", "media", "medium", "shapes", "lights", "render"});
    camera(require(root, "", "camera"), scene.camera);
    time(require(root, "", "time"), scene);
    if (const Json* m = find(root, "media")) media(*m, scene);
    if (const Json* m = find(root, "medium"))
      scene.global_medium = medium_ref(*m, "/medium", scene);
    if (const Json* s = find(root, "shapes")) shapes(*s, scene);
    if (const Json* l = find(root, "lights")) lights(*l, scene);
    if (const Json* r = find(root, "render")) render(*r, scene.integrator);
    enclosing_shapes(scene);  // media may nest but not overlap: refused here, before any work

    const bool emissive = std::any_of(scene.shapes.begin(), scene.shapes.end(),
                                      [](const ShapeDesc& s) { return s.emissive; });
    if (scene.lights.empty() && !emissive)
      fail("/lights",
           "scene has no light: add an entry to \"lights\" or an \"emission\" to a shape");
    return scene;
  }

 private:
  std::string source_, base_dir_;

  [[noreturn]] void fail(const std::string& path, const std::string& problem) const {
    throw InputError(clip(source_, 200) + ": " + (path.empty() ? "/" : path) + ": " + problem);
  }
  [[noreturn]] void fail(const std::string& path, const std::string& problem,
                         const Json& got) const {
    fail(path, problem + " (got " + show(got) + ")");
  }

  // ---- parsing

  Json parse(const std::string& text) const {
    // Track the path of the value being parsed so duplicate keys (which nlohmann would silently
    // collapse to the last one) can be reported with their JSON path.
    struct Frame {
      explicit Frame(bool is_array) : array(is_array) {}
      bool array;
      std::size_t index = 0;
      std::string key;
      std::set<std::string> keys;
    };
    std::vector<Frame> stack;
    const auto path_of_stack = [&] {
      std::string path;
      for (std::size_t i = 0; i + 1 < stack.size(); ++i)
        path = stack[i].array ? at(path, stack[i].index) : at(path, stack[i].key);
      return clip(path, 200);
    };
    const Json::parser_callback_t cb = [&](int depth, nlohmann::json::parse_event_t ev,
                                           Json& parsed) {
      using E = nlohmann::json::parse_event_t;
      // Deep nesting would make printing and freeing the value recurse past the stack.
      if ((ev == E::object_start || ev == E::array_start) && depth >= kMaxNesting)
        fail(path_of_stack(), "values are nested more than " + std::to_string(kMaxNesting) +
                                  " levels deep; a scene needs far fewer");
      auto next_element = [&] {
        if (!stack.empty() && stack.back().array) ++stack.back().index;
      };
      switch (ev) {
        case E::object_start:
          stack.emplace_back(false);
          break;
        case E::array_start:
          stack.emplace_back(true);
          break;
        case E::key: {
          const std::string k = parsed.get<std::string>();
          Frame& f = stack.back();
          if (!f.keys.insert(k).second) fail(at(path_of_stack(), k), "duplicate key '" + clip(k) + "'");
          f.key = k;
          break;
        }
        case E::object_end:
        case E::array_end:
          stack.pop_back();
          next_element();
          break;
        case E::value:
          next_element();
          break;
      }
      return true;
    };
    try {
      return Json::parse(text, cb, /*allow_exceptions=*/true, /*ignore_comments=*/true);
    } catch (const nlohmann::json::parse_error& e) {
      const std::string what = e.what();
      const std::size_t k = what.find(": ", what.find("parse error"));
      const std::string msg = k == std::string::npos ? what : what.substr(k + 2);
      throw InputError(clip(source_, 200) + ": " + line_col(text, e.byte) + ": " + clip(msg, 200));
    } catch (const nlohmann::json::exception& e) {
      // e.g. "number overflow parsing '1e999'": locate the quoted token to give a position.
      std::string what = e.what();
      if (const std::size_t k = what.find("] "); k != std::string::npos) what = what.substr(k + 2);
      std::string where;
      const std::size_t q0 = what.find('\''), q1 = what.rfind('\'');
      if (q0 != std::string::npos && q1 > q0 + 1) {
        const std::size_t pos = text.find(what.substr(q0 + 1, q1 - q0 - 1));
        if (pos != std::string::npos) where = line_col(text, pos + 1) + ": ";
      }
      throw InputError(clip(source_, 200) + ": " + where + clip(what, 200));
    }
  }

  // ---- generic value readers

  static const Json* find(const Json& o, const std::string& key) {
    const auto it = o.find(key);
    return it == o.end() ? nullptr : &*it;
  }

  const Json& require(const Json& o, const std::string& path, const std::string& key) const {
    const Json* v = find(o, key);
    if (!v) fail(at(path, key), "missing required key '" + key + "'");
    return *v;
  }

  const Json& object(const Json& v, const std::string& path) const {
    if (!v.is_object()) fail(path, "expected an object", v);
    return v;
  }

  /// Rejects keys outside `allowed`; keys listed in `elsewhere` are valid for another type, so
  /// the message says they do not apply to `what` instead of calling them unknown.
  void check_keys(const Json& o, const std::string& path, const Keys& allowed,
                  const std::string& what = "", const Keys& elsewhere = {}) const {
    for (const auto& item : o.items()) {
      const std::string& k = item.key();
      if (std::find(allowed.begin(), allowed.end(), k) != allowed.end()) continue;
      if (std::find(elsewhere.begin(), elsewhere.end(), k) != elsewhere.end())
        fail(at(path, k), "key '" + clip(k) + "' does not apply to " + what);
      fail(at(path, k), "unknown key '" + clip(k) + "'" + suggest(k, allowed));
    }
  }

  double number(const Json& v, const std::string& path, const Range& r = {}) const {
    if (!v.is_number()) fail(path, "expected a number", v);
    const double x = v.get<double>();
    if (!std::isfinite(x)) fail(path, "must be finite", v);
    if (!r.contains(x)) fail(path, r.text(), v);
    if (std::abs(x) > kMaxMagnitude)
      fail(path, "must be within +-1e9, the bound for every number (docs/scene-format.md, Bounds)",
           v);
    return x;
  }

  /// Rejects a positive value below `lo` (lengths and rates that get inverted).
  double not_tiny(double x, double lo, const std::string& path, const Json& v) const {
    if (x < lo) fail(path, "must be >= " + fmt(lo) + " (docs/scene-format.md, Bounds)", v);
    return x;
  }

  long long integer(const Json& v, const std::string& path, long long lo, long long hi) const {
    long long x = 0;
    if (v.is_number_unsigned() && v.get<std::uint64_t>() > static_cast<std::uint64_t>(LLONG_MAX))
      x = LLONG_MAX;
    else if (v.is_number_integer())
      x = v.get<long long>();
    else if (v.is_number_float() && std::floor(v.get<double>()) == v.get<double>() &&
             std::abs(v.get<double>()) < 9e18)  // accept 1e6 and 16.0
      x = static_cast<long long>(v.get<double>());
    else
      fail(path, "expected an integer", v);
    if (x < lo || x > hi)
      fail(path,
           hi == LLONG_MAX ? "must be >= " + std::to_string(lo)
                           : "must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]",
           v);
    return x;
  }

  int int_in(const Json& v, const std::string& path, int lo, int hi) const {
    return static_cast<int>(integer(v, path, lo, hi));
  }

  std::string string(const Json& v, const std::string& path) const {
    if (!v.is_string()) fail(path, "expected a string", v);
    return v.get<std::string>();
  }

  std::string choice(const Json& v, const std::string& path, const Keys& options) const {
    const std::string s = string(v, path);
    if (std::find(options.begin(), options.end(), s) == options.end())
      fail(path, "must be one of " + quoted_list(options) + suggest(s, options), v);
    return s;
  }

  Vec3 vec3(const Json& v, const std::string& path) const {
    if (!v.is_array() || v.size() != 3 ||
        !std::all_of(v.begin(), v.end(), [](const Json& c) { return c.is_number(); }))
      fail(path, "expected an array of 3 numbers", v);
    Vec3 out;
    for (int i = 0; i < 3; ++i) out[i] = number(v[static_cast<std::size_t>(i)], at(path, i));
    return out;
  }

  Vec3 nonzero_vec3(const Json& v, const std::string& path) const {
    const Vec3 d = vec3(v, path);
    if (!(length(d) > 0)) fail(path, "must be a non-zero vector", v);
    return d;
  }

  /// A colour: one number (grey) or [r, g, b], each in [0, hi].
  RGB rgb(const Json& v, const std::string& path, double hi = kInf) const {
    const Range r = hi == kInf ? at_least(0) : within(0, hi);
    if (v.is_number()) return RGB(number(v, path, r));
    if (!v.is_array() || v.size() != 3 ||
        !std::all_of(v.begin(), v.end(), [](const Json& c) { return c.is_number(); }))
      fail(path, "expected a number or an array of 3 numbers", v);
    return {number(v[0], at(path, 0), r), number(v[1], at(path, 1), r),
            number(v[2], at(path, 2), r)};
  }

  /// An emitted quantity: like rgb(), but all-zero is rejected since such an emitter would only
  /// dilute light sampling.
  RGB bright_rgb(const Json& v, const std::string& path) const {
    const RGB c = rgb(v, path);
    if (c.is_black()) fail(path, "must be > 0 in some channel", v);
    return c;
  }

  /// Reads "type" from a typed object; a missing type is reported after checking the keys
  /// against every type, so a misspelt "tpye" gets its own, clearer message.
  std::string type_of(const Json& o, const std::string& path, const Keys& types,
                      const Keys& all_keys) const {
    const Json* t = find(o, "type");
    if (!t) {
      check_keys(o, path, all_keys);
      fail(at(path, "type"), "missing required key 'type' (one of " + quoted_list(types) + ")");
    }
    return choice(*t, at(path, "type"), types);
  }

  static Keys join(Keys a, const Keys& b) {
    a.insert(a.end(), b.begin(), b.end());
    return a;
  }

  // ---- sections

  void camera(const Json& v, CameraDesc& c) const {
    const std::string p = "/camera";
    const Json& o = object(v, p);
    std::string type = "perspective";
    if (const Json* t = find(o, "type"))
      type = choice(*t, at(p, "type"), {"perspective", "orthographic"});
    const bool persp = type == "perspective";
    const Keys common = {"type", "position", "look_at", "up", "resolution"};
    check_keys(o, p, join(common, {persp ? "fov" : "width"}),
               persp ? "a perspective camera" : "an orthographic camera", {"fov", "width"});
    c.type = persp ? CameraDesc::Type::Perspective : CameraDesc::Type::Orthographic;

    c.position = vec3(require(o, p, "position"), at(p, "position"));
    const Json& look = require(o, p, "look_at");
    c.look_at = vec3(look, at(p, "look_at"));
    if (!(length(c.look_at - c.position) > 0))
      fail(at(p, "look_at"), "must differ from 'position'", look);
    if (const Json* u = find(o, "up")) {
      c.up = nonzero_vec3(*u, at(p, "up"));
      const Vec3 view = normalize(c.look_at - c.position);
      if (length(cross(view, normalize(c.up))) < 1e-6)
        fail(at(p, "up"), "must not be parallel to the view direction " + fmt(view), *u);
    } else if (length(cross(normalize(c.look_at - c.position), c.up)) < 1e-6) {
      fail(at(p, "up"), "the default up [0, 1, 0] is parallel to the view direction; give 'up'");
    }
    c.up = normalize(c.up);

    if (persp) {
      if (const Json* f = find(o, "fov"))
        c.fov_deg = number(*f, at(p, "fov"), within(0, 180, true, true));
    } else {
      const Json& w = require(o, p, "width");
      c.ortho_width = not_tiny(number(w, at(p, "width"), above(0)), kMinLength, at(p, "width"), w);
    }

    const std::string rp = at(p, "resolution");
    const Json& r = require(o, p, "resolution");
    if (!r.is_array() || r.size() != 2)
      fail(rp, "expected an array of 2 integers [width, height]", r);
    c.width = int_in(r[0], at(rp, 0), 1, 16384);
    c.height = int_in(r[1], at(rp, 1), 1, 16384);
  }

  void time(const Json& v, SceneDesc& scene) const {
    const std::string p = "/time";
    const Json& o = object(v, p);
    check_keys(o, p,
               {"t_start", "bin_width", "bins", "start_opl", "bin_width_opl", "mode", "reconstruction"});
    const Json* bw = find(o, "bin_width");
    const Json* bw_opl = find(o, "bin_width_opl");
    if (bw && bw_opl)
      fail(at(p, "bin_width_opl"), "give either 'bin_width' (ps) or 'bin_width_opl' (mm), not both",
           *bw_opl);
    if (!bw && !bw_opl)
      fail(at(p, "bin_width"), "missing required key 'bin_width' (or 'bin_width_opl' in mm)");
    // One unit per axis: a ps start with an mm width (or the reverse) is almost surely a mistake.
    if (const Json* s = find(o, "start_opl"); s && bw)
      fail(at(p, "start_opl"), "cannot mix 'start_opl' (mm) with 'bin_width' (ps); use 't_start'",
           *s);
    if (const Json* s = find(o, "t_start"); s && bw_opl)
      fail(at(p, "t_start"), "cannot mix 't_start' (ps) with 'bin_width_opl' (mm); use 'start_opl'",
           *s);

    TimeAxis& axis = scene.time;
    if (bw) {
      axis.bin_width_ps =
          not_tiny(number(*bw, at(p, "bin_width"), above(0)), kMinBinWidth, at(p, "bin_width"), *bw);
      if (const Json* s = find(o, "t_start")) axis.t_start_ps = number(*s, at(p, "t_start"));
    } else {
      axis.bin_width_ps = TimeAxis::time_of_opl(not_tiny(number(*bw_opl, at(p, "bin_width_opl"), above(0)),
                                                         kMinBinWidth, at(p, "bin_width_opl"), *bw_opl));
      if (const Json* s = find(o, "start_opl"))
        axis.t_start_ps = TimeAxis::time_of_opl(number(*s, at(p, "start_opl")));
      else
        axis.t_start_ps = 0.0;
    }
    const Json& bins = require(o, p, "bins");
    axis.bins = int_in(bins, at(p, "bins"), 1, 100000);
    if (axis.t_end_ps() > kMaxWindowEnd)
      fail(at(p, "bins"), "the window ends at " + fmt(axis.t_end_ps()) + " ps, beyond the bound of " +
                              fmt(kMaxWindowEnd) + " ps (docs/scene-format.md, Bounds)",
           bins);

    const std::uint64_t bytes = std::uint64_t(scene.camera.width) *
                                std::uint64_t(scene.camera.height) * std::uint64_t(axis.bins) * 3u *
                                4u;
    if (bytes > kMaxFilmBytes)
      fail(at(p, "bins"),
           "a " + std::to_string(scene.camera.width) + " x " + std::to_string(scene.camera.height) +
               " x " + std::to_string(axis.bins) + " film needs " +
               fmt(double(bytes) / double(1ull << 30)) +
               " GiB (3 float channels), above the 64 GiB limit; lower 'bins' or "
               "/camera/resolution",
           bins);

    if (const Json* m = find(o, "mode"))
      scene.time_mode = choice(*m, at(p, "mode"), {"camera", "unwarp"}) == "camera"
                            ? TimeMode::Camera
                            : TimeMode::Unwarp;
    if (const Json* r = find(o, "reconstruction")) reconstruction(*r, at(p, "reconstruction"), scene.reconstruction);
  }

  // "histogram", or {"type": "kernel", "kernel", "alpha", "k", "first_pass_spp", "bandwidth"}.
  void reconstruction(const Json& v, const std::string& p, ReconstructionDesc& r) const {
    const Keys kernel_keys = {"kernel", "alpha", "k", "first_pass_spp", "bandwidth", "onset_reflection"};
    if (v.is_string()) {
      r.type = choice(v, p, {"histogram", "kernel"}) == "kernel" ? TemporalFilter::Kind::Kernel
                                                                 : TemporalFilter::Kind::Histogram;
      return;
    }
    const Json& o = object(v, p);
    const std::string type = type_of(o, p, {"histogram", "kernel"}, kernel_keys);
    if (type == "histogram") {
      check_keys(o, p, {"type"}, "the histogram reconstruction", kernel_keys);
      r.type = TemporalFilter::Kind::Histogram;
      return;
    }
    check_keys(o, p, join(Keys{"type"}, kernel_keys));
    r.type = TemporalFilter::Kind::Kernel;
    if (const Json* k = find(o, "kernel"))
      r.kernel = choice(*k, at(p, "kernel"), {"perlin", "epanechnikov"}) == "perlin" ? TemporalKernel::Perlin
                                                                                   : TemporalKernel::Epanechnikov;
    if (const Json* a = find(o, "alpha")) r.alpha = number(*a, at(p, "alpha"), within(0, 1, true, false));
    if (const Json* k = find(o, "k")) r.knn = int_in(*k, at(p, "k"), 1, 100000);
    if (const Json* f = find(o, "first_pass_spp")) r.first_pass_spp = int_in(*f, at(p, "first_pass_spp"), 1, 1000000);
    if (const Json* b = find(o, "bandwidth")) r.bandwidth_ps = number(*b, at(p, "bandwidth"), above(0));
    if (const Json* f = find(o, "onset_reflection")) {
      if (!f->is_boolean()) fail(at(p, "onset_reflection"), "expected true or false", *f);
      r.onset_reflection = f->get<bool>();
    }
  }

  void media(const Json& v, SceneDesc& scene) const {
    const std::string p = "/media";
    object(v, p);
    const Keys common = {"type",          "g",                   "eta",
                         "distance_sampling", "time_uniform_rate", "mis_heuristic",
                         "connection_sampling", "direction_sampling"};
    const Keys homogeneous = {"sigma_a", "sigma_s"};
    const Keys vdb = {"file",        "density_grid", "sigma_t_scale", "albedo",
                      "albedo_grid", "eta_grid",     "interpolation", "transform", "storage"};
    for (const auto& item : v.items()) {
      const std::string& name = item.key();
      const std::string mp = at(p, name);
      if (name.empty()) fail(mp, "a medium name must not be empty");
      const Json& o = object(item.value(), mp);
      const std::string type =
          type_of(o, mp, {"homogeneous", "vdb"}, join(common, join(homogeneous, vdb)));
      MediumDesc m;
      m.name = name;
      if (type == "homogeneous") {
        check_keys(o, mp, join(common, homogeneous), "a homogeneous medium", vdb);
        m.medium.sigma_a = number(require(o, mp, "sigma_a"), at(mp, "sigma_a"), at_least(0));
        m.medium.sigma_s = number(require(o, mp, "sigma_s"), at(mp, "sigma_s"), at_least(0));
      } else {
        check_keys(o, mp, join(common, vdb), "a vdb medium", homogeneous);
        m.type = MediumDesc::Type::Vdb;
        vdb_medium(o, mp, m.vdb);
      }
      if (const Json* g = find(o, "g"))
        m.medium.g = number(*g, at(mp, "g"), within(-1, 1, true, true));
      if (const Json* e = find(o, "eta")) m.medium.eta = number(*e, at(mp, "eta"), at_least(1));
      // A VDB medium's constant eta also serves the dielectric-interface check on shapes.
      m.vdb.eta = m.medium.eta;
      distance_sampling(o, mp, m);
      connection_sampling(o, mp, m);
      scene.media.push_back(m);
    }
  }

  // Keys of a "vdb" medium except the common ones; loading the file happens in load_volume.
  void vdb_medium(const Json& o, const std::string& mp, VdbMediumDesc& d) const {
    const std::string fp = at(mp, "file");
    const Json& jf = require(o, mp, "file");
    const std::string file = string(jf, fp);
    if (file.empty()) fail(fp, "must name a VDB file", jf);
    d.file = resolve(file);
    std::error_code ec;
    if (!fs::is_regular_file(d.file, ec)) fail(fp, "VDB file not found: " + clip(d.file, 200), jf);
    const auto grid_name = [&](const std::string& key) {
      const std::string s = string(o.at(key), at(mp, key));
      if (s.empty()) fail(at(mp, key), "must name a grid", o.at(key));
      return s;
    };
    if (find(o, "density_grid")) d.density_grid = grid_name("density_grid");
    d.sigma_t_scale =
        number(require(o, mp, "sigma_t_scale"), at(mp, "sigma_t_scale"), above(0));
    const Json* a = find(o, "albedo");
    if (a && find(o, "albedo_grid"))
      fail(at(mp, "albedo_grid"), "give either 'albedo' (a constant) or 'albedo_grid', not both",
           o.at("albedo_grid"));
    if (a) d.albedo = number(*a, at(mp, "albedo"), within(0, 1));
    if (find(o, "albedo_grid")) d.albedo_grid = grid_name("albedo_grid");
    if (find(o, "eta_grid")) d.eta_grid = grid_name("eta_grid");
    if (const Json* i = find(o, "interpolation"))
      d.interpolation = choice(*i, at(mp, "interpolation"), {"nearest", "trilinear"}) == "nearest"
                            ? VdbMediumDesc::Interpolation::Nearest
                            : VdbMediumDesc::Interpolation::Trilinear;
    if (const Json* st = find(o, "storage")) {
      const std::string c = choice(*st, at(mp, "storage"), {"auto", "dense", "sparse"});
      d.storage = c == "dense"    ? VdbMediumDesc::Storage::Dense
                  : c == "sparse" ? VdbMediumDesc::Storage::Sparse
                                  : VdbMediumDesc::Storage::Auto;
    }
    if (const Json* t = find(o, "transform")) {
      const Transform tf = transform(*t, at(mp, "transform"));
      d.transform = {tf.translate, tf.rotate_deg, tf.scale};
    }
  }

  // Distance-sampling keys, valid for every medium type.
  void connection_sampling(const Json& o, const std::string& mp, MediumDesc& m) const {
    if (const Json* c = find(o, "connection_sampling")) {
      const std::string v = choice(*c, at(mp, "connection_sampling"),
                                   {"collision", "equiangular", "line_to_point", "mis", "auto"});
      m.connection = v == "collision"       ? ConnectionSampling::Collision
                     : v == "equiangular"   ? ConnectionSampling::Equiangular
                     : v == "line_to_point" ? ConnectionSampling::LineToPoint
                     : v == "mis"           ? ConnectionSampling::Mis
                                            : ConnectionSampling::Auto;
    } else {
      m.connection = ConnectionSampling::Auto;  // the default for scene files (docs/scene-format.md)
    }
    if (const Json* d = find(o, "direction_sampling"))
      m.direction = choice(*d, at(mp, "direction_sampling"), {"phase", "angular"}) == "phase"
                        ? DirectionSampling::Phase
                        : DirectionSampling::Angular;
  }

  void distance_sampling(const Json& o, const std::string& mp, MediumDesc& m) const {
    const Json* s = find(o, "distance_sampling");
    if (s) {
      const std::string v =
          choice(*s, at(mp, "distance_sampling"), {"mfp", "time_uniform", "mis", "mixture"});
      m.sampling = v == "mfp"            ? DistanceSampling::Mfp
                   : v == "time_uniform" ? DistanceSampling::TimeUniform
                   : v == "mis"          ? DistanceSampling::Mis
                                         : DistanceSampling::Mixture;
    } else {
      m.sampling = DistanceSampling::Mfp;  // the default for scene files (docs/scene-format.md)
    }
    const std::string uses = std::string("; this medium uses \"") +
                             (m.sampling == DistanceSampling::Mfp           ? "mfp"
                              : m.sampling == DistanceSampling::TimeUniform ? "time_uniform"
                              : m.sampling == DistanceSampling::Mis         ? "mis"
                                                                            : "mixture") +
                             "\"" + (s ? "" : " (the default)");
    if (const Json* r = find(o, "time_uniform_rate")) {
      if (m.sampling == DistanceSampling::Mfp)
        fail(at(mp, "time_uniform_rate"),
             "only applies with \"distance_sampling\": \"time_uniform\", \"mis\" or \"mixture\"" +
                 uses,
             *r);
      m.time_uniform_rate =
          not_tiny(number(*r, at(mp, "time_uniform_rate"), above(0)), kMinRate, at(mp, "time_uniform_rate"), *r);
    }
    if (const Json* h = find(o, "mis_heuristic")) {
      if (m.sampling != DistanceSampling::Mis)
        fail(at(mp, "mis_heuristic"), "only applies with \"distance_sampling\": \"mis\"" + uses,
             *h);
      m.mis_heuristic = choice(*h, at(mp, "mis_heuristic"), {"balance", "power"}) == "balance"
                            ? MisHeuristic::Balance
                            : MisHeuristic::Power;
    }
  }

  int medium_ref(const Json& v, const std::string& path, const SceneDesc& scene) const {
    const std::string name = string(v, path);
    Keys names;
    for (std::size_t i = 0; i < scene.media.size(); ++i) {
      if (scene.media[i].name == name) return static_cast<int>(i);
      names.push_back(scene.media[i].name);
    }
    if (names.empty()) fail(path, "unknown medium '" + clip(name) + "' (\"media\" defines none)", v);
    fail(path,
         "unknown medium '" + clip(name) + "'" + suggest(name, names) + "; defined: " +
             quoted_list(names),
         v);
  }

  PulseDesc pulse(const Json& v, const std::string& p) const {
    const Json& o = object(v, p);
    check_keys(o, p, {"fwhm", "offset"});
    PulseDesc d;
    if (const Json* f = find(o, "fwhm")) d.fwhm_ps = number(*f, at(p, "fwhm"), at_least(0));
    if (const Json* f = find(o, "offset")) d.offset_ps = number(*f, at(p, "offset"));
    return d;
  }

  MaterialDesc material(const Json& v, const std::string& p) const {
    const Json& o = object(v, p);
    const Keys types = {"diffuse", "mirror", "dielectric", "rough_dielectric", "rough_conductor"};
    const Keys specific = {"albedo", "reflectance", "eta", "roughness"};
    const std::string type = type_of(o, p, types, join({"type"}, specific));
    MaterialDesc m;
    // GGX alpha: 0 would be a smooth surface (use "dielectric" or "mirror"), above 1 is unphysical.
    const auto roughness = [&] {
      if (const Json* r = find(o, "roughness"))
        m.roughness = number(*r, at(p, "roughness"), within(0, 1, true, false));
    };
    if (type == "diffuse") {
      check_keys(o, p, {"type", "albedo"}, "a diffuse material", specific);
      m.type = MaterialDesc::Type::Diffuse;
      m.albedo = rgb(require(o, p, "albedo"), at(p, "albedo"), 1.0);
    } else if (type == "mirror") {
      check_keys(o, p, {"type", "reflectance"}, "a mirror material", specific);
      m.type = MaterialDesc::Type::Mirror;
      if (const Json* r = find(o, "reflectance"))
        m.reflectance = rgb(*r, at(p, "reflectance"), 1.0);
    } else if (type == "rough_conductor") {
      check_keys(o, p, {"type", "reflectance", "roughness"}, "a rough conductor material",
                 specific);
      m.type = MaterialDesc::Type::RoughConductor;
      if (const Json* r = find(o, "reflectance"))
        m.reflectance = rgb(*r, at(p, "reflectance"), 1.0);
      roughness();
    } else {
      const bool rough = type == "rough_dielectric";
      check_keys(o, p, rough ? Keys{"type", "eta", "roughness"} : Keys{"type", "eta"},
                 rough ? "a rough dielectric material" : "a dielectric material", specific);
      m.type = rough ? MaterialDesc::Type::RoughDielectric : MaterialDesc::Type::Dielectric;
      if (const Json* e = find(o, "eta")) m.eta = number(*e, at(p, "eta"), at_least(1));
      if (rough) roughness();
    }
    return m;
  }

  Transform transform(const Json& v, const std::string& p) const {
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

  void check_scale(double x, const std::string& path, const Json& v) const {
    if (x == 0) fail(path, "must be non-zero", v);
    if (std::abs(x) < kMinScale || std::abs(x) > kMaxScale)
      fail(path, "magnitude must be in [1e-6, 1e6] (docs/scene-format.md, Bounds)", v);
  }

  // Every vertex Embree sees must stay far inside float range (transforms can scale them out).
  void check_vertices(const ShapeDesc& s, const std::string& path) const {
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

  std::string resolve(const std::string& file) const {
    fs::path f(file);
    if (f.is_relative() && !base_dir_.empty()) f = fs::path(base_dir_) / f;
    return f.lexically_normal().string();
  }

  void shapes(const Json& v, SceneDesc& scene) const {
    if (!v.is_array()) fail("/shapes", "expected an array of shapes", v);
    for (std::size_t i = 0; i < v.size(); ++i)
      scene.shapes.push_back(shape(v[i], at("/shapes", i), scene));
  }

  ShapeDesc shape(const Json& v, const std::string& p, const SceneDesc& scene) const {
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
      s.vertices = {c, c + e1, c + e1 + e2, c + e2};
      s.triangles = {{0, 1, 2}, {0, 2, 3}};  // both have normal along edge1 x edge2
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
        if (fs::path(path).extension() == ".ply")
          load_ply(path, s.vertices, s.triangles);
        else
          load_obj(path, s.vertices, s.triangles);
      } catch (const InputError& e) {
        fail(fp, e.what());
      }
    }

    if (const Json* m = find(o, "material")) s.material = material(*m, at(p, "material"));
    // Diffuse, mirror and rough conductor surfaces let no light in; dielectrics (smooth or rough)
    // bound a region of their own index.
    const bool opaque =
        s.material.type != MaterialDesc::Type::None && !s.material.is_transmissive();
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
        fail(mp, "the shape's material is opaque, so its interior medium could never be reached",
             *m);
      s.interior_medium = medium_ref(*m, mp, scene);
      const MediumDesc& md = scene.media[static_cast<std::size_t>(s.interior_medium)];
      if (s.material.is_transmissive() && std::abs(md.medium.eta - s.material.eta) > 1e-12) {
        const Json& mat = o.at("material");
        const Json* e = find(mat, "eta");
        fail(e ? at(at(p, "material"), "eta") : at(p, "material"),
             dielectric + " eta " + fmt(s.material.eta) + (e ? "" : " (the default)") +
                 " differs from eta " + fmt(md.medium.eta) + " of its interior medium '" + clip(md.name) +
                 "'; they must be equal",
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
    check_vertices(s, at(p, t                                    ? "transform"
                            : s.type == ShapeDesc::Type::Mesh ? "file"
                            : s.type == ShapeDesc::Type::Box  ? "max"
                                                              : "corner"));
    if (s.type == ShapeDesc::Type::Mesh &&
        (s.interior_medium >= 0 || s.material.is_transmissive())) {
      const std::string problem = closed_mesh_problem(s.vertices, s.triangles);
      if (!problem.empty())
        fail(at(p, "file"),
             "a mesh with a medium or a " + dielectric +
                 " material must be closed and outward-facing, but " + problem,
             o.at("file"));
    }
    return s;
  }

  Vec3 aim(const Json& o, const std::string& p, const Vec3& position) const {
    const Json* d = find(o, "direction");
    const Json* l = find(o, "look_at");
    if (d && l) fail(at(p, "look_at"), "give either 'direction' or 'look_at', not both", *l);
    if (!d && !l) fail(at(p, "direction"), "missing required key 'direction' (or 'look_at')");
    if (d) return normalize(nonzero_vec3(*d, at(p, "direction")));
    const Vec3 target = vec3(*l, at(p, "look_at"));
    if (!(length(target - position) > 0)) fail(at(p, "look_at"), "must differ from 'position'", *l);
    return normalize(target - position);
  }

  void lights(const Json& v, SceneDesc& scene) const {
    if (!v.is_array()) fail("/lights", "expected an array of lights", v);
    const Keys types = {"point", "spot", "laser"};
    const Keys specific = {"intensity",     "direction", "look_at", "cone_angle",
                           "falloff_start", "radius",    "power"};
    for (std::size_t i = 0; i < v.size(); ++i) {
      const std::string p = at("/lights", i);
      const Json& o = object(v[i], p);
      const std::string type = type_of(o, p, types, join({"type", "position", "pulse"}, specific));
      LightDesc l;
      l.where = p;
      if (type == "point") {
        check_keys(o, p, {"type", "position", "intensity", "pulse"}, "a point light", specific);
        l.type = LightDesc::Type::Point;
      } else if (type == "spot") {
        check_keys(o, p,
                   {"type", "position", "direction", "look_at", "intensity", "cone_angle",
                    "falloff_start", "pulse"},
                   "a spot light", specific);
        l.type = LightDesc::Type::Spot;
      } else {
        check_keys(o, p, {"type", "position", "direction", "look_at", "radius", "power", "pulse"},
                   "a laser", specific);
        l.type = LightDesc::Type::Laser;
      }
      l.position = vec3(require(o, p, "position"), at(p, "position"));
      if (l.type != LightDesc::Type::Point) l.direction = aim(o, p, l.position);
      if (l.type == LightDesc::Type::Laser) {
        const Json& jr = require(o, p, "radius");
        l.radius = not_tiny(number(jr, at(p, "radius"), above(0)), kMinLength, at(p, "radius"), jr);
        l.power = bright_rgb(require(o, p, "power"), at(p, "power"));
      } else {
        l.intensity = bright_rgb(require(o, p, "intensity"), at(p, "intensity"));
      }
      if (l.type == LightDesc::Type::Spot) {
        l.cone_angle_deg =
            number(require(o, p, "cone_angle"), at(p, "cone_angle"), within(0, 90, true, false));
        l.falloff_deg = 0.8 * l.cone_angle_deg;
        if (const Json* f = find(o, "falloff_start")) {
          l.falloff_deg = number(*f, at(p, "falloff_start"));
          if (!within(0, l.cone_angle_deg).contains(l.falloff_deg))
            fail(at(p, "falloff_start"), within(0, l.cone_angle_deg).text() + " (0 to cone_angle)",
                 *f);
        }
      }
      if (const Json* pl = find(o, "pulse")) l.pulse = pulse(*pl, at(p, "pulse"));
      scene.lights.push_back(l);
    }
  }

  // Transient progressive photon mapping: {"per_pass", "radius", "bandwidth", "alpha", "beta_t", "kernel"}.
  void photons(const Json& v, const std::string& p, PhotonDesc& d) const {
    const Json& o = object(v, p);
    check_keys(o, p, {"per_pass", "radius", "bandwidth", "alpha", "beta_t", "kernel"});
    if (const Json* s = find(o, "per_pass")) d.per_pass = integer(*s, at(p, "per_pass"), 1, 1000000000LL);
    if (const Json* s = find(o, "radius")) d.radius = number(*s, at(p, "radius"), above(0));
    if (const Json* s = find(o, "bandwidth")) d.bandwidth_ps = number(*s, at(p, "bandwidth"), above(0));
    if (const Json* s = find(o, "alpha")) d.alpha = number(*s, at(p, "alpha"), within(0, 1, true, false));
    if (const Json* s = find(o, "beta_t")) d.beta_t = number(*s, at(p, "beta_t"), within(0, 1));
    if (const Json* k = find(o, "kernel"))
      d.kernel = choice(*k, at(p, "kernel"), {"perlin", "epanechnikov"}) == "perlin" ? TemporalKernel::Perlin
                                                                                   : TemporalKernel::Epanechnikov;
  }

  void render(const Json& v, IntegratorDesc& d) const {
    const std::string p = "/render";
    const Json& o = object(v, p);
    check_keys(o, p, {"spp", "max_depth", "seed", "integrator", "light_paths", "photons"});
    if (const Json* s = find(o, "spp")) d.spp = int_in(*s, at(p, "spp"), 1, 10000000);
    if (const Json* s = find(o, "integrator")) {
      const std::string k = choice(*s, at(p, "integrator"), {"auto", "path", "light", "photons", "beams", "hybrid"});
      d.kind = k == "path"      ? IntegratorKind::Path
               : k == "light"   ? IntegratorKind::Light
               : k == "photons" ? IntegratorKind::Photons
               : k == "beams"   ? IntegratorKind::Beams
               : k == "hybrid"  ? IntegratorKind::Hybrid
                                : IntegratorKind::Auto;
    }
    if (const Json* s = find(o, "light_paths"))
      d.light_paths = integer(*s, at(p, "light_paths"), 1, 1000000000000LL);
    if (const Json* s = find(o, "photons")) photons(*s, at(p, "photons"), d.photons);
    if (const Json* s = find(o, "max_depth")) {
      d.max_depth = int_in(*s, at(p, "max_depth"), 1, 1000000);
      d.max_depth_set = true;
    }
    if (const Json* s = find(o, "seed")) {
      // Seeds span the full uint64 range, beyond what integer() reads.
      if (s->is_number_unsigned())
        d.seed = s->get<std::uint64_t>();
      else
        d.seed = static_cast<std::uint64_t>(integer(*s, at(p, "seed"), 0, LLONG_MAX));
    }
  }
};

}  // namespace

SceneDesc load_scene_string(const std::string& json_text, const std::string& source,
                            const std::string& base_dir) {
  return Loader(source, base_dir).load(json_text);
}

std::string read_scene_text(const std::string& path) {
  const std::string name = clip(path, 200);
  std::error_code ec;
  if (fs::is_directory(path, ec)) throw InputError(name + ": is a directory, not a scene file");
  if (!fs::exists(path, ec)) throw InputError(name + ": scene file not found");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(name + ": cannot open scene file");
  // Read at most one byte past the limit: /dev/zero or a pipe must not be read forever. Read in
  // pieces, so that a small file does not cost (resident) memory for the whole limit.
  std::string text;
  char piece[1 << 16];
  while (text.size() <= kMaxSceneBytes && in) {
    const std::size_t want = std::min(sizeof piece, kMaxSceneBytes + 1 - text.size());
    in.read(piece, static_cast<std::streamsize>(want));
    text.append(piece, static_cast<std::size_t>(in.gcount()));
  }
  if (in.bad()) throw InputError(name + ": cannot read scene file");
  if (text.size() > kMaxSceneBytes)
    throw InputError(name + ": scene file is larger than the 64 MiB limit");
  return text;
}

SceneDesc load_scene_file(const std::string& path) {
  const std::string base_dir = fs::path(path).parent_path().string();
  if (is_mitsuba_xml_path(path)) return load_mitsuba_xml(read_scene_text(path), path, base_dir).desc;
  return load_scene_string(read_scene_text(path), path, base_dir);
}

}  // namespace femto
