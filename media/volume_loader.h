#pragma once
// Internal to load_volume (media/volume_data.h): the loader of one VDB medium, whose steps are
// defined by concept in volume_loader.cpp, volume_checks.cpp, volume_storage.cpp and
// volume_placement.cpp. This header includes OpenVDB; users of volumes include volume_data.h.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "media/openvdb_headers.h"
#include "media/vdb_init.h"
#include "media/volume_data.h"

namespace femto::vdb_load {

using openvdb::Coord;
using openvdb::CoordBBox;
using openvdb::FloatGrid;
using openvdb::Vec3d;

// Limits of docs/volumes.md ("Limits").
constexpr uint64_t kMaxFileBytes = 16ull << 30;
constexpr double kMaxCells = 1073741824.0;  // 2^30 = 1024^3 dense cells
constexpr uint64_t kMaxDenseBytes = 16ull << 30;
constexpr double kMaxWorld = 1e9;   // mm, as for scene coordinates
constexpr double kMaxSigmaT = 1e9;  // 1/mm: sigma_t is stored as float

// Numbers, vectors and voxel coordinates in messages (volume_loader.cpp).
std::string fmt(double v);
std::string fmt(const Vec3d& v);
std::string fmt(const Coord& c);

// Which role a grid plays, with its valid range.
enum class Role { Density, Albedo, Eta };

std::string value_problem(Role r, float x);

/// A grid the medium uses.
struct Used {
  Role role;
  std::string key;   // JSON key naming the grid, for the error path
  std::string name;  // grid name in the file
  FloatGrid::Ptr grid;
  float fill = 0;  // value of inactive cells in the dense grid
  DenseGrid* dense = nullptr;
};

class VolumeLoader {
 public:
  VolumeLoader(const VdbMediumDesc& desc, const std::string& source, const std::string& where)
      : desc_(desc), prefix_(source + ": " + where + "/") {}

  // volume_loader.cpp: the steps in order.
  VolumeData load();

 private:
  using Storage = VdbMediumDesc::Storage;
  const VdbMediumDesc& desc_;
  std::string prefix_;
  Storage storage_ = desc_.storage;  // Auto until decided, from the metadata or the trees

  bool trilinear() const { return desc_.interpolation == VdbMediumDesc::Interpolation::Trilinear; }

  // volume_loader.cpp: reading the file, and failures.
  [[noreturn]] void fail_at(const std::string& key, const std::string& problem) const;
  [[noreturn]] void fail_file(const std::string& problem) const;
  [[noreturn]] void fail(const Used& u, const std::string& problem) const;
  void read_grids(std::vector<Used>& used);
  openvdb::GridBase::Ptr find_meta(const openvdb::GridPtrVec& metas, const Used& u) const;
  FloatGrid::Ptr read_grid(openvdb::io::File& file, const openvdb::GridBase& meta, const Used& u,
                           std::size_t grids) const;

  // volume_checks.cpp: validation of boxes, values, backgrounds and transforms.
  void check_box(const Coord& lo, const Coord& hi, std::size_t grids,
                 const std::string& what) const;
  void check_sigma_t(const Used& d, const DenseGrid& g) const;
  void check_metadata_box(const openvdb::GridBase& meta, std::size_t grids) const;
  void check_same_transform(const Used& u, const Used& d) const;
  void check_background(Used& u) const;

  // volume_storage.cpp: dense or sparse storage, and building it.
  static uint64_t tree_bytes(const std::vector<Used>& used);
  static double sparse_index_estimate(const double dim[3], double trees, bool trilinear);
  Storage choose_from(const double dim[3], std::size_t grids, double trees) const;
  Storage choose(const CoordBBox& box, const std::vector<Used>& used, uint64_t trees) const;
  void plan_from_metadata(const std::vector<openvdb::GridBase::Ptr>& metas,
                          const std::vector<Used>& used);
  static std::string fmt_mib(double bytes);
  void check_sparse_memory(double need, const std::string& about, const std::string& parts) const;
  void check_sparse_box(const Coord& lo, const Coord& hi, const std::string& what) const;
  void make_sparse(VolumeData& out, std::vector<Used>& used, const CoordBBox& box) const;
  void densify(Used& u, const CoordBBox& box) const;

  // volume_placement.cpp: grid space to world.
  void set_transform(VolumeData& out, const openvdb::math::Transform& tf, const Coord& min) const;
};

}  // namespace femto::vdb_load
