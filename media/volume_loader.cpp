// Reading a VDB medium: the file checked, its grids found and read, then the steps in order.
#include <algorithm>
#include <cstdio>
#include <filesystem>

#include "core/error.h"
#include "media/vdb_structure.h"
#include "media/volume_loader.h"

namespace femto::vdb_load {

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

VolumeData VolumeLoader::load() {
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
  const bool has_eta =
      std::any_of(used.begin(), used.end(), [](const Used& u) { return u.role == Role::Eta; });
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

void VolumeLoader::fail_at(const std::string& key, const std::string& problem) const {
  throw InputError(prefix_ + key + ": " + clip(desc_.file, 200) + ": " + problem);
}

void VolumeLoader::fail_file(const std::string& problem) const {
  fail_at("file", problem);
}

void VolumeLoader::fail(const Used& u, const std::string& problem) const {
  fail_at(u.key, problem);
}

// Every failure inside OpenVDB's reader, including running out of memory, is bad input.
void VolumeLoader::read_grids(std::vector<Used>& used) {
  try {
    openvdb::io::File file(desc_.file);
    file.open(/*delayLoad=*/false);
    const openvdb::GridPtrVecPtr metas = file.readAllGridMetadata();
    std::vector<openvdb::GridBase::Ptr> mine;
    for (const Used& u : used) mine.push_back(find_meta(*metas, u));
    plan_from_metadata(mine, used);
    for (std::size_t i = 0; i < used.size(); ++i)
      used[i].grid = read_grid(file, *mine[i], used[i], used.size());
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

// The grid's metadata, checked: it exists, holds floats, has a usable class and transform.
openvdb::GridBase::Ptr VolumeLoader::find_meta(const openvdb::GridPtrVec& metas,
                                               const Used& u) const {
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
                (meta->valueType().rfind("vec", 0) == 0
                     ? "; vector grids such as velocity are not supported"
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

FloatGrid::Ptr VolumeLoader::read_grid(openvdb::io::File& file, const openvdb::GridBase& meta,
                                       const Used& u, std::size_t grids) const {
  if (storage_ != Storage::Sparse) check_metadata_box(meta, grids);
  return openvdb::gridPtrCast<FloatGrid>(file.readGrid(u.name));
}

}  // namespace femto::vdb_load

namespace femto {

VolumeData load_volume(const VdbMediumDesc& desc, const std::string& source,
                       const std::string& where) {
  return vdb_load::VolumeLoader(desc, source, where).load();
}

}  // namespace femto
