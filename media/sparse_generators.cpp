#include "media/sparse_generators.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <mutex>
#include <vector>

#include "core/error.h"
#include "core/io/atomic_file.h"
#include "core/rng.h"
#include "media/openvdb_headers.h"
#include "media/vdb_init.h"
#include "media/vdb_new_grid.h"

namespace femto {
namespace {

using openvdb::Coord;
using openvdb::FloatGrid;
using Leaf = openvdb::FloatTree::LeafNodeType;

double hash01(uint64_t key, int64_t x, int64_t y, int64_t z) {
  const uint64_t h = mix64(mix64(mix64(key + uint64_t(x)) + uint64_t(y)) + uint64_t(z));
  return double(h >> 11) * 0x1.0p-53;
}

// Trilinear value noise in [0, 1] with smooth (quintic) fading; integer hashing only.
double value_noise(uint64_t key, double px, double py, double pz) {
  const double fx = std::floor(px), fy = std::floor(py), fz = std::floor(pz);
  const auto fade = [](double t) { return t * t * t * (t * (t * 6 - 15) + 10); };
  const double u = fade(px - fx), v = fade(py - fy), w = fade(pz - fz);
  const auto x = int64_t(fx), y = int64_t(fy), z = int64_t(fz);
  double sum = 0;
  for (int c = 0; c < 8; ++c) {
    const int a = c & 1, b = (c >> 1) & 1, d = (c >> 2) & 1;
    sum += (a ? u : 1 - u) * (b ? v : 1 - v) * (d ? w : 1 - w) * hash01(key, x + a, y + b, z + d);
  }
  return sum;
}

// Builds a grid over the box [0, dims) leaf by leaf, in parallel: `near(lo, hi)` says whether
// the leaf box [lo, hi] (voxel centres) may hold density, `density(x, y, z)` gives it at a voxel
// centre (<= 0: inactive).
template <class Near, class Density>
FloatGrid::Ptr generate(const int dims[3], Near near, Density density) {
  vdb_load::init_openvdb();
  const int nl[3] = {(dims[0] + 7) / 8, (dims[1] + 7) / 8, (dims[2] + 7) / 8};
  std::vector<std::vector<Leaf*>> slabs(static_cast<size_t>(nl[2]));
  tbb::parallel_for(tbb::blocked_range<int>(0, nl[2]), [&](const tbb::blocked_range<int>& r) {
    for (int lk = r.begin(); lk != r.end(); ++lk)
      for (int lj = 0; lj < nl[1]; ++lj)
        for (int li = 0; li < nl[0]; ++li) {
          const Coord o(li * 8, lj * 8, lk * 8);
          const double lo[3] = {o.x() + 0.5, o.y() + 0.5, o.z() + 0.5};
          const double hi[3] = {lo[0] + 7, lo[1] + 7, lo[2] + 7};
          if (!near(lo, hi)) continue;
          Leaf* leaf = nullptr;
          for (int i = 0; i < 8; ++i)
            for (int j = 0; j < 8; ++j)
              for (int k = 0; k < 8; ++k) {
                const Coord c = o.offsetBy(i, j, k);
                if (c.x() >= dims[0] || c.y() >= dims[1] || c.z() >= dims[2]) continue;
                const float d = static_cast<float>(density(c.x() + 0.5, c.y() + 0.5, c.z() + 0.5));
                if (!(d > 0)) continue;
                if (!leaf) leaf = new Leaf(o, 0.0f, false);
                leaf->setValueOn(c, d);
              }
          if (leaf) slabs[static_cast<size_t>(lk)].push_back(leaf);
        }
  });
  FloatGrid::Ptr grid = new_vdb_grid<FloatGrid>(0.0f);
  for (auto& slab : slabs)
    for (Leaf* leaf : slab) grid->tree().addLeaf(leaf);  // the tree owns it from here
  return grid;
}

SparseVolumeInfo write_grid(const std::string& path, FloatGrid::Ptr grid, const int dims[3],
                            double voxel_mm) {
  grid->setName("density");
  grid->setGridClass(openvdb::GRID_FOG_VOLUME);
  // Voxel (0,0,0)'s lower corner at -dims/2 voxel: the box is centred on the world origin.
  auto tf = openvdb::math::Transform::createLinearTransform(voxel_mm);
  tf->postTranslate(openvdb::Vec3d((0.5 - dims[0] / 2.0) * voxel_mm,
                                   (0.5 - dims[1] / 2.0) * voxel_mm,
                                   (0.5 - dims[2] / 2.0) * voxel_mm));
  grid->setTransform(tf);
  SparseVolumeInfo info;
  std::copy(dims, dims + 3, info.dims);
  info.active_voxels = grid->activeVoxelCount();
  info.leaves = grid->tree().leafCount();
  info.memory_bytes = grid->memUsage();
  for (auto it = grid->cbeginValueOn(); it; ++it)
    info.max_density = std::max(info.max_density, *it);
  write_atomically(path, [&](const std::string& tmp) {
    try {
      openvdb::io::File file(tmp);
      file.setCompression(openvdb::io::COMPRESS_ACTIVE_MASK);  // no zip: large files read fast
      file.write({grid});
      file.close();
    } catch (const openvdb::Exception& e) {
      throw RuntimeError("cannot write '" + path + "': " + e.what());
    }
  });
  return info;
}

}  // namespace

SparseVolumeInfo write_sparse_cloud(const std::string& path, int n, uint64_t seed,
                                    double voxel_mm) {
  const int dims[3] = {n, std::max(8, int(std::lround(0.68 * n))),
                       std::max(8, int(std::lround(1.22 * n)))};
  struct Puff {
    double c[3], r;
  };
  std::vector<Puff> puffs;
  const uint64_t key = mix64(seed * 0x9e3779b97f4a7c15ULL + 11);
  for (int p = 0; p < 48; ++p) {
    const auto u = [&](int f) { return hash01(key, p, f, 0); };
    Puff q;
    q.r = n * (0.05 + 0.06 * u(3));
    // Puffs fill the box out to its faces, denser in its lower half, like a cumulus.
    q.c[0] = dims[0] * (0.05 + 0.9 * u(0));
    q.c[1] = dims[1] * (0.1 + 0.8 * u(1));
    q.c[2] = dims[2] * (0.05 + 0.9 * std::pow(u(2), 1.5));
    for (int a = 0; a < 3; ++a) q.c[a] = std::clamp(q.c[a], q.r + 2, dims[a] - q.r - 2);
    puffs.push_back(q);
  }
  const uint64_t nkey = mix64(key + 1), nkey2 = mix64(key + 2);
  const double f1 = 1.0 / (0.04 * n), f2 = 1.0 / (0.012 * n);
  const auto near = [&](const double lo[3], const double hi[3]) {
    for (const Puff& q : puffs) {
      double d2 = 0;
      for (int a = 0; a < 3; ++a) {
        const double e = std::max({lo[a] - q.c[a], 0.0, q.c[a] - hi[a]});
        d2 += e * e;
      }
      if (d2 < q.r * q.r) return true;
    }
    return false;
  };
  const auto density = [&](double x, double y, double z) {
    double w = 0;
    for (const Puff& q : puffs) {
      const double dx = x - q.c[0], dy = y - q.c[1], dz = z - q.c[2];
      const double s = (dx * dx + dy * dy + dz * dz) / (q.r * q.r);
      if (s < 1) w += (1 - s) * (1 - s);
    }
    if (w <= 0) return 0.0;
    const double noise = 0.65 * value_noise(nkey, x * f1, y * f1, z * f1) +
                         0.35 * value_noise(nkey2, x * f2, y * f2, z * f2);
    return std::min(1.0, 2.2 * std::min(w, 1.0) * noise - 0.25);
  };
  return write_grid(path, generate(dims, near, density), dims, voxel_mm);
}

SparseVolumeInfo write_plume(const std::string& path, int n, uint64_t seed, double voxel_mm) {
  const int dims[3] = {n, n, n};
  const double phase = 6.283185307179586 * hash01(mix64(seed + 5), 0, 0, 0);
  // Centre line and radius at height z (voxels); the plume drifts along +x and sways in y.
  const auto centre = [&](double z, double& cx, double& cy) {
    const double t = z / n;
    cx = n * (0.15 + 0.6 * t + 0.04 * std::sin(7 * t + phase));
    cy = n * (0.5 + 0.15 * std::sin(3 * t + phase));
  };
  const auto radius = [&](double z) { return n * (0.01 + 0.03 * z / n); };
  const uint64_t nkey = mix64(seed * 0x9e3779b97f4a7c15ULL + 21);
  const double f = 1.0 / (0.01 * n);
  const auto near = [&](const double lo[3], const double hi[3]) {
    const double z = 0.5 * (lo[2] + hi[2]);
    double cx, cy;
    centre(z, cx, cy);
    // The centre line moves less than 1.2 voxels per voxel of height: margin for the leaf.
    const double reach = radius(hi[2]) + 1.2 * 4 + 1;
    const double ex = std::max({lo[0] - cx, 0.0, cx - hi[0]}),
                 ey = std::max({lo[1] - cy, 0.0, cy - hi[1]});
    return ex * ex + ey * ey < reach * reach;
  };
  const auto density = [&](double x, double y, double z) {
    double cx, cy;
    centre(z, cx, cy);
    const double r = radius(z), s = ((x - cx) * (x - cx) + (y - cy) * (y - cy)) / (r * r);
    if (s >= 1) return 0.0;
    return std::min(1.0, (1 - s) * (0.3 + value_noise(nkey, x * f, y * f, z * f)));
  };
  return write_grid(path, generate(dims, near, density), dims, voxel_mm);
}

}  // namespace femto
