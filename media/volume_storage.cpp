// Dense or sparse storage of a VDB medium: the choice, its memory limits, and building either.
#include <algorithm>
#include <cmath>
#include <memory>

#include "core/error.h"
#include "media/sparse_from_vdb.h"
#include "media/volume_loader.h"

namespace femto::vdb_load {

uint64_t VolumeLoader::tree_bytes(const std::vector<Used>& used) {
  uint64_t b = 0;
  for (const Used& u : used) b += u.grid->memUsage();
  return b;
}

// Memory of the sparse index for a box (voxels) and trees of `trees` bytes: node arrays over
// the box, and per node with leaves (at most one per 2 KiB of tree) a leaf table and bounds.
double VolumeLoader::sparse_index_estimate(const double dim[3], double trees, bool trilinear) {
  double nodes = 1;
  for (int a = 0; a < 3; ++a) nodes *= std::ceil((dim[a] + 256) / 128);
  const double leaves = trees / 2048;
  const double tabled = std::min(nodes, leaves) * (trilinear ? 2 : 1);
  return nodes * (sizeof(uint32_t) * 2 + sizeof(SparseBound)) +
         tabled * SparseField::kLeavesPerNode * (sizeof(uint32_t) + sizeof(SparseBound)) +
         leaves * sizeof(SparseField::Brick);
}

// The documented rule (docs/volumes.md, "Dense or sparse"): dense while its box fits the
// dense limits and costs at most 4x the sparse storage (or under 64 MiB), else sparse.
VolumeLoader::Storage VolumeLoader::choose_from(const double dim[3], std::size_t grids,
                                                double trees) const {
  const double cells = dim[0] * dim[1] * dim[2];
  const double dense = cells * sizeof(float) * double(grids);
  const double sparse = trees + sparse_index_estimate(dim, trees, trilinear());
  const double limit = double(std::min(kMaxDenseBytes, desc_.max_dense_bytes));
  if (cells > kMaxCells || dense > limit) return Storage::Sparse;
  return dense <= std::max(64.0 * (1 << 20), 4 * sparse) ? Storage::Dense : Storage::Sparse;
}

VolumeLoader::Storage VolumeLoader::choose(const CoordBBox& box, const std::vector<Used>& used,
                                           uint64_t trees) const {
  double dim[3];
  for (int a = 0; a < 3; ++a) dim[a] = double(int64_t(box.max()[a]) - int64_t(box.min()[a]) + 1);
  return choose_from(dim, used.size(), double(trees));
}

// Before the trees are read: the storage from the grids' metadata (their stored boxes and
// OpenVDB's in-memory sizes), and the sparse memory estimate against the limit.
void VolumeLoader::plan_from_metadata(const std::vector<openvdb::GridBase::Ptr>& metas,
                                      const std::vector<Used>& used) {
  CoordBBox box;
  double trees = 0;
  for (const auto& meta : metas) {
    if (!meta) return;
    const auto lo = meta->getMetadata<openvdb::Vec3IMetadata>("file_bbox_min");
    const auto hi = meta->getMetadata<openvdb::Vec3IMetadata>("file_bbox_max");
    const auto mem = meta->getMetadata<openvdb::Int64Metadata>("file_mem_bytes");
    if (!lo || !hi || !mem) return;  // decided once the trees are read
    const Coord a(lo->value()), b(hi->value());
    if (a.x() <= b.x() && a.y() <= b.y() && a.z() <= b.z()) box.expand(CoordBBox(a, b));
    trees += double(std::max<int64_t>(0, mem->value()));
  }
  if (box.empty()) return;
  double dim[3];
  for (int a = 0; a < 3; ++a) dim[a] = double(int64_t(box.max()[a]) - int64_t(box.min()[a]) + 1);
  if (storage_ == Storage::Auto) storage_ = choose_from(dim, used.size(), trees);
  if (storage_ != Storage::Sparse) return;
  check_sparse_box(box.min(), box.max(), "grids' stored ");
  const double need = trees + sparse_index_estimate(dim, trees, trilinear());
  check_sparse_memory(need, "about ", "OpenVDB trees " + fmt_mib(trees) + " + index");
}

std::string VolumeLoader::fmt_mib(double bytes) {
  return fmt(bytes / double(1ull << 20)) + " MiB";
}

void VolumeLoader::check_sparse_memory(double need, const std::string& about,
                                       const std::string& parts) const {
  const double limit = double(desc_.max_sparse_bytes);
  if (need > limit)
    fail_file("the sparse grids need " + about + fmt_mib(need) + " (" + parts +
              "), above the limit of " + fmt_mib(limit) +
              " left by --max-memory (docs/volumes.md, Limits)");
}

// Sparse field coordinates are int: each edge of the box, from its node-aligned start, must
// stay below 2^30 voxels.
void VolumeLoader::check_sparse_box(const Coord& lo, const Coord& hi,
                                    const std::string& what) const {
  for (int a = 0; a < 3; ++a) {
    const int64_t start = (int64_t(lo[a]) >> SparseField::kNodeLog2) * SparseField::kNode;
    if (int64_t(hi[a]) - start + 1 > (int64_t(1) << 30))
      fail_file("the " + what + "box " + fmt(lo) + " to " + fmt(hi) + " is " +
                std::to_string(int64_t(hi[a]) - int64_t(lo[a]) + 1) + " voxels along axis " +
                std::string(1, char('x' + a)) +
                ", above the limit of 2^30 (docs/volumes.md, Limits)");
  }
}

// Keeps the trees: builds the sparse field over their leaves and records the value ranges.
void VolumeLoader::make_sparse(VolumeData& out, std::vector<Used>& used,
                               const CoordBBox& box) const {
  std::vector<SparseGridInput> in;
  for (const Used& u : used) {
    SparseGridInput s;
    s.role = u.role == Role::Density  ? SparseGridInput::Role::Density
             : u.role == Role::Albedo ? SparseGridInput::Role::Albedo
                                      : SparseGridInput::Role::Eta;
    s.grid = u.grid;
    s.fill = u.fill;
    in.push_back(s);
  }
  const auto check = [&](const SparseGridInput& s, const Coord& c, float x) {
    const Used& u = used[std::size_t(&s - in.data())];
    if (const std::string p = value_problem(u.role, x); !p.empty())
      fail(u, "grid '" + clip(u.name) + "' voxel " + fmt(c) + ": " + p + " (got " + fmt(x) + ")");
  };
  std::shared_ptr<SparseField> f;
  try {
    f = build_sparse_field(in, box, trilinear(), desc_.sigma_t_scale,
                           static_cast<float>(desc_.albedo), static_cast<float>(desc_.eta), check);
  } catch (const std::bad_alloc&) {
    fail_file("not enough memory for the sparse index of the grids");
  }
  check_sparse_memory(double(f->tree_bytes + f->index_bytes()), "",
                      "OpenVDB trees " + fmt_mib(double(f->tree_bytes)) + " + index " +
                          fmt_mib(double(f->index_bytes())));
  uint64_t cells = 1;
  for (int a = 0; a < 3; ++a) cells *= uint64_t(f->hi[a] - f->lo[a]);
  for (std::size_t i = 0; i < used.size(); ++i) {
    DenseGrid& d = *used[i].dense;
    d.nx = f->hi[0] - f->lo[0];
    d.ny = f->hi[1] - f->lo[1];
    d.nz = f->hi[2] - f->lo[2];
    // Inactive voxels in the box take the fill value.
    const bool gaps = used[i].grid->activeVoxelCount() < cells;
    const bool any = in[i].min_active <= in[i].max_active && used[i].grid->activeVoxelCount() > 0;
    d.min_value =
        any ? (gaps ? std::min(in[i].min_active, used[i].fill) : in[i].min_active) : used[i].fill;
    d.max_value =
        any ? (gaps ? std::max(in[i].max_active, used[i].fill) : in[i].max_active) : used[i].fill;
  }
  out.sparse = std::move(f);
}

// Copies the active values into a dense grid over `box`, validating each one.
void VolumeLoader::densify(Used& u, const CoordBBox& box) const {
  const Coord o = box.min();
  const auto extent = [&](int a) { return int(int64_t(box.max()[a]) - int64_t(o[a]) + 1); };
  DenseGrid& d = *u.dense;
  d = DenseGrid(extent(0), extent(1), extent(2), u.fill);
  for (auto it = u.grid->cbeginValueOn(); it; ++it) {
    const float x = *it;
    const CoordBBox b = it.getBoundingBox();  // one voxel, or an active tile
    if (const std::string p = value_problem(u.role, x); !p.empty())
      fail(u, "grid '" + clip(u.name) + "' voxel " + fmt(b.min()) + ": " + p + " (got " + fmt(x) +
                  ")");
    // 64-bit counters: a voxel at INT_MAX would make `++i` overflow.
    for (int64_t k = b.min().z(); k <= b.max().z(); ++k)
      for (int64_t j = b.min().y(); j <= b.max().y(); ++j)
        for (int64_t i = b.min().x(); i <= b.max().x(); ++i)
          d.at(int(i - o.x()), int(j - o.y()), int(k - o.z())) = x;
  }
  d.update_range();
}

}  // namespace femto::vdb_load
