#pragma once
// Mitsuba 3 XML scenes (a subset, with mitransient's transient film and integrators; see
// docs/mitsuba.md). The XML is translated to an equivalent femto JSON scene, which the JSON
// loader then validates: both formats share every check and give identical scenes.
#include <map>
#include <string>

#include "core/scene_desc.h"

namespace femto {

/// Whether `path` names a Mitsuba XML scene (extension .xml, any case).
bool is_mitsuba_xml_path(const std::string& path);

struct MitsubaImport {
  std::string femto_json;  ///< the equivalent femto scene (docs/scene-format.md)
  SceneDesc desc;          ///< as load_scene_string gives it; desc.warnings lists unused settings
};

/// Values for $name variables given outside the file (femto's -D NAME=VALUE, as Mitsuba's);
/// they take precedence over the file's <default> elements.
using XmlDefines = std::map<std::string, std::string>;

/// Translates and loads a Mitsuba XML scene; `source` names it in messages and base_dir resolves
/// mesh files. Throws InputError "<source>:<line>: <element>: <problem>" for anything outside the
/// subset, and for any value the femto loader rejects (then naming the XML element it came from).
MitsubaImport load_mitsuba_xml(const std::string& xml_text, const std::string& source,
                               const std::string& base_dir, const XmlDefines& defines = {});

/// Parses "NAME=VALUE" of a -D flag into `defines`; false when the text has no '=' or no name.
bool add_xml_define(const std::string& text, XmlDefines& defines);

}  // namespace femto
