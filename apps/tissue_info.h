#pragma once
// `femto info` for tissue-optics scenes (docs/tissue.md): what the scene holds and what a run of
// it will need, without running it.
#include <string>

namespace femto {

/// Prints the tissue scene `text` (read from `path`) to stdout; throws InputError for bad input.
void print_tissue_info(const std::string& text, const std::string& path);

}  // namespace femto
