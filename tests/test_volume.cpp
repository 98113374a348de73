// OpenVDB volumes: round trip through write/load, placement, and one clear error per class of
// bad volume (file, grid, voxel index and value named).
#include <catch2/catch.hpp>

#include <filesystem>
#include <unistd.h>

#include "core/error.h"
#include "media/volume_data.h"
#include "media/volume_generators.h"

using namespace femto;
namespace fs = std::filesystem;

namespace {
std::string vol_path(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("femto_volume_test_" + std::to_string(getpid()));
  fs::create_directories(dir);
  return (dir / name).string();
}

VdbMediumDesc desc_for(const std::string& file) {
  VdbMediumDesc d;
  d.file = file;
  d.sigma_t_scale = 1.0;
  return d;
}

// Loads and returns the InputError message ("" if it loaded).
std::string load_error(const VdbMediumDesc& d) {
  try {
    load_volume(d, "scene.json", "/media/m");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}
}  // namespace

// Catches: transposed axes, off-by-one dense boxes, transforms applied in the wrong order.
TEST_CASE("volume round trip keeps values and placement", "[vdb]") {
  DenseGrid density(5, 4, 3, 0.0f), eta(5, 4, 3, 1.25f);
  for (int k = 0; k < 3; ++k)
    for (int j = 0; j < 4; ++j)
      for (int i = 0; i < 5; ++i) density.at(i, j, k) = 0.5f + 0.125f * static_cast<float>(i + 10 * j + 100 * k);
  density.update_range();
  eta.update_range();
  const std::string file = vol_path("roundtrip.vdb");
  write_volume(file, density, nullptr, &eta, 2.0, {10, 20, 30});
  VdbMediumDesc d = desc_for(file);
  d.eta_grid = "eta";
  const VolumeData v = load_volume(d, "scene.json", "/media/m");
  REQUIRE(v.density.nx == 5);
  REQUIRE(v.density.ny == 4);
  REQUIRE(v.density.nz == 3);
  for (int k = 0; k < 3; ++k)
    for (int j = 0; j < 4; ++j)
      for (int i = 0; i < 5; ++i) REQUIRE(v.density.at(i, j, k) == density.at(i, j, k));
  REQUIRE(v.eta.at(4, 3, 2) == 1.25f);
  // Grid corner (0,0,0) sits at the origin given to write_volume; voxels are 2 mm.
  const Vec3 w = v.to_world({1, 2, 3});
  CHECK(w.x == Approx(12.0));
  CHECK(w.y == Approx(24.0));
  CHECK(w.z == Approx(36.0));
  const Vec3 g = v.to_grid({17.0, 21.0, 31.0});
  CHECK(g.x == Approx(3.5));
  CHECK(g.y == Approx(0.5));
  CHECK(g.z == Approx(0.5));
  // The scene's transform is applied after the file's: scale 2 then translate.
  d.transform.scale = {2, 2, 2};
  d.transform.translate = {1, 0, 0};
  const VolumeData t = load_volume(d, "scene.json", "/media/m");
  const Vec3 wt = t.to_world({1, 2, 3});
  CHECK(wt.x == Approx(2 * 12.0 + 1));
  CHECK(wt.y == Approx(2 * 24.0));
}

// Catches: silent acceptance of unusable volumes; messages that do not say where the problem is.
TEST_CASE("bad volumes give one clear error each", "[vdb]") {
  DenseGrid ok(4, 4, 4, 0.5f);
  ok.update_range();
  SECTION("missing file") {
    const std::string msg = load_error(desc_for(vol_path("nope.vdb")));
    CHECK_THAT(msg, Catch::Contains("nope.vdb") && Catch::Contains("not found") && Catch::Contains("/media/m"));
  }
  SECTION("not a VDB file") {
    const std::string f = vol_path("text.vdb");
    FILE* fp = std::fopen(f.c_str(), "w");
    std::fputs("hello", fp);
    std::fclose(fp);
    CHECK_THAT(load_error(desc_for(f)), Catch::Contains("text.vdb") && Catch::Contains("OpenVDB"));
  }
  SECTION("grid name not found lists the grids") {
    const std::string f = vol_path("names.vdb");
    write_volume(f, ok, nullptr, nullptr, 1.0, {0, 0, 0}, "smoke");
    CHECK_THAT(load_error(desc_for(f)), Catch::Contains("'density'") && Catch::Contains("smoke"));
  }
  SECTION("wrong grid type") {
    const std::string f = vol_path("double.vdb");
    VdbGridSpec g;
    g.name = "density";
    g.values = &ok;
    g.type = VdbGridSpec::Type::Double;
    write_vdb(f, {g});
    CHECK_THAT(load_error(desc_for(f)), Catch::Contains("density") && Catch::Contains("double"));
  }
  SECTION("level set class") {
    const std::string f = vol_path("levelset.vdb");
    VdbGridSpec g;
    g.name = "density";
    g.values = &ok;
    g.grid_class = VdbGridSpec::Class::LevelSet;
    write_vdb(f, {g});
    CHECK_THAT(load_error(desc_for(f)), Catch::Contains("level set"));
  }
  SECTION("frustum transform") {
    const std::string f = vol_path("frustum.vdb");
    VdbGridSpec g;
    g.name = "density";
    g.values = &ok;
    g.frustum = true;
    write_vdb(f, {g});
    CHECK_THAT(load_error(desc_for(f)), Catch::Contains("non-linear"));
  }
  SECTION("negative density names the voxel and the value") {
    DenseGrid bad = ok;
    bad.at(1, 2, 3) = -0.25f;
    const std::string f = vol_path("negative.vdb");
    write_volume(f, bad, nullptr, nullptr, 1.0, {0, 0, 0});
    CHECK_THAT(load_error(desc_for(f)), Catch::Contains("(1, 2, 3)") && Catch::Contains("-0.25") &&
                                            Catch::Contains("density must be >= 0"));
  }
  SECTION("eta below 1") {
    DenseGrid eta(4, 4, 4, 1.2f);
    eta.at(0, 1, 2) = 0.75f;
    const std::string f = vol_path("eta.vdb");
    write_volume(f, ok, nullptr, &eta, 1.0, {0, 0, 0});
    VdbMediumDesc d = desc_for(f);
    d.eta_grid = "eta";
    CHECK_THAT(load_error(d), Catch::Contains("eta must be >= 1") && Catch::Contains("0.75") &&
                                  Catch::Contains("(0, 1, 2)"));
  }
  SECTION("albedo above 1") {
    DenseGrid albedo(4, 4, 4, 0.9f);
    albedo.at(3, 3, 3) = 1.5f;
    const std::string f = vol_path("albedo.vdb");
    write_volume(f, ok, &albedo, nullptr, 1.0, {0, 0, 0});
    VdbMediumDesc d = desc_for(f);
    d.albedo_grid = "albedo";
    CHECK_THAT(load_error(d), Catch::Contains("albedo must be in [0, 1]") && Catch::Contains("1.5"));
  }
}

// Catches: generators that depend on anything but (resolution, seed), or leave their ranges.
TEST_CASE("volume generators are deterministic and in range", "[vdb]") {
  const GeneratedVolume a = make_cloud(24, 3), b = make_cloud(24, 3), c = make_cloud(24, 4);
  REQUIRE(a.density.v == b.density.v);
  REQUIRE(a.density.v != c.density.v);
  for (float x : a.density.v) REQUIRE((x >= 0.0f && x <= 1.0f));
  const GeneratedVolume t = make_tissue(16, 1);
  REQUIRE_FALSE(t.eta.empty());
  for (float x : t.eta.v) REQUIRE((x == 0.0f || (x >= 1.37f && x <= 1.45f)));
  for (float x : t.albedo.v) REQUIRE((x > 0.8f && x < 1.0f));
}
