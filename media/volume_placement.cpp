// Placement of a VDB medium: grid space to world through the file's and the scene's transforms.
#include <algorithm>
#include <cmath>
#include <limits>

#include "core/constants.h"
#include "media/volume_loader.h"

namespace femto::vdb_load {

namespace {

/// The scene's placement (docs/scene-format.md, transform): scale, rotate about x, y, z, translate.
Vec3 place(const TransformDesc& tf, const Vec3& p) {
  Vec3 q{p.x * tf.scale.x, p.y * tf.scale.y, p.z * tf.scale.z};
  for (int axis = 0; axis < 3; ++axis) {
    const double a = tf.rotate_deg[axis] * kPi / 180.0;
    if (a == 0.0) continue;
    const double c = std::cos(a), s = std::sin(a);
    const int i = (axis + 1) % 3, j = (axis + 2) % 3;  // same convention as shape transforms
    const double qi = q[i], qj = q[j];
    q[i] = c * qi - s * qj;
    q[j] = s * qi + c * qj;
  }
  return q + tf.translate;
}

}  // namespace

// grid space g -> VDB index g + min - 0.5 (cell centres are VDB voxel centres) -> VDB world
// -> the scene's transform.
void VolumeLoader::set_transform(VolumeData& out, const openvdb::math::Transform& tf,
                                 const Coord& min) const {
  const auto world = [&](double x, double y, double z) {
    const Vec3d w = tf.indexToWorld(Vec3d(x + min.x() - 0.5, y + min.y() - 0.5, z + min.z() - 0.5));
    return place(desc_.transform, Vec3(w.x(), w.y(), w.z()));
  };
  double* m = out.grid_to_world;
  const Vec3 t = world(0, 0, 0);
  const Vec3 cols[3] = {world(1, 0, 0) - t, world(0, 1, 0) - t, world(0, 0, 1) - t};
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) m[4 * r + c] = cols[c][r];
    m[4 * r + 3] = t[r];
  }
  for (int c = 0; c < 3; ++c) out.voxel_size[c] = length(cols[c]);

  // Inverse of the 3x3 part by cofactors; the translation follows.
  const auto a = [&](int r, int c) { return m[4 * r + c]; };
  const double det = a(0, 0) * (a(1, 1) * a(2, 2) - a(1, 2) * a(2, 1)) -
                     a(0, 1) * (a(1, 0) * a(2, 2) - a(1, 2) * a(2, 0)) +
                     a(0, 2) * (a(1, 0) * a(2, 1) - a(1, 1) * a(2, 0));
  if (!(std::abs(det) > 0) || !std::isfinite(det))
    fail_file("the grid-to-world transform is singular");
  double* inv = out.world_to_grid;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) {
      const int r1 = (c + 1) % 3, r2 = (c + 2) % 3, c1 = (r + 1) % 3, c2 = (r + 2) % 3;
      inv[4 * r + c] = (a(r1, c1) * a(r2, c2) - a(r1, c2) * a(r2, c1)) / det;
    }
  for (int r = 0; r < 3; ++r)
    inv[4 * r + 3] = -(inv[4 * r] * t.x + inv[4 * r + 1] * t.y + inv[4 * r + 2] * t.z);

  const DenseGrid& g = out.density;
  Vec3 lo(std::numeric_limits<double>::infinity()), hi(-std::numeric_limits<double>::infinity());
  for (int corner = 0; corner < 8; ++corner) {
    const Vec3 p =
        out.to_world({(corner & 1) ? double(g.nx) : 0.0, (corner & 2) ? double(g.ny) : 0.0,
                      (corner & 4) ? double(g.nz) : 0.0});
    lo = vmin(lo, p);
    hi = vmax(hi, p);
  }
  out.world_bounds_min = lo;
  out.world_bounds_max = hi;
  const double far = std::max(max_abs_component(lo), max_abs_component(hi));
  if (!(far <= kMaxWorld))  // also NaN: the renderer works in float far inside this
    fail_file("the grid's world box " + fmt(Vec3d(lo.x, lo.y, lo.z)) + " to " +
              fmt(Vec3d(hi.x, hi.y, hi.z)) +
              " mm reaches beyond +-1e9 mm (voxel size, file transform or the scene's transform)");
}

}  // namespace femto::vdb_load
