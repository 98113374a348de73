#pragma once
// The render settings that `femto render` flags (and the Python module's keywords) override in
// a scene: one parser and one set of checks for both, so the two accept the same values with
// the same messages.
#include <cstdint>
#include <optional>
#include <string>

#include "apps/cli.h"
#include "core/render.h"
#include "core/scene_desc.h"

namespace femto {

/// Overrides of the scene's "render" block and sampling settings; unset ones keep the scene's.
struct RenderOverrides {
  std::optional<int> spp, max_depth;
  std::optional<RouletteDesc> roulette;
  std::optional<uint64_t> seed;
  int threads = 0;  ///< 0: all cores
  std::optional<DistanceSampling> sampling;
  std::optional<ConnectionSampling> connection;
  std::optional<DirectionSampling> direction;
  std::optional<TemporalFilter::Kind> reconstruction;
  std::optional<TemporalKernel> kernel;
  std::optional<double> alpha, bandwidth;
  std::optional<int> knn, first_pass_spp;
  bool no_onset_reflection = false;
  std::optional<IntegratorKind> integrator;
  std::optional<int64_t> light_paths, photons_per_pass;
  std::optional<double> camera_ball;
  std::optional<double> photon_radius, photon_bandwidth;
  std::optional<bool> photon_aim;
  std::string kernel_flag;  ///< the first kernel-only flag given, for the error message
  std::string photon_flag;  ///< the first photon-only flag given, for the error message

  /// The first flag given that applies to camera scenes only (not to tissue scenes), or null.
  const char* camera_only_flag() const;
};

/// If `flag` (as returned by args.next()) is a render override, reads its value from `args`
/// into `o` and returns true. Bad values throw InputError "<command>: <flag>: <problem> (got
/// '<value>')".
bool parse_render_flag(cli::Args& args, const std::string& flag, RenderOverrides& o);

/// What a render runs with once the overrides are applied.
struct RenderSetup {
  IntegratorKind kind = IntegratorKind::Path;  ///< resolved (never Auto)
  std::string integrator_why;                  ///< which rule chose `kind`
  RenderOptions options;                       ///< spp, seed, max depth, threads, integrator
};

/// Applies `o` to `desc` (media sampling, reconstruction, integrator) and checks the
/// combinations; `command` prefixes messages about flags, `where` (the scene file, or the
/// command) those about the scene.
RenderSetup apply_render_overrides(SceneDesc& desc, const RenderOverrides& o,
                                   const std::string& command, const std::string& where);

}  // namespace femto
