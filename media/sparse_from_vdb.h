#pragma once
// Builds a SparseField over OpenVDB float grids without copying their values: the leaf buffers
// become the bricks (inactive voxels in them are set to the grid's fill value first). Internal to
// the volume loader (this header includes OpenVDB).
#include <functional>
#include <memory>
#include <vector>

#include "media/openvdb_headers.h"
#include "media/sparse_field.h"

namespace femto {

struct SparseGridInput {
  enum class Role { Density, Albedo, Eta };
  Role role = Role::Density;
  openvdb::FloatGrid::Ptr grid;          ///< modified: inactive voxels in leaves take `fill`
  float fill = 0;                        ///< value of inactive voxels
  float min_active = 0, max_active = 0;  ///< out: range of the active values (0, 0 if none)
};

/// Called for every active value (voxel or tile, with its first voxel); throws on a bad value.
using SparseValueCheck = std::function<void(const SparseGridInput&, const openvdb::Coord&, float)>;

/// The sparse field over `box` (the union of the active boxes). `inputs` holds density, then the
/// optional albedo and eta grids; a missing albedo or eta takes the constant `albedo` / `eta`.
std::shared_ptr<SparseField> build_sparse_field(std::vector<SparseGridInput>& inputs,
                                                const openvdb::CoordBBox& box, bool trilinear,
                                                double sigma_t_scale, float albedo, float eta,
                                                const SparseValueCheck& check);

}  // namespace femto
