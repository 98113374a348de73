#pragma once
// Files of a tissue run (docs/tissue.md, "Outputs"): fluence volumes (.npy, .nii), detector TPSFs,
// detected photons, face exitance images, summary.json and render.json.
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/tissue/simulate.h"

namespace femto::tissue {

/// The summary: energy balance, absorbed fraction and per label, detectors, counters, timing.
nlohmann::json summary_json(const Setup& setup, const Result& result);

/// Writes every output into `dir` (each file atomically); `record` (version, command, scene...)
/// goes into render.json together with the summary and the list of files ("outputs"). Returns
/// the files.
std::vector<std::string> write_outputs(const std::string& dir, const Setup& setup,
                                       const Result& result, nlohmann::json record);

}  // namespace femto::tissue
