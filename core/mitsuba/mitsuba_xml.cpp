#include "core/mitsuba/mitsuba_xml.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <pugixml.hpp>
#include <set>
#include <vector>

#include "core/error.h"
#include "core/mitsuba/affine.h"
#include "core/scene_loader.h"

namespace femto {
namespace {

using Json = nlohmann::ordered_json;
using Node = pugi::xml_node;
using mitsuba::Affine;
using mitsuba::SplitTransform;

constexpr int kMaxRefDepth = 8;  // bsdf/medium references; deeper means a cycle
const char* const kUnitDefault = "femto_unit_mm";

std::string fmt(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.10g", v);
  return buf;
}

Json vec_json(const Vec3& v) {
  return Json::array({v.x, v.y, v.z});
}

// Mitsuba's named refractive indices (its ior table) for int_ior and ext_ior given as strings.
bool named_ior(const std::string& name, double& eta) {
  static const std::map<std::string, double> kIor = {
      {"vacuum", 1.0},      {"helium", 1.000036},        {"hydrogen", 1.000132},
      {"air", 1.000277},    {"carbon dioxide", 1.00045}, {"water", 1.3330},
      {"acetone", 1.36},    {"ethanol", 1.361},          {"carbon tetrachloride", 1.461},
      {"glycerol", 1.4729}, {"benzene", 1.501},          {"silicone oil", 1.52045},
      {"bromine", 1.661},   {"water ice", 1.31},         {"fused quartz", 1.458},
      {"pyrex", 1.470},     {"acrylic glass", 1.49},     {"polypropylene", 1.49},
      {"bk7", 1.5046},      {"sodium chloride", 1.544},  {"amber", 1.55},
      {"pet", 1.5750},      {"diamond", 2.419}};
  const auto it = kIor.find(name);
  if (it == kIor.end()) return false;
  eta = it->second;
  return true;
}

// Offset of the first byte that breaks UTF-8 (overlong forms, surrogates and values above
// U+10FFFF included), or npos.
std::size_t invalid_utf8(const std::string& s) {
  std::size_t i = 0;
  while (i < s.size()) {
    const auto c = static_cast<unsigned char>(s[i]);
    std::size_t n = 0;
    std::uint32_t cp = 0, min = 0;
    if (c < 0x80) {
      ++i;
      continue;
    } else if ((c & 0xE0) == 0xC0) {
      n = 1, cp = c & 0x1Fu, min = 0x80;
    } else if ((c & 0xF0) == 0xE0) {
      n = 2, cp = c & 0x0Fu, min = 0x800;
    } else if ((c & 0xF8) == 0xF0) {
      n = 3, cp = c & 0x07u, min = 0x10000;
    } else {
      return i;
    }
    if (i + n >= s.size()) return i;  // truncated sequence
    for (std::size_t k = 1; k <= n; ++k) {
      const auto cc = static_cast<unsigned char>(s[i + k]);
      if ((cc & 0xC0) != 0x80) return i;
      cp = (cp << 6) | (cc & 0x3Fu);
    }
    if (cp < min || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF)) return i;
    i += n + 1;
  }
  return std::string::npos;
}

const std::set<std::string> kPropertyTags = {"float",    "integer", "boolean", "string",   "rgb",
                                             "spectrum", "point",   "vector",  "transform"};
const std::set<std::string> kObjectTags = {"bsdf",       "emitter", "medium", "phase",  "film",
                                           "sampler",    "rfilter", "shape",  "sensor", "texture",
                                           "integrator", "volume",  "ref"};

/// The properties and nested objects of one plugin element. Every property must be consumed by
/// the plugin's reader; check_all_used() reports the rest as unsupported.
struct Props {
  Node owner;
  std::map<std::string, Node> by_name;
  std::set<std::string> used;
  std::vector<Node> objects;  ///< nested plugins and <ref> elements, in file order
};

class Importer {
 public:
  Importer(const std::string& text, std::string source, std::string base_dir,
           const XmlDefines& defines)
      : text_(text), source_(std::move(source)), base_dir_(std::move(base_dir)), defines_(defines) {
    line_starts_.push_back(0);
    for (std::size_t i = 0; i < text_.size(); ++i)
      if (text_[i] == '\n') line_starts_.push_back(i + 1);
  }

  MitsubaImport run() {
    // Names and values end up in JSON strings, which must be UTF-8.
    if (const std::size_t bad = invalid_utf8(text_); bad != std::string::npos)
      throw InputError(clip(source_, 200) + ":" +
                       std::to_string(line_of(static_cast<std::ptrdiff_t>(bad))) +
                       ": the file is not valid UTF-8 (byte " + std::to_string(bad) + ")");
    pugi::xml_document doc;
    const pugi::xml_parse_result parsed =
        doc.load_buffer(text_.data(), text_.size(), pugi::parse_default, pugi::encoding_utf8);
    if (!parsed)
      throw InputError(clip(source_, 200) + ":" + std::to_string(line_of(parsed.offset)) +
                       ": XML syntax error: " + parsed.description());
    Node scene = doc.document_element();
    if (std::string(scene.name()) != "scene")
      fail(scene, "the root element must be <scene> (a Mitsuba 3 scene file)");
    check_attributes(scene, {"version"});
    check_text(scene);

    // Definitions first: <default> values and objects with an id, wherever they appear.
    for (Node c : scene.children()) {
      if (c.type() != pugi::node_element) continue;
      const std::string tag = c.name();
      if (tag == "default") {
        check_attributes(c, {"name", "value"});
        const std::string name = required_attr(c, "name");
        if (defaults_.count(name)) fail(c, "duplicate <default name=\"" + clip(name) + "\">");
        defaults_[name] = raw_attr(c, "value");
      }
    }
    for (const auto& [name, value] : defines_) defaults_[name] = value;
    if (defaults_.count(kUnitDefault)) {
      const Node d = scene.find_child_by_attribute("default", "name", kUnitDefault);
      const std::string v = defaults_.at(kUnitDefault);
      if (defines_.count(kUnitDefault)) {
        if (!parse_number(v, unit_mm_))
          throw InputError(clip(source_, 200) + ": -D femto_unit_mm: expected a number (got \"" +
                           clip(v) + "\")");
      } else {
        unit_mm_ = number(d, "value", v);
      }
      if (!(unit_mm_ >= 1e-6 && unit_mm_ <= 1e9))
        throw InputError(
            (defines_.count(kUnitDefault) ? clip(source_, 200) + ": -D femto_unit_mm" : where(d)) +
            ": femto_unit_mm must be in [1e-6, 1e9] mm per scene unit (got " + clip(v) + ")");
    }
    for (Node c : scene.children()) {
      if (c.type() != pugi::node_element || std::string(c.name()) == "default") continue;
      if (!kObjectTags.count(c.name()) || std::string(c.name()) == "ref")
        fail(c, "unsupported element <" + clip(c.name()) + "> at the scene level" +
                    (kPropertyTags.count(c.name()) ? "" : " (docs/mitsuba.md lists the subset)"));
      if (c.attribute("id")) {
        const std::string id = attr(c, "id");
        if (!ids_.emplace(id, c).second)
          fail(c, "duplicate id \"" + clip(id) + "\" (first on line " +
                      std::to_string(line_of(ids_[id])) + ")");
      }
    }

    // The sensor first: its medium is the global one that shapes and lights sit in.
    Node sensor_node;
    for (Node c : scene.children("sensor")) {
      if (sensor_node) fail(c, "a second <sensor>; femto renders one camera per scene");
      sensor_node = c;
    }
    if (!sensor_node) fail(scene, "the scene has no <sensor>");
    Node integrator_node;
    for (Node c : scene.children("integrator")) {
      if (integrator_node) fail(c, "a second <integrator>");
      integrator_node = c;
    }
    out_ = Json::object();
    sensor(sensor_node);
    integrator(integrator_node);
    out_["shapes"] = Json::array();
    out_["lights"] = Json::array();
    for (Node c : scene.children()) {
      if (c.type() != pugi::node_element) continue;
      const std::string tag = c.name();
      if (tag == "shape") {
        shape(c);
      } else if (tag == "emitter") {
        light(c);
      } else if (tag == "bsdf" || tag == "medium" || tag == "texture") {
        if (!c.attribute("id"))
          fail(c, "a scene-level <" + tag + "> needs an id, used by <ref id=\"...\"/>");
        if (tag == "texture") fail(c, "textures are not supported (docs/mitsuba.md)");
      } else if (tag != "default" && tag != "sensor" && tag != "integrator") {
        fail(c, "unsupported element <" + clip(tag) + "> at the scene level");
      }
    }
    const bool emissive = std::any_of(out_["shapes"].begin(), out_["shapes"].end(),
                                      [](const Json& sh) { return sh.contains("emission"); });
    if (out_["lights"].empty() && !emissive)
      fail(scene,
           std::string("the scene has no emitter (a point or spot emitter, or an area emitter "
                       "in a shape)") +
               (infinite_emitters_ ? "; a constant emitter adds nothing to the time bins" : ""));
    if (!media_.empty()) {
      Json media = Json::object();
      for (const auto& m : media_) media[m.name] = m.json;
      out_["media"] = media;
    }
    // Place "media" and "medium" before "shapes" for readability of the converted scene.
    Json ordered = Json::object();
    for (const char* k : {"camera", "time", "media", "medium", "shapes", "lights", "render"})
      if (out_.contains(k)) ordered[k] = out_[k];
    if (ordered["lights"].empty()) ordered.erase("lights");
    if (ordered["shapes"].empty()) ordered.erase("shapes");

    MitsubaImport result;
    result.femto_json = ordered.dump(2);
    try {
      result.desc = load_scene_string(result.femto_json, source_, base_dir_);
    } catch (const InputError& e) {
      rethrow_at_element(e.what());
    }
    result.desc.warnings = warnings_;
    return result;
  }

 private:
  const std::string& text_;
  std::string source_, base_dir_;
  std::vector<std::size_t> line_starts_;
  std::map<std::string, std::string> defaults_;
  XmlDefines defines_;  // from the command line; override defaults_
  std::map<std::string, Node> ids_;
  double unit_mm_ = 1.0;
  Json out_;
  std::vector<std::pair<std::string, Node>> origins_;  // femto JSON path -> XML element
  std::vector<std::string> warnings_;
  struct Medium {
    Node node;
    double eta;
    std::string name;
    Json json;
  };
  std::vector<Medium> media_;
  Node global_medium_;              // the sensor's medium, or none (vacuum)
  bool infinite_emitters_ = false;  // constant emitters, left out

  // ---- messages

  std::size_t line_of(std::ptrdiff_t offset) const {
    if (offset < 0) return 0;
    const auto it = std::upper_bound(line_starts_.begin(), line_starts_.end(),
                                     static_cast<std::size_t>(offset));
    return static_cast<std::size_t>(it - line_starts_.begin());
  }
  std::size_t line_of(Node n) const { return line_of(n.offset_debug()); }

  std::string describe(Node n) const {
    std::string s = "<" + clip(n.name(), 40);
    for (const char* a : {"type", "name", "id"})
      if (n.attribute(a))
        s += std::string(" ") + a + "=\"" + clip(n.attribute(a).value(), 40) + "\"";
    return s + ">";
  }

  std::string where(Node n) const {
    return clip(source_, 200) + ":" + std::to_string(line_of(n)) + ": " + describe(n);
  }

  [[noreturn]] void fail(Node n, const std::string& problem) const {
    throw InputError(where(n) + ": " + problem);
  }

  void warn(Node n, const std::string& text) { warnings_.push_back(where(n) + ": " + text); }

  // A message of the JSON loader ("<source>: <json path>: <problem>") told at the XML element
  // the value came from.
  [[noreturn]] void rethrow_at_element(const std::string& msg) const {
    const std::string prefix = clip(source_, 200) + ": ";
    if (msg.compare(0, prefix.size(), prefix) != 0) throw InputError(msg);
    const std::string rest = msg.substr(prefix.size());
    const std::size_t colon = rest.find(": ");
    const std::string path = rest.substr(0, colon);
    const std::string problem = colon == std::string::npos ? rest : rest.substr(colon + 2);
    const Node* best = nullptr;
    std::size_t best_len = 0;
    for (const auto& [p, node] : origins_) {
      const bool covers = path == p || (path.size() > p.size() &&
                                        path.compare(0, p.size(), p) == 0 && path[p.size()] == '/');
      if (covers && p.size() >= best_len) {
        best = &node;
        best_len = p.size();
      }
    }
    if (!best) throw InputError(prefix + "in the translated femto scene: " + rest);
    throw InputError(where(*best) + ": " + problem + " (femto scene key " + path + ")");
  }

  void origin(const std::string& json_path, Node n) { origins_.emplace_back(json_path, n); }

  // ---- attributes and $variables

  void check_attributes(Node n, std::initializer_list<const char*> allowed) const {
    for (pugi::xml_attribute a : n.attributes()) {
      const std::string name = a.name();
      if (std::none_of(allowed.begin(), allowed.end(), [&](const char* x) { return name == x; }))
        fail(n, "unknown attribute '" + clip(name) + "'");
    }
  }

  // Mitsuba's structure is attributes only: text between tags is a mistake.
  void check_text(Node n) const {
    for (Node c : n.children())
      if (c.type() == pugi::node_pcdata || c.type() == pugi::node_cdata)
        fail(n, "unexpected text '" + clip(c.value(), 40) + "' inside the element");
  }

  std::string raw_attr(Node n, const char* name) const {
    const pugi::xml_attribute a = n.attribute(name);
    if (!a) fail(n, std::string("missing attribute '") + name + "'");
    return a.value();
  }
  std::string required_attr(Node n, const char* name) const { return attr(n, name); }

  /// An attribute's value with every $name replaced by its <default>.
  std::string attr(Node n, const char* name) const {
    const std::string raw = raw_attr(n, name);
    std::string out;
    for (std::size_t i = 0; i < raw.size(); ++i) {
      if (raw[i] != '$') {
        out += raw[i];
        continue;
      }
      std::size_t j = i + 1;
      while (j < raw.size() && (std::isalnum(static_cast<unsigned char>(raw[j])) || raw[j] == '_'))
        ++j;
      const std::string var = raw.substr(i + 1, j - i - 1);
      if (var.empty())
        fail(n, std::string("attribute '") + name + "': '$' must start a variable name (got \"" +
                    clip(raw) + "\")");
      const auto it = defaults_.find(var);
      if (it == defaults_.end())
        fail(n, std::string("attribute '") + name + "': undefined variable $" + clip(var) +
                    " (no <default name=\"" + clip(var) + "\" .../>, nor -D " + clip(var) +
                    "=...)");
      out += it->second;
      i = j - 1;
    }
    return out;
  }

  // ---- values

  static bool parse_number(const std::string& s, double& v) {
    std::string t = s;
    t.erase(0, t.find_first_not_of(" \t\r\n"));
    t.erase(t.find_last_not_of(" \t\r\n") + 1);
    if (!t.empty() && t[0] == '+') t.erase(0, 1);
    const auto r = std::from_chars(t.data(), t.data() + t.size(), v);
    return !t.empty() && r.ec == std::errc() && r.ptr == t.data() + t.size() && std::isfinite(v);
  }

  double number(Node n, const char* what, const std::string& s) const {
    double v = 0;
    if (!parse_number(s, v))
      fail(n, std::string("attribute '") + what + "': expected a finite number (got \"" + clip(s) +
                  "\")");
    return v;
  }

  std::vector<double> numbers(Node n, const char* what, const std::string& s) const {
    std::vector<double> out;
    std::string tok;
    for (std::size_t i = 0; i <= s.size(); ++i) {
      const char c = i < s.size() ? s[i] : ' ';
      if (c == ',' || std::isspace(static_cast<unsigned char>(c))) {
        if (!tok.empty()) out.push_back(number(n, what, tok));
        tok.clear();
      } else {
        tok += c;
      }
    }
    return out;
  }

  // Properties of a plugin element, sorted from its nested objects.
  Props props(Node n) const {
    check_text(n);
    Props p;
    p.owner = n;
    for (Node c : n.children()) {
      if (c.type() != pugi::node_element) continue;
      const std::string tag = c.name();
      if (kObjectTags.count(tag)) {
        p.objects.push_back(c);
        continue;
      }
      if (!kPropertyTags.count(tag))
        fail(c, "unknown element <" + clip(tag) + "> inside " + describe(n));
      const std::string name = attr(c, "name");
      if (!p.by_name.emplace(name, c).second)
        fail(c, "property '" + clip(name) + "' is given twice");
    }
    return p;
  }

  Node take(Props& p, const std::string& name) const {
    const auto it = p.by_name.find(name);
    if (it == p.by_name.end()) return Node();
    p.used.insert(name);
    return it->second;
  }

  void check_all_used(const Props& p) const {
    for (const auto& [name, node] : p.by_name)
      if (!p.used.count(name))
        fail(node, "property '" + clip(name) + "' is not supported for " + describe(p.owner) +
                       " (docs/mitsuba.md)");
  }

  void expect_tag(Node n, std::initializer_list<const char*> tags) const {
    const std::string tag = n.name();
    if (std::none_of(tags.begin(), tags.end(), [&](const char* t) { return tag == t; })) {
      std::string list;
      for (const char* t : tags) list += (list.empty() ? "<" : ", <") + std::string(t) + ">";
      fail(n, "expected " + list);
    }
  }

  double get_float(Props& p, const std::string& name, double fallback) const {
    const Node n = take(p, name);
    if (!n) return fallback;
    expect_tag(n, {"float", "integer"});
    check_attributes(n, {"name", "value"});
    return number(n, "value", attr(n, "value"));
  }

  long long get_int(Props& p, const std::string& name, long long fallback) const {
    const Node n = take(p, name);
    if (!n) return fallback;
    expect_tag(n, {"integer"});
    check_attributes(n, {"name", "value"});
    const double v = number(n, "value", attr(n, "value"));
    if (std::floor(v) != v || std::abs(v) > 9e15)
      fail(n, "expected an integer (got \"" + clip(attr(n, "value")) + "\")");
    return static_cast<long long>(v);
  }

  bool get_bool(Props& p, const std::string& name, bool fallback) const {
    const Node n = take(p, name);
    if (!n) return fallback;
    expect_tag(n, {"boolean"});
    check_attributes(n, {"name", "value"});
    const std::string v = attr(n, "value");
    if (v == "true") return true;
    if (v == "false") return false;
    fail(n, "expected true or false (got \"" + clip(v) + "\")");
  }

  std::string get_string(Props& p, const std::string& name, const std::string& fallback) const {
    const Node n = take(p, name);
    if (!n) return fallback;
    expect_tag(n, {"string"});
    check_attributes(n, {"name", "value"});
    return attr(n, "value");
  }

  /// A colour: <rgb value="r, g, b"> (or one value), <float>, or a constant <spectrum value="v">.
  RGB get_rgb(Props& p, const std::string& name, RGB fallback) const {
    const Node n = take(p, name);
    if (!n) return fallback;
    expect_tag(n, {"rgb", "float", "spectrum"});
    check_attributes(n, {"name", "value"});
    const std::string s = attr(n, "value");
    if (std::string(n.name()) == "spectrum" && s.find(':') != std::string::npos)
      fail(n, "spectra given as wavelength:value pairs are not supported; use <rgb>");
    const std::vector<double> v = numbers(n, "value", s);
    if (std::string(n.name()) == "float" && v.size() != 1)
      fail(n, "expected one number (got \"" + clip(s) + "\")");
    if (v.size() == 1) return RGB(v[0]);
    if (v.size() != 3) fail(n, "expected 1 or 3 numbers (got \"" + clip(s) + "\")");
    return {v[0], v[1], v[2]};
  }

  /// One value for a grey quantity (femto media have one coefficient for all colours).
  double get_grey(Props& p, const std::string& name, double fallback) const {
    const Node n = p.by_name.count(name) ? p.by_name.at(name) : Node();
    const RGB c = get_rgb(p, name, RGB(fallback));
    if (n && !(c.r == c.g && c.g == c.b))
      fail(n, "femto media are grey (one value for all colours); the components differ (got \"" +
                  clip(attr(n, "value")) + "\")");
    return c.r;
  }

  Vec3 xyz(Node n, double fallback) const {
    if (n.attribute("value")) {
      if (n.attribute("x") || n.attribute("y") || n.attribute("z"))
        fail(n, "give either 'value' or 'x', 'y', 'z', not both");
      const std::vector<double> v = numbers(n, "value", attr(n, "value"));
      if (v.size() == 1) return Vec3(v[0]);
      if (v.size() != 3)
        fail(n, "attribute 'value': expected 3 numbers (got \"" + clip(attr(n, "value")) + "\")");
      return {v[0], v[1], v[2]};
    }
    Vec3 out(fallback);
    const char* names[3] = {"x", "y", "z"};
    for (int i = 0; i < 3; ++i)
      if (n.attribute(names[i])) out[i] = number(n, names[i], attr(n, names[i]));
    return out;
  }

  Vec3 triple(Node n, const char* name) const {
    const std::string s = attr(n, name);
    const std::vector<double> v = numbers(n, name, s);
    if (v.size() != 3)
      fail(n,
           std::string("attribute '") + name + "': expected 3 numbers (got \"" + clip(s) + "\")");
    return {v[0], v[1], v[2]};
  }

  Vec3 get_point(Props& p, const std::string& name, const Vec3& fallback) const {
    const Node n = take(p, name);
    if (!n) return fallback;
    expect_tag(n, {"point", "vector"});
    check_attributes(n, {"name", "value", "x", "y", "z"});
    check_text(n);
    return xyz(n, 0.0);
  }

  // ---- transforms

  struct Placement {
    Affine m;  ///< to_world in mm (femto_unit_mm applied)
    bool single_lookat = false;
    Vec3 origin, target, up;  ///< the lookat's own values (mm) when it is the only operation
  };

  Placement get_transform(Props& p, const std::string& name) const {
    Placement out;
    const Node n = take(p, name);
    Affine m;
    int ops = 0;
    if (n) {
      expect_tag(n, {"transform"});
      check_attributes(n, {"name"});
      check_text(n);
      for (Node c : n.children()) {
        if (c.type() != pugi::node_element) continue;
        const std::string op = c.name();
        check_text(c);
        ++ops;
        if (op == "translate") {
          check_attributes(c, {"value", "x", "y", "z"});
          m = Affine::translate(xyz(c, 0.0)) * m;
        } else if (op == "scale") {
          check_attributes(c, {"value", "x", "y", "z"});
          m = Affine::scale(xyz(c, 1.0)) * m;
        } else if (op == "rotate") {
          check_attributes(c, {"value", "x", "y", "z", "angle"});
          const Vec3 axis = xyz(c, 0.0);
          if (!(length(axis) > 0)) fail(c, "the rotation axis must be non-zero");
          const double angle = c.attribute("angle") ? number(c, "angle", attr(c, "angle")) : 0.0;
          m = Affine::rotate(normalize(axis), angle) * m;
        } else if (op == "matrix") {
          check_attributes(c, {"value"});
          const std::vector<double> v = numbers(c, "value", attr(c, "value"));
          Affine a;
          if (v.size() == 16) {
            if (v[12] != 0 || v[13] != 0 || v[14] != 0 || v[15] != 1)
              fail(c, "the last row must be 0 0 0 1 (projective matrices are not supported)");
            for (int i = 0; i < 3; ++i)
              for (int j = 0; j < 4; ++j) a.m[i][j] = v[static_cast<std::size_t>(4 * i + j)];
          } else if (v.size() == 9) {
            for (int i = 0; i < 3; ++i)
              for (int j = 0; j < 3; ++j) a.m[i][j] = v[static_cast<std::size_t>(3 * i + j)];
          } else {
            fail(c, "attribute 'value': expected 16 (or 9) numbers, row by row");
          }
          m = a * m;
        } else if (op == "lookat") {
          check_attributes(c, {"origin", "target", "up"});
          const Vec3 o = triple(c, "origin"), t = triple(c, "target");
          Vec3 up = c.attribute("up") ? triple(c, "up") : Vec3(0, 0, 0);
          if (up.x == 0 && up.y == 0 && up.z == 0 && length(t - o) > 0)
            up = mitsuba::any_perpendicular(normalize(t - o));  // what Mitsuba does
          if (!(length(t - o) > 0)) fail(c, "'target' must differ from 'origin'");
          if (!(length(cross(normalize(up), normalize(t - o))) > 1e-9))
            fail(c, "'up' must be non-zero and not parallel to target - origin");
          m = Affine::lookat(o, t, up) * m;
          if (ops == 1) {
            out.single_lookat = true;
            out.origin = o * unit_mm_;
            out.target = t * unit_mm_;
            out.up = up;
          }
        } else {
          fail(c, "unsupported transform operation <" + clip(op) +
                      "> (translate, rotate, scale, matrix and lookat are)");
        }
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 4; ++j)
            if (!std::isfinite(m.m[i][j])) fail(c, "the transform is not finite");
      }
    }
    if (ops != 1) out.single_lookat = false;
    out.m = unit_mm_ == 1.0 ? m : Affine::scale(Vec3(unit_mm_)) * m;
    return out;
  }

  // ---- sensor, film, sampler, integrator

  void sensor(Node n) {
    check_attributes(n, {"type", "id", "name"});
    const std::string type = attr(n, "type");
    if (type != "perspective")
      fail(n, "unsupported sensor type \"" + clip(type) + "\" (femto supports \"perspective\")");
    Props p = props(n);
    origin("/camera", n);
    const Node fov_node = p.by_name.count("fov") ? p.by_name.at("fov") : Node();
    if (!fov_node)
      fail(n,
           "give the field of view as <float name=\"fov\" .../> (focal_length is not supported)");
    const double fov = get_float(p, "fov", 0);
    if (!(fov > 0 && fov < 180))
      fail(fov_node, "fov must be in (0, 180) degrees (got " + fmt(fov) + ")");
    const Node axis_node = p.by_name.count("fov_axis") ? p.by_name.at("fov_axis") : Node();
    const std::string fov_axis = get_string(p, "fov_axis", "x");
    const Placement place = get_transform(p, "to_world");
    for (const char* unused : {"near_clip", "far_clip", "focus_distance"})
      if (const Node u = take(p, unused))
        warn(u, "not used (femto has no clipping planes or focus)");
    for (const char* must_be_zero : {"principal_point_offset_x", "principal_point_offset_y"})
      if (p.by_name.count(must_be_zero) && get_float(p, must_be_zero, 0) != 0)
        fail(p.by_name.at(must_be_zero), "a shifted principal point is not supported");
    check_all_used(p);

    Node film_node, sampler_node;
    for (Node c : p.objects) {
      const std::string tag = c.name();
      if (tag == "film") {
        if (film_node) fail(c, "a second <film>");
        film_node = c;
      } else if (tag == "sampler") {
        if (sampler_node) fail(c, "a second <sampler>");
        sampler_node = c;
      } else if (tag == "medium" || (tag == "ref" && ref_tag(c) == "medium")) {
        if (global_medium_) fail(c, "a second medium for the sensor");
        global_medium_ = resolve(c, 0);
        medium_check(global_medium_);
      } else {
        fail(c, "unsupported element inside <sensor> (film, sampler and a medium are)");
      }
    }
    if (!film_node)
      fail(
          n,
          "the sensor needs <film type=\"transient_hdr_film\"> (mitransient's time-resolved film)");
    Json camera = Json::object();
    camera["type"] = "perspective";
    if (place.single_lookat) {
      camera["position"] = vec_json(place.origin);
      camera["look_at"] = vec_json(place.target);
      camera["up"] = vec_json(place.up);
    } else {
      // A camera frame: rotation times a uniform scale, not mirrored (the image cannot flip).
      const Affine& m = place.m;
      const Vec3 x = m.column(0), y = m.column(1), z = m.column(2);
      const double s = length(z);
      const bool frame = s > 0 && std::abs(length(x) - s) <= 1e-9 * s &&
                         std::abs(length(y) - s) <= 1e-9 * s &&
                         std::abs(dot(x, y)) <= 1e-9 * s * s &&
                         std::abs(dot(x, z)) <= 1e-9 * s * s && std::abs(dot(y, z)) <= 1e-9 * s * s;
      if (!frame || !(m.det() > 0))
        fail(p.by_name.count("to_world") ? p.by_name.at("to_world") : n,
             "the camera's to_world must be a rotation and translation (no mirroring, shear or "
             "non-uniform scale)");
      const Vec3 pos = m.point(Vec3(0, 0, 0));
      camera["position"] = vec_json(pos);
      camera["look_at"] = vec_json(pos + z / s);
      camera["up"] = vec_json(y / s);
    }
    const auto [width, height] = film(film_node);
    // Mitsuba's fov spans the axis fov_axis names; femto's is vertical.
    const double t = std::tan(0.5 * fov * kPi / 180.0);
    const double w = static_cast<double>(width), h = static_cast<double>(height);
    double vertical = fov;
    if (fov_axis == "x")
      vertical = 2.0 * std::atan(t * h / w) * 180.0 / kPi;
    else if (fov_axis == "y")
      vertical = fov;
    else if (fov_axis == "diagonal")
      vertical = 2.0 * std::atan(t * h / std::sqrt(w * w + h * h)) * 180.0 / kPi;
    else if (fov_axis == "smaller")
      vertical = w < h ? 2.0 * std::atan(t * h / w) * 180.0 / kPi : fov;
    else if (fov_axis == "larger")
      vertical = w > h ? 2.0 * std::atan(t * h / w) * 180.0 / kPi : fov;
    else
      fail(axis_node,
           "fov_axis must be one of \"x\", \"y\", \"diagonal\", \"smaller\", \"larger\" (got \"" +
               clip(fov_axis) + "\")");
    camera["fov"] = vertical;
    camera["resolution"] = Json::array({width, height});
    out_["camera"] = camera;
    if (global_medium_) {
      out_["medium"] = medium_name(global_medium_, 1.0);
      origin("/medium", global_medium_);
    }
    sampler(sampler_node);
  }

  std::pair<long long, long long> film(Node n) {
    check_attributes(n, {"type", "id", "name"});
    const std::string type = attr(n, "type");
    if (type != "transient_hdr_film")
      fail(n, "unsupported film \"" + clip(type) +
                  "\": femto renders a time axis; use mitransient's \"transient_hdr_film\" with "
                  "temporal_bins, start_opl and bin_width_opl");
    Props p = props(n);
    origin("/time", n);
    const auto int_in = [&](const char* name, long long fallback, long long lo, long long hi) {
      const Node node = p.by_name.count(name) ? p.by_name.at(name) : Node();
      const long long v = get_int(p, name, fallback);
      if (node && (v < lo || v > hi))
        fail(node, std::string(name) + " must be in [" + std::to_string(lo) + ", " +
                       std::to_string(hi) + "] (got " + std::to_string(v) + ")");
      return v;
    };
    const long long width = int_in("width", 768, 1, 16384);  // Mitsuba's film defaults
    const long long height = int_in("height", 576, 1, 16384);
    const long long bins = int_in("temporal_bins", 2048, 1, 100000);  // mitransient's defaults
    const Node bw_node = p.by_name.count("bin_width_opl") ? p.by_name.at("bin_width_opl") : Node();
    const double bin_width = get_float(p, "bin_width_opl", 0.003);
    if (!(bin_width > 0)) fail(bw_node, "bin_width_opl must be > 0 (got " + fmt(bin_width) + ")");
    const double start = get_float(p, "start_opl", 0.0);
    for (const char* unused : {"file_format", "pixel_format", "component_format", "banner"})
      if (const Node u = take(p, unused))
        warn(u, "not used (femto writes its own outputs, docs/outputs.md)");
    if (p.by_name.count("sample_border") && get_bool(p, "sample_border", false))
      fail(p.by_name.at("sample_border"), "sample_border is not supported");
    check_all_used(p);
    for (Node c : p.objects) {
      if (std::string(c.name()) != "rfilter")
        fail(c, "unsupported element inside <film> (an <rfilter> is)");
      check_attributes(c, {"type", "id", "name"});
      if (attr(c, "type") != "box")
        warn(c, "not used: femto's pixel filter is a box (uniform over the pixel)");
      else
        check_all_used(props(c));
    }
    Json time = Json::object();
    time["start_opl"] = start * unit_mm_;
    time["bin_width_opl"] = bin_width * unit_mm_;
    time["bins"] = bins;
    out_["time"] = time;
    return {width, height};
  }

  void sampler(Node n) {
    long long spp = 4;  // Mitsuba's default sample_count
    Json render = out_.contains("render") ? out_["render"] : Json::object();
    if (n) {
      check_attributes(n, {"type", "id", "name"});
      origin("/render", n);
      const std::string type = attr(n, "type");
      static const std::set<std::string> kSamplers = {"independent", "stratified", "multijitter",
                                                      "orthogonal", "ldsampler"};
      if (!kSamplers.count(type)) fail(n, "unknown sampler \"" + clip(type) + "\"");
      if (type != "independent")
        warn(n,
             "femto draws its own independent random numbers; only sample_count and seed are used");
      Props p = props(n);
      const Node sc = p.by_name.count("sample_count") ? p.by_name.at("sample_count") : Node();
      spp = get_int(p, "sample_count", 4);
      if (sc && (spp < 1 || spp > 10000000))
        fail(sc, "sample_count must be in [1, 10000000] (got " + std::to_string(spp) + ")");
      if (p.by_name.count("seed")) {
        const Node sn = p.by_name.at("seed");
        const long long seed = get_int(p, "seed", 0);
        if (seed < 0) fail(sn, "seed must be >= 0");
        render["seed"] = seed;
      }
      for (const char* unused : {"jitter", "scramble_seed", "dimension", "strength"})
        if (const Node u = take(p, unused)) warn(u, "not used (femto's own sampler)");
      check_all_used(p);
      if (!p.objects.empty()) fail(p.objects.front(), "unexpected element inside <sampler>");
    }
    render["spp"] = spp;
    out_["render"] = render;
  }

  void integrator(Node n) {
    Json render = out_.contains("render") ? out_["render"] : Json::object();
    render["integrator"] = "path";  // mitransient's integrators trace camera paths only
    if (n) {
      check_attributes(n, {"type", "id", "name"});
      const std::string type = attr(n, "type");
      static const std::set<std::string> kTransient = {"transient_path", "transientpath",
                                                       "transient_prbvolpath"};
      if (!kTransient.count(type))
        fail(n, "unsupported integrator \"" + clip(type) +
                    "\" (femto reads mitransient's \"transient_path\", \"transientpath\" and "
                    "\"transient_prbvolpath\")");
      Props p = props(n);
      const Node md = p.by_name.count("max_depth") ? p.by_name.at("max_depth") : Node();
      const long long max_depth = get_int(p, "max_depth", -1);
      if (md) {
        origin("/render/max_depth", md);
        // Mitsuba counts path segments (1: emitters seen directly, 2: direct light); femto counts
        // scattering and bounce vertices, one fewer.
        if (max_depth == -1) {
        } else if (max_depth < 2 || max_depth > 1000001) {
          fail(md,
               "max_depth must be -1 (no bound) or in [2, 1000001]: femto's bound counts "
               "scattering events, max_depth - 1, at least 1 (got " +
                   std::to_string(max_depth) + ")");
        } else {
          render["max_depth"] = max_depth - 1;
        }
      }
      if (const Node rr = take(p, "rr_depth"))
        warn(rr,
             "not used: femto applies no Russian roulette (paths end at the time window's end "
             "or at max_depth)");
      for (const char* unused : {"temporal_filter", "gaussian_stddev", "block_size"})
        if (const Node u = take(p, unused)) warn(u, "not used");
      if (p.by_name.count("camera_unwarp")) {
        const Node cu = p.by_name.at("camera_unwarp");
        const bool unwarp = get_bool(p, "camera_unwarp", false);
        out_["time"]["mode"] = unwarp ? "unwarp" : "camera";
        origin("/time/mode", cu);
      }
      for (const char* must_be_false : {"discard_direct_light", "hide_emitters"})
        if (p.by_name.count(must_be_false) && get_bool(p, must_be_false, false))
          fail(p.by_name.at(must_be_false), std::string(must_be_false) + " is not supported");
      check_all_used(p);
      if (!p.objects.empty()) fail(p.objects.front(), "unexpected element inside <integrator>");
    }
    out_["render"] = render;
  }

  // ---- references

  std::string ref_tag(Node ref) const {
    check_attributes(ref, {"id", "name"});
    const std::string id = attr(ref, "id");
    const auto it = ids_.find(id);
    if (it == ids_.end()) {
      std::string known;
      for (const auto& [k, v] : ids_)
        known += (known.empty() ? "" : ", ") + ("\"" + clip(k, 30) + "\"");
      fail(ref,
           "reference to an unknown id \"" + clip(id) + "\"" +
               (known.empty() ? " (no element has an id)" : " (ids: " + clip(known, 200) + ")"));
    }
    return it->second.name();
  }

  Node resolve(Node n, int depth) const {
    if (depth > kMaxRefDepth) fail(n, "references nest too deep (a cycle?)");
    if (std::string(n.name()) != "ref") return n;
    ref_tag(n);
    return ids_.at(attr(n, "id"));
  }

  // ---- media

  void medium_check(Node n) const {
    if (std::string(n.name()) != "medium")
      fail(n, "expected a <medium> (the id names a <" + clip(n.name()) + ">)");
  }

  Json medium_json(Node n) const {
    check_attributes(n, {"type", "id", "name"});
    const std::string type = attr(n, "type");
    if (type != "homogeneous")
      fail(n, "unsupported medium \"" + clip(type) +
                  "\" (femto reads \"homogeneous\"; voxel media: "
                  "use a femto JSON scene with a .vdb file)");
    Props p = props(n);
    const bool st = p.by_name.count("sigma_t") || p.by_name.count("albedo");
    const bool as = p.by_name.count("sigma_a") || p.by_name.count("sigma_s");
    if (st && as) fail(n, "give sigma_t and albedo, or sigma_a and sigma_s, not both pairs");
    const double scale = get_float(p, "scale", 1.0);
    if (!(scale >= 0)) fail(p.by_name.at("scale"), "scale must be >= 0 (got " + fmt(scale) + ")");
    double sigma_a, sigma_s;
    if (as) {
      sigma_a = get_grey(p, "sigma_a", 0.0);
      sigma_s = get_grey(p, "sigma_s", 0.0);
      if (!(sigma_a >= 0 && sigma_s >= 0)) fail(n, "sigma_a and sigma_s must be >= 0");
    } else {
      const double sigma_t = get_grey(p, "sigma_t", 1.0);  // Mitsuba's defaults
      const double albedo = get_grey(p, "albedo", 0.75);
      if (!(sigma_t >= 0))
        fail(p.by_name.at("sigma_t"), "sigma_t must be >= 0 (got " + fmt(sigma_t) + ")");
      if (!(albedo >= 0 && albedo <= 1))
        fail(p.by_name.at("albedo"), "albedo must be in [0, 1] (got " + fmt(albedo) + ")");
      sigma_s = albedo * sigma_t;
      sigma_a = sigma_t - sigma_s;
    }
    for (const char* unused : {"sample_emitters", "has_spectral_extinction"})
      (void)take(p, unused);  // sampling hints of Mitsuba's integrators; nothing to map
    check_all_used(p);
    double g = 0.0;
    for (Node c : p.objects) {
      if (std::string(c.name()) != "phase")
        fail(c, "unsupported element inside <medium> (a <phase> is)");
      check_attributes(c, {"type", "id", "name"});
      const std::string pt = attr(c, "type");
      Props pp = props(c);
      if (pt == "hg") {
        g = get_float(pp, "g", 0.8);  // Mitsuba's default
        if (!(g > -1 && g < 1))
          fail(pp.by_name.at("g"), "g must be in (-1, 1) (got " + fmt(g) + ")");
      } else if (pt != "isotropic") {
        fail(c, "unsupported phase function \"" + clip(pt) + "\" (\"isotropic\" and \"hg\" are)");
      }
      check_all_used(pp);
      if (!pp.objects.empty()) fail(pp.objects.front(), "unexpected element inside <phase>");
    }
    // Coefficients are per scene unit; femto's are per mm.
    Json m = Json::object();
    m["type"] = "homogeneous";
    m["sigma_a"] = sigma_a * scale / unit_mm_;
    m["sigma_s"] = sigma_s * scale / unit_mm_;
    m["g"] = g;
    return m;
  }

  /// The femto medium for a Mitsuba medium with refractive index eta (a dielectric's interior
  /// medium carries the dielectric's index in femto).
  std::string medium_name(Node n, double eta) {
    for (const Medium& m : media_)
      if (m.node == n && m.eta == eta) return m.name;
    Medium m;
    m.node = n;
    m.eta = eta;
    std::string base =
        n.attribute("id") ? attr(n, "id") : "medium (line " + std::to_string(line_of(n)) + ")";
    m.name = eta == 1.0 ? base : base + " (eta " + fmt(eta) + ")";
    for (const Medium& other : media_)
      if (other.name == m.name) m.name += " #" + std::to_string(media_.size());
    m.json = medium_json(n);
    if (eta != 1.0) m.json["eta"] = eta;
    origin("/media/" + escape(m.name), n);
    media_.push_back(m);
    return m.name;
  }

  static std::string escape(const std::string& key) {
    std::string out;
    for (char ch : clip(key, 40))
      out += ch == '~' ? std::string("~0") : ch == '/' ? std::string("~1") : std::string(1, ch);
    return out;
  }

  // ---- BSDFs

  struct Material {
    bool null = false;
    bool transmissive = false;
    double eta = 1.0;
    Json json;  // empty for null
  };

  double ior(Props& p, const std::string& name, double fallback) const {
    const Node n = take(p, name);
    if (!n) return fallback;
    expect_tag(n, {"float", "string"});
    check_attributes(n, {"name", "value"});
    const std::string v = attr(n, "value");
    double eta = 0;
    if (std::string(n.name()) == "string") {
      if (!named_ior(v, eta))
        fail(n, "unknown refractive index name \"" + clip(v) + "\" (Mitsuba's table)");
    } else {
      eta = number(n, "value", v);
    }
    if (!(eta >= 1.0)) fail(n, name + " must be >= 1 (got " + fmt(eta) + ")");
    return eta;
  }

  double roughness(Props& p, Node n) const {
    const std::string dist = get_string(p, "distribution", "beckmann");
    if (dist != "ggx")
      fail(n,
           "femto's rough surfaces use the GGX distribution: add <string name=\"distribution\" "
           "value=\"ggx\"/> (got \"" +
               clip(dist) + "\"" + (p.by_name.count("distribution") ? "" : ", Mitsuba's default") +
               ")");
    double alpha = get_float(p, "alpha", 0.1);
    if (p.by_name.count("alpha_u") || p.by_name.count("alpha_v")) {
      const double au = get_float(p, "alpha_u", 0.1), av = get_float(p, "alpha_v", 0.1);
      if (au != av) fail(n, "anisotropic roughness (alpha_u != alpha_v) is not supported");
      alpha = au;
    }
    if (!(alpha > 0 && alpha <= 1)) fail(n, "alpha must be in (0, 1] (got " + fmt(alpha) + ")");
    take(p, "sample_visible");
    return alpha;
  }

  Material bsdf(Node ref, int depth) const {
    const Node n = resolve(ref, depth);
    if (std::string(n.name()) != "bsdf")
      fail(ref, "expected a <bsdf> (the id names a <" + clip(n.name()) + ">)");
    check_attributes(n, {"type", "id", "name"});
    const std::string type = attr(n, "type");
    Props p = props(n);
    Material m;
    if (type == "twosided") {
      // femto's diffuse and conductor surfaces reflect on both sides already.
      check_all_used(p);
      if (p.objects.size() != 1)
        fail(n, "a twosided wrapper with different front and back BSDFs is not supported");
      m = bsdf(p.objects.front(), depth + 1);
      if (m.null || m.transmissive)
        fail(n, "twosided applies to opaque BSDFs (diffuse, conductors)");
      return m;
    }
    if (!p.objects.empty()) {
      const Node o = p.objects.front();
      fail(o, std::string(o.name()) == "texture" ||
                      (std::string(o.name()) == "ref" && ref_tag(o) == "texture")
                  ? "textures are not supported (docs/mitsuba.md)"
                  : "unexpected element inside " + describe(n));
    }
    if (type == "diffuse") {
      const Node rn = p.by_name.count("reflectance") ? p.by_name.at("reflectance") : Node();
      const RGB r = get_rgb(p, "reflectance", RGB(0.5));
      if (rn && !(r.r >= 0 && r.g >= 0 && r.b >= 0 && r.r <= 1 && r.g <= 1 && r.b <= 1))
        fail(rn, "reflectance must be in [0, 1]");
      m.json = {{"type", "diffuse"}, {"albedo", Json::array({r.r, r.g, r.b})}};
    } else if (type == "dielectric" || type == "roughdielectric") {
      const double int_ior = ior(p, "int_ior", 1.5046), ext_ior = ior(p, "ext_ior", 1.000277);
      m.eta = int_ior / ext_ior;  // Mitsuba refracts (and mitransient times) with the ratio
      if (!(m.eta >= 1.0))
        fail(n, "int_ior / ext_ior = " + fmt(m.eta) + " < 1: femto needs the denser side inside");
      for (const char* s : {"specular_reflectance", "specular_transmittance"})
        if (p.by_name.count(s)) {
          const Node sn = p.by_name.at(s);
          const RGB c = get_rgb(p, s, RGB(1.0));
          if (!(c.r == 1 && c.g == 1 && c.b == 1))
            fail(sn, std::string(s) + " other than 1 is not supported");
        }
      m.transmissive = true;
      if (type == "dielectric") {
        m.json = {{"type", "dielectric"}, {"eta", m.eta}};
      } else {
        const double alpha = roughness(p, n);
        m.json = {{"type", "rough_dielectric"}, {"eta", m.eta}, {"roughness", alpha}};
      }
    } else if (type == "conductor" || type == "roughconductor") {
      const std::string material = get_string(p, "material", "none");
      if (material != "none" || p.by_name.count("eta") || p.by_name.count("k"))
        fail(n,
             "conductors with a material or eta/k are not supported; femto reflects a constant "
             "colour: use <rgb name=\"specular_reflectance\"> with material \"none\"");
      const Node sn =
          p.by_name.count("specular_reflectance") ? p.by_name.at("specular_reflectance") : Node();
      const RGB r = get_rgb(p, "specular_reflectance", RGB(1.0));
      if (sn && !(r.r >= 0 && r.g >= 0 && r.b >= 0 && r.r <= 1 && r.g <= 1 && r.b <= 1))
        fail(sn, "specular_reflectance must be in [0, 1]");
      const Json refl = Json::array({r.r, r.g, r.b});
      if (type == "conductor") {
        m.json = {{"type", "mirror"}, {"reflectance", refl}};
      } else {
        const double alpha = roughness(p, n);
        m.json = {{"type", "rough_conductor"}, {"reflectance", refl}, {"roughness", alpha}};
      }
    } else if (type == "null") {
      m.null = true;
    } else {
      fail(n, "unsupported bsdf \"" + clip(type) +
                  "\" (diffuse, dielectric, roughdielectric, conductor, roughconductor, null and "
                  "twosided are)");
    }
    check_all_used(p);
    return m;
  }

  // ---- shapes

  void shape(Node n) {
    check_attributes(n, {"type", "id", "name"});
    const std::string type = attr(n, "type");
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
      fail(n,
           "unsupported shape \"" + clip(type) + "\" (sphere, rectangle, cube, obj and ply are)");
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
      fail(exterior,
           "a shape's exterior medium must be the sensor's medium (femto's global medium)" +
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
      check_attributes(e, {"type", "id", "name"});
      if (attr(e, "type") != "area") fail(e, "a shape's emitter must be of type \"area\"");
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

  // ---- lights

  void light(Node n) {
    check_attributes(n, {"type", "id", "name"});
    const std::string type = attr(n, "type");
    const std::string path = "/lights/" + std::to_string(out_["lights"].size());
    origin(path, n);
    if (type == "area") fail(n, "an area emitter belongs inside a <shape>");
    if (type == "constant") {
      // mitransient stamps light from infinity with an infinite path length (the escaped ray's
      // distance), so it never lands in a time bin: leaving it out keeps the transient the same.
      Props p = props(n);
      const RGB L = get_rgb(p, "radiance", RGB(1.0));
      (void)L;
      check_all_used(p);
      if (!p.objects.empty()) fail(p.objects.front(), "unexpected element inside <emitter>");
      warn(n,
           "left out: its light arrives at infinite path length, after every time bin, as in "
           "mitransient's transient film (docs/mitsuba.md)");
      infinite_emitters_ = true;
      return;
    }
    if (type == "envmap" || type == "directional")
      fail(n, "unsupported emitter \"" + type +
                  "\": femto has no light at infinity (point, spot and "
                  "area emitters are; constant is accepted and left out)");
    if (type != "point" && type != "spot")
      fail(n, "unsupported emitter \"" + clip(type) + "\" (point, spot and area are)");
    Props p = props(n);
    for (Node c : p.objects) {
      const std::string tag = std::string(c.name()) == "ref" ? ref_tag(c) : std::string(c.name());
      if (tag != "medium") fail(c, "unsupported element inside <emitter> (a medium is)");
      if (resolve(c, 0) != global_medium_)
        fail(c,
             "an emitter's medium must be the sensor's medium (lights sit in femto's global "
             "medium)");
    }
    // Point and spot intensities are per steradian, but the irradiance they give falls with the
    // squared distance: scaling lengths by femto_unit_mm needs unit^2 on the intensity.
    const RGB I = get_rgb(p, "intensity", RGB(1.0)) * (unit_mm_ * unit_mm_);
    Json l = Json::object();
    l["type"] = type;
    const bool has_position = p.by_name.count("position") > 0;
    const Vec3 position = get_point(p, "position", Vec3(0, 0, 0)) * unit_mm_;
    const Placement place = get_transform(p, "to_world");
    if (has_position && p.by_name.count("to_world"))
      fail(p.by_name.at("position"), "give either 'position' or 'to_world', not both");
    if (type == "point") {
      l["position"] = vec_json(has_position ? position : place.m.point(Vec3(0, 0, 0)));
    } else {
      const double cutoff = get_float(p, "cutoff_angle", 20.0);
      const double beam = get_float(p, "beam_width", cutoff * 0.75);
      if (!(cutoff > 0 && cutoff <= 90))
        fail(p.by_name.count("cutoff_angle") ? p.by_name.at("cutoff_angle") : n,
             "cutoff_angle must be in (0, 90] degrees (got " + fmt(cutoff) + ")");
      if (!(beam >= 0 && beam <= cutoff))
        fail(p.by_name.count("beam_width") ? p.by_name.at("beam_width") : n,
             "beam_width must be in [0, cutoff_angle] (got " + fmt(beam) + ")");
      if (has_position) fail(p.by_name.at("position"), "a spot is placed by to_world");
      if (place.single_lookat) {
        l["position"] = vec_json(place.origin);
        l["look_at"] = vec_json(place.target);
      } else {
        l["position"] = vec_json(place.m.point(Vec3(0, 0, 0)));
        l["direction"] = vec_json(place.m.vector(Vec3(0, 0, 1)));
      }
      l["cone_angle"] = cutoff;
      l["falloff_start"] = beam;
    }
    l["intensity"] = Json::array({I.r, I.g, I.b});
    check_all_used(p);
    out_["lights"].push_back(l);
  }
};

}  // namespace

bool is_mitsuba_xml_path(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& ch : ext) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  return ext == ".xml";
}

MitsubaImport load_mitsuba_xml(const std::string& xml_text, const std::string& source,
                               const std::string& base_dir, const XmlDefines& defines) {
  return Importer(xml_text, source, base_dir, defines).run();
}

bool add_xml_define(const std::string& text, XmlDefines& defines) {
  const std::size_t eq = text.find('=');
  if (eq == std::string::npos || eq == 0) return false;
  defines[text.substr(0, eq)] = text.substr(eq + 1);
  return true;
}

}  // namespace femto
