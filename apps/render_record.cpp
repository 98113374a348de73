// What `femto render` records about a run (apps/render_record.h).
#include "apps/render_record.h"

#include <algorithm>

#include "core/distributed/comm.h"
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

// Russian roulette on camera paths: false, or where it starts and its throughput threshold.
nlohmann::json roulette_json(IntegratorKind kind, const RouletteDesc& r) {
  if (kind == IntegratorKind::Light || r.depth <= 0) return false;
  return {{"depth", r.depth}, {"threshold", r.threshold}};
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
      j["description"] =
          beams ? "camera paths + transient progressive photon beams: every light-path segment in "
                  "a scattering medium is a beam; light scattered in media before a camera "
                  "path's first non-specular surface comes from the beams gathered along its "
                  "segments"
          : kind == IntegratorKind::Hybrid
              ? "camera paths + transient progressive photon mapping + caustic photon beams + "
                "light tracing: photons that reach a diffuse surface through non-diffuse "
                "surfaces are gathered there, except on the surface a camera path meets first, "
                "where light tracing splats that light; caustic beams in scattering media; camera "
                "paths leave those paths out (docs/ARCHITECTURE.md, \"Path-space partition\")"
              : "camera paths + transient progressive photon mapping: photons that reach a "
                "diffuse surface through non-diffuse surfaces are gathered there; camera paths "
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
      if (!beams || p.hybrid_beams) {
        nlohmann::json lights = nlohmann::json::array();
        for (double share : p.aim_share)
          lights.push_back(share < 0
                               ? nlohmann::json{{"aimed", false}}
                               : nlohmann::json{{"aimed", true}, {"solid_angle_share", share}});
        j["aim"] = {
            {"enabled", p.aim}, {"lights", lights}, {"paths_per_pass_scale", p.aim_paths_scale}};
      }
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
      if (p.hybrid_light_paths > 0)
        j["light_tracing"] = {
            {"description",
             "light paths splatted to the sensor for the light that camera paths leave to them "
             "(docs/ARCHITECTURE.md, \"Path-space partition\")"},
            {"light_paths_per_pass", p.hybrid_light_paths},
            {"set_by", opt.light_paths > 0 ? "light_paths" : "default: one per four pixels"}};
      if (p.hybrid_light_paths > 0 && p.camera_ball_radius > 0)
        j["light_tracing"]["camera_ball"] = {
            {"description",
             "medium points within radius_mm of the pinhole are gathered by the camera's own "
             "segment from the light paths' pieces through the ball (long beams, 1-D kernel of "
             "radius max(slope s, min_radius) at distance s from the pinhole)"},
            {"radius_mm", p.camera_ball_radius},
            {"kernel_slope",
             {{"first_pass", p.camera_ball_slope_first},
              {"after_last_pass", p.camera_ball_slope_last}}},
            {"kernel_min_radius_mm",
             {{"first_pass", p.camera_ball_r_min_first},
              {"after_last_pass", p.camera_ball_r_min_last}}},
            {"max_beams_per_pass", p.camera_ball_beams_max}};
      j[beams ? "beam_memory_bytes_peak" : "photon_memory_bytes_peak"] = p.peak_photon_bytes;
      break;
    }
    case IntegratorKind::Auto:
      break;
  }
  return j;
}

const char* sampling_name(DistanceSampling s) {
  const char* names[] = {"mfp", "time_uniform", "mis", "mixture"};
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
          {"femto_instruction_set", FEMTO_INSTRUCTION_SET},
          {"scene_sha256", sha256_hex(scene_text)},
          {"settings",
           {{"spp", opt.spp},
            {"seed", opt.seed},
            {"max_depth", opt.max_depth},
            {"russian_roulette", roulette_json(kind, opt.roulette)},
            {"integrator", integrator_name(kind)},
            {"light_paths",
             kind == IntegratorKind::Light || kind == IntegratorKind::Hybrid ? opt.light_paths : 0},
            {"camera_ball", kind == IntegratorKind::Hybrid ? opt.camera_ball_mm : -1.0},
            {"photons", kind != IntegratorKind::Photons && kind != IntegratorKind::Beams &&
                                kind != IntegratorKind::Hybrid
                            ? nlohmann::json(nullptr)
                            : nlohmann::json{{"per_pass", pd.per_pass},
                                             {"radius", pd.radius},
                                             {"bandwidth_ps", pd.bandwidth_ps},
                                             {"alpha", pd.alpha},
                                             {"beta_t", pd.beta_t},
                                             {"kernel", static_cast<int>(pd.kernel)},
                                             {"aim", pd.aim}}},
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

nlohmann::json render_info(const Scene& scene, const std::string& scene_text, const RenderSetup& setup,
                           bool max_depth_given, const RenderResult& result, uint64_t film_nonfinite,
                           const char* stopped_by) {
  const RenderOptions& opt = setup.options;
  const IntegratorKind kind = setup.kind;
  const std::string& integrator_why = setup.integrator_why;
  const CameraDesc& cam = scene.desc().camera;
  const TimeAxis& axis = scene.desc().time;
  const bool kernel_film = scene.desc().reconstruction.type == TemporalFilter::Kind::Kernel;
  const uint64_t film_bytes = TransientFilm::memory_bytes(cam.width, cam.height, axis.bins);
  const PathStats& st = result.stats;
  const std::string depth_source = max_depth_source(max_depth_given, scene.desc().integrator);
  nlohmann::json info;
  info["femto_version"] = FEMTO_VERSION;
  info["femto_build"] = FEMTO_GIT_DESCRIBE;
  info["femto_instruction_set"] = FEMTO_INSTRUCTION_SET;
  info["scene"] = {{"source", scene.desc().source},
                   {"json", scene_json(scene_text)}};
  if (!scene.desc().warnings.empty()) info["scene"]["warnings"] = scene.desc().warnings;
  info["settings"] = {{"spp", opt.spp},
                      {"seed", opt.seed},
                      {"threads", result.threads},
                      {"threads_requested", opt.threads},
                      {"mpi_ranks", opt.comm ? opt.comm->size() : 1},
                      {"max_depth", opt.max_depth},
                      {"max_depth_source", depth_source},
                      {"integrator", integrator_json(kind, integrator_why, opt, result)},
                      {"reconstruction", reconstruction_json(scene.desc().reconstruction, result)},
                      {"russian_roulette", roulette_json(kind, opt.roulette)}};
  nlohmann::json media = nlohmann::json::array();
  {
    for (size_t i = 0; i < scene.desc().media.size(); ++i) {
      const MediumDesc& md = scene.desc().media[i];
      const Medium& rm = scene.media()[i];
      nlohmann::json e = {{"name", md.name},
                          {"type", md.type == MediumDesc::Type::Vdb ? "vdb" : "homogeneous"},
                          {"distance_sampling", sampling_name(md.sampling)}};
      if (md.sampling != DistanceSampling::Mfp) e["time_uniform_rate_per_mm_opl"] = rm.strategy.lambda;
      if (md.sampling == DistanceSampling::Mis)
        e["mis_heuristic"] = md.mis_heuristic == MisHeuristic::Power ? "power" : "balance";
      e["connection_sampling"] = connection_sampling_name(md.connection);
      e["direction_sampling"] = md.direction == DirectionSampling::Angular ? "angular" : "phase";
      media.push_back(e);
    }
  }
  info["media"] = media;
  info["time_axis"] = {{"t_start_ps", axis.t_start_ps},
                       {"bin_width_ps", axis.bin_width_ps},
                       {"bins", axis.bins},
                       {"t_end_ps", axis.t_end_ps()},
                       {"start_opl_mm", TimeAxis::opl_of_time(axis.t_start_ps)},
                       {"bin_width_opl_mm", TimeAxis::opl_of_time(axis.bin_width_ps)},
                       {"end_opl_mm", TimeAxis::opl_of_time(axis.t_end_ps())},
                       {"mode", scene.desc().time_mode == TimeMode::Camera ? "camera" : "unwarp"},
                       {"speed_of_light_mm_per_ps", kSpeedOfLight}};
  info["film"] = {{"width", cam.width},
                  {"height", cam.height},
                  {"bins", axis.bins},
                  {"npy_shape", {cam.height, cam.width, axis.bins, 3}},
                  {"dtype", "float32"},
                  {"units", "radiance integrated over each bin; sum over bins = steady.exr"},
                  {"memory_bytes", film_bytes}};
  info["counters"] = {{"paths", st.paths},
                      {"medium_scattering_events", st.medium_events},
                      {"surface_events", st.surface_events},
                      {"null_boundary_crossings", st.null_crossings},
                      {"max_depth_terminations", st.max_depth_hits},
                      {"roulette_terminations", st.roulette_ends},
                      {"nonfinite_samples_dropped", st.nonfinite_dropped},
                      {"nonfinite_film_values_zeroed", film_nonfinite},
                      {"light_paths", st.light_paths},
                      {"photons_stored", st.photons_stored},
                      {"photon_gathers", st.photon_gathers},
                      {"beams_stored", st.beams_stored},
                      {"beam_gathers", st.beam_gathers}};
  info["timing"] = {{"render_seconds", result.wall_seconds},
                    {"paths_per_second", result.wall_seconds > 0 ? static_cast<double>(st.paths) / result.wall_seconds : 0.0}};
  info["complete"] = result.complete;
  info["progress"] = {{"complete", result.complete},
                      {"unit", result.unit},
                      {"units_done", result.units_done},
                      {"units_total", result.units_total},
                      {"spp_done", result.spp_done},
                      {"sessions", result.sessions},
                      {"stopped_by", stopped_by ? nlohmann::json(stopped_by) : nlohmann::json(nullptr)}};
  if (kind == IntegratorKind::Light) info["progress"]["light_paths_done"] = result.light_paths;
  // Where the passes' time went (this session's passes, wall clock): the data for choosing each
  // part's share of a pass.
  if (kind == IntegratorKind::Photons || kind == IntegratorKind::Beams ||
      kind == IntegratorKind::Hybrid) {
    const auto& p = result.photons;
    info["timing"]["pass_seconds"] = {{"beams", p.seconds_beams},
                                      {"photons", p.seconds_photons},
                                      {"light_paths", p.seconds_light_paths},
                                      {"camera_paths", p.seconds_camera}};
  }
  if (kernel_film && !result.complete)
    info["progress"]["rows_done"] = std::min<int64_t>(cam.height, result.units_done * 16);

  info["energy"] = {{"in_window", rgb_json(result.film.total_steady())},
                    {"before_window", rgb_json(result.film.total_before())},
                    {"after_window", rgb_json(result.film.total_after())},
                    {"note", "sums over pixels; after_window only counts contributions of paths "
                             "still alive (paths stop once they pass the window end)"}};
  return info;
}

}  // namespace femto
