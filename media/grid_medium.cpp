#include "media/grid_medium.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/scene_desc.h"
#include "media/volume_data.h"

namespace femto {

namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();

int floor_int(double x) { return clamped_floor(x); }
}  // namespace

GridMedium::GridMedium(const VolumeData& data, const VdbMediumDesc& desc)
    : trilinear_(desc.interpolation == VdbMediumDesc::Interpolation::Trilinear),
      albedo_const_(desc.albedo),
      eta_const_(desc.eta),
      eta_outside_(desc.eta) {
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

float GridMedium::field_sigma(int i, int j, int k) const {
  if (i < 0 || j < 0 || k < 0 || i >= n_[0] || j >= n_[1] || k >= n_[2]) return 0.0f;
  return sigma_t_[(static_cast<size_t>(k) * n_[1] + j) * n_[0] + i];
}

float GridMedium::field_eta(int i, int j, int k) const {
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
  return (block_sigma_max_.size() + block_eta_.size()) * sizeof(float);
}

uint64_t GridMedium::field_memory_bytes() const {
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
  return interpolate(to_field(p), trilinear_, [&](int i, int j, int k) { return field_sigma(i, j, k); });
}

double GridMedium::eta_at(const Vec3& p) const {
  return interpolate(to_field(p), trilinear_, [&](int i, int j, int k) { return field_eta(i, j, k); });
}

double GridMedium::albedo_at(const Vec3& p) const {
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
                                   const int lo_[3], const int hi_[3], double cs) {
  s = s0;
  s_end = s1;
  const double s_probe = s0 + 0.5 * std::min(s1 - s0, 1e-9 * (1.0 + std::abs(s0)));
  for (int a = 0; a < 3; ++a) {
    lo[a] = lo_[a];
    hi[a] = hi_[a];
    const double p = o[a] + d[a] * s_probe;
    cell[a] = std::clamp(floor_int(p / cs), lo[a], hi[a] - 1);
    if (d[a] > 0) {
      step[a] = 1;
      s_next[a] = ((cell[a] + 1) * cs - o[a]) / d[a];
      s_delta[a] = cs / d[a];
    } else if (d[a] < 0) {
      step[a] = -1;
      s_next[a] = (cell[a] * cs - o[a]) / d[a];
      s_delta[a] = -cs / d[a];
    } else {
      step[a] = 0;
      s_next[a] = kInf;
      s_delta[a] = kInf;
    }
  }
}

bool GridMedium::Walker::Dda::next(int out[3], double& sa, double& sb) {
  if (s >= s_end) return false;
  const int axis = s_next[0] < s_next[1] ? (s_next[0] < s_next[2] ? 0 : 2) : (s_next[1] < s_next[2] ? 1 : 2);
  out[0] = cell[0];
  out[1] = cell[1];
  out[2] = cell[2];
  sa = s;
  sb = std::min(std::max(s_next[axis], s), s_end);
  s = sb;
  cell[axis] += step[axis];
  s_next[axis] += s_delta[axis];
  if (cell[axis] < lo[axis] || cell[axis] >= hi[axis]) s = s_end;
  return true;
}

GridMedium::Walker::Walker(const GridMedium& m, const Ray& ray, double s_max) : m_(m), s_max_(s_max) {
  oq_ = m.to_field(ray.o);
  const double* w = m.w2g_;
  dq_ = {w[0] * ray.d.x + w[1] * ray.d.y + w[2] * ray.d.z, w[4] * ray.d.x + w[5] * ray.d.y + w[6] * ray.d.z,
         w[8] * ray.d.x + w[9] * ray.d.y + w[10] * ray.d.z};
  // Clip [0, s_max] to the field box [0, m]^3.
  double s0 = 0, s1 = s_max;
  for (int a = 0; a < 3 && s0 <= s1; ++a) {
    if (dq_[a] == 0) {
      if (oq_[a] < 0 || oq_[a] > m.m_[a]) s1 = -1;
      continue;
    }
    double ta = (0 - oq_[a]) / dq_[a], tb = (m.m_[a] - oq_[a]) / dq_[a];
    if (ta > tb) std::swap(ta, tb);
    s0 = std::max(s0, ta);
    s1 = std::min(s1, tb);
  }
  if (s0 < s1) {
    s_in_ = s0;
    s_out_ = s1;
    const int lo[3] = {0, 0, 0};
    blocks_.init(oq_, dq_, s_in_, s_out_, lo, m.nb_, static_cast<double>(kBlock));
  } else {
    s_in_ = s_out_ = s_max;
  }
}

void GridMedium::Walker::cell_segment(const int c[3], double sa, double sb, MediumSegment& seg) const {
  seg.s0 = sa;
  seg.s1 = sb;
  if (!m_.trilinear_) {
    seg.sigma_t = Poly3::constant(m_.field_sigma(c[0], c[1], c[2]));
    seg.eta = Poly3::constant(m_.field_eta(c[0], c[1], c[2]));
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
    sv[k] = m_.field_sigma(i, j, l);
    ev[k] = m_.field_eta(i, j, l);
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
          cell_segment(c, sa, sb, seg);
          return true;
        }
        in_block_ = false;
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

}  // namespace femto
