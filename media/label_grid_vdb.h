#pragma once
// Integer label volumes in OpenVDB files (an Int32Grid), for tissue optics. OpenVDB stays inside
// the .cpp file.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "core/vec3.h"

namespace femto {

struct LabelGridData {
  std::array<int, 3> n{0, 0, 0};  ///< dense cells over the active bounding box
  double voxel = 1;               ///< voxel edge, mm (the transform must scale uniformly)
  Vec3 origin{0, 0, 0};           ///< world position of the box's lower corner, mm
  std::vector<int32_t> labels;    ///< (i * ny + j) * nz + k; inactive voxels hold the background
};

/// Reads Int32Grid `grid` of `path` densely over its active voxels. Throws InputError starting
/// with `where` (e.g. "scene.json: /tissue/volume/vdb") for a missing file or grid, a grid that
/// is not Int32, a non-uniform or non-linear transform, or more than 2^30 cells.
LabelGridData read_vdb_labels(const std::string& path, const std::string& grid,
                              const std::string& where);

/// Writes labels as an Int32Grid named `grid` (background 0; zeros stay inactive), cell (0,0,0)
/// with its lower corner at `origin` (for tests and examples). Atomic.
void write_vdb_labels(const std::string& path, const std::string& grid, const LabelGridData& data);

}  // namespace femto
