#pragma once
// How far a photon may fly in a labelled voxel grid without meeting another label: per voxel,
// the chessboard (L-infinity) distance in voxels to the nearest voxel of another label or beyond
// the grid. Inside that box every voxel has the photon's label, so the walk needs no march there
// (docs/tissue.md, "Design").
#include <cstdint>
#include <vector>

#include "core/transport/tissue_volume.h"

namespace femto {

/// Per voxel (LabelVolume::index order): 1 + the chessboard distance from the voxel to the
/// nearest voxel of another label or outside the grid, capped at 255: the voxels within
/// distance - 1 of it all have its label. Label 0 voxels get 0.
std::vector<uint8_t> safe_distances(const LabelVolume& vol);

/// True if the segment from x0 to x1 stays inside the box of voxels within safe - 1 of voxel
/// `cell` (both ends at least `margin` inside it; a box is convex, so the whole segment is).
inline bool inside_safe_box(const LabelVolume& vol, const int cell[3], int safe, const Vec3& x1,
                            double margin) {
  if (safe <= 0) return false;
  const double h = vol.voxel;
  // Plain arrays: Vec3's operator[] is a chain of selects where a loop is not unrolled.
  const double o[3] = {vol.origin.x, vol.origin.y, vol.origin.z}, e[3] = {x1.x, x1.y, x1.z};
  const double below = (safe - 1) * h - margin, above = safe * h - margin;
  bool inside = true;
  for (int a = 0; a < 3; ++a) {
    const double corner = o[a] + cell[a] * h;                  // the voxel's lower corner
    inside &= e[a] > corner - below && e[a] < corner + above;  // NaN and inf fail too
  }
  return inside;
}

}  // namespace femto
