#pragma once
// `femto uniformity`'s settings read from its flags (also the Python module's keywords): one
// parser and one set of checks for both, with the same messages.
#include <string>
#include <vector>

#include "core/uniformity.h"

namespace femto {

struct UniformityRequest {
  bool help = false;  ///< --help was given (nothing else is set)
  uniformity::Config config;
  std::vector<uniformity::Strategy> strategies;
  std::string out_dir = "femto-uniformity";
  bool expect_uniform = false, quiet = false;
};

/// Reads `femto uniformity` flags and checks them together. Bad input throws InputError
/// "<command>: <flag>: <problem> (got '<value>')".
UniformityRequest parse_uniformity_args(const std::vector<std::string>& argv,
                                        const std::string& command);

}  // namespace femto
