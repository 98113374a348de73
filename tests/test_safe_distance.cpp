// The safe boxes of the labelled tissue walk (core/transport/safe_distance.h): the distance field
// against a brute-force search, and the walk's distance to the next label change with the boxes
// against a plain voxel march that looks up every label. Fixed seeds.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>

#include "core/rng.h"
#include "core/transport/safe_distance.h"
#include "core/transport/tissue_walk.h"

using namespace femto;

namespace {

// A 24 x 20 x 16 grid of 0.5 mm voxels: label 1 with a block of label 2, a slab of label 3, a
// few holes of label 0 and a scattering of single voxels of label 2.
LabelVolume patchwork() {
  LabelVolume v;
  v.n[0] = 24, v.n[1] = 20, v.n[2] = 16;
  v.voxel = 0.5;
  v.origin = Vec3(-1.0, 2.0, 0.25);
  v.labels.assign(v.cells(), 1);
  for (int i = 0; i < v.n[0]; ++i)
    for (int j = 0; j < v.n[1]; ++j)
      for (int k = 0; k < v.n[2]; ++k) {
        uint16_t l = 1;
        if (i >= 14 && j >= 10 && k >= 9) l = 2;
        if (k == 1) l = 3;
        if ((i * 7 + j * 3 + k * 5) % 211 == 0) l = 0;
        if ((i * 5 + j * 11 + k * 13) % 173 == 0) l = 2;
        v.labels[v.index(i, j, k)] = l;
      }
  v.optics.assign(4, TissueOptics{0.01, 1.0, 0.0, 1.0});
  return v;
}

// 1 + the chessboard distance to the nearest voxel of another label (or beyond the grid).
int brute_safe(const LabelVolume& v, int i, int j, int k) {
  const int label = v.labels[v.index(i, j, k)];
  if (label == 0) return 0;
  for (int r = 1;; ++r)
    for (int a = i - r; a <= i + r; ++a)
      for (int b = j - r; b <= j + r; ++b)
        for (int c = k - r; c <= k + r; ++c)
          if (v.label_at(a, b, c) != label) return std::min(r, 255);
}

}  // namespace

TEST_CASE("safe distances are the chessboard distances to another label") {
  // Catches an off-by-one in the transform (a box reaching into another label) or a pass that
  // misses a direction of the 26-neighbourhood.
  const LabelVolume v = patchwork();
  const std::vector<uint8_t> d = safe_distances(v);
  int above_two = 0;
  for (int i = 0; i < v.n[0]; ++i)
    for (int j = 0; j < v.n[1]; ++j)
      for (int k = 0; k < v.n[2]; ++k) {
        INFO("voxel " << i << " " << j << " " << k);
        REQUIRE(d[v.index(i, j, k)] == brute_safe(v, i, j, k));
        above_two += d[v.index(i, j, k)] > 2;
      }
  CHECK(above_two > 200);  // the test reaches the transform's propagation, not only its seeds
}

TEST_CASE("the walk's safe boxes give the distance to the next label of a plain march") {
  // A wrong box would let a step run through a label change; a wrong end voxel would put the
  // photon's cell out of step with its position.
  const LabelVolume v = patchwork();
  const LabelSpace space(v, false);
  Rng rng(7, 3);
  int skipped = 0, compared = 0;
  for (int n = 0; n < 20000; ++n) {
    Photon p;
    for (int a = 0; a < 3; ++a) p.cell[a] = static_cast<int>(rng.uniform() * v.n[a]);
    p.label = v.labels[v.index(p.cell[0], p.cell[1], p.cell[2])];
    if (p.label == 0) continue;
    for (int a = 0; a < 3; ++a) p.x[a] = v.origin[a] + (p.cell[a] + rng.uniform()) * v.voxel;
    const double z = 1 - 2 * rng.uniform(), phi = 2 * kPi * rng.uniform();
    const double r = std::sqrt(std::max(0.0, 1 - z * z));
    p.d = Vec3(r * std::cos(phi), r * std::sin(phi), z);
    const double s_stop = -std::log(1 - rng.uniform()) * v.voxel * 2;
    const uint16_t label = static_cast<uint16_t>(p.label);
    int axis_ref = -1, end_ref[3];
    const double s_ref = march_to_change(v, p, s_stop, axis_ref, end_ref, nullptr,
                                         [&](ptrdiff_t i) { return v.labels[i] == label; });
    for (const bool with_faces : {false, true}) {
      VoxelCrossings faces;
      int axis = -1, end[3];
      const double s =
          space.distance_to_interface(p, s_stop, axis, end, with_faces ? &faces : nullptr);
      ++compared;
      REQUIRE(s == s_ref);
      if (std::isfinite(s)) {
        CHECK(axis == axis_ref);
        CHECK((end[0] == end_ref[0] && end[1] == end_ref[1] && end[2] == end_ref[2]));
        continue;
      }
      skipped += !with_faces;
      // The end voxel holds the end of the step.
      const Vec3 x1 = p.x + p.d * s_stop;
      for (int a = 0; a < 3; ++a) {
        CHECK(std::abs(end[a] - end_ref[a]) <= 1);
        CHECK(x1[a] >= v.origin[a] + end[a] * v.voxel - 1e-9);
        CHECK(x1[a] <= v.origin[a] + (end[a] + 1) * v.voxel + 1e-9);
      }
    }
  }
  CHECK(compared > 30000);
  CHECK(skipped > 3000);  // the boxes are used
}

TEST_CASE("closed-form voxel crossings are the faces the march crosses") {
  // The fluence tally takes a step's voxel faces inside a safe box from three stages: the closed
  // form where each axis has at most one face, crossings_two_per_axis where an axis has two,
  // and the merge crossings_from_axis_faces beyond that. Catches a face on the wrong side of the
  // voxel, a wrong order of faces (a deposit into a voxel the step never enters), a stage that
  // takes a step with more faces on an axis than it handles (a face missed), an end voxel out of
  // step with the march, and in the merge a wrong axis choice.
  LabelVolume v;
  v.n[0] = 12, v.n[1] = 10, v.n[2] = 14;
  v.voxel = 0.7;
  v.origin = Vec3(-2.0, 1.0, 0.3);
  v.labels.assign(v.cells(), 1);
  v.optics.assign(2, TissueOptics{0.01, 1.0, 0.0, 1.0});
  Rng rng(11, 5);
  int closed = 0, two = 0, merged = 0, with_faces = 0, in_grid = 0;
  for (int n = 0; n < 50000; ++n) {
    Photon p;
    p.label = 1;
    for (int a = 0; a < 3; ++a) {
      p.cell[a] = 3 + static_cast<int>(rng.uniform() * (v.n[a] - 6));
      p.x[a] = v.origin[a] + (p.cell[a] + rng.uniform()) * v.voxel;
    }
    if (n % 10 == 0) p.x[n % 3] = v.origin[n % 3] + p.cell[n % 3] * v.voxel;  // on a face
    const double z = 1 - 2 * rng.uniform(), phi = 2 * kPi * rng.uniform();
    const double r = std::sqrt(std::max(0.0, 1 - z * z));
    p.d = Vec3(r * std::cos(phi), r * std::sin(phi), z);
    if (n % 50 == 1) p.d = Vec3(0, n % 100 == 1 ? 1.0 : -1.0, 0);        // along an axis
    if (n % 50 == 2) {  // through voxel corners: faces on two axes at one distance (ties)
      for (int a = 0; a < 3; ++a) p.x[a] = v.origin[a] + (p.cell[a] + 0.5) * v.voxel;
      p.d = Vec3(std::sqrt(0.5), n % 100 == 2 ? std::sqrt(0.5) : -std::sqrt(0.5), 0);
    }
    const double s_stop = -std::log(1 - rng.uniform()) * v.voxel * 0.9;  // within 3 voxels
    VoxelCrossings ref, got;
    int axis = -1, end_ref[3], end[3];
    const double s_edge =
        march_to_change(v, p, s_stop, axis, end_ref, &ref, [](ptrdiff_t) { return true; });
    if (!std::isinf(s_edge)) continue;  // leaves the grid: not a safe-box step
    ++in_grid;
    int per_axis[3] = {0, 0, 0};
    for (int q = 0; q < ref.count; ++q) ++per_axis[ref.axis[q]];
    const int most = std::max({per_axis[0], per_axis[1], per_axis[2]});
#if defined(__AVX2__) && defined(__FMA__)
    {  // the AVX form of the per-axis stage (what this build's walk uses) against the scalar one
      AxisFaces f_s, f_v;
      int end_s[3], end_v[3], count_s = -1, count_v = -1;
      const bool single_s = axis_faces_scalar(v, p.x, p.d, p.cell, s_stop, f_s, end_s, count_s);
      const bool single_v = axis_faces_avx2(v, p.x, p.d, p.cell, s_stop, f_v, end_v, count_v);
      REQUIRE(single_v == single_s);
      CHECK(f_v.up == f_s.up);
      for (int a = 0; a < 3; ++a) {
        CHECK(f_v.t[a] == Approx(f_s.t[a]).epsilon(1e-12).margin(1e-12));
        CHECK(f_v.delta[a] == Approx(f_s.delta[a]).epsilon(1e-12).margin(1e-12));
      }
      if (single_s) {
        CHECK(count_v == count_s);
        for (int a = 0; a < 3; ++a) CHECK(end_v[a] == end_s[a]);
      }
    }
#endif
    AxisFaces f;
    if (crossings_closed_form(v, p.x, p.d, p.cell, s_stop, end, got, f)) {
      ++closed;
      REQUIRE(most <= 1);
    } else if (crossings_two_per_axis(f, p.cell, s_stop, end, got)) {
      ++two;
      REQUIRE(most == 2);
    } else {
      ++merged;
      REQUIRE(most >= 3);
      crossings_from_axis_faces(f, p.cell, s_stop, end, got);
    }
    with_faces += got.count > 0;
    REQUIRE(got.count == ref.count);
    for (int q = 0; q < ref.count; ++q) {
      CHECK(got.s[q] == Approx(ref.s[q]).epsilon(1e-12).margin(1e-12));
      // Faces at the same distance (a corner) may come in either order; otherwise in the march's.
      if (q + 1 < ref.count && std::abs(ref.s[q + 1] - ref.s[q]) < 1e-12) continue;
      if (q > 0 && std::abs(ref.s[q] - ref.s[q - 1]) < 1e-12) continue;
      CHECK(got.axis[q] == ref.axis[q]);
    }
    for (int a = 0; a < 3; ++a) CHECK(end[a] == end_ref[a]);
    // The walk's entry point takes the same stage.
    VoxelCrossings walk;
    int end_walk[3];
    crossings_in_safe_box(v, p.x, p.d, p.cell, s_stop, end_walk, walk);
    REQUIRE(walk.count == got.count);
    for (int q = 0; q < got.count; ++q)
      CHECK((walk.s[q] == got.s[q] && walk.axis[q] == got.axis[q]));
    for (int a = 0; a < 3; ++a) CHECK(end_walk[a] == end[a]);
  }
  CHECK(closed > 38000);
  CHECK(two > 4500);
  CHECK(merged > 1400);
  CHECK(in_grid > 48000);
  CHECK(with_faces > 28000);
}
