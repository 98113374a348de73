#pragma once
// The tissue-optics run shared by `femto tissue SCENE` and `femto render SCENE` (when the scene
// has a "tissue" section): validate, state the memory, simulate, write the output folder.
#include <cstdint>
#include <optional>
#include <string>

namespace femto {

struct TissueRunOptions {
  std::optional<uint64_t> photons, seed;
  int threads = 0;
  std::string out = "femto-out";
  bool quiet = false;
  uint64_t max_memory = 0;  ///< bytes; 0: 75% of physical memory
};

/// Runs the tissue scene `text` read from `path`. Returns the exit code; throws InputError for
/// bad input (before anything is written).
int run_tissue_scene(const std::string& text, const std::string& path, const TissueRunOptions& opt,
                     const std::string& command_line);

}  // namespace femto
