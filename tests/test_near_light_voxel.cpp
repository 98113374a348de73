// auto's near-light rule in a voxel medium: a segment's collisions sample the light's peak with
// the extinction around the light, not the one where the segment starts.
#include <catch2/catch.hpp>

#include <cmath>
#include <string>
#include <vector>

#include "core/constants.h"
#include "core/scene.h"
#include "media/volume_data.h"
#include "scene_builders.h"
#include "temp_dir.h"

using namespace femto;
using namespace femto::test;

// Catches: the rule weighing a light's distance from a segment with the extinction at the
// segment's start (here a dense slab around the camera, 0.5 / mm: the light 2 mm beside the ray
// looks 1 mean free path away, and its peak is left to the collisions, whose 1 / r^2 there gives
// fireflies) instead of at the light (thin fog, 0.05 / mm: 0.1 mean free paths, a near-light
// pair); a light read with another light's extinction (the second light sits in a dense pocket,
// 1 / mm, 2.5 mm beside the ray: collisions alone); and either light gathered twice or by
// neither (every bin against collision next-event estimation, within 4 standard errors), which
// includes the camera segments that pass the medium without a collision: only those that meet no
// extinction at all may go without a plan (15% pass this one, and dropping their connections
// takes 8% off the peak).
TEST_CASE("auto's near-light rule in a voxel medium reads the extinction at the light",
          "[time-sampling][statistical]") {
  TempDir tmp("femto_near_light_voxel");
  // 0.5 mm voxels over x, y in [-4, 4), z in [-1, 29); nearest lookup: piecewise constant.
  const int nx = 16, ny = 16, nz = 60;
  const double voxel = 0.5;
  const Vec3 origin(-4, -4, -1);
  DenseGrid density(nx, ny, nz, 0.05f);
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        const Vec3 c = origin + Vec3(i + 0.5, j + 0.5, k + 0.5) * voxel;
        if (c.z < 1.0) density.at(i, j, k) = 0.5f;  // the slab the camera sits in
        if (c.x > 1.5 && c.x < 3.5 && std::abs(c.y) < 1.0 && c.z > 21.0 && c.z < 23.0)
          density.at(i, j, k) = 1.0f;  // the second light's pocket
      }
  density.update_range();
  const std::string vdb = (tmp.dir / "slab.vdb").string();
  write_volume(vdb, density, nullptr, nullptr, voxel, origin);

  SceneDesc d;
  d.source = "near light in voxels";
  d.camera = ortho_camera({0, 0, 0}, {0, 0, 1}, 1e-4, 1, 1);  // one ray along +z from the slab
  d.time.t_start_ps = 45;
  d.time.bin_width_ps = 5;
  d.time.bins = 40;
  d.media.push_back(vdb_medium("voxels", vdb, 0.8, 0.4));
  d.global_medium = 0;
  LightDesc near_light;
  near_light.position = {0, 2, 15};
  near_light.intensity = RGB(1000.0);
  d.lights.push_back(near_light);
  LightDesc pocket_light;
  pocket_light.position = {2.5, 0, 22};
  pocket_light.intensity = RGB(1000.0);
  d.lights.push_back(pocket_light);
  // Every vertex before the near light reaches the film in the bin of its onset; the pocket
  // light's first light comes 23 ps later.
  const TimeAxis& axis = d.time;
  const int peak = axis.bin_of(std::sqrt(15.0 * 15.0 + 2.0 * 2.0) / kSpeedOfLight);
  REQUIRE(peak >= 0);
  REQUIRE(axis.bin_of(std::sqrt(22.0 * 22.0 + 2.5 * 2.5) / kSpeedOfLight) > peak + 2);

  // The collisions' reference takes 4x the samples: its peak is what auto improves on.
  std::vector<MeanSE> bins[2];
  const ConnectionSampling kinds[2] = {ConnectionSampling::Auto, ConnectionSampling::Collision};
  const int spp[2] = {1000, 4000};
  for (int k = 0; k < 2; ++k) {
    SceneDesc e = d;
    e.media[0].connection = kinds[k];
    const auto films = render_batches(e, spp[k], 16, /*max_depth=*/1);
    for (int i = 0; i < axis.bins; ++i) bins[k].push_back(bin_mean_se(films, i));
  }
  int compared = 0;
  for (int i = 0; i < axis.bins; ++i) {
    const MeanSE &a = bins[0][i], &c = bins[1][i];
    const double se = std::sqrt(a.se * a.se + c.se * c.se);
    INFO("bin " << i << ": auto " << a.mean << " +- " << a.se << ", collisions " << c.mean << " +- "
                << c.se);
    CHECK(std::abs(a.mean - c.mean) <= 4.0 * se + 1e-12 * std::abs(c.mean));
    compared += c.mean > 0;
  }
  CHECK(compared >= 15);
  const double rv_auto = std::pow(bins[0][peak].se / bins[0][peak].mean, 2);
  const double rv_coll = 4.0 * std::pow(bins[1][peak].se / bins[1][peak].mean, 2);  // at 1000
  INFO("peak bin " << peak << ": relative variance auto " << rv_auto << ", collisions " << rv_coll);
  CHECK(rv_auto < 0.3 * rv_coll);
}
