// Plugin properties: typed readers (<float>, <rgb>, ...), unused-property errors, <ref> lookup.
#include <algorithm>
#include <cmath>

#include "core/error.h"
#include "core/mitsuba/importer.h"

namespace femto::mitsuba {

namespace {

constexpr int kMaxRefDepth = 8;  // bsdf/medium references; deeper means a cycle

}  // namespace

const std::set<std::string> kPropertyTags = {"float",    "integer", "boolean", "string",   "rgb",
                                             "spectrum", "point",   "vector",  "transform"};
const std::set<std::string> kObjectTags = {"bsdf",       "emitter", "medium", "phase",  "film",
                                           "sampler",    "rfilter", "shape",  "sensor", "texture",
                                           "integrator", "volume",  "ref"};

// Properties of a plugin element, sorted from its nested objects.
Props Importer::props(Node n) const {
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
    if (!p.by_name.emplace(name, c).second) fail(c, "property '" + clip(name) + "' is given twice");
  }
  return p;
}

Node Importer::take(Props& p, const std::string& name) const {
  const auto it = p.by_name.find(name);
  if (it == p.by_name.end()) return Node();
  p.used.insert(name);
  return it->second;
}

void Importer::check_all_used(const Props& p) const {
  for (const auto& [name, node] : p.by_name)
    if (!p.used.count(name))
      fail(node, "property '" + clip(name) + "' is not supported for " + describe(p.owner) +
                     " (docs/mitsuba.md)");
}

void Importer::expect_tag(Node n, std::initializer_list<const char*> tags) const {
  const std::string tag = n.name();
  if (std::none_of(tags.begin(), tags.end(), [&](const char* t) { return tag == t; })) {
    std::string list;
    for (const char* t : tags) list += (list.empty() ? "<" : ", <") + std::string(t) + ">";
    fail(n, "expected " + list);
  }
}

double Importer::get_float(Props& p, const std::string& name, double fallback) const {
  const Node n = take(p, name);
  if (!n) return fallback;
  expect_tag(n, {"float", "integer"});
  check_attributes(n, {"name", "value"});
  return number(n, "value", attr(n, "value"));
}

long long Importer::get_int(Props& p, const std::string& name, long long fallback) const {
  const Node n = take(p, name);
  if (!n) return fallback;
  expect_tag(n, {"integer"});
  check_attributes(n, {"name", "value"});
  const double v = number(n, "value", attr(n, "value"));
  if (std::floor(v) != v || std::abs(v) > 9e15)
    fail(n, "expected an integer (got \"" + clip(attr(n, "value")) + "\")");
  return static_cast<long long>(v);
}

bool Importer::get_bool(Props& p, const std::string& name, bool fallback) const {
  const Node n = take(p, name);
  if (!n) return fallback;
  expect_tag(n, {"boolean"});
  check_attributes(n, {"name", "value"});
  const std::string v = attr(n, "value");
  if (v == "true") return true;
  if (v == "false") return false;
  fail(n, "expected true or false (got \"" + clip(v) + "\")");
}

std::string Importer::get_string(Props& p, const std::string& name,
                                 const std::string& fallback) const {
  const Node n = take(p, name);
  if (!n) return fallback;
  expect_tag(n, {"string"});
  check_attributes(n, {"name", "value"});
  return attr(n, "value");
}

/// A colour: <rgb value="r, g, b"> (or one value), <float>, or a constant <spectrum value="v">.
RGB Importer::get_rgb(Props& p, const std::string& name, RGB fallback) const {
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
double Importer::get_grey(Props& p, const std::string& name, double fallback) const {
  const Node n = p.by_name.count(name) ? p.by_name.at(name) : Node();
  const RGB c = get_rgb(p, name, RGB(fallback));
  if (n && !(c.r == c.g && c.g == c.b))
    fail(n, "femto media are grey (one value for all colours); the components differ (got \"" +
                clip(attr(n, "value")) + "\")");
  return c.r;
}

Vec3 Importer::get_point(Props& p, const std::string& name, const Vec3& fallback) const {
  const Node n = take(p, name);
  if (!n) return fallback;
  expect_tag(n, {"point", "vector"});
  check_attributes(n, {"name", "value", "x", "y", "z"});
  check_text(n);
  return xyz(n, 0.0);
}

std::string Importer::ref_tag(Node ref) const {
  check_attributes(ref, {"id", "name"});
  const std::string id = attr(ref, "id");
  const auto it = ids_.find(id);
  if (it == ids_.end()) {
    std::string known;
    for (const auto& [k, v] : ids_)
      known += (known.empty() ? "" : ", ") + ("\"" + clip(k, 30) + "\"");
    fail(ref, "reference to an unknown id \"" + clip(id) + "\"" +
                  (known.empty() ? " (no element has an id)" : " (ids: " + clip(known, 200) + ")"));
  }
  return it->second.name();
}

Node Importer::resolve(Node n, int depth) const {
  if (depth > kMaxRefDepth) fail(n, "references nest too deep (a cycle?)");
  if (std::string(n.name()) != "ref") return n;
  ref_tag(n);
  return ids_.at(attr(n, "id"));
}

}  // namespace femto::mitsuba
