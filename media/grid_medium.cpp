#include "media/grid_medium.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "core/constants.h"
#include "core/scene_desc.h"
#include "media/volume_data.h"

namespace femto {

namespace {

int floor_int(double x) {
  return clamped_floor(x);
}
}  // namespace

GridMedium::GridMedium(const VolumeData& data, const VdbMediumDesc& desc)
    : trilinear_(desc.interpolation == VdbMediumDesc::Interpolation::Trilinear),
      albedo_const_(desc.albedo),
      eta_const_(desc.eta),
      eta_outside_(desc.eta) {
  if (data.sparse) {
    init_sparse(data, desc);
    return;
  }
  n_[0] = data.density.nx;
  n_[1] = data.density.ny;
  n_[2] = data.density.nz;
  for (int a = 0; a < 3; ++a) {
    m_[a] = n_[a] + (trilinear_ ? 1 : 0);
    nb_[a] = (m_[a] + kBlock - 1) / kBlock;
  }
  std::copy(data.world_to_grid, data.world_to_grid + 12, w2g_);
  const size_t cells = data.density.v.size();
  sigma_t_.resize(cells);
  double sum = 0;
  for (size_t i = 0; i < cells; ++i) {
    sigma_t_[i] = static_cast<float>(desc.sigma_t_scale * data.density.v[i]);
    max_sigma_t_ = std::max(max_sigma_t_, static_cast<double>(sigma_t_[i]));
    sum += sigma_t_[i];
  }
  mean_sigma_t_ = cells > 0 ? sum / static_cast<double>(cells) : 0.0;
  if (!data.albedo.empty()) albedo_ = data.albedo.v;
  if (!data.eta.empty()) eta_ = data.eta.v;

  // Block structure: per block of field cells, the largest sigma_t any of its cells can take
  // and the refractive index if it is the same everywhere in the block (else -1).
  const size_t nblocks = static_cast<size_t>(nb_[0]) * nb_[1] * nb_[2];
  block_sigma_max_.assign(nblocks, 0.0f);
  block_eta_.assign(nblocks, -1.0f);
  const int pad = trilinear_ ? 1 : 0;  // dual cell I touches voxels I - 1 and I
  tbb::parallel_for(tbb::blocked_range<int>(0, nb_[2]), [&](const tbb::blocked_range<int>& r) {
    for (int bz = r.begin(); bz != r.end(); ++bz)
      for (int by = 0; by < nb_[1]; ++by)
        for (int bx = 0; bx < nb_[0]; ++bx) {
          float smax = 0, emin = std::numeric_limits<float>::max(), emax = 0;
          for (int k = bz * kBlock - pad; k < std::min((bz + 1) * kBlock, m_[2]); ++k)
            for (int j = by * kBlock - pad; j < std::min((by + 1) * kBlock, m_[1]); ++j)
              for (int i = bx * kBlock - pad; i < std::min((bx + 1) * kBlock, m_[0]); ++i) {
                smax = std::max(smax, field_sigma(i, j, k));
                const float e = field_eta(i, j, k);
                emin = std::min(emin, e);
                emax = std::max(emax, e);
              }
          const size_t b = (static_cast<size_t>(bz) * nb_[1] + by) * nb_[0] + bx;
          block_sigma_max_[b] = smax;
          block_eta_[b] = emin == emax ? emin : -1.0f;
        }
  });
}

void GridMedium::init_sparse(const VolumeData& data, const VdbMediumDesc& desc) {
  const SparseField& f = *data.sparse;
  // The bounds were built for one interpolation, scale and outside index.
  if (f.trilinear != trilinear_ || f.sigma_t_scale != desc.sigma_t_scale ||
      f.eta_outside != static_cast<float>(desc.eta))
    throw std::logic_error("GridMedium: the sparse volume was loaded with another description");
  sparse_ = data.sparse;
  const int pad = trilinear_ ? 1 : 0;
  for (int a = 0; a < 3; ++a) {
    lo_[a] = f.lo[a];
    n_[a] = f.hi[a];
    m_[a] = f.hi[a] + pad;
    nb_[a] = (m_[a] + kBlock - 1) / kBlock;
  }
  // World -> field voxel coordinates: the grid space of VolumeData shifted by the box start.
  std::copy(data.world_to_grid, data.world_to_grid + 12, w2g_);
  for (int a = 0; a < 3; ++a) w2g_[4 * a + 3] += f.lo[a];
  max_sigma_t_ = static_cast<float>(desc.sigma_t_scale * f.max_density);  // as the stored floats
  double cells = 1;
  for (int a = 0; a < 3; ++a) cells *= double(f.hi[a] - f.lo[a]);
  mean_sigma_t_ = cells > 0 ? desc.sigma_t_scale * f.sum_density / cells : 0.0;
}

float GridMedium::field_sigma(int i, int j, int k) const {
  return sparse_ ? sparse_->sigma_t(i, j, k) : dense_sigma(i, j, k);
}

float GridMedium::field_eta(int i, int j, int k) const {
  return sparse_ ? sparse_->eta(i, j, k) : dense_eta(i, j, k);
}

float GridMedium::dense_sigma(int i, int j, int k) const {
  if (i < 0 || j < 0 || k < 0 || i >= n_[0] || j >= n_[1] || k >= n_[2]) return 0.0f;
  return sigma_t_[(static_cast<size_t>(k) * n_[1] + j) * n_[0] + i];
}

float GridMedium::dense_eta(int i, int j, int k) const {
  if (i < 0 || j < 0 || k < 0 || i >= n_[0] || j >= n_[1] || k >= n_[2])
    return static_cast<float>(eta_outside_);
  if (eta_.empty()) return static_cast<float>(eta_const_);
  return eta_[(static_cast<size_t>(k) * n_[1] + j) * n_[0] + i];
}

Vec3 GridMedium::to_field(const Vec3& p) const {
  const double off = trilinear_ ? 0.5 : 0.0;
  return {w2g_[0] * p.x + w2g_[1] * p.y + w2g_[2] * p.z + w2g_[3] + off,
          w2g_[4] * p.x + w2g_[5] * p.y + w2g_[6] * p.z + w2g_[7] + off,
          w2g_[8] * p.x + w2g_[9] * p.y + w2g_[10] * p.z + w2g_[11] + off};
}

uint64_t GridMedium::block_memory_bytes() const {
  if (sparse_) return sparse_->index_bytes();
  return (block_sigma_max_.size() + block_eta_.size()) * sizeof(float);
}

uint64_t GridMedium::field_memory_bytes() const {
  if (sparse_) return sparse_->tree_bytes;
  return (sigma_t_.size() + albedo_.size() + eta_.size()) * sizeof(float);
}

namespace {
// Trilinear (or nearest) lookup of a per-voxel field in field space.
template <class Fetch>
double interpolate(const Vec3& q, bool trilinear, Fetch fetch) {
  if (!trilinear) return fetch(floor_int(q.x), floor_int(q.y), floor_int(q.z));
  const int I = floor_int(q.x), J = floor_int(q.y), K = floor_int(q.z);
  constexpr int kFar = 1 << 30;  // clamped: far outside, where every cell has the outside value
  if (std::abs(I) == kFar || std::abs(J) == kFar || std::abs(K) == kFar) return fetch(I, J, K);
  const double fx = q.x - I, fy = q.y - J, fz = q.z - K;
  double v = 0;
  for (int c = 0; c < 8; ++c) {
    const int a = c & 1, b = (c >> 1) & 1, d = (c >> 2) & 1;
    const double w = (a ? fx : 1 - fx) * (b ? fy : 1 - fy) * (d ? fz : 1 - fz);
    if (w != 0) v += w * fetch(I - 1 + a, J - 1 + b, K - 1 + d);
  }
  return v;
}
}  // namespace

double GridMedium::sigma_t_at(const Vec3& p) const {
  return interpolate(to_field(p), trilinear_,
                     [&](int i, int j, int k) { return field_sigma(i, j, k); });
}

double GridMedium::eta_at(const Vec3& p) const {
  return interpolate(to_field(p), trilinear_,
                     [&](int i, int j, int k) { return field_eta(i, j, k); });
}

double GridMedium::albedo_at(const Vec3& p) const {
  if (sparse_)
    return interpolate(to_field(p), trilinear_, [&](int i, int j, int k) {
      const SparseField& f = *sparse_;  // outside the box sigma_t is 0: any albedo will do
      return f.albedo(std::clamp(i, f.lo[0], f.hi[0] - 1), std::clamp(j, f.lo[1], f.hi[1] - 1),
                      std::clamp(k, f.lo[2], f.hi[2] - 1));
    });
  if (albedo_.empty()) return albedo_const_;
  return interpolate(to_field(p), trilinear_, [&](int i, int j, int k) {
    i = std::clamp(i, 0, n_[0] - 1);  // outside the grid sigma_t is 0: any albedo will do
    j = std::clamp(j, 0, n_[1] - 1);
    k = std::clamp(k, 0, n_[2] - 1);
    return albedo_[(static_cast<size_t>(k) * n_[1] + j) * n_[0] + i];
  });
}

// ---------------------------------------------------------------------------------------------
// Walker

void GridMedium::Walker::Dda::init(const Vec3& o, const Vec3& d, double s0, double s1,
                                   const int lo_in[3], const int hi_in[3], double cs) {
  s = s0;
  s_end = s1;
  const double s_probe = s0 + 0.5 * std::min(s1 - s0, 1e-9 * (1.0 + std::abs(s0)));
  for (int a = 0; a < 3; ++a) {
    lo[a] = lo_in[a];
    hi[a] = hi_in[a];
    const double p = o[a] + d[a] * s_probe;
    cell[a] = std::clamp(floor_int(p / cs), lo[a], hi[a] - 1);
    cs_ = cs;
    o_[a] = o[a];
    if (d[a] > 0) {
      step[a] = 1;
      inv_d[a] = 1.0 / d[a];
      s_next[a] = plane(a, cell[a] + 1);
    } else if (d[a] < 0) {
      step[a] = -1;
      inv_d[a] = 1.0 / d[a];
      s_next[a] = plane(a, cell[a]);
    } else {
      step[a] = 0;
      inv_d[a] = 0;
      s_next[a] = kInf;
    }
  }
}

bool GridMedium::Walker::Dda::next(int out[3], double& sa, double& sb) {
  if (s >= s_end) return false;
  const int axis =
      s_next[0] < s_next[1] ? (s_next[0] < s_next[2] ? 0 : 2) : (s_next[1] < s_next[2] ? 1 : 2);
  out[0] = cell[0];
  out[1] = cell[1];
  out[2] = cell[2];
  sa = s;
  sb = std::min(std::max(s_next[axis], s), s_end);
  s = sb;
  cell[axis] += step[axis];
  // Each crossing from its own plane (no running sum): the same plane gives the same distance
  // at every level of the walk (cells, blocks, nodes) and wherever the walk started.
  s_next[axis] = plane(axis, step[axis] > 0 ? cell[axis] + 1 : cell[axis]);
  if (cell[axis] < lo[axis] || cell[axis] >= hi[axis]) s = s_end;
  return true;
}

GridMedium::Walker::Walker(const GridMedium& m, const Ray& ray, double s_max)
    : m_(m), s_max_(s_max) {
  oq_ = m.to_field(ray.o);
  const double* w = m.w2g_;
  dq_ = {w[0] * ray.d.x + w[1] * ray.d.y + w[2] * ray.d.z,
         w[4] * ray.d.x + w[5] * ray.d.y + w[6] * ray.d.z,
         w[8] * ray.d.x + w[9] * ray.d.y + w[10] * ray.d.z};
  // Clip [0, s_max] to the field box [lo, m]^3 (lo = 0 when dense).
  double s0 = 0, s1 = s_max;
  for (int a = 0; a < 3 && s0 <= s1; ++a) {
    if (dq_[a] == 0) {
      if (oq_[a] < m.lo_[a] || oq_[a] > m.m_[a]) s1 = -1;
      continue;
    }
    double ta = (m.lo_[a] - oq_[a]) / dq_[a], tb = (m.m_[a] - oq_[a]) / dq_[a];
    if (ta > tb) std::swap(ta, tb);
    s0 = std::max(s0, ta);
    s1 = std::min(s1, tb);
  }
  if (s0 < s1) {
    s_in_ = s0;
    s_out_ = s1;
    if (m.sparse_) {
      const SparseField& f = *m.sparse_;
      const int lo[3] = {m.lo_[0] >> SparseField::kNodeLog2, m.lo_[1] >> SparseField::kNodeLog2,
                         m.lo_[2] >> SparseField::kNodeLog2};
      nodes_.init(oq_, dq_, s_in_, s_out_, lo, f.nn, static_cast<double>(SparseField::kNode));
      in_node_ = false;
    } else {
      const int lo[3] = {0, 0, 0};
      blocks_.init(oq_, dq_, s_in_, s_out_, lo, m.nb_, static_cast<double>(kBlock));
    }
  } else {
    s_in_ = s_out_ = s_max;
  }
}

template <class Fetch>
void GridMedium::Walker::cell_segment(const int c[3], double sa, double sb, MediumSegment& seg,
                                      Fetch fetch) const {
  seg.s0 = sa;
  seg.s1 = sb;
  if (!m_.trilinear_) {
    float s, e;
    fetch(c[0], c[1], c[2], s, e);
    seg.sigma_t = Poly3::constant(s);
    seg.eta = Poly3::constant(e);
    return;
  }
  // Dual cell c spans voxel centres c - 1 and c on each axis; local coordinate u = q - c.
  double u0[3], u1[3];
  for (int a = 0; a < 3; ++a) {
    u0[a] = oq_[a] + dq_[a] * sa - c[a];
    u1[a] = dq_[a];
  }
  float sv[8], ev[8];
  bool s_const = true, e_const = true;
  for (int k = 0; k < 8; ++k) {
    const int i = c[0] - 1 + (k & 1), j = c[1] - 1 + ((k >> 1) & 1), l = c[2] - 1 + ((k >> 2) & 1);
    fetch(i, j, l, sv[k], ev[k]);
    s_const = s_const && sv[k] == sv[0];
    e_const = e_const && ev[k] == ev[0];
  }
  seg.sigma_t = Poly3::constant(s_const ? sv[0] : 0.0);
  seg.eta = Poly3::constant(e_const ? ev[0] : 0.0);
  if (s_const && e_const) return;
  for (int k = 0; k < 8; ++k) {
    const int a = k & 1, b = (k >> 1) & 1, d = (k >> 2) & 1;
    // Linear factors: (1 - u) for the lower corner, u for the upper one.
    const double x0 = a ? u0[0] : 1 - u0[0], x1 = a ? u1[0] : -u1[0];
    const double y0 = b ? u0[1] : 1 - u0[1], y1 = b ? u1[1] : -u1[1];
    const double z0 = d ? u0[2] : 1 - u0[2], z1 = d ? u1[2] : -u1[2];
    const Poly3 w = Poly3::product_of_linears(x0, x1, y0, y1, z0, z1);
    if (!s_const) seg.sigma_t += w * sv[k];
    if (!e_const) seg.eta += w * ev[k];
  }
}

bool GridMedium::Walker::next(MediumSegment& seg) {
  for (;;) {
    if (phase_ == 0) {
      phase_ = 1;
      if (s_in_ > 0) {
        seg = {0.0, s_in_, Poly3::constant(0.0), Poly3::constant(m_.eta_outside_)};
        return true;
      }
      continue;
    }
    if (phase_ == 1) {
      if (s_in_ >= s_out_) {
        phase_ = 2;
        continue;
      }
      if (in_block_) {
        int c[3];
        double sa, sb;
        if (cells_.next(c, sa, sb)) {
          if (m_.sparse_) {
            cell_segment(c, sa, sb, seg, [this](int i, int j, int k, float& s, float& e) {
              const SparseField& f = *m_.sparse_;
              if (!f.inside(i, j, k)) {
                s = 0.0f;
                e = f.eta_outside;
                return;
              }
              const int slot = ((i >> 3) - view_base_[0]) | (((j >> 3) - view_base_[1]) << 1) |
                               (((k >> 3) - view_base_[2]) << 2);
              const SparseField::Brick& b = views_[slot];
              const int o = SparseField::voxel_in_leaf(i, j, k);
              s = static_cast<float>(f.sigma_t_scale * (b.density ? b.density[o] : b.density_c));
              e = b.eta ? b.eta[o] : b.eta_c;
            });
          } else {
            cell_segment(c, sa, sb, seg, [this](int i, int j, int k, float& s, float& e) {
              s = m_.dense_sigma(i, j, k);
              e = m_.dense_eta(i, j, k);
            });
          }
          return true;
        }
        in_block_ = false;
      }
      if (m_.sparse_) {
        if (next_sparse_block(seg)) return true;
        continue;
      }
      int b[3];
      double sa, sb;
      if (!blocks_.next(b, sa, sb)) {
        phase_ = 2;
        continue;
      }
      const size_t bi = (static_cast<size_t>(b[2]) * m_.nb_[1] + b[1]) * m_.nb_[0] + b[0];
      if (m_.skip_empty_ && m_.block_sigma_max_[bi] == 0.0f && m_.block_eta_[bi] >= 0.0f) {
        seg = {sa, sb, Poly3::constant(0.0), Poly3::constant(m_.block_eta_[bi])};
        return true;
      }
      int lo[3], hi[3];
      for (int a = 0; a < 3; ++a) {
        lo[a] = b[a] * kBlock;
        hi[a] = std::min(lo[a] + kBlock, m_.m_[a]);
      }
      cells_.init(oq_, dq_, sa, sb, lo, hi, 1.0);
      in_block_ = true;
      continue;
    }
    if (phase_ == 2) {
      phase_ = 3;
      if (s_out_ < s_max_) {
        seg = {s_out_, s_max_, Poly3::constant(0.0), Poly3::constant(m_.eta_outside_)};
        return true;
      }
    }
    return false;
  }
}

void GridMedium::Walker::set_views(const int b[3]) {
  const SparseField& f = *m_.sparse_;
  const int pad = m_.trilinear_ ? 1 : 0;  // dual cells of block b read leaves b - 1 and b
  for (int a = 0; a < 3; ++a) view_base_[a] = b[a] - pad;
  const int lim[3] = {f.nn[0] * 16, f.nn[1] * 16, f.nn[2] * 16};
  for (int v = 0; v < (pad ? 8 : 1); ++v) {
    const int l[3] = {view_base_[0] + (v & 1), view_base_[1] + ((v >> 1) & 1),
                      view_base_[2] + ((v >> 2) & 1)};
    if (l[0] < 0 || l[1] < 0 || l[2] < 0 || l[0] >= lim[0] || l[1] >= lim[1] || l[2] >= lim[2]) {
      views_[v] =
          SparseField::Brick{};  // outside every node: never read (the box test comes first)
      continue;
    }
    views_[v] = f.view(f.leaf(l[0], l[1], l[2]));
  }
}

// Sparse: the next node or leaf block. Constant ones become one segment; otherwise the walk
// descends (returns false, the caller continues with the block's or node's cells).
bool GridMedium::Walker::next_sparse_block(MediumSegment& seg) {
  const SparseField& f = *m_.sparse_;
  double sa, sb;
  if (!in_node_) {
    int n[3];
    if (!nodes_.next(n, sa, sb)) {
      phase_ = 2;
      return false;
    }
    node_ = f.node_index(n[0], n[1], n[2]);
    const SparseBound& nb = f.node_bound[node_];
    if (m_.skip_empty_ && nb.constant()) {
      seg = {sa, sb, Poly3::constant(nb.sigma_max), Poly3::constant(nb.eta)};
      return true;
    }
    int lo[3], hi[3];
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::max(n[a] * 16, m_.lo_[a] / kBlock);
      hi[a] = std::min(n[a] * 16 + 16, m_.nb_[a]);
    }
    blocks_.init(oq_, dq_, sa, sb, lo, hi, static_cast<double>(kBlock));
    in_node_ = true;
    return false;
  }
  int b[3];
  if (!blocks_.next(b, sa, sb)) {
    in_node_ = false;
    return false;
  }
  const SparseBound& bb = f.block_bound(node_, b[0], b[1], b[2]);
  if (m_.skip_empty_ && bb.constant()) {
    seg = {sa, sb, Poly3::constant(bb.sigma_max), Poly3::constant(bb.eta)};
    return true;
  }
  int lo[3], hi[3];
  for (int a = 0; a < 3; ++a) {
    lo[a] = std::max(b[a] * kBlock, m_.lo_[a]);
    hi[a] = std::min(b[a] * kBlock + kBlock, m_.m_[a]);
  }
  set_views(b);
  cells_.init(oq_, dq_, sa, sb, lo, hi, 1.0);
  in_block_ = true;
  return false;
}

}  // namespace femto
