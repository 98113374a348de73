#pragma once
// Small tissue-optics setups built in code for the tests.
#include <catch2/catch.hpp>

#include "core/tissue/simulate.h"

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

/// Checks that two runs gave bit-identical volume, detector and balance outputs (not the per-label
/// tallies, which may differ in width).
inline void check_same_outputs(const tissue::Result& a, const tissue::Result& b) {
  CHECK(a.scatterings == b.scatterings);
  CHECK(a.segments == b.segments);
  CHECK(a.fluence == b.fluence);
  CHECK(a.fluence_err == b.fluence_err);
  CHECK(a.tpsf == b.tpsf);
  CHECK(a.face_exitance == b.face_exitance);
  CHECK(a.detected.weight == b.detected.weight);
  CHECK(a.detected.time_ps == b.detected.time_ps);
  CHECK(a.detected.exit == b.detected.exit);
  CHECK(a.balance.absorbed == b.balance.absorbed);
  CHECK(a.balance.escaped_faces == b.balance.escaped_faces);
  CHECK(a.balance.specular == b.balance.specular);
  CHECK(a.balance.alive == b.balance.alive);
}

}  // namespace femto::test
