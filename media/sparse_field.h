#pragma once
// A voxel medium kept sparse: the OpenVDB trees stay in memory and their 8^3 leaf buffers are the
// bricks, found through a two-level table (nodes of 128^3 voxels, then leaves of 8^3); regions
// without a leaf (empty space, tiles) are constants. Per node and per leaf block of field cells
// the walker has bounds (largest and smallest sigma_t, constant eta) to cross them in one step.
// Plain data: OpenVDB stays inside the volume loader (media/volume_loader.h), which builds it.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

namespace femto {

/// sigma_t range and constant refractive index over a set of field cells.
struct SparseBound {
  float sigma_max = 0, sigma_min = 0;
  float eta = -1;  ///< < 0: the index varies
  /// sigma_t and eta are the same everywhere: the set is crossed in one step.
  bool constant() const { return sigma_min == sigma_max && eta >= 0; }
};

struct SparseField {
  static constexpr int kLeafLog2 = 3, kLeaf = 8;    ///< voxels per leaf edge (an OpenVDB leaf)
  static constexpr int kNodeLog2 = 7, kNode = 128;  ///< voxels per node edge
  static constexpr int kLeavesPerNode = 4096;       ///< 16^3 leaves per node
  static constexpr uint32_t kConst = 0x80000000u;   ///< flag: the index names a Constant

  /// One leaf position: the VDB leaf buffer of each grid (VDB order, x slowest), or null where
  /// that grid is constant over the leaf (then the value beside it).
  struct Brick {
    const float* density = nullptr;
    const float* albedo = nullptr;
    const float* eta = nullptr;
    float density_c = 0, albedo_c = 0, eta_c = 0;
  };
  /// Values of a leaf or node without any leaf buffer.
  struct Constant {
    float density = 0, albedo = 0, eta = 0;
  };

  // Field voxel (i, j, k) is the grid-space cell (i - lo[0], j - lo[1], k - lo[2]) of VolumeData,
  // i.e. VDB index origin + (i, j, k) with `origin` a multiple of 128 (nodes match OpenVDB's).
  int origin[3] = {0, 0, 0};
  int lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};  ///< the voxel box [lo, hi)
  int nn[3] = {0, 0, 0};                     ///< nodes per axis (covering the field cells)
  double sigma_t_scale = 1;
  bool trilinear = false;
  float eta_outside = 1;  ///< outside the voxel box

  std::vector<uint32_t> node_ref;  ///< per node: leaf-table number, or kConst | constant
  std::vector<uint32_t> leaf_ref;  ///< kLeavesPerNode per table: brick, or kConst | constant
  std::vector<Brick> bricks;
  std::vector<Constant> constants;

  /// Walker bounds over field cells (the dual cells for trilinear): per node, and per leaf block
  /// for nodes with a bound table (node_bound_table != kNone).
  static constexpr uint32_t kNone = 0xffffffffu;
  std::vector<SparseBound> node_bound;
  std::vector<uint32_t> node_bound_table;
  std::vector<SparseBound> leaf_bound;

  std::shared_ptr<const void> trees;  ///< keeps the OpenVDB grids (and so the bricks) alive
  uint64_t tree_bytes = 0;            ///< OpenVDB's own in-memory size of the grids
  uint64_t leaf_count = 0, tile_count = 0;
  double max_density = 0, sum_density = 0;  ///< over the voxel box (sum for the mean)

  std::size_t node_index(int ni, int nj, int nk) const {
    return (std::size_t(nk) * std::size_t(nn[1]) + std::size_t(nj)) * std::size_t(nn[0]) +
           std::size_t(ni);
  }
  static int leaf_in_node(int li, int lj, int lk) {
    return ((li & 15) << 8) | ((lj & 15) << 4) | (lk & 15);
  }
  static int voxel_in_leaf(int i, int j, int k) {
    return ((i & 7) << 6) | ((j & 7) << 3) | (k & 7);
  }
  bool inside(int i, int j, int k) const {
    return i >= lo[0] && j >= lo[1] && k >= lo[2] && i < hi[0] && j < hi[1] && k < hi[2];
  }
  /// The reference (brick, or kConst | constant) of leaf (li, lj, lk), which must lie in a node.
  uint32_t leaf(int li, int lj, int lk) const {
    const uint32_t n = node_ref[node_index(li >> 4, lj >> 4, lk >> 4)];
    if (n & kConst) return n;
    return leaf_ref[std::size_t(n) * kLeavesPerNode + std::size_t(leaf_in_node(li, lj, lk))];
  }
  /// The brick view of a reference: constants become a brick without buffers.
  Brick view(uint32_t ref) const {
    if (!(ref & kConst)) return bricks[ref];
    const Constant& c = constants[ref & ~kConst];
    Brick b;
    b.density_c = c.density;
    b.albedo_c = c.albedo;
    b.eta_c = c.eta;
    return b;
  }
  /// Raw values of voxel (i, j, k) inside the box.
  Brick voxel_brick(int i, int j, int k) const { return view(leaf(i >> 3, j >> 3, k >> 3)); }
  float sigma_t(int i, int j, int k) const;  ///< 0 outside the box
  float eta(int i, int j, int k) const;      ///< eta_outside outside the box
  float albedo(int i, int j, int k) const;   ///< inside the box only
  /// Bound of field block (bi, bj, bk) (leaf-sized block of field cells) in node `node`.
  const SparseBound& block_bound(std::size_t node, int bi, int bj, int bk) const {
    const uint32_t t = node_bound_table[node];
    if (t == kNone) return node_bound[node];
    return leaf_bound[std::size_t(t) * kLeavesPerNode + std::size_t(leaf_in_node(bi, bj, bk))];
  }
  /// Computes node_bound, node_bound_table and leaf_bound from the storage (parallel).
  void build_bounds();
  /// Memory of the index and bounds (the OpenVDB trees are tree_bytes), bytes.
  uint64_t index_bytes() const;
};

}  // namespace femto
