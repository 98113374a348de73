// Validation of a VDB medium: values per role, backgrounds, shared transforms and dense limits.
#include <algorithm>
#include <cmath>

#include "core/error.h"
#include "media/volume_loader.h"

namespace femto::vdb_load {

namespace {

const char* role_name(Role r) {
  return r == Role::Density ? "density" : r == Role::Albedo ? "albedo" : "eta";
}

}  // namespace

// Empty when `x` is a valid value for the role, else the problem ("eta must be >= 1").
std::string value_problem(Role r, float x) {
  if (!std::isfinite(x)) return std::string(role_name(r)) + " must be finite";
  if (r == Role::Density && x < 0) return "density must be >= 0";
  if (r == Role::Albedo && !(x >= 0 && x <= 1)) return "albedo must be in [0, 1]";
  if (r == Role::Eta && x < 1) return "eta must be >= 1";
  return "";
}

// Dense size of the box [lo, hi] in 64-bit arithmetic (hi - lo + 1 overflows int when the
// voxels are far apart), against the cell limit and the memory budget.
void VolumeLoader::check_box(const Coord& lo, const Coord& hi, std::size_t grids,
                             const std::string& what) const {
  int64_t dim[3];
  double cells = 1;
  for (int a = 0; a < 3; ++a) {
    dim[a] = int64_t(hi[a]) - int64_t(lo[a]) + 1;
    cells *= double(dim[a]);
  }
  const std::string size = std::to_string(dim[0]) + " x " + std::to_string(dim[1]) + " x " +
                           std::to_string(dim[2]) + " voxels";
  const std::string box = what + "dense box " + fmt(lo) + " to " + fmt(hi);
  if (cells > kMaxCells)
    fail_file("the " + box + " is " + size + " (" + fmt(cells) +
              " cells), above the limit of 2^30 cells (docs/volumes.md, Limits)");
  const uint64_t bytes = uint64_t(cells) * sizeof(float) * grids;
  const uint64_t limit = std::min(kMaxDenseBytes, desc_.max_dense_bytes);
  if (bytes > limit)
    fail_file("the " + box + " (" + size + ") needs " + fmt(double(bytes) / double(1ull << 20)) +
              " MiB for " + std::to_string(grids) + " grid(s), above the limit of " +
              fmt(double(limit) / double(1ull << 20)) + " MiB" +
              (limit < kMaxDenseBytes ? " left by --max-memory" : "") +
              " (docs/volumes.md, Limits)");
}

// sigma_t is stored as float; a finite density times the scale can still overflow it.
void VolumeLoader::check_sigma_t(const Used& d, const DenseGrid& g) const {
  if (desc_.sigma_t_scale * g.max_value > kMaxSigmaT)
    fail(d, "grid '" + clip(d.name) + "' density " + fmt(g.max_value) + " times sigma_t_scale " +
                fmt(desc_.sigma_t_scale) + " exceeds the bound of 1e9 /mm for sigma_t");
}

// The grid's box as stored in its metadata (written by OpenVDB), checked before the tree is
// read so that a huge box is refused before OpenVDB allocates it.
void VolumeLoader::check_metadata_box(const openvdb::GridBase& meta, std::size_t grids) const {
  const auto lo = meta.getMetadata<openvdb::Vec3IMetadata>("file_bbox_min");
  const auto hi = meta.getMetadata<openvdb::Vec3IMetadata>("file_bbox_max");
  if (!lo || !hi) return;
  const Coord a(lo->value()), b(hi->value());
  if (a.x() > b.x() || a.y() > b.y() || a.z() > b.z()) return;  // empty grid
  check_box(a, b, grids, "grid '" + clip(meta.getName()) + "' ");
}

void VolumeLoader::check_same_transform(const Used& u, const Used& d) const {
  const auto& a = u.grid->transform();
  const auto& b = d.grid->transform();
  const auto close = [](const Vec3d& x, const Vec3d& y) {
    return (x - y).length() <= 1e-9 * std::max({1.0, x.length(), y.length()});
  };
  const std::string rule =
      "; all grids must share the transform of density grid '" + clip(d.name) + "'";
  if (!close(a.voxelSize(), b.voxelSize()))
    fail(u, "grid '" + clip(u.name) + "' has voxel size " + fmt(a.voxelSize()) + " mm but '" +
                clip(d.name) + "' has " + fmt(b.voxelSize()) + rule);
  for (const Vec3d p : {Vec3d(0, 0, 0), Vec3d(1, 0, 0), Vec3d(0, 1, 0), Vec3d(0, 0, 1)})
    if (!close(a.indexToWorld(p), b.indexToWorld(p)))
      fail(u, "grid '" + clip(u.name) + "' is offset or rotated: its voxel " +
                  fmt(Coord::round(p)) + " is at " + fmt(a.indexToWorld(p)) + " mm but in '" +
                  clip(d.name) + "' at " + fmt(b.indexToWorld(p)) + rule);
}

// Sets the fill value of inactive cells from the background (see docs/volumes.md).
void VolumeLoader::check_background(Used& u) const {
  const float bg = u.grid->background();
  const std::string grid = "grid '" + clip(u.name) + "' background";
  if (u.role == Role::Density) {
    if (bg != 0.0f)
      fail(u, grid + " must be 0, since inactive voxels are empty space (got " + fmt(bg) + ")");
  } else if (u.role == Role::Eta && bg == 0.0f) {
    u.fill = static_cast<float>(desc_.eta);  // background 0 = "not set": the medium's eta
    return;
  } else if (const std::string p = value_problem(u.role, bg); !p.empty()) {
    fail(u, grid + ": " + p + (u.role == Role::Eta ? " or 0 for the medium's eta" : "") + " (got " +
                fmt(bg) + ")");
  }
  u.fill = bg;
}

}  // namespace femto::vdb_load
