#pragma once
// Procedural example volumes for `femto make-volume` (docs/volumes.md). Deterministic: the same
// (resolution, seed) gives bit-identical grids on every machine.
#include <cstdint>
#include <string>

#include "media/volume_data.h"

namespace femto {

struct GeneratedVolume {
  std::string kind;      ///< "cloud" or "tissue"
  DenseGrid density;     ///< in [0, 1] for the cloud; ~1 (x3 in the inclusion) for tissue
  DenseGrid albedo;      ///< empty: none
  DenseGrid eta;         ///< empty: none
  float eta_background = 0.0f;  ///< background of the eta grid; cells equal to it stay inactive
};

/// A fog/smoke cloud on an n^3 grid: smooth fractal value noise under a soft spherical falloff,
/// density in [0, 1] and exactly 0 near the faces of the grid; no albedo or eta grid.
GeneratedVolume make_cloud(int n, uint64_t seed);

/// A block of tissue filling an n^3 grid: density 1 +- 0.1 (mild noise), albedo 0.9 +- 0.03,
/// eta 1.37 (the eta grid's background); a sphere of radius 0.35 half-widths centred 0.25
/// half-widths above the centre (+y) has 3x the density and eta 1.45.
GeneratedVolume make_tissue(int n, uint64_t seed);

/// Writes the volume as a .vdb file with cubic voxels of `voxel_mm`, centred on the world origin.
void write_generated(const std::string& path, const GeneratedVolume& vol, double voxel_mm);

}  // namespace femto
