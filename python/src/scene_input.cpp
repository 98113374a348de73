// Scenes given as None, dict, JSON text or path (python/src/bindings.h).
#include <filesystem>

#include "core/default_scene.h"
#include "core/error.h"
#include "core/scene_loader.h"
#include "python/src/bindings.h"

namespace femto::python {

SceneText scene_text_of(const py::object& scene) {
  SceneText s;
  if (scene.is_none()) {
    s.text = default_scene_json();
    s.source = "<default scene>";
    s.base_dir = ".";
    return s;
  }
  if (py::isinstance<py::dict>(scene)) {
    s.text = py::module_::import("json").attr("dumps")(scene).cast<std::string>();
    s.source = "<dict>";
    return s;  // relative mesh and volume paths: the current folder
  }
  std::string text;
  if (py::isinstance<py::str>(scene)) {
    text = scene.cast<std::string>();
    const size_t first = text.find_first_not_of(" \t\r\n");
    if (first != std::string::npos && text[first] == '{') {
      s.text = text;
      s.source = "<string>";
      return s;
    }
  } else if (py::hasattr(scene, "__fspath__")) {
    text = py::module_::import("os").attr("fspath")(scene).cast<std::string>();
  } else {
    throw py::type_error("scene: expected None, a dict, JSON text or a path (got " +
                         py::str(py::type::of(scene).attr("__name__")).cast<std::string>() + ")");
  }
  s.path = text;
  s.source = text;
  s.base_dir = std::filesystem::path(text).parent_path().string();
  try {
    s.text = read_scene_text(text);
  } catch (const InputError& e) {
    throw SceneError(e.what());
  }
  return s;
}

}  // namespace femto::python
