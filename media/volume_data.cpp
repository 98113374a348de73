// The plain volume data: value ranges, memory, grid <-> world maps, and medium paths.
#include "media/volume_data.h"

#include <algorithm>

namespace femto {

void DenseGrid::update_range() {
  if (v.empty()) {
    min_value = max_value = 0.0f;
    return;
  }
  const auto [lo, hi] = std::minmax_element(v.begin(), v.end());
  min_value = *lo;
  max_value = *hi;
}

uint64_t VolumeData::memory_bytes() const {
  if (sparse) return sparse->tree_bytes + sparse->index_bytes();
  return (density.v.size() + albedo.v.size() + eta.v.size()) * sizeof(float);
}

static Vec3 affine(const double* m, const Vec3& p) {
  return {m[0] * p.x + m[1] * p.y + m[2] * p.z + m[3], m[4] * p.x + m[5] * p.y + m[6] * p.z + m[7],
          m[8] * p.x + m[9] * p.y + m[10] * p.z + m[11]};
}
Vec3 VolumeData::to_world(const Vec3& g) const {
  return affine(grid_to_world, g);
}
Vec3 VolumeData::to_grid(const Vec3& w) const {
  return affine(world_to_grid, w);
}

std::string medium_where(const std::string& name) {
  std::string out = "/media/";
  for (const char ch : name) out += ch == '~' ? "~0" : ch == '/' ? "~1" : std::string(1, ch);
  return out;
}

}  // namespace femto
