#include "media/sparse_field.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <limits>

namespace femto {

float SparseField::sigma_t(int i, int j, int k) const {
  if (!inside(i, j, k)) return 0.0f;
  const Brick b = voxel_brick(i, j, k);
  // Same rounding as the dense path: float(scale * density) in double.
  return static_cast<float>(sigma_t_scale *
                            (b.density ? b.density[voxel_in_leaf(i, j, k)] : b.density_c));
}

float SparseField::eta(int i, int j, int k) const {
  if (!inside(i, j, k)) return eta_outside;
  const Brick b = voxel_brick(i, j, k);
  return b.eta ? b.eta[voxel_in_leaf(i, j, k)] : b.eta_c;
}

float SparseField::albedo(int i, int j, int k) const {
  const Brick b = voxel_brick(i, j, k);
  return b.albedo ? b.albedo[voxel_in_leaf(i, j, k)] : b.albedo_c;
}

namespace {

// Running bound: sigma_t range and eta range.
struct Range {
  float smax = 0, smin = std::numeric_limits<float>::max();
  float emin = std::numeric_limits<float>::max(), emax = -1;
  void add(float s, float e) {
    smax = std::max(smax, s);
    smin = std::min(smin, s);
    emin = std::min(emin, e);
    emax = std::max(emax, e);
  }
  SparseBound bound() const {
    SparseBound b;
    b.sigma_max = smax;
    b.sigma_min = std::min(smin, smax);
    b.eta = emin == emax ? emin : -1.0f;
    return b;
  }
};

// Adds every voxel value of the inclusive voxel range [a, b] to `r`, one value per constant
// node or leaf, and the outside values when the range leaves the box.
void visit(const SparseField& f, const int a[3], const int b[3], Range& r) {
  int c0[3], c1[3];
  bool outside = false;
  for (int x = 0; x < 3; ++x) {
    c0[x] = std::max(a[x], f.lo[x]);
    c1[x] = std::min(b[x], f.hi[x] - 1);
    outside = outside || a[x] < f.lo[x] || b[x] >= f.hi[x];
  }
  if (outside) r.add(0.0f, f.eta_outside);
  if (c0[0] > c1[0] || c0[1] > c1[1] || c0[2] > c1[2]) return;
  const auto sigma = [&](float d) { return static_cast<float>(f.sigma_t_scale * d); };
  constexpr int N = SparseField::kNodeLog2, L = SparseField::kLeafLog2;
  for (int nk = c0[2] >> N; nk <= c1[2] >> N; ++nk)
    for (int nj = c0[1] >> N; nj <= c1[1] >> N; ++nj)
      for (int ni = c0[0] >> N; ni <= c1[0] >> N; ++ni) {
        const uint32_t nref = f.node_ref[f.node_index(ni, nj, nk)];
        if (nref & SparseField::kConst) {
          const SparseField::Constant& c = f.constants[nref & ~SparseField::kConst];
          r.add(sigma(c.density), c.eta);
          continue;
        }
        int n0[3], n1[3];  // this node's part of the range
        const int nc[3] = {ni, nj, nk};
        for (int x = 0; x < 3; ++x) {
          n0[x] = std::max(c0[x], nc[x] << N);
          n1[x] = std::min(c1[x], ((nc[x] + 1) << N) - 1);
        }
        for (int lk = n0[2] >> L; lk <= n1[2] >> L; ++lk)
          for (int lj = n0[1] >> L; lj <= n1[1] >> L; ++lj)
            for (int li = n0[0] >> L; li <= n1[0] >> L; ++li) {
              const SparseField::Brick br = f.view(f.leaf(li, lj, lk));
              if (!br.density && !br.eta) {
                r.add(sigma(br.density_c), br.eta_c);
                continue;
              }
              const int lc[3] = {li, lj, lk};
              int l0[3], l1[3];
              for (int x = 0; x < 3; ++x) {
                l0[x] = std::max(n0[x], lc[x] << L);
                l1[x] = std::min(n1[x], ((lc[x] + 1) << L) - 1);
              }
              for (int k = l0[2]; k <= l1[2]; ++k)
                for (int j = l0[1]; j <= l1[1]; ++j)
                  for (int i = l0[0]; i <= l1[0]; ++i) {
                    const int o = SparseField::voxel_in_leaf(i, j, k);
                    r.add(sigma(br.density ? br.density[o] : br.density_c),
                          br.eta ? br.eta[o] : br.eta_c);
                  }
            }
      }
}
}  // namespace

void SparseField::build_bounds() {
  const int pad = trilinear ? 1 : 0;  // dual cell I touches voxels I - 1 and I
  int m[3];
  for (int a = 0; a < 3; ++a) m[a] = hi[a] + pad;
  // Voxels touched by the field cells [c0, c1) of each axis.
  const auto touched = [&](const int c0[3], const int c1[3], int a[3], int b[3]) {
    for (int x = 0; x < 3; ++x) {
      a[x] = std::max(c0[x], lo[x]) - pad;
      b[x] = std::min(c1[x], m[x]) - 1;
    }
  };
  const std::size_t nodes = node_ref.size();
  node_bound.assign(nodes, SparseBound{});
  node_bound_table.assign(nodes, kNone);
  // A node needs per-block bounds when a voxel node it touches has leaves.
  uint32_t tables = 0;
  for (int nk = 0; nk < nn[2]; ++nk)
    for (int nj = 0; nj < nn[1]; ++nj)
      for (int ni = 0; ni < nn[0]; ++ni) {
        bool leaves = false;
        for (int d = 0; d < (pad ? 8 : 1) && !leaves; ++d) {
          const int x = ni - (d & 1), y = nj - ((d >> 1) & 1), z = nk - ((d >> 2) & 1);
          if (x < 0 || y < 0 || z < 0) continue;
          leaves = !(node_ref[node_index(x, y, z)] & kConst);
        }
        if (leaves) node_bound_table[node_index(ni, nj, nk)] = tables++;
      }
  leaf_bound.assign(std::size_t(tables) * kLeavesPerNode, SparseBound{});

  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nodes),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t n = r.begin(); n != r.end(); ++n) {
                        const int nc[3] = {int(n % std::size_t(nn[0])),
                                           int((n / std::size_t(nn[0])) % std::size_t(nn[1])),
                                           int(n / (std::size_t(nn[0]) * std::size_t(nn[1])))};
                        int c0[3], c1[3], a[3], b[3];
                        for (int x = 0; x < 3; ++x) {
                          c0[x] = nc[x] * kNode;
                          c1[x] = c0[x] + kNode;
                        }
                        touched(c0, c1, a, b);
                        if (a[0] > b[0] || a[1] > b[1] || a[2] > b[2])
                          continue;  // no field cell of the box here
                        const uint32_t t = node_bound_table[n];
                        if (t == kNone) {
                          Range range;
                          visit(*this, a, b, range);
                          node_bound[n] = range.bound();
                          continue;
                        }
                        Range node_range;
                        for (int bk = 0; bk < 16; ++bk)
                          for (int bj = 0; bj < 16; ++bj)
                            for (int bi = 0; bi < 16; ++bi) {
                              const int bc[3] = {nc[0] * 16 + bi, nc[1] * 16 + bj, nc[2] * 16 + bk};
                              int d0[3], d1[3], va[3], vb[3];
                              for (int x = 0; x < 3; ++x) {
                                d0[x] = bc[x] * kLeaf;
                                d1[x] = d0[x] + kLeaf;
                              }
                              touched(d0, d1, va, vb);
                              if (va[0] > vb[0] || va[1] > vb[1] || va[2] > vb[2]) continue;
                              Range range;
                              visit(*this, va, vb, range);
                              leaf_bound[std::size_t(t) * kLeavesPerNode +
                                         std::size_t(leaf_in_node(bi, bj, bk))] = range.bound();
                              node_range.smax = std::max(node_range.smax, range.smax);
                              node_range.smin = std::min(node_range.smin, range.smin);
                              node_range.emin = std::min(node_range.emin, range.emin);
                              node_range.emax = std::max(node_range.emax, range.emax);
                            }
                        node_bound[n] = node_range.bound();
                      }
                    });
}

uint64_t SparseField::index_bytes() const {
  return node_ref.size() * sizeof(uint32_t) + leaf_ref.size() * sizeof(uint32_t) +
         bricks.size() * sizeof(Brick) + constants.size() * sizeof(Constant) +
         node_bound.size() * sizeof(SparseBound) + node_bound_table.size() * sizeof(uint32_t) +
         leaf_bound.size() * sizeof(SparseBound);
}

}  // namespace femto
