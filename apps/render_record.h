#pragma once
// What `femto render` records about a run: the render.json pieces built from the settings and the
// result, and the fingerprint a checkpoint must match to be resumed.
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "apps/render_flags.h"
#include "core/render.h"
#include "core/scene.h"

namespace femto {

nlohmann::json rgb_json(const RGB& c);
/// The scene as parsed (scene files may hold // comments), or its text if it cannot be parsed
/// again: render.json must stay valid JSON.
nlohmann::json scene_json(const std::string& text);
/// Where max_depth came from: a chosen bound ends paths on purpose, the default is a safety bound.
std::string max_depth_source(bool flag, const IntegratorDesc& d);
/// "a, b, c".
std::string file_list(const std::vector<std::string>& files);
nlohmann::json reconstruction_json(const ReconstructionDesc& r, const RenderResult& result);
/// settings.integrator: which integrator ran, why, and its settings as used.
nlohmann::json integrator_json(IntegratorKind kind, const std::string& why,
                               const RenderOptions& opt, const RenderResult& result);
const char* sampling_name(DistanceSampling s);
/// Everything that decides the bits of a render, for checkpoints: a resume must match it.
nlohmann::json render_fingerprint(const std::string& scene_text, const SceneDesc& desc,
                                  IntegratorKind kind, const RenderOptions& opt);

/// render.json's record of a render, without the command line and date: version, scene, settings,
/// media, time axis, film, counters, timing, progress (`stopped_by`: null when complete) and
/// energy. `film_nonfinite`: the values TransientFilm::zero_nonfinite set to 0.
nlohmann::json render_info(const Scene& scene, const std::string& scene_text, const RenderSetup& setup,
                           bool max_depth_given, const RenderResult& result, uint64_t film_nonfinite,
                           const char* stopped_by);

}  // namespace femto
