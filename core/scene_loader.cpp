// The JSON scene loader's entry points: reading the file, and the sections in order.
#include "core/scene_loader.h"

#include <algorithm>
#include <filesystem>
#include <fstream>

#include "core/error.h"
#include "core/medium_nesting.h"
#include "core/mitsuba/mitsuba_xml.h"
#include "core/scene_json/loader.h"

namespace femto {
namespace {

namespace fs = std::filesystem;

constexpr std::uint64_t kMaxSceneBytes = 64ull << 20;

}  // namespace

namespace scene_json {

SceneDesc Loader::load(const std::string& text) {
  const Json root = parse(text);
  SceneDesc scene;
  scene.source = source_;
  if (!root.is_object()) fail("/", "the scene must be a JSON object", root);
  if (root.contains("tissue"))  // a tissue-optics run, not a camera scene
    fail("/tissue",
         "a tissue-optics scene (docs/tissue.md): run it with femto render or femto tissue; "
         "it cannot be used as a camera scene here");
  check_keys(root, "", {"camera", "time", "media", "medium", "shapes", "lights", "render"});
  camera(require(root, "", "camera"), scene.camera);
  time(require(root, "", "time"), scene);
  if (const Json* m = find(root, "media")) media(*m, scene);
  if (const Json* m = find(root, "medium")) scene.global_medium = medium_ref(*m, "/medium", scene);
  if (const Json* s = find(root, "shapes")) shapes(*s, scene);
  if (const Json* l = find(root, "lights")) lights(*l, scene);
  if (const Json* r = find(root, "render")) render(*r, scene.integrator);
  enclosing_shapes(scene);  // media may nest but not overlap: refused here, before any work

  const bool emissive = std::any_of(scene.shapes.begin(), scene.shapes.end(),
                                    [](const ShapeDesc& s) { return s.emissive; });
  if (scene.lights.empty() && !emissive)
    fail("/lights", "scene has no light: add an entry to \"lights\" or an \"emission\" to a shape");
  return scene;
}

}  // namespace scene_json

SceneDesc load_scene_string(const std::string& json_text, const std::string& source,
                            const std::string& base_dir) {
  return scene_json::Loader(source, base_dir).load(json_text);
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
  if (is_mitsuba_xml_path(path))
    return load_mitsuba_xml(read_scene_text(path), path, base_dir).desc;
  return load_scene_string(read_scene_text(path), path, base_dir);
}

}  // namespace femto
