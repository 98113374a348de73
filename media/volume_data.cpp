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

    VolumeData out;
    std::vector<Used> used{{Role::Density, "density_grid", desc_.density_grid, {}, 0, &out.density}};
    if (!desc_.albedo_grid.empty())
      used.push_back({Role::Albedo, "albedo_grid", desc_.albedo_grid, {}, 0, &out.albedo});
    if (!desc_.eta_grid.empty())
      used.push_back({Role::Eta, "eta_grid", desc_.eta_grid, {}, 0, &out.eta});

    openvdb::io::File file(desc_.file);
    try {
      file.open(/*delayLoad=*/false);
    } catch (const openvdb::Exception& e) {
      fail_file(std::string("not a readable OpenVDB file (") + e.what() + ")");
    }
    try {
      const openvdb::GridPtrVecPtr metas = file.readAllGridMetadata();
      for (Used& u : used) u.grid = read_grid(file, *metas, u);
    } catch (const openvdb::Exception& e) {
      fail_file(std::string("cannot read the file (") + e.what() + ")");
    }
    file.close();

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

    const Coord dim = box.dim();
    const uint64_t cells = uint64_t(dim.x()) * uint64_t(dim.y()) * uint64_t(dim.z());
    const uint64_t bytes = cells * sizeof(float) * used.size();
    const std::string size = std::to_string(dim.x()) + " x " + std::to_string(dim.y()) + " x " +
                             std::to_string(dim.z()) + " voxels";
    if (cells > (uint64_t(1) << 31))
      fail_file("the dense box " + fmt(box.min()) + " to " + fmt(box.max()) + " is " + size + " (" +
                fmt(double(cells)) + " cells), above the limit of 2^31 cells");
    if (bytes > (uint64_t(16) << 30))
      fail_file("the dense box of " + size + " needs " + fmt(double(bytes) / double(1ull << 30)) +
                " GiB for " + std::to_string(used.size()) + " grids, above the 16 GiB limit");

    for (Used& u : used) densify(u, box);
    set_transform(out, density.transform(), box.min());
    for (int a = 0; a < 3; ++a) out.index_min[a] = box.min()[a];
    return out;
  }

 private:
  const VdbMediumDesc& desc_;
  std::string prefix_;

  [[noreturn]] void fail_at(const std::string& key, const std::string& problem) const {
    throw InputError(prefix_ + key + ": " + desc_.file + ": " + problem);
  }
  [[noreturn]] void fail_file(const std::string& problem) const { fail_at("file", problem); }
  [[noreturn]] void fail(const Used& u, const std::string& problem) const {
    fail_at(u.key, problem);
  }

  FloatGrid::Ptr read_grid(openvdb::io::File& file, const openvdb::GridPtrVec& metas,
                           const Used& u) const {
    openvdb::GridBase::Ptr meta;
    std::string available;
    for (const auto& g : metas) {
      if (g->getName() == u.name && !meta) meta = g;
      available += (available.empty() ? "'" : ", '") + g->getName() + "' (" + g->valueType() + ")";
    }
    const std::string grid = "grid '" + u.name + "'";
    if (!meta)
      fail(u, "no grid named '" + u.name + "'; the file has " +
                  (available.empty() ? std::string("no grids") : available));
    if (!meta->isType<FloatGrid>())
      fail(u, grid + " holds " + meta->valueType() + " values (" + meta->type() +
                  "); femto needs a FloatGrid (float values)");
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
    return openvdb::gridPtrCast<FloatGrid>(file.readGrid(u.name));
  }

  void check_same_transform(const Used& u, const Used& d) const {
    const auto& a = u.grid->transform();
    const auto& b = d.grid->transform();
    const auto close = [](const Vec3d& x, const Vec3d& y) {
      return (x - y).length() <= 1e-9 * std::max({1.0, x.length(), y.length()});
    };
    const std::string rule = "; all grids must share the transform of density grid '" + d.name + "'";
    if (!close(a.voxelSize(), b.voxelSize()))
      fail(u, "grid '" + u.name + "' has voxel size " + fmt(a.voxelSize()) + " mm but '" + d.name +
                  "' has " + fmt(b.voxelSize()) + rule);
    for (const Vec3d p : {Vec3d(0, 0, 0), Vec3d(1, 0, 0), Vec3d(0, 1, 0), Vec3d(0, 0, 1)})
      if (!close(a.indexToWorld(p), b.indexToWorld(p)))
        fail(u, "grid '" + u.name + "' is offset or rotated: its voxel " + fmt(Coord::round(p)) +
                    " is at " + fmt(a.indexToWorld(p)) + " mm but in '" + d.name + "' at " +
                    fmt(b.indexToWorld(p)) + rule);
  }

  // Sets the fill value of inactive cells from the background (see docs/volumes.md).
  void check_background(Used& u) const {
    const float bg = u.grid->background();
    const std::string grid = "grid '" + u.name + "' background";
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
    const Coord o = box.min(), dim = box.dim();
    DenseGrid& d = *u.dense;
    d = DenseGrid(dim.x(), dim.y(), dim.z(), u.fill);
    for (auto it = u.grid->cbeginValueOn(); it; ++it) {
      const float x = *it;
      const CoordBBox b = it.getBoundingBox();  // one voxel, or an active tile
      if (const std::string p = value_problem(u.role, x); !p.empty())
        fail(u, "grid '" + u.name + "' voxel " + fmt(b.min()) + ": " + p + " (got " + fmt(x) + ")");
      for (int k = b.min().z(); k <= b.max().z(); ++k)
        for (int j = b.min().y(); j <= b.max().y(); ++j)
          for (int i = b.min().x(); i <= b.max().x(); ++i)
            d.at(i - o.x(), j - o.y(), k - o.z()) = x;
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
  }
};

template <typename GridT>
openvdb::GridBase::Ptr make_grid(const VdbGridSpec& s) {
  using V = typename GridT::ValueType;
  const auto grid = GridT::create(static_cast<V>(s.background));
  auto acc = grid->getAccessor();
  const DenseGrid& d = *s.values;
  const Coord off(static_cast<int>(s.index_offset.x), static_cast<int>(s.index_offset.y),
                  static_cast<int>(s.index_offset.z));
  for (int k = 0; k < d.nz; ++k)
    for (int j = 0; j < d.ny; ++j)
      for (int i = 0; i < d.nx; ++i) {
        const float x = d.at(i, j, k);
        if (!(x == s.background)) acc.setValue(off + Coord(i, j, k), static_cast<V>(x));  // NaN too
      }
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
    if (!s.values || s.values->empty()) throw RuntimeError("write_vdb: grid '" + s.name + "' is empty");
    openvdb::GridBase::Ptr g = s.type == VdbGridSpec::Type::Float ? make_grid<FloatGrid>(s)
                                                                  : make_grid<openvdb::DoubleGrid>(s);
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
