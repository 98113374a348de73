// libFuzzer target: the scene loaders (load_scene_string, load_tissue_scene for text with a
// top-level "tissue", and load_mitsuba_xml for text starting with '<') on arbitrary text.
// Bad input must be an InputError; any other exception, a crash, a hang or a sanitizer report is
// a finding. Mesh and volume paths resolve against data/scenes, so the seeds' "../meshes/..."
// and "../volumes/..." references exist (volumes are only checked for existence here).
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>

#include "core/error.h"
#include "core/mitsuba/mitsuba_xml.h"
#include "core/scene_loader.h"
#include "core/tissue/scene.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const std::size_t first = text.find_first_not_of(" \t\r\n");
    if (first != std::string::npos && text[first] == '<') {  // a Mitsuba XML scene
      const femto::MitsubaImport xml =
          femto::load_mitsuba_xml(text, "fuzz.xml", FEMTO_SOURCE_DIR "/data/scenes");
      (void)xml;
    } else if (femto::tissue::is_tissue_scene(text)) {  // what femto render does with a tissue scene
      const femto::tissue::Setup setup =
          femto::tissue::load_tissue_scene(text, "fuzz.json", FEMTO_SOURCE_DIR "/data/scenes");
      (void)setup;
    } else {
      const femto::SceneDesc scene =
          femto::load_scene_string(text, "fuzz.json", FEMTO_SOURCE_DIR "/data/scenes");
      (void)scene;
    }
  } catch (const femto::InputError&) {
    // expected for bad input
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fuzz_scene: bad input escaped as %s, not InputError\n", e.what());
    std::abort();
  }
  return 0;
}
