#pragma once
// Heterogeneous volumes read from OpenVDB files into dense in-memory grids (docs/volumes.md).
// OpenVDB stays inside the loader and writer (media/volume_loader.h); this header is plain data.
#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "core/scene_desc.h"
#include "core/vec3.h"
#include "media/sparse_field.h"

namespace femto {

/// Dense float grid, x fastest: value(i,j,k) = v[(size_t(k) * ny + j) * nx + i].
struct DenseGrid {
  int nx = 0, ny = 0, nz = 0;
  std::vector<float> v;
  float min_value = 0, max_value = 0;  ///< over all cells (set by load_volume and the generators)

  DenseGrid() = default;
  DenseGrid(int nx_, int ny_, int nz_, float fill = 0.0f)
      : nx(nx_), ny(ny_), nz(nz_), v(std::size_t(nx_) * std::size_t(ny_) * std::size_t(nz_), fill) {}
  bool empty() const { return v.empty(); }
  std::size_t index(int i, int j, int k) const {
    return (std::size_t(k) * std::size_t(ny) + std::size_t(j)) * std::size_t(nx) + std::size_t(i);
  }
  float at(int i, int j, int k) const { return v[index(i, j, k)]; }
  float& at(int i, int j, int k) { return v[index(i, j, k)]; }
  /// Recomputes min_value and max_value.
  void update_range();
};

/// A volume on a regular grid. Grid space: cell (i,j,k) covers [i,i+1]x[j,j+1]x[k,k+1]; its value is
/// the voxel's value (nearest) and sits at the cell centre (i+0.5, j+0.5, k+0.5) for trilinear.
struct VolumeData {
  DenseGrid density;         ///< raw density (sigma_t = sigma_t_scale * density)
  DenseGrid albedo;          ///< empty => constant VdbMediumDesc::albedo
  DenseGrid eta;             ///< empty => constant VdbMediumDesc::eta
  double grid_to_world[12] = {};  ///< row-major 3x4 affine: world = M * g + t (VDB transform, then the
                             ///< scene's TransformDesc)
  double world_to_grid[12] = {};  ///< its inverse
  Vec3 world_bounds_min, world_bounds_max;  ///< of the grid box [0,nx]x[0,ny]x[0,nz]
  double voxel_size[3] = {};  ///< world length of one cell edge along each grid axis, mm
  int index_min[3] = {};      ///< VDB index coordinate of dense cell (0,0,0) (for messages)
  uint64_t active_voxels = 0;  ///< active voxels of the density grid in the file
  /// Sparse storage (docs/volumes.md): then density, albedo and eta hold only their shape
  /// (nx, ny, nz) and value ranges, with no values.
  std::shared_ptr<const SparseField> sparse;

  uint64_t memory_bytes() const;
  Vec3 to_world(const Vec3& g) const;  ///< grid space -> world (mm)
  Vec3 to_grid(const Vec3& w) const;   ///< world (mm) -> grid space
};

/// Loads and validates `desc.file` (a path already resolved against the scene). `source` (scene
/// file) and `where` (JSON path of the medium, by convention "/media/<name>") start every
/// InputError, e.g. "scene.json: /media/tissue/eta_grid: tissue.vdb: grid 'eta' voxel (12, 4, 7):
/// eta must be >= 1 (got 0.93)". Voxel indices in messages are the file's VDB index coordinates.
VolumeData load_volume(const VdbMediumDesc& desc, const std::string& source,
                       const std::string& where);

/// The `where` of medium `name` for load_volume: "/media/<name>", escaped as a JSON pointer.
std::string medium_where(const std::string& name);

/// Writes float grids (density, and optional albedo and eta with the same shape) as a .vdb file
/// with voxel size `voxel_mm` and the grid's cell (0,0,0) with its lower corner at `origin_mm`.
/// Every grid has background 0 and keeps cells equal to 0 inactive (for eta that means "use the
/// medium's constant eta"). Atomic (temp + rename). For the generator and tests.
void write_volume(const std::string& path, const DenseGrid& density, const DenseGrid* albedo,
                  const DenseGrid* eta, double voxel_mm, const Vec3& origin_mm,
                  const std::string& density_name = "density",
                  const std::string& albedo_name = "albedo", const std::string& eta_name = "eta");

/// One grid for write_vdb with full control, including deliberately invalid files for tests.
struct VdbGridSpec {
  enum class Type { Float, Double, Vec3 };  ///< Double, Vec3 (x, x, x): wrong types, for tests
  enum class Class { Unknown, FogVolume, LevelSet };
  std::string name;
  const DenseGrid* values = nullptr;  ///< cells equal to `background` stay inactive
  float background = 0.0f;
  Type type = Type::Float;
  Class grid_class = Class::FogVolume;
  Vec3 voxel_mm{1, 1, 1};             ///< per-axis voxel size
  Vec3 origin_mm{0, 0, 0};            ///< world position of the lower corner of cell (0,0,0)
  Vec3 index_offset{0, 0, 0};         ///< VDB index of cell (0,0,0) (integers); moves nothing in world
  bool frustum = false;               ///< a non-linear (frustum) transform, for tests
  /// Single active voxels (VDB index, value) written in addition to `values`, which may then be
  /// null: sparse grids spanning far-apart coordinates, for tests.
  std::vector<std::pair<std::array<int, 3>, float>> voxels;
};

/// Writes grids to a .vdb file atomically (temp + rename). Throws RuntimeError on I/O failure.
void write_vdb(const std::string& path, const std::vector<VdbGridSpec>& grids);

}  // namespace femto
