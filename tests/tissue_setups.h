#pragma once
// Small tissue-optics setups built in code for the tests.
#include "core/tissue/setup.h"

namespace femto::test {

/// A box of nx x ny x nz voxels of edge `voxel`, lower corner at the origin, filled with label 1.
inline tissue::Setup tissue_box(int nx, int ny, int nz, double voxel, const TissueOptics& o,
                                double outside_n = 1.0) {
  tissue::Setup s;
  LabelVolume& v = s.volume;
  v.n[0] = nx, v.n[1] = ny, v.n[2] = nz;
  v.voxel = voxel;
  v.labels.assign(v.cells(), 1);
  v.optics = {TissueOptics{0, 0, 0, outside_n}, o};
  s.fluence_grid.origin = v.origin;
  for (int a = 0; a < 3; ++a) {
    s.fluence_grid.n[a] = v.n[a];
    s.fluence_grid.size[a] = v.n[a] * voxel;
  }
  s.source.type = tissue::Source::Type::Pencil;
  s.source.position = {0.5 * nx * voxel, 0.5 * ny * voxel, 0.0};
  s.source.direction = {0, 0, 1};
  s.threads = 2;
  return s;
}

}  // namespace femto::test
