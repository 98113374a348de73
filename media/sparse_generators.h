#pragma once
// Large sparse procedural volumes for `femto make-volume` (sparse-cloud, plume), generated leaf
// by leaf straight into an OpenVDB tree, so a 2048-voxel-wide box never exists densely. Used by
// tests and benchmarks, which then need no downloads. Deterministic for a given (n, seed).
#include <cstdint>
#include <string>

namespace femto {

struct SparseVolumeInfo {
  int dims[3] = {0, 0, 0};     ///< voxels of the box the volume was generated in
  uint64_t active_voxels = 0;  ///< of the density grid
  uint64_t leaves = 0;
  uint64_t memory_bytes = 0;  ///< OpenVDB's in-memory size of the grid
  float max_density = 0;
};

/// A cumulus-like cloud of noisy spherical puffs in a box of n x 0.68n x 1.22n voxels (the
/// proportions of the usual production test cloud), density in (0, 1], about 5-10% of the box
/// active. Written uncompressed (fast to read), atomically.
SparseVolumeInfo write_sparse_cloud(const std::string& path, int n, uint64_t seed, double voxel_mm);

/// A thin smoke plume rising through an n^3 box: a tube whose radius grows from 0.01 n to
/// 0.04 n while it drifts across the box, so almost all of the box is empty.
SparseVolumeInfo write_plume(const std::string& path, int n, uint64_t seed, double voxel_mm);

}  // namespace femto
