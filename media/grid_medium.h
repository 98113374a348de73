#pragma once
// A heterogeneous medium on a regular grid (from an OpenVDB volume): sigma_t, albedo and
// refractive index per voxel, interpolated `nearest` (piecewise constant cells) or `trilinear`.
// Rays are walked cell by cell (3-D DDA) so optical depth and optical path length are exact;
// blocks of 8^3 cells with no extinction and a constant index are crossed in one step.
// Storage is dense (float arrays over the box) or sparse (media/sparse_field.h: the OpenVDB
// trees, walked node -> leaf block -> cell, with constant nodes and blocks crossed in one step).
#include <cmath>
#include <cstdint>
#include <memory>
#include <vector>

#include "core/vec3.h"
#include "media/poly3.h"
#include "media/sparse_field.h"

namespace femto {

/// floor(x) as an int, clamped to +-2^30 (NaN gives -2^30): points far outside every grid (long
/// paths, wide pulses) must not overflow the conversion, which is undefined behaviour.
inline int clamped_floor(double x) {
  constexpr double kLimit = 1073741824.0;
  const double f = std::floor(x);
  if (f >= kLimit) return static_cast<int>(kLimit);
  if (!(f > -kLimit)) return -static_cast<int>(kLimit);
  return static_cast<int>(f);
}

struct VolumeData;
struct VdbMediumDesc;

/// A piece of a ray over which sigma_t and eta are cubic polynomials of t = s - s0.
struct MediumSegment {
  double s0 = 0, s1 = 0;  ///< world distances along the ray, mm
  Poly3 sigma_t;          ///< 1/mm
  Poly3 eta;
};

class GridMedium {
 public:
  static constexpr int kBlock = 8;  ///< cells per block edge for empty-space skipping

  GridMedium(const VolumeData& data, const VdbMediumDesc& desc);

  bool trilinear() const { return trilinear_; }
  /// Refractive index outside the grid's box.
  double eta_outside() const { return eta_outside_; }
  /// Point values with the medium's interpolation (0 extinction outside the grid).
  double sigma_t_at(const Vec3& p) const;
  double albedo_at(const Vec3& p) const;
  double eta_at(const Vec3& p) const;
  double max_sigma_t() const { return max_sigma_t_; }
  /// Mean sigma_t over the grid's cells (for reports).
  double mean_sigma_t() const { return mean_sigma_t_; }
  /// Memory of the block structure (dense: per-block majorant and index range; sparse: the
  /// node and leaf tables with their bounds), bytes.
  uint64_t block_memory_bytes() const;
  /// Memory of the per-cell fields (dense arrays, or the OpenVDB trees), bytes.
  uint64_t field_memory_bytes() const;
  /// Whether the grids are kept sparse (SparseField) rather than as dense arrays.
  bool sparse() const { return sparse_ != nullptr; }
  /// Turns empty-space skipping off (for benchmarks).
  void set_empty_space_skipping(bool on) { skip_empty_ = on; }

  /// Walks a ray [0, s_max] in order, producing segments that cover it without gaps.
  class Walker {
   public:
    Walker(const GridMedium& m, const Ray& ray, double s_max);
    bool next(MediumSegment& seg);

   private:
    struct Dda {
      int cell[3], step[3], lo[3], hi[3];
      double s_next[3], inv_d[3], o_[3], cs_, s, s_end;
      double plane(int a, int c) const { return (c * cs_ - o_[a]) * inv_d[a]; }
      void init(const Vec3& o, const Vec3& d, double s0, double s1, const int lo_in[3],
                const int hi_in[3], double cell_size);
      bool next(int out[3], double& sa, double& sb);
    };
    template <class Fetch>
    void cell_segment(const int c[3], double sa, double sb, MediumSegment& seg, Fetch fetch) const;
    void set_views(const int b[3]);  // sparse: the leaves a field block's cells read
    bool next_sparse_block(MediumSegment& seg);

    const GridMedium& m_;
    Vec3 oq_, dq_;  // ray in field space, parametrised by world distance
    double s_max_, s_in_, s_out_;
    int phase_ = 0;  // 0 before the grid, 1 inside, 2 after
    bool in_block_ = false;
    bool in_node_ = true;  // dense: one implicit node covering the grid
    std::size_t node_ = 0;
    Dda nodes_, blocks_, cells_;
    int view_base_[3] = {0, 0, 0};  // leaf of views_[0]
    SparseField::Brick views_[8];   // leaves view_base_ + {0,1}^3 (trilinear) or view_base_
  };

 private:
  friend class Walker;
  float field_sigma(int i, int j, int k) const;  // field-space sample, padded outside
  float field_eta(int i, int j, int k) const;
  float dense_sigma(int i, int j, int k) const;
  float dense_eta(int i, int j, int k) const;
  Vec3 to_field(const Vec3& p) const;
  void init_sparse(const VolumeData& data, const VdbMediumDesc& desc);

  bool trilinear_ = false;
  bool skip_empty_ = true;
  int lo_[3] = {0, 0, 0};  // first field cell (sparse: the box starts inside a node)
  int n_[3] = {0, 0, 0};   // voxels
  int m_[3] = {0, 0, 0};   // field cells: n (nearest) or n + 1 (trilinear, dual cells)
  int nb_[3] = {0, 0, 0};  // blocks
  std::vector<float> sigma_t_, albedo_, eta_;  // per voxel; albedo_/eta_ empty when constant
  double albedo_const_ = 1, eta_const_ = 1, eta_outside_ = 1;
  double w2g_[12];  // world -> grid (voxel (i,j,k) covers [i, i+1]^3)
  double max_sigma_t_ = 0, mean_sigma_t_ = 0;
  std::vector<float> block_sigma_max_, block_eta_;  // block_eta_ < 0: index varies in the block
  std::shared_ptr<const SparseField> sparse_;       // sparse storage (then the vectors are empty)
};

}  // namespace femto
