// Writing .vdb files (write_vdb, write_volume): for the volume generator and the tests.
#include "core/error.h"
#include "core/io/atomic_file.h"
#include "media/vdb_init.h"
#include "media/vdb_new_grid.h"
#include "media/volume_data.h"

namespace femto {

namespace {

using openvdb::Coord;
using openvdb::FloatGrid;
using openvdb::Vec3d;
using vdb_load::init_openvdb;

template <typename GridT>
openvdb::GridBase::Ptr make_grid(const VdbGridSpec& s) {
  using V = typename GridT::ValueType;
  const auto grid = new_vdb_grid<GridT>(static_cast<V>(s.background));
  auto acc = grid->getAccessor();
  const Coord off(static_cast<int>(s.index_offset.x), static_cast<int>(s.index_offset.y),
                  static_cast<int>(s.index_offset.z));
  if (s.values) {
    const DenseGrid& d = *s.values;
    for (int k = 0; k < d.nz; ++k)
      for (int j = 0; j < d.ny; ++j)
        for (int i = 0; i < d.nx; ++i) {
          const float x = d.at(i, j, k);
          if (!(x == s.background))
            acc.setValue(off + Coord(i, j, k), static_cast<V>(x));  // NaN too
        }
  }
  for (const auto& [c, x] : s.voxels) acc.setValue(Coord(c[0], c[1], c[2]), static_cast<V>(x));
  grid->tree().prune();  // merges constant active blocks into tiles: smaller files
  return grid;
}

}  // namespace

void write_vdb(const std::string& path, const std::vector<VdbGridSpec>& grids) {
  init_openvdb();
  openvdb::GridPtrVec out;
  for (const VdbGridSpec& s : grids) {
    if ((!s.values || s.values->empty()) && s.voxels.empty())
      throw RuntimeError("write_vdb: grid '" + s.name + "' is empty");
    openvdb::GridBase::Ptr g = s.type == VdbGridSpec::Type::Float ? make_grid<FloatGrid>(s)
                               : s.type == VdbGridSpec::Type::Double
                                   ? make_grid<openvdb::DoubleGrid>(s)
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
