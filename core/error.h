#pragma once
// Errors. InputError is the user's fault (bad scene, flag or file) and maps to exit code 2.
#include <stdexcept>
#include <string>

namespace femto {

/// Bad user input: the message names the file, the key (JSON path or flag) and the value.
struct InputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// A failure that is not the user's input (I/O errors, resource limits, internal errors).
struct RuntimeError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

}  // namespace femto
