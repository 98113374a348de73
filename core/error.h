#pragma once
// Errors. InputError is the user's fault (bad scene, flag or file) and maps to exit code 2.
#include <cstddef>
#include <stdexcept>
#include <string>

namespace femto {

/// Bad user input: the message names the file, the key (JSON path or flag) and the value.
struct InputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// `s` shortened to at most `max` bytes (ending in "...") for messages: user values such as keys,
/// names and paths can be arbitrarily long, and a message must stay one readable line.
inline std::string clip(const std::string& s, std::size_t max = 60) {
  if (s.size() <= max) return s;
  std::size_t n = max > 3 ? max - 3 : 0;
  while (n > 0 && (static_cast<unsigned char>(s[n]) & 0xC0) == 0x80) --n;  // keep UTF-8 whole
  return s.substr(0, n) + "...";
}

/// A failure that is not the user's input (I/O errors, resource limits, internal errors).
struct RuntimeError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

}  // namespace femto
