#pragma once
// `femto diffusion`'s settings read from its flags (also the Python module's keywords): one
// parser and one set of checks for both, with the same messages.
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/diffusion/simulate.h"
#include "core/diffusion/transport.h"
#include "media/grid_medium.h"

namespace femto {

/// A checked diffusion run: what `simulate` and the report need.
struct DiffusionRequest {
  bool help = false;  ///< --help was given (nothing else is set)
  diffusion::DiffusionSetup setup;
  double threshold = 0.05;         ///< distance to the Gaussian that defines t*
  std::vector<double> plot_times;  ///< ps; defaults to 1, 3, 10, 30 mean free times in the window
  std::string out_dir = "femto-diffusion";
  bool quiet = false;
  nlohmann::json source;  ///< where the source sits (report's "source")
  /// A voxel medium around the source (--scene with a VDB medium), else null: simulate(setup).
  std::unique_ptr<GridMedium> grid;
  std::unique_ptr<diffusion::PhotonTransport> transport;
};

/// Reads `femto diffusion` flags (--sigma_s and --sigma-s alike), loads the scene medium when
/// --scene is given and checks the flags together. Bad input throws InputError "<command>:
/// <flag>: <problem> (got '<value>')".
DiffusionRequest parse_diffusion_args(const std::vector<std::string>& argv,
                                      const std::string& command);

}  // namespace femto
