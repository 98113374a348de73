#pragma once
// JSON scene loader with strict validation (format: docs/scene-format.md).
#include <string>

#include "core/scene_desc.h"

namespace femto {

/// Reads and validates a scene file; relative mesh paths resolve against the file's folder.
/// A .xml file is read as a Mitsuba 3 scene (core/mitsuba/mitsuba_xml.h, docs/mitsuba.md).
/// Throws InputError with a one-line message "<file>: <json path>: <problem> (got <value>)".
SceneDesc load_scene_file(const std::string& path);

/// The text of a scene file, at most 64 MiB (larger files, and endless ones such as /dev/zero,
/// are an InputError).
std::string read_scene_text(const std::string& path);

/// Same from text; `source` names it in messages ("<default scene>" or a path), base_dir resolves
/// mesh files (empty = current directory).
SceneDesc load_scene_string(const std::string& json_text, const std::string& source,
                            const std::string& base_dir);

}  // namespace femto
