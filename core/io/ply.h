#pragma once
// Minimal Stanford PLY reader: triangle geometry only (vertex positions and faces).
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "core/vec3.h"

namespace femto {

/// Reads the vertex positions (x, y, z) and faces (vertex_indices or vertex_index lists) of an
/// ASCII or binary little-endian PLY file; polygons are fan-triangulated in file winding order.
/// Other properties and elements are skipped. Replaces `vertices` and `triangles`.
/// Throws InputError "<path>: <problem>" on big-endian files, bad headers, short or malformed
/// data, out-of-range indices, or a file without faces.
void load_ply(const std::string& path, std::vector<Vec3>& vertices,
              std::vector<std::array<uint32_t, 3>>& triangles);

}  // namespace femto
