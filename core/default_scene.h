#pragma once

namespace femto {
/// The built-in scene (data/scenes/default.json), compiled into the binary.
const char* default_scene_json();
}  // namespace femto
