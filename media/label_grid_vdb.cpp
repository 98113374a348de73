#include "media/label_grid_vdb.h"

#include <openvdb/openvdb.h>

#include <cmath>

#include "core/error.h"
#include "core/io/atomic_file.h"
#include "media/vdb_init.h"
#include "media/vdb_new_grid.h"

namespace femto {

namespace {
constexpr double kMaxCells = 1073741824.0;  // 2^30, as for density volumes
}  // namespace

LabelGridData read_vdb_labels(const std::string& path, const std::string& name,
                              const std::string& where) {
  vdb_load::init_openvdb();
  const std::string at = where + ": " + clip(path, 200) + ": ";
  openvdb::Int32Grid::Ptr grid;
  try {
    openvdb::io::File file(path);
    file.open(false);
    if (!file.hasGrid(name)) throw InputError(at + "no grid named '" + clip(name) + "'");
    // The type from the grid's header: a grid of another type is refused before it is read.
    const openvdb::GridBase::Ptr meta = file.readGridMetadata(name);
    if (!meta->isType<openvdb::Int32Grid>())
      throw InputError(at + "grid '" + clip(name) + "' is of type " + clip(meta->valueType()) +
                       "; labels need an Int32 grid");
    grid = openvdb::gridPtrCast<openvdb::Int32Grid>(file.readGrid(name));
    file.close();
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {
    throw InputError(at + "cannot read the file (" + clip(e.what(), 200) + ")");
  }
  const openvdb::math::Transform& tf = grid->transform();
  const openvdb::Vec3d vs = tf.voxelSize();
  if (!tf.isLinear() || std::abs(vs.x() - vs.y()) > 1e-9 * vs.x() ||
      std::abs(vs.x() - vs.z()) > 1e-9 * vs.x())
    throw InputError(at + "grid '" + clip(name) + "' needs a linear transform with cubic voxels");
  const openvdb::CoordBBox box = grid->evalActiveVoxelBoundingBox();
  if (box.empty()) throw InputError(at + "grid '" + clip(name) + "' has no active voxels");
  LabelGridData out;
  double cells = 1;
  for (int a = 0; a < 3; ++a) {
    out.n[static_cast<size_t>(a)] = box.max()[a] - box.min()[a] + 1;
    cells *= out.n[static_cast<size_t>(a)];
  }
  if (cells > kMaxCells) throw InputError(at + "the active box has more than 2^30 cells");
  out.voxel = vs.x();
  const openvdb::Vec3d lo = tf.indexToWorld(
      openvdb::Vec3d(box.min().x() - 0.5, box.min().y() - 0.5, box.min().z() - 0.5));
  out.origin = {lo.x(), lo.y(), lo.z()};
  out.labels.resize(static_cast<size_t>(cells));
  auto acc = grid->getConstAccessor();
  size_t i = 0;
  for (int x = box.min().x(); x <= box.max().x(); ++x)
    for (int y = box.min().y(); y <= box.max().y(); ++y)
      for (int z = box.min().z(); z <= box.max().z(); ++z)
        out.labels[i++] = acc.getValue(openvdb::Coord(x, y, z));
  return out;
}

void write_vdb_labels(const std::string& path, const std::string& name, const LabelGridData& d) {
  vdb_load::init_openvdb();
  const auto grid = new_vdb_grid<openvdb::Int32Grid>(0);
  auto acc = grid->getAccessor();
  size_t i = 0;
  for (int x = 0; x < d.n[0]; ++x)
    for (int y = 0; y < d.n[1]; ++y)
      for (int z = 0; z < d.n[2]; ++z, ++i)
        if (d.labels[i] != 0) acc.setValue(openvdb::Coord(x, y, z), d.labels[i]);
  grid->setName(name);
  auto tf = openvdb::math::Transform::createLinearTransform(d.voxel);
  tf->postTranslate(openvdb::Vec3d(d.origin.x + 0.5 * d.voxel, d.origin.y + 0.5 * d.voxel,
                                   d.origin.z + 0.5 * d.voxel));
  grid->setTransform(tf);
  write_atomically(path, [&](const std::string& tmp) {
    openvdb::io::File file(tmp);
    file.write({grid});
    file.close();
  });
}

}  // namespace femto
