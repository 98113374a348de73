// Mitsuba XML entry points and the scene-level walk: defaults, ids, sensor, shapes, emitters.
#include "core/mitsuba/mitsuba_xml.h"

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <filesystem>

#include "core/error.h"
#include "core/mitsuba/importer.h"
#include "core/scene_loader.h"

namespace femto {
namespace mitsuba {
namespace {

const char* const kUnitDefault = "femto_unit_mm";

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

}  // namespace

Importer::Importer(const std::string& text, std::string source, std::string base_dir,
                   const XmlDefines& defines)
    : text_(text), source_(std::move(source)), base_dir_(std::move(base_dir)), defines_(defines) {
  line_starts_.push_back(0);
  for (std::size_t i = 0; i < text_.size(); ++i)
    if (text_[i] == '\n') line_starts_.push_back(i + 1);
}

MitsubaImport Importer::run() {
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

}  // namespace mitsuba

bool is_mitsuba_xml_path(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& ch : ext) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  return ext == ".xml";
}

MitsubaImport load_mitsuba_xml(const std::string& xml_text, const std::string& source,
                               const std::string& base_dir, const XmlDefines& defines) {
  return mitsuba::Importer(xml_text, source, base_dir, defines).run();
}

bool add_xml_define(const std::string& text, XmlDefines& defines) {
  const std::size_t eq = text.find('=');
  if (eq == std::string::npos || eq == 0) return false;
  defines[text.substr(0, eq)] = text.substr(eq + 1);
  return true;
}

}  // namespace femto
