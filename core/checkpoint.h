#pragma once
// Checkpoints of a render: the state it continues from (core/render.h, RenderState) and a
// fingerprint of everything that decides its bits (femto version, scene text hash, settings,
// seed), so that a resume with anything different is refused.
//
// File layout (little-endian): "FEMTOCKP", uint32 format version, uint32 0, uint64 n + n bytes
// of JSON ({"fingerprint": ..., "state": ...}), uint64 n + n doubles (the per-pixel sums),
// uint64 n + n floats (kernel film bandwidths), then the SHA-256 of everything before it.
#include <string>

#include <nlohmann/json.hpp>

#include "core/render.h"

namespace femto {

struct Checkpoint {
  nlohmann::json fingerprint;
  RenderState state;
};

/// Writes atomically (temporary name, then rename). Throws RuntimeError naming the file.
void write_checkpoint(const std::string& path, const nlohmann::json& fingerprint, const RenderState& state);

/// Reads and verifies a checkpoint (magic, format, sizes, SHA-256). Throws InputError naming the
/// file when it is not a femto checkpoint, is truncated or corrupt.
Checkpoint read_checkpoint(const std::string& path);

/// True when the file starts like a femto checkpoint.
bool looks_like_checkpoint(const std::string& path);

/// Empty when `saved` and `now` are equal, else "KEY: checkpoint has A, this run has B" for the
/// first key that differs (keys as JSON paths, e.g. /settings/spp).
std::string fingerprint_difference(const nlohmann::json& saved, const nlohmann::json& now);

}  // namespace femto
