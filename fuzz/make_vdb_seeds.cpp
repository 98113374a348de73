// Writes small .vdb seed files for fuzz_vdb into the folder given as the only argument, with
// femto's own writers: the two example volumes of data/volumes (cloud, tissue) at a small
// resolution, and variants that reach other parts of the loader (tiles, far-apart voxels, an
// index offset with non-cubic voxels, a double grid, a level set, a bad background).
#include <cstdio>
#include <string>

#include "media/volume_data.h"
#include "media/volume_generators.h"

using namespace femto;

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s FOLDER\n", argv[0]);
    return 2;
  }
  const std::string dir = argv[1];
  write_generated(dir + "/cloud8.vdb", make_cloud(8, 1), 2.0);
  write_generated(dir + "/tissue6.vdb", make_tissue(6, 1), 0.5);

  const DenseGrid block(16, 16, 16, 0.5f);  // constant: stored as tiles
  VdbGridSpec tiles;
  tiles.name = "density";
  tiles.values = &block;
  write_vdb(dir + "/tiles.vdb", {tiles});

  VdbGridSpec sparse;
  sparse.name = "density";
  sparse.voxels = {{{0, 0, 0}, 1.0f}, {{40, -3, 7}, 0.25f}, {{-9, 12, 30}, 2.0f}};
  write_vdb(dir + "/sparse.vdb", {sparse});

  DenseGrid ramp(3, 4, 5);
  for (int k = 0; k < 5; ++k)
    for (int j = 0; j < 4; ++j)
      for (int i = 0; i < 3; ++i) ramp.at(i, j, k) = 0.1f * float(i + j + k);
  DenseGrid eta(3, 4, 5, 1.2f), albedo(3, 4, 5, 0.8f);
  VdbGridSpec d, a, e;
  d.name = "density";
  d.values = &ramp;
  d.voxel_mm = Vec3(0.5, 1.0, 2.0);
  d.index_offset = Vec3(-100, 7, 3);
  a = d;
  a.name = "albedo";
  a.values = &albedo;
  a.grid_class = VdbGridSpec::Class::Unknown;
  e = a;
  e.name = "eta";
  e.values = &eta;
  write_vdb(dir + "/offset3.vdb", {d, a, e});

  VdbGridSpec dbl = d;
  dbl.type = VdbGridSpec::Type::Double;
  write_vdb(dir + "/double.vdb", {dbl});

  VdbGridSpec ls = d;
  ls.grid_class = VdbGridSpec::Class::LevelSet;
  write_vdb(dir + "/levelset.vdb", {ls});

  VdbGridSpec bg = d;
  bg.background = 0.5f;
  write_vdb(dir + "/background.vdb", {bg});
  return 0;
}
