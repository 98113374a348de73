#pragma once
// A labelled tissue volume: a regular grid of integer labels and, per label, the optical
// properties of that tissue. Label 0 is outside (no tissue: photons that reach it have left).
#include <cstdint>
#include <vector>

#include "core/vec3.h"

namespace femto {

/// Optical properties of one tissue type, per mm (MCX/MMC conventions).
struct TissueOptics {
  double mu_a = 0;  ///< absorption coefficient, 1/mm
  double mu_s = 0;  ///< scattering coefficient, 1/mm
  double g = 0;     ///< Henyey-Greenstein anisotropy, -1 < g < 1
  double n = 1;     ///< refractive index, >= 1
};

/// Optical properties of one voxel of a voxel medium (an OpenVDB density/albedo/eta medium used
/// as a tissue; docs/tissue.md, "Voxel media"): g is the medium's, shared by every voxel.
struct VoxelOptics {
  float mu_a = 0, mu_s = 0;  ///< 1/mm
  float n = 1;
  bool operator==(const VoxelOptics& o) const {
    return mu_a == o.mu_a && mu_s == o.mu_s && n == o.n;
  }
  bool operator!=(const VoxelOptics& o) const { return !(*this == o); }
};

/// Labels on an nx x ny x nz grid of cubic voxels; voxel (i, j, k) covers
/// origin + voxel * [i, i + 1] x [j, j + 1] x [k, k + 1] (mm).
struct LabelVolume {
  int n[3] = {0, 0, 0};
  double voxel = 1;                  ///< voxel edge, mm
  Vec3 origin{0, 0, 0};              ///< world position of the grid's lower corner, mm
  std::vector<uint16_t> labels;      ///< index (i * ny + j) * nz + k: x slowest, z fastest
  std::vector<TissueOptics> optics;  ///< per label; optics[0] is outside (only n is used)
  /// A voxel medium: each voxel's own optics (same index as `labels`), with g = optics[1].g.
  /// Every voxel then has label 1, which names the whole medium in per-label tallies. Empty for
  /// labelled volumes.
  std::vector<VoxelOptics> voxel_optics;

  size_t cells() const { return static_cast<size_t>(n[0]) * n[1] * n[2]; }
  size_t index(int i, int j, int k) const { return (static_cast<size_t>(i) * n[1] + j) * n[2] + k; }
  /// The label of voxel (i, j, k), 0 outside the grid.
  int label_at(int i, int j, int k) const {
    if (i < 0 || j < 0 || k < 0 || i >= n[0] || j >= n[1] || k >= n[2]) return 0;
    return labels[index(i, j, k)];
  }
  Vec3 upper() const { return origin + Vec3(n[0], n[1], n[2]) * voxel; }
  uint64_t memory_bytes() const {
    return labels.size() * sizeof(uint16_t) + voxel_optics.size() * sizeof(VoxelOptics);
  }
};

}  // namespace femto
