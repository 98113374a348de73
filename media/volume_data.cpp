#include "media/volume_data.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <mutex>

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wshadow"
#pragma GCC diagnostic ignored "-Wconversion"
#pragma GCC diagnostic ignored "-Wpedantic"
#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>
#pragma GCC diagnostic pop

#include "core/constants.h"
#include "core/error.h"
#include "core/io/atomic_file.h"
#include "media/sparse_from_vdb.h"
#include "media/vdb_structure.h"

namespace femto {

void DenseGrid::update_range() {
  if (v.empty()) {
    min_value = max_value = 0.0f;
    return;
  }
  const auto [lo, hi] = std::minmax_element(v.begin(), v.end());
  min_value = *lo;
  max_value = *hi;
}

uint64_t VolumeData::memory_bytes() const {
  if (sparse) return sparse->tree_bytes + sparse->index_bytes();
  return (density.v.size() + albedo.v.size() + eta.v.size()) * sizeof(float);
}

static Vec3 affine(const double* m, const Vec3& p) {
  return {m[0] * p.x + m[1] * p.y + m[2] * p.z + m[3], m[4] * p.x + m[5] * p.y + m[6] * p.z + m[7],
          m[8] * p.x + m[9] * p.y + m[10] * p.z + m[11]};
}
Vec3 VolumeData::to_world(const Vec3& g) const { return affine(grid_to_world, g); }
Vec3 VolumeData::to_grid(const Vec3& w) const { return affine(world_to_grid, w); }

namespace {

using openvdb::Coord;
using openvdb::CoordBBox;
using openvdb::FloatGrid;
using openvdb::Vec3d;

// Limits of docs/volumes.md ("Limits").
constexpr uint64_t kMaxFileBytes = 16ull << 30;
constexpr double kMaxCells = 1073741824.0;  // 2^30 = 1024^3 dense cells
constexpr uint64_t kMaxDenseBytes = 16ull << 30;
constexpr double kMaxWorld = 1e9;       // mm, as for scene coordinates
constexpr double kMaxSigmaT = 1e9;      // 1/mm: sigma_t is stored as float

void init_openvdb() {
  static std::once_flag once;
  std::call_once(once, [] { openvdb::initialize(); });
}

std::string fmt(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}
std::string fmt(const Vec3d& v) {
  return "[" + fmt(v.x()) + ", " + fmt(v.y()) + ", " + fmt(v.z()) + "]";
}
std::string fmt(const Coord& c) {
  return "(" + std::to_string(c.x()) + ", " + std::to_string(c.y()) + ", " + std::to_string(c.z()) +
         ")";
}

/// The scene's placement (docs/scene-format.md, transform): scale, rotate about x, y, z, translate.
Vec3 place(const TransformDesc& tf, const Vec3& p) {
  Vec3 q{p.x * tf.scale.x, p.y * tf.scale.y, p.z * tf.scale.z};
  for (int axis = 0; axis < 3; ++axis) {
    const double a = tf.rotate_deg[axis] * kPi / 180.0;
    if (a == 0.0) continue;
    const double c = std::cos(a), s = std::sin(a);
    const int i = (axis + 1) % 3, j = (axis + 2) % 3;  // same convention as shape transforms
    const double qi = q[i], qj = q[j];
    q[i] = c * qi - s * qj;
    q[j] = s * qi + c * qj;
  }
  return q + tf.translate;
}

// Which role a grid plays, with its valid range.
enum class Role { Density, Albedo, Eta };
const char* role_name(Role r) { return r == Role::Density ? "density" : r == Role::Albedo ? "albedo" : "eta"; }

// Empty when `x` is a valid value for the role, else the problem ("eta must be >= 1").
std::string value_problem(Role r, float x) {
  if (!std::isfinite(x)) return std::string(role_name(r)) + " must be finite";
  if (r == Role::Density && x < 0) return "density must be >= 0";
  if (r == Role::Albedo && !(x >= 0 && x <= 1)) return "albedo must be in [0, 1]";
  if (r == Role::Eta && x < 1) return "eta must be >= 1";
  return "";
}

struct Used {
  Role role;
  std::string key;   // JSON key naming the grid, for the error path
  std::string name;  // grid name in the file
  FloatGrid::Ptr grid;
  float fill = 0;    // value of inactive cells in the dense grid
  DenseGrid* dense = nullptr;
};

class VolumeLoader {
 public:
  VolumeLoader(const VdbMediumDesc& desc, const std::string& source, const std::string& where)
      : desc_(desc), prefix_(source + ": " + where + "/") {}

  VolumeData load() {
    init_openvdb();
    namespace fs = std::filesystem;
    std::error_code ec;
    if (!fs::exists(desc_.file, ec)) fail_file("file not found");
    if (fs::is_directory(desc_.file, ec)) fail_file("is a directory, not a VDB file");
    if (!fs::is_regular_file(desc_.file, ec)) fail_file("is not a regular file");
    const uint64_t file_bytes = fs::file_size(desc_.file, ec);
    if (ec) fail_file("cannot read the file size (" + ec.message() + ")");
    if (file_bytes > kMaxFileBytes) fail_file("the file is larger than the 16 GiB limit");
    // Our own bounded checks first: OpenVDB trusts the sizes stored in the file.
    if (const std::string p = vdb_structure_problem(desc_.file); !p.empty())
      fail_file("corrupt or unsupported OpenVDB file: " + p);

    VolumeData out;
    std::vector<Used> used{{Role::Density, "density_grid", desc_.density_grid, {}, 0, &out.density}};
    if (!desc_.albedo_grid.empty())
      used.push_back({Role::Albedo, "albedo_grid", desc_.albedo_grid, {}, 0, &out.albedo});
    if (!desc_.eta_grid.empty())
      used.push_back({Role::Eta, "eta_grid", desc_.eta_grid, {}, 0, &out.eta});

    read_grids(used);

    const FloatGrid& density = *used[0].grid;
    CoordBBox box;  // union of the active boxes; inactive cells inside take the fill value
    for (Used& u : used) {
      if (u.role != Role::Density) check_same_transform(u, used[0]);
      check_background(u);
      box.expand(u.grid->evalActiveVoxelBoundingBox());
    }
    // An empty density is fine when an eta grid gives the medium a shape (a pure index medium).
    const bool has_eta = std::any_of(used.begin(), used.end(), [](const Used& u) { return u.role == Role::Eta; });
    if (density.evalActiveVoxelBoundingBox().empty() && (!has_eta || box.empty()))
      fail(used[0], "grid '" + used[0].name + "' has no active voxels, so the medium is empty");
    out.active_voxels = density.activeVoxelCount();

    if (storage_ == Storage::Auto) storage_ = choose(box, used, tree_bytes(used));
    if (storage_ == Storage::Dense) {
      check_box(box.min(), box.max(), used.size(), "");
      for (Used& u : used) densify(u, box);
    } else {
      check_sparse_box(box.min(), box.max(), "");
      // Again from the trees (the metadata may be missing): before any index is allocated.
      double dim[3];
      for (int a = 0; a < 3; ++a) dim[a] = double(int64_t(box.max()[a]) - int64_t(box.min()[a]) + 1);
      const double trees = double(tree_bytes(used));
      check_sparse_memory(trees + sparse_index_estimate(dim, trees, trilinear()), "about ",
                          "OpenVDB trees " + fmt_mib(trees) + " + index");
      make_sparse(out, used, box);
    }
    check_sigma_t(used[0], out.density);
    set_transform(out, density.transform(), box.min());
    for (int a = 0; a < 3; ++a) out.index_min[a] = box.min()[a];
    return out;
  }

 private:
  using Storage = VdbMediumDesc::Storage;
  const VdbMediumDesc& desc_;
  std::string prefix_;
  Storage storage_ = desc_.storage;  // Auto until decided, from the metadata or the trees

  static uint64_t tree_bytes(const std::vector<Used>& used) {
    uint64_t b = 0;
    for (const Used& u : used) b += u.grid->memUsage();
    return b;
  }

  // Memory of the sparse index for a box (voxels) and trees of `trees` bytes: node arrays over
  // the box, and per node with leaves (at most one per 2 KiB of tree) a leaf table and bounds.
  static double sparse_index_estimate(const double dim[3], double trees, bool trilinear) {
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
  Storage choose_from(const double dim[3], std::size_t grids, double trees) const {
    const double cells = dim[0] * dim[1] * dim[2];
    const double dense = cells * sizeof(float) * double(grids);
    const double sparse = trees + sparse_index_estimate(dim, trees, trilinear());
    const double limit = double(std::min(kMaxDenseBytes, desc_.max_dense_bytes));
    if (cells > kMaxCells || dense > limit) return Storage::Sparse;
    return dense <= std::max(64.0 * (1 << 20), 4 * sparse) ? Storage::Dense : Storage::Sparse;
  }
  Storage choose(const CoordBBox& box, const std::vector<Used>& used, uint64_t trees) const {
    double dim[3];
    for (int a = 0; a < 3; ++a) dim[a] = double(int64_t(box.max()[a]) - int64_t(box.min()[a]) + 1);
    return choose_from(dim, used.size(), double(trees));
  }
  bool trilinear() const { return desc_.interpolation == VdbMediumDesc::Interpolation::Trilinear; }

  // Before the trees are read: the storage from the grids' metadata (their stored boxes and
  // OpenVDB's in-memory sizes), and the sparse memory estimate against the limit.
  void plan_from_metadata(const std::vector<openvdb::GridBase::Ptr>& metas, const std::vector<Used>& used) {
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

  static std::string fmt_mib(double bytes) { return fmt(bytes / double(1ull << 20)) + " MiB"; }

  void check_sparse_memory(double need, const std::string& about, const std::string& parts) const {
    const double limit = double(desc_.max_sparse_bytes);
    if (need > limit)
      fail_file("the sparse grids need " + about + fmt_mib(need) + " (" + parts + "), above the limit of " +
                fmt_mib(limit) + " left by --max-memory (docs/volumes.md, Limits)");
  }

  // Sparse field coordinates are int: each edge of the box, from its node-aligned start, must
  // stay below 2^30 voxels.
  void check_sparse_box(const Coord& lo, const Coord& hi, const std::string& what) const {
    for (int a = 0; a < 3; ++a) {
      const int64_t start = (int64_t(lo[a]) >> SparseField::kNodeLog2) * SparseField::kNode;
      if (int64_t(hi[a]) - start + 1 > (int64_t(1) << 30))
        fail_file("the " + what + "box " + fmt(lo) + " to " + fmt(hi) + " is " +
                  std::to_string(int64_t(hi[a]) - int64_t(lo[a]) + 1) + " voxels along axis " +
                  std::string(1, char('x' + a)) + ", above the limit of 2^30 (docs/volumes.md, Limits)");
    }
  }

  // Keeps the trees: builds the sparse field over their leaves and records the value ranges.
  void make_sparse(VolumeData& out, std::vector<Used>& used, const CoordBBox& box) const {
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
      f = build_sparse_field(in, box, trilinear(), desc_.sigma_t_scale, static_cast<float>(desc_.albedo),
                             static_cast<float>(desc_.eta), check);
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
      d.min_value = any ? (gaps ? std::min(in[i].min_active, used[i].fill) : in[i].min_active) : used[i].fill;
      d.max_value = any ? (gaps ? std::max(in[i].max_active, used[i].fill) : in[i].max_active) : used[i].fill;
    }
    out.sparse = std::move(f);
  }

  [[noreturn]] void fail_at(const std::string& key, const std::string& problem) const {
    throw InputError(prefix_ + key + ": " + clip(desc_.file, 200) + ": " + problem);
  }
  [[noreturn]] void fail_file(const std::string& problem) const { fail_at("file", problem); }
  [[noreturn]] void fail(const Used& u, const std::string& problem) const {
    fail_at(u.key, problem);
  }

  // Every failure inside OpenVDB's reader, including running out of memory, is bad input.
  void read_grids(std::vector<Used>& used) {
    try {
      openvdb::io::File file(desc_.file);
      file.open(/*delayLoad=*/false);
      const openvdb::GridPtrVecPtr metas = file.readAllGridMetadata();
      std::vector<openvdb::GridBase::Ptr> mine;
      for (const Used& u : used) mine.push_back(find_meta(*metas, u));
      plan_from_metadata(mine, used);
      for (std::size_t i = 0; i < used.size(); ++i) used[i].grid = read_grid(file, *mine[i], used[i], used.size());
      file.close();
    } catch (const InputError&) {
      throw;
    } catch (const std::bad_alloc&) {
      fail_file("cannot read the file: it asks for more memory than is available (corrupt?)");
    } catch (const std::exception& e) {
      fail_file("cannot read the file (" + clip(e.what(), 200) + ")");
    } catch (...) {
      fail_file("cannot read the file (unknown error in the OpenVDB reader)");
    }
    for (const Used& u : used)
      if (!u.grid) fail(u, "grid '" + clip(u.name) + "' could not be read");
  }

  // Dense size of the box [lo, hi] in 64-bit arithmetic (hi - lo + 1 overflows int when the
  // voxels are far apart), against the cell limit and the memory budget.
  void check_box(const Coord& lo, const Coord& hi, std::size_t grids, const std::string& what) const {
    int64_t dim[3];
    double cells = 1;
    for (int a = 0; a < 3; ++a) {
      dim[a] = int64_t(hi[a]) - int64_t(lo[a]) + 1;
      cells *= double(dim[a]);
    }
    const std::string size = std::to_string(dim[0]) + " x " + std::to_string(dim[1]) + " x " +
                             std::to_string(dim[2]) + " voxels";
    const std::string box = what + "dense box " + fmt(lo) + " to " + fmt(hi);
    if (cells > kMaxCells)
      fail_file("the " + box + " is " + size + " (" + fmt(cells) +
                " cells), above the limit of 2^30 cells (docs/volumes.md, Limits)");
    const uint64_t bytes = uint64_t(cells) * sizeof(float) * grids;
    const uint64_t limit = std::min(kMaxDenseBytes, desc_.max_dense_bytes);
    if (bytes > limit)
      fail_file("the " + box + " (" + size + ") needs " + fmt(double(bytes) / double(1ull << 20)) +
                " MiB for " + std::to_string(grids) + " grid(s), above the limit of " +
                fmt(double(limit) / double(1ull << 20)) + " MiB" +
                (limit < kMaxDenseBytes ? " left by --max-memory" : "") + " (docs/volumes.md, Limits)");
  }

  // sigma_t is stored as float; a finite density times the scale can still overflow it.
  void check_sigma_t(const Used& d, const DenseGrid& g) const {
    if (desc_.sigma_t_scale * g.max_value > kMaxSigmaT)
      fail(d, "grid '" + clip(d.name) + "' density " + fmt(g.max_value) + " times sigma_t_scale " +
                  fmt(desc_.sigma_t_scale) + " exceeds the bound of 1e9 /mm for sigma_t");
  }

  // The grid's box as stored in its metadata (written by OpenVDB), checked before the tree is
  // read so that a huge box is refused before OpenVDB allocates it.
  void check_metadata_box(const openvdb::GridBase& meta, std::size_t grids) const {
    const auto lo = meta.getMetadata<openvdb::Vec3IMetadata>("file_bbox_min");
    const auto hi = meta.getMetadata<openvdb::Vec3IMetadata>("file_bbox_max");
    if (!lo || !hi) return;
    const Coord a(lo->value()), b(hi->value());
    if (a.x() > b.x() || a.y() > b.y() || a.z() > b.z()) return;  // empty grid
    check_box(a, b, grids, "grid '" + clip(meta.getName()) + "' ");
  }

  // The grid's metadata, checked: it exists, holds floats, has a usable class and transform.
  openvdb::GridBase::Ptr find_meta(const openvdb::GridPtrVec& metas, const Used& u) const {
    openvdb::GridBase::Ptr meta;
    std::string available;
    for (const auto& g : metas) {
      if (g->getName() == u.name && !meta) meta = g;
      if (available.size() < 400)  // names come from the file: keep the message short
        available += (available.empty() ? "'" : ", '") + clip(g->getName()) + "' (" +
                     clip(g->valueType()) + ")";
    }
    const std::string grid = "grid '" + clip(u.name) + "'";
    if (!meta)
      fail(u, "no grid named '" + clip(u.name) + "'; the file has " +
                  (available.empty() ? std::string("no grids") : clip(available, 400)));
    if (!meta->isType<FloatGrid>())
      fail(u, grid + " holds " + clip(meta->valueType()) + " values (" + clip(meta->type()) +
                  "); femto needs a FloatGrid (float values)" +
                  (meta->valueType().rfind("vec", 0) == 0 ? "; vector grids such as velocity are not supported"
                                                          : ""));
    const openvdb::GridClass cls = meta->getGridClass();
    if (u.role == Role::Density && cls == openvdb::GRID_LEVEL_SET)
      fail(u, grid +
                  " is a level set (signed distances to a surface, not a density); convert it "
                  "to a fog volume first, e.g. with openvdb::tools::sdfToFogVolume");
    if (u.role == Role::Density && cls == openvdb::GRID_STAGGERED)
      fail(u, grid + " has class 'staggered'; a density needs class 'fog volume' or 'unknown'");
    if (!meta->transform().isLinear())
      fail(u, grid + " has a non-linear transform (" + meta->transform().mapType() +
                  "); only affine (linear) transforms are supported");
    return meta;
  }

  FloatGrid::Ptr read_grid(openvdb::io::File& file, const openvdb::GridBase& meta, const Used& u,
                           std::size_t grids) const {
    if (storage_ != Storage::Sparse) check_metadata_box(meta, grids);
    return openvdb::gridPtrCast<FloatGrid>(file.readGrid(u.name));
  }

  void check_same_transform(const Used& u, const Used& d) const {
    const auto& a = u.grid->transform();
    const auto& b = d.grid->transform();
    const auto close = [](const Vec3d& x, const Vec3d& y) {
      return (x - y).length() <= 1e-9 * std::max({1.0, x.length(), y.length()});
    };
    const std::string rule = "; all grids must share the transform of density grid '" + clip(d.name) + "'";
    if (!close(a.voxelSize(), b.voxelSize()))
      fail(u, "grid '" + clip(u.name) + "' has voxel size " + fmt(a.voxelSize()) + " mm but '" + clip(d.name) +
                  "' has " + fmt(b.voxelSize()) + rule);
    for (const Vec3d p : {Vec3d(0, 0, 0), Vec3d(1, 0, 0), Vec3d(0, 1, 0), Vec3d(0, 0, 1)})
      if (!close(a.indexToWorld(p), b.indexToWorld(p)))
        fail(u, "grid '" + clip(u.name) + "' is offset or rotated: its voxel " + fmt(Coord::round(p)) +
                    " is at " + fmt(a.indexToWorld(p)) + " mm but in '" + clip(d.name) + "' at " +
                    fmt(b.indexToWorld(p)) + rule);
  }

  // Sets the fill value of inactive cells from the background (see docs/volumes.md).
  void check_background(Used& u) const {
    const float bg = u.grid->background();
    const std::string grid = "grid '" + clip(u.name) + "' background";
    if (u.role == Role::Density) {
      if (bg != 0.0f)
        fail(u, grid + " must be 0, since inactive voxels are empty space (got " + fmt(bg) + ")");
    } else if (u.role == Role::Eta && bg == 0.0f) {
      u.fill = static_cast<float>(desc_.eta);  // background 0 = "not set": the medium's eta
      return;
    } else if (const std::string p = value_problem(u.role, bg); !p.empty()) {
      fail(u, grid + ": " + p + (u.role == Role::Eta ? " or 0 for the medium's eta" : "") +
                  " (got " + fmt(bg) + ")");
    }
    u.fill = bg;
  }

  // Copies the active values into a dense grid over `box`, validating each one.
  void densify(Used& u, const CoordBBox& box) const {
    const Coord o = box.min();
    const auto extent = [&](int a) { return int(int64_t(box.max()[a]) - int64_t(o[a]) + 1); };
    DenseGrid& d = *u.dense;
    d = DenseGrid(extent(0), extent(1), extent(2), u.fill);
    for (auto it = u.grid->cbeginValueOn(); it; ++it) {
      const float x = *it;
      const CoordBBox b = it.getBoundingBox();  // one voxel, or an active tile
      if (const std::string p = value_problem(u.role, x); !p.empty())
        fail(u, "grid '" + clip(u.name) + "' voxel " + fmt(b.min()) + ": " + p + " (got " + fmt(x) + ")");
      // 64-bit counters: a voxel at INT_MAX would make `++i` overflow.
      for (int64_t k = b.min().z(); k <= b.max().z(); ++k)
        for (int64_t j = b.min().y(); j <= b.max().y(); ++j)
          for (int64_t i = b.min().x(); i <= b.max().x(); ++i)
            d.at(int(i - o.x()), int(j - o.y()), int(k - o.z())) = x;
    }
    d.update_range();
  }

  // grid space g -> VDB index g + min - 0.5 (cell centres are VDB voxel centres) -> VDB world
  // -> the scene's transform.
  void set_transform(VolumeData& out, const openvdb::math::Transform& tf, const Coord& min) const {
    const auto world = [&](double x, double y, double z) {
      const Vec3d w = tf.indexToWorld(Vec3d(x + min.x() - 0.5, y + min.y() - 0.5, z + min.z() - 0.5));
      return place(desc_.transform, Vec3(w.x(), w.y(), w.z()));
    };
    double* m = out.grid_to_world;
    const Vec3 t = world(0, 0, 0);
    const Vec3 cols[3] = {world(1, 0, 0) - t, world(0, 1, 0) - t, world(0, 0, 1) - t};
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) m[4 * r + c] = cols[c][r];
      m[4 * r + 3] = t[r];
    }
    for (int c = 0; c < 3; ++c) out.voxel_size[c] = length(cols[c]);

    // Inverse of the 3x3 part by cofactors; the translation follows.
    const auto a = [&](int r, int c) { return m[4 * r + c]; };
    const double det = a(0, 0) * (a(1, 1) * a(2, 2) - a(1, 2) * a(2, 1)) -
                       a(0, 1) * (a(1, 0) * a(2, 2) - a(1, 2) * a(2, 0)) +
                       a(0, 2) * (a(1, 0) * a(2, 1) - a(1, 1) * a(2, 0));
    if (!(std::abs(det) > 0) || !std::isfinite(det))
      fail_file("the grid-to-world transform is singular");
    double* inv = out.world_to_grid;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) {
        const int r1 = (c + 1) % 3, r2 = (c + 2) % 3, c1 = (r + 1) % 3, c2 = (r + 2) % 3;
        inv[4 * r + c] = (a(r1, c1) * a(r2, c2) - a(r1, c2) * a(r2, c1)) / det;
      }
    for (int r = 0; r < 3; ++r)
      inv[4 * r + 3] = -(inv[4 * r] * t.x + inv[4 * r + 1] * t.y + inv[4 * r + 2] * t.z);

    const DenseGrid& g = out.density;
    Vec3 lo(std::numeric_limits<double>::infinity()), hi(-std::numeric_limits<double>::infinity());
    for (int corner = 0; corner < 8; ++corner) {
      const Vec3 p = out.to_world({(corner & 1) ? double(g.nx) : 0.0, (corner & 2) ? double(g.ny) : 0.0,
                                   (corner & 4) ? double(g.nz) : 0.0});
      lo = vmin(lo, p);
      hi = vmax(hi, p);
    }
    out.world_bounds_min = lo;
    out.world_bounds_max = hi;
    const double far = std::max(max_abs_component(lo), max_abs_component(hi));
    if (!(far <= kMaxWorld))  // also NaN: the renderer works in float far inside this
      fail_file("the grid's world box " + fmt(Vec3d(lo.x, lo.y, lo.z)) + " to " +
                fmt(Vec3d(hi.x, hi.y, hi.z)) +
                " mm reaches beyond +-1e9 mm (voxel size, file transform or the scene's transform)");
  }
};

template <typename GridT>
openvdb::GridBase::Ptr make_grid(const VdbGridSpec& s) {
  using V = typename GridT::ValueType;
  const auto grid = GridT::create(static_cast<V>(s.background));
  auto acc = grid->getAccessor();
  const Coord off(static_cast<int>(s.index_offset.x), static_cast<int>(s.index_offset.y),
                  static_cast<int>(s.index_offset.z));
  if (s.values) {
    const DenseGrid& d = *s.values;
    for (int k = 0; k < d.nz; ++k)
      for (int j = 0; j < d.ny; ++j)
        for (int i = 0; i < d.nx; ++i) {
          const float x = d.at(i, j, k);
          if (!(x == s.background)) acc.setValue(off + Coord(i, j, k), static_cast<V>(x));  // NaN too
        }
  }
  for (const auto& [c, x] : s.voxels) acc.setValue(Coord(c[0], c[1], c[2]), static_cast<V>(x));
  grid->tree().prune();  // merges constant active blocks into tiles: smaller files
  return grid;
}

}  // namespace

VolumeData load_volume(const VdbMediumDesc& desc, const std::string& source,
                       const std::string& where) {
  return VolumeLoader(desc, source, where).load();
}

std::string medium_where(const std::string& name) {
  std::string out = "/media/";
  for (const char ch : name) out += ch == '~' ? "~0" : ch == '/' ? "~1" : std::string(1, ch);
  return out;
}

void write_vdb(const std::string& path, const std::vector<VdbGridSpec>& grids) {
  init_openvdb();
  openvdb::GridPtrVec out;
  for (const VdbGridSpec& s : grids) {
    if ((!s.values || s.values->empty()) && s.voxels.empty())
      throw RuntimeError("write_vdb: grid '" + s.name + "' is empty");
    openvdb::GridBase::Ptr g = s.type == VdbGridSpec::Type::Float    ? make_grid<FloatGrid>(s)
                               : s.type == VdbGridSpec::Type::Double ? make_grid<openvdb::DoubleGrid>(s)
                                                                     : make_grid<openvdb::Vec3SGrid>(s);
    g->setName(s.name);
    g->setGridClass(s.grid_class == VdbGridSpec::Class::LevelSet    ? openvdb::GRID_LEVEL_SET
                    : s.grid_class == VdbGridSpec::Class::FogVolume ? openvdb::GRID_FOG_VOLUME
                                                                    : openvdb::GRID_UNKNOWN);
    openvdb::math::Transform::Ptr tf;
    if (s.frustum) {
      tf = openvdb::math::Transform::createFrustumTransform(
          openvdb::BBoxd(Vec3d(0), Vec3d(s.values->nx, s.values->ny, s.values->nz)), 0.5, 10.0,
          s.voxel_mm.x);
    } else {
      // index p -> voxel * p + t, with cell (0,0,0) (index `index_offset`) spanning from origin.
      tf = openvdb::math::Transform::createLinearTransform(1.0);
      tf->preScale(Vec3d(s.voxel_mm.x, s.voxel_mm.y, s.voxel_mm.z));
      const Vec3 t{s.origin_mm.x + (0.5 - s.index_offset.x) * s.voxel_mm.x,
                   s.origin_mm.y + (0.5 - s.index_offset.y) * s.voxel_mm.y,
                   s.origin_mm.z + (0.5 - s.index_offset.z) * s.voxel_mm.z};
      tf->postTranslate(Vec3d(t.x, t.y, t.z));
    }
    g->setTransform(tf);
    out.push_back(g);
  }
  write_atomically(path, [&](const std::string& tmp) {
    try {
      openvdb::io::File file(tmp);
      file.write(out);
      file.close();
    } catch (const openvdb::Exception& e) {
      throw RuntimeError("cannot write '" + path + "': " + e.what());
    }
  });
}

void write_volume(const std::string& path, const DenseGrid& density, const DenseGrid* albedo,
                  const DenseGrid* eta, double voxel_mm, const Vec3& origin_mm,
                  const std::string& density_name, const std::string& albedo_name,
                  const std::string& eta_name) {
  const auto spec = [&](const std::string& name, const DenseGrid& g, VdbGridSpec::Class cls) {
    if (g.nx != density.nx || g.ny != density.ny || g.nz != density.nz)
      throw RuntimeError("write_volume: grid '" + name + "' differs in shape from the density");
    VdbGridSpec s;
    s.name = name;
    s.values = &g;
    s.grid_class = cls;
    s.voxel_mm = Vec3(voxel_mm);
    s.origin_mm = origin_mm;
    return s;
  };
  std::vector<VdbGridSpec> grids{spec(density_name, density, VdbGridSpec::Class::FogVolume)};
  if (albedo) grids.push_back(spec(albedo_name, *albedo, VdbGridSpec::Class::Unknown));
  if (eta) grids.push_back(spec(eta_name, *eta, VdbGridSpec::Class::Unknown));
  write_vdb(path, grids);
}

}  // namespace femto
