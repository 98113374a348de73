#pragma once
// Atomic file replacement: write to a temporary next to the target, then rename() over it,
// so readers (and a crash mid-write) never see a half-written output file.
#include <functional>
#include <string>

namespace femto {

/// Calls write(tmp_path) with tmp_path = path + ".tmp.<pid>" (same directory, so the rename
/// stays on one filesystem), then renames it onto path. If write throws, or the rename fails,
/// the temporary is removed and the error propagates; the previous target is left untouched.
/// Rename failures throw RuntimeError naming path. Not durable across OS crashes (no fsync).
void write_atomically(const std::string& path,
                      const std::function<void(const std::string& tmp_path)>& write);

/// Atomically replaces path with text (written byte for byte). Throws RuntimeError naming path.
void write_text_atomically(const std::string& path, const std::string& text);

}  // namespace femto
