// What `femto render` records about a run (apps/render_record.h).
#include "apps/render_record.h"

#include <algorithm>

#include "core/io/sha256.h"
#include "femto_version.h"

namespace femto {

nlohmann::json rgb_json(const RGB& c) {
  return nlohmann::json::array({c.r, c.g, c.b});
}

/// The scene as parsed (scene files may hold // comments), or its text if it cannot be parsed
/// again: render.json must stay valid JSON.
nlohmann::json scene_json(const std::string& text) {
  nlohmann::json j =
      nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false, /*ignore_comments=*/true);
  return j.is_discarded() ? nlohmann::json(text) : j;
}

// Where max_depth came from: a chosen bound ends paths on purpose, the default is a safety bound.
std::string max_depth_source(bool flag, const IntegratorDesc& d) {
  return flag ? "--max-depth" : d.max_depth_set ? "scene" : "default";
}

std::string file_list(const std::vector<std::string>& files) {
  std::string s;
  for (const auto& f : files) s += (s.empty() ? "" : ", ") + f;
  return s;
}

nlohmann::json reconstruction_json(const ReconstructionDesc& r, const RenderResult& result) {
  if (r.type == TemporalFilter::Kind::Histogram) return {{"type", "histogram"}};
  nlohmann::json j = {{"type", "kernel"},
                      {"kernel", r.kernel == TemporalKernel::Perlin ? "perlin" : "epanechnikov"},
                      {"alpha", r.alpha},
                      {"schedule", "T_{j+1} = T_j (j + alpha) / (j + 1), j = sample index from 1"}};
  if (r.bandwidth_ps > 0) {
    j["initial_bandwidth_ps"] = r.bandwidth_ps;
  } else {
    j["initial_bandwidth"] = "k nearest arrivals of the first pass, per pixel";
    j["k"] = r.knn;
    j["first_pass_spp"] = r.first_pass_spp;
    j["onset_reflection"] = r.onset_reflection;
  }
  std::vector<float> T = result.final_bandwidth_ps;
  if (!T.empty()) {
    std::sort(T.begin(), T.end());
    j["final_bandwidth_ps"] = {{"min", T.front()}, {"median", T[T.size() / 2]}, {"max", T.back()}};
  }
  return j;
}

nlohmann::json integrator_json(IntegratorKind kind, const std::string& why,
                               const RenderOptions& opt, const RenderResult& result) {
  nlohmann::json j = {{"type", integrator_name(kind)}, {"why", why}};
  switch (kind) {
    case IntegratorKind::Path:
      j["description"] =
          "camera paths: distance sampling per medium, next-event estimation, MIS with BSDF "
          "sampling";
      break;
    case IntegratorKind::Light:
      j["description"] = "light paths, every non-delta vertex connected to the camera";
      j["light_paths"] = result.light_paths;
      break;
    case IntegratorKind::Photons:
    case IntegratorKind::Beams:
    case IntegratorKind::Hybrid: {
      const bool beams = kind == IntegratorKind::Beams;
      const auto& p = result.photons;
      j["description"] = beams ? "camera paths + transient progressive photon beams: every "
                                 "light-path segment in a scattering "
                                 "medium is a beam; light scattered in media before a camera "
                                 "path's first non-specular surface "
                                 "comes from the beams gathered along its segments"
                               : "camera paths + transient progressive photon mapping: photons "
                                 "that reach a diffuse surface "
                                 "through non-diffuse surfaces are gathered there; camera paths "
                                 "leave those paths out";
      j["passes"] = p.passes;
      j["camera_samples_per_pass"] = 1;
      j["photons_per_pass"] = p.per_pass;
      j["radius_mm"] = {{"first_pass", p.radius_first}, {"last_pass", p.radius_last}};
      j["bandwidth_ps"] = {{"first_pass", p.bandwidth_first_ps},
                           {"last_pass", p.bandwidth_last_ps}};
      j["alpha"] = p.alpha;
      j["beta_t"] = p.beta_t;
      j["temporal_kernel"] =
          opt.photons.kernel == TemporalKernel::Perlin ? "perlin" : "epanechnikov";
      j["spatial_kernel"] =
          beams ? "1-D across the beam, 1 / (2 R), with 1 / sin(theta)" : "disc, 1 / (pi R^2)";
      j["schedule"] = beams ? "R_{j+1} = R_j ((j + alpha) / (j + 1))^(1 - beta_t), T_{j+1} = T_j "
                              "((j + alpha) / (j + 1))^beta_t"
                            : "R_{j+1}^2 = R_j^2 ((j + alpha) / (j + 1))^(1 - beta_t), T_{j+1} = "
                              "T_j ((j + alpha) / (j + 1))^beta_t";
      j[beams ? "max_beams_stored_per_pass" : "max_photons_stored_per_pass"] =
          p.max_stored_per_pass;
      if (p.hybrid_beams)
        j["caustic_beams"] = {
            {"description",
             "segments in media of light paths after one or more non-diffuse surfaces"},
            {"light_paths_per_pass", p.beam_paths},
            {"radius_mm",
             {{"first_pass", p.beam_radius_first}, {"after_last_pass", p.beam_radius_last}}},
            {"bandwidth_ps",
             {{"first_pass", p.beam_bandwidth_first_ps},
              {"after_last_pass", p.beam_bandwidth_last_ps}}},
            {"alpha", p.beam_alpha},
            {"beta_t", p.beam_beta_t},
            {"spatial_kernel", "1-D across the beam, 1 / (2 R), with 1 / sin(theta)"},
            {"schedule",
             "R_{j+1} = R_j ((j + alpha) / (j + 1))^(1 - beta_t), T_{j+1} = T_j ((j + alpha) / (j "
             "+ 1))^beta_t"}};
      j[beams ? "beam_memory_bytes_peak" : "photon_memory_bytes_peak"] = p.peak_photon_bytes;
      break;
    }
    case IntegratorKind::Auto:
      break;
  }
  return j;
}

const char* sampling_name(DistanceSampling s) {
  const char* names[] = {"mfp", "time_uniform", "mis"};
  return names[static_cast<int>(s)];
}

/// Everything that decides the bits of a render, for checkpoints: a resume must match it.
nlohmann::json render_fingerprint(const std::string& scene_text, const SceneDesc& desc,
                                  IntegratorKind kind, const RenderOptions& opt) {
  const ReconstructionDesc& r = desc.reconstruction;
  const PhotonDesc& pd = opt.photons;
  nlohmann::json media = nlohmann::json::array();
  for (const MediumDesc& m : desc.media)
    media.push_back({{"name", m.name},
                     {"distance_sampling", sampling_name(m.sampling)},
                     {"connection_sampling", static_cast<int>(m.connection)},
                     {"direction_sampling", static_cast<int>(m.direction)}});
  return {{"femto_version", FEMTO_VERSION},
          {"femto_build", FEMTO_GIT_DESCRIBE},
          {"scene_sha256", sha256_hex(scene_text)},
          {"settings",
           {{"spp", opt.spp},
            {"seed", opt.seed},
            {"max_depth", opt.max_depth},
            {"integrator", integrator_name(kind)},
            {"light_paths", kind == IntegratorKind::Light ? opt.light_paths : 0},
            {"photons", kind != IntegratorKind::Photons && kind != IntegratorKind::Beams &&
                                kind != IntegratorKind::Hybrid
                            ? nlohmann::json(nullptr)
                            : nlohmann::json{{"per_pass", pd.per_pass},
                                             {"radius", pd.radius},
                                             {"bandwidth_ps", pd.bandwidth_ps},
                                             {"alpha", pd.alpha},
                                             {"beta_t", pd.beta_t},
                                             {"kernel", static_cast<int>(pd.kernel)}}},
            {"reconstruction",
             {{"type", r.type == TemporalFilter::Kind::Kernel ? "kernel" : "histogram"},
              {"kernel", static_cast<int>(r.kernel)},
              {"alpha", r.alpha},
              {"knn", r.knn},
              {"first_pass_spp", r.first_pass_spp},
              {"bandwidth_ps", r.bandwidth_ps},
              {"onset_reflection", r.onset_reflection}}},
            {"media", media},
            {"film", {desc.camera.width, desc.camera.height, desc.time.bins}}}}};
}

}  // namespace femto
