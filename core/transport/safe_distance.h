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
  for (int a = 0; a < 3; ++a) {
    const double lo = vol.origin[a] + (cell[a] - (safe - 1)) * h + margin;
    const double hi = vol.origin[a] + (cell[a] + safe) * h - margin;
    if (!(x1[a] > lo && x1[a] < hi)) return false;  // NaN and inf fail too
  }
  return true;
}

}  // namespace femto
