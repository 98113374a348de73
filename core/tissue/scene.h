#pragma once
// The "tissue" scene file (docs/scene-format.md, "Tissue optics"): a labelled volume, its optical
// properties per label, a pulsed source, time gates and tallies. Strict: unknown keys, wrong
// types and out-of-range values are InputErrors naming the file, the JSON path and the value.
#include <string>

#include "core/tissue/setup.h"

namespace femto::tissue {

/// Whether `text` is a JSON object with a top-level "tissue" key (femto render then runs the
/// tissue mode). Malformed text gives false: the scene loader reports it.
bool is_tissue_scene(const std::string& text);

/// Reads the "tissue" section; `source` names the file in messages, `base_dir` resolves the
/// volume files. Loads the label volume (NIfTI-1 or OpenVDB) and checks that every label in it
/// has optical properties.
Setup load_tissue_scene(const std::string& text, const std::string& source,
                        const std::string& base_dir);

}  // namespace femto::tissue
