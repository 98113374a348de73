#include "core/transport/safe_distance.h"

#include <algorithm>
#include <cstddef>

namespace femto {

std::vector<uint8_t> safe_distances(const LabelVolume& vol) {
  const int nx = vol.n[0], ny = vol.n[1], nz = vol.n[2];
  std::vector<uint8_t> d(vol.cells(), 0);
  // 1 where a 26-neighbour has another label or lies beyond the grid; 255 (unknown) elsewhere.
  for (int i = 0; i < nx; ++i)
    for (int j = 0; j < ny; ++j)
      for (int k = 0; k < nz; ++k) {
        const int label = vol.labels[vol.index(i, j, k)];
        if (label == 0) continue;
        bool border = false;
        for (int di = -1; di <= 1 && !border; ++di)
          for (int dj = -1; dj <= 1 && !border; ++dj)
            for (int dk = -1; dk <= 1 && !border; ++dk)
              border = vol.label_at(i + di, j + dj, k + dk) != label;  // 0 beyond the grid
        d[vol.index(i, j, k)] = border ? 1 : 255;
      }
  // Chessboard distance transform in two raster passes over the 26-neighbourhood (exact for this
  // metric): a voxel whose neighbours all share its label is one further than the nearest of
  // them. Border voxels (1) and label 0 (0) never change.
  auto relax = [&](int i, int j, int k, int sign) {
    uint8_t& v = d[vol.index(i, j, k)];
    if (v <= 1) return;
    for (int di = -1; di <= 1; ++di)
      for (int dj = -1; dj <= 1; ++dj)
        for (int dk = -1; dk <= 1; ++dk) {
          const int order = di != 0 ? di : (dj != 0 ? dj : dk);  // neighbour before (-1) or after
          if (order != sign) continue;
          const uint8_t n = d[vol.index(i + di, j + dj, k + dk)];  // inside: v is not a border
          v = static_cast<uint8_t>(std::min<int>(v, n + 1));
        }
  };
  for (int i = 0; i < nx; ++i)
    for (int j = 0; j < ny; ++j)
      for (int k = 0; k < nz; ++k) relax(i, j, k, -1);
  for (int i = nx - 1; i >= 0; --i)
    for (int j = ny - 1; j >= 0; --j)
      for (int k = nz - 1; k >= 0; --k) relax(i, j, k, +1);
  return d;
}

}  // namespace femto
