#pragma once
// Internal to core/mitsuba: the translator from a Mitsuba XML scene to femto JSON, one class
// whose methods are defined by concept in the .cpp files named beside each group below.
#include <cstdio>
#include <initializer_list>
#include <map>
#include <nlohmann/json.hpp>
#include <pugixml.hpp>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "core/mitsuba/affine.h"
#include "core/mitsuba/mitsuba_xml.h"

namespace femto::mitsuba {

using Json = nlohmann::ordered_json;
using Node = pugi::xml_node;

/// A number as written into the femto scene and into messages.
inline std::string fmt(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.10g", v);
  return buf;
}

inline Json vec_json(const Vec3& v) {
  return Json::array({v.x, v.y, v.z});
}

/// Elements that are properties of a plugin, and elements that are plugins (or references).
extern const std::set<std::string> kPropertyTags;
extern const std::set<std::string> kObjectTags;

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
           const XmlDefines& defines);

  // mitsuba_xml.cpp: the scene-level walk.
  MitsubaImport run();

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

  // messages.cpp: messages.
  std::size_t line_of(std::ptrdiff_t offset) const;
  std::size_t line_of(Node n) const;
  std::string describe(Node n) const;
  std::string where(Node n) const;
  [[noreturn]] void fail(Node n, const std::string& problem) const;
  void warn(Node n, const std::string& text);
  [[noreturn]] void rethrow_at_element(const std::string& msg) const;
  void origin(const std::string& json_path, Node n);

  // attributes.cpp: attributes, $variables and the numbers in them.
  void check_attributes(Node n, std::initializer_list<const char*> allowed) const;
  void check_text(Node n) const;
  std::string plugin_type(Node n) const;
  std::string raw_attr(Node n, const char* name) const;
  std::string required_attr(Node n, const char* name) const;
  std::string attr(Node n, const char* name) const;
  static bool parse_number(const std::string& s, double& v);
  double number(Node n, const char* what, const std::string& s) const;
  std::vector<double> numbers(Node n, const char* what, const std::string& s) const;
  Vec3 xyz(Node n, double fallback) const;
  Vec3 triple(Node n, const char* name) const;

  // properties.cpp: plugin properties and references.
  Props props(Node n) const;
  Node take(Props& p, const std::string& name) const;
  void check_all_used(const Props& p) const;
  void expect_tag(Node n, std::initializer_list<const char*> tags) const;
  double get_float(Props& p, const std::string& name, double fallback) const;
  long long get_int(Props& p, const std::string& name, long long fallback) const;
  bool get_bool(Props& p, const std::string& name, bool fallback) const;
  std::string get_string(Props& p, const std::string& name, const std::string& fallback) const;
  RGB get_rgb(Props& p, const std::string& name, RGB fallback) const;
  double get_grey(Props& p, const std::string& name, double fallback) const;
  Vec3 get_point(Props& p, const std::string& name, const Vec3& fallback) const;
  std::string ref_tag(Node ref) const;
  Node resolve(Node n, int depth) const;

  // transform.cpp: transforms.
  struct Placement {
    Affine m;  ///< to_world in mm (femto_unit_mm applied)
    bool single_lookat = false;
    Vec3 origin, target, up;  ///< the lookat's own values (mm) when it is the only operation
  };
  Placement get_transform(Props& p, const std::string& name) const;

  // sensor.cpp: sensor, film, sampler, integrator.
  void sensor(Node n);
  std::pair<long long, long long> film(Node n);
  void sampler(Node n);
  void integrator(Node n);

  // medium.cpp: media.
  void medium_check(Node n) const;
  Json medium_json(Node n) const;
  std::string medium_name(Node n, double eta);
  static std::string escape(const std::string& key);

  // bsdf.cpp: BSDFs.
  struct Material {
    bool null = false;
    bool transmissive = false;
    double eta = 1.0;
    Json json;  // empty for null
  };
  double ior(Props& p, const std::string& name, double fallback) const;
  double roughness(Props& p, Node n) const;
  Material bsdf(Node ref, int depth) const;

  // shape.cpp: shapes.
  void shape(Node n);

  // emitter.cpp: point, spot and constant emitters (area emitters belong to shapes).
  void light(Node n);
};

}  // namespace femto::mitsuba
