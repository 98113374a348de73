#pragma once
// Minimal Wavefront OBJ reader: triangle geometry only (positions and faces).
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "core/vec3.h"

namespace femto {

/// Reads the vertex positions and faces of an OBJ file; polygons are fan-triangulated in file
/// winding order. Accepts face corners as v, v/vt, v//vn and v/vt/vn, with 1-based or negative
/// (relative) indices. Ignores vt, vn, vp, l, p, o, g, s, usemtl, mtllib and comments.
/// Replaces the contents of `vertices` and `triangles`.
/// Throws InputError "<path>:<line>: <problem>" on bad numbers, out-of-range indices, unsupported
/// statements, or "<path>: ..." when the file cannot be read or has no faces.
void load_obj(const std::string& path, std::vector<Vec3>& vertices,
              std::vector<std::array<uint32_t, 3>>& triangles);

}  // namespace femto
