// OpenVDB volumes: round trip through write/load, placement, and one clear error per class of
// bad volume (file, grid, voxel index and value named).
#include <catch2/catch.hpp>

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>
#include <vector>

#include "core/error.h"
#include "media/volume_data.h"
#include "media/volume_generators.h"

using namespace femto;
namespace fs = std::filesystem;

namespace {
// A folder private to this process, removed at exit.
struct VolDir {
  fs::path path = fs::temp_directory_path() / ("femto_volume_test_" + std::to_string(getpid()));
  VolDir() { fs::create_directories(path); }
  ~VolDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
};

std::string vol_path(const std::string& name) {
  static const VolDir dir;
  return (dir.path / name).string();
}

VdbMediumDesc desc_for(const std::string& file) {
  VdbMediumDesc d;
  d.file = file;
  d.sigma_t_scale = 1.0;
  return d;
}

// Loads and returns the InputError message ("" if it loaded).
std::string volume_load_error(const VdbMediumDesc& d) {
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
    const std::string msg = volume_load_error(desc_for(vol_path("nope.vdb")));
    CHECK_THAT(msg, Catch::Contains("nope.vdb") && Catch::Contains("not found") && Catch::Contains("/media/m"));
  }
  SECTION("not a VDB file") {
    const std::string f = vol_path("text.vdb");
    FILE* fp = std::fopen(f.c_str(), "w");
    std::fputs("hello", fp);
    std::fclose(fp);
    CHECK_THAT(volume_load_error(desc_for(f)),
               Catch::Contains("text.vdb") && Catch::Contains("OpenVDB"));
  }
  SECTION("grid name not found lists the grids") {
    const std::string f = vol_path("names.vdb");
    write_volume(f, ok, nullptr, nullptr, 1.0, {0, 0, 0}, "smoke");
    CHECK_THAT(volume_load_error(desc_for(f)), Catch::Contains("'density'") && Catch::Contains("smoke"));
  }
  SECTION("wrong grid type") {
    const std::string f = vol_path("double.vdb");
    VdbGridSpec g;
    g.name = "density";
    g.values = &ok;
    g.type = VdbGridSpec::Type::Double;
    write_vdb(f, {g});
    CHECK_THAT(volume_load_error(desc_for(f)), Catch::Contains("density") && Catch::Contains("double"));
  }
  SECTION("level set class") {
    const std::string f = vol_path("levelset.vdb");
    VdbGridSpec g;
    g.name = "density";
    g.values = &ok;
    g.grid_class = VdbGridSpec::Class::LevelSet;
    write_vdb(f, {g});
    CHECK_THAT(volume_load_error(desc_for(f)), Catch::Contains("level set"));
  }
  SECTION("frustum transform") {
    const std::string f = vol_path("frustum.vdb");
    VdbGridSpec g;
    g.name = "density";
    g.values = &ok;
    g.frustum = true;
    write_vdb(f, {g});
    CHECK_THAT(volume_load_error(desc_for(f)), Catch::Contains("non-linear"));
  }
  SECTION("negative density names the voxel and the value") {
    DenseGrid bad = ok;
    bad.at(1, 2, 3) = -0.25f;
    const std::string f = vol_path("negative.vdb");
    write_volume(f, bad, nullptr, nullptr, 1.0, {0, 0, 0});
    CHECK_THAT(volume_load_error(desc_for(f)), Catch::Contains("(1, 2, 3)") && Catch::Contains("-0.25") &&
                                            Catch::Contains("density must be >= 0"));
  }
  SECTION("eta below 1") {
    DenseGrid eta(4, 4, 4, 1.2f);
    eta.at(0, 1, 2) = 0.75f;
    const std::string f = vol_path("eta.vdb");
    write_volume(f, ok, nullptr, &eta, 1.0, {0, 0, 0});
    VdbMediumDesc d = desc_for(f);
    d.eta_grid = "eta";
    CHECK_THAT(volume_load_error(d), Catch::Contains("eta must be >= 1") && Catch::Contains("0.75") &&
                                  Catch::Contains("(0, 1, 2)"));
  }
  SECTION("albedo above 1") {
    DenseGrid albedo(4, 4, 4, 0.9f);
    albedo.at(3, 3, 3) = 1.5f;
    const std::string f = vol_path("albedo.vdb");
    write_volume(f, ok, &albedo, nullptr, 1.0, {0, 0, 0});
    VdbMediumDesc d = desc_for(f);
    d.albedo_grid = "albedo";
    CHECK_THAT(volume_load_error(d), Catch::Contains("albedo must be in [0, 1]") && Catch::Contains("1.5"));
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

namespace {
VdbGridSpec grid_spec(const std::string& name, const DenseGrid& values, float background = 0.0f) {
  VdbGridSpec s;
  s.name = name;
  s.values = &values;
  s.background = background;
  return s;
}
}  // namespace

// Catches: per-grid checks that only look at the density, or at voxels but not the background.
TEST_CASE("bad volumes: transforms, backgrounds, non-finite values, sizes", "[vdb]") {
  DenseGrid ok(4, 4, 4, 0.5f), eta(4, 4, 4, 1.2f);
  VdbMediumDesc d = desc_for(vol_path("more.vdb"));
  d.eta_grid = "eta";
  const auto write = [&](const std::vector<VdbGridSpec>& grids) { write_vdb(d.file, grids); };
  SECTION("eta grid with another voxel size") {
    VdbGridSpec e = grid_spec("eta", eta);
    e.voxel_mm = Vec3(0.5);
    write({grid_spec("density", ok), e});
    CHECK_THAT(volume_load_error(d), Catch::Contains("/media/m/eta_grid: ") && Catch::Contains("voxel size") &&
                                  Catch::Contains("[0.5, 0.5, 0.5]"));
  }
  SECTION("eta grid with another offset") {
    VdbGridSpec e = grid_spec("eta", eta);
    e.origin_mm = {0.25, 0, 0};
    write({grid_spec("density", ok), e});
    CHECK_THAT(volume_load_error(d), Catch::Contains("offset") && Catch::Contains("'eta'"));
  }
  SECTION("density background must be 0") {
    write({grid_spec("density", ok, 0.25f)});
    CHECK_THAT(volume_load_error(desc_for(d.file)), Catch::Contains("background must be 0") && Catch::Contains("0.25"));
  }
  SECTION("eta background below 1") {
    write({grid_spec("density", ok), grid_spec("eta", eta, 0.5f)});
    CHECK_THAT(volume_load_error(d), Catch::Contains("'eta' background") && Catch::Contains("(got 0.5)"));
  }
  SECTION("non-finite density") {
    DenseGrid bad = ok;
    bad.at(2, 0, 1) = std::numeric_limits<float>::quiet_NaN();
    write({grid_spec("density", bad)});
    CHECK_THAT(volume_load_error(desc_for(d.file)), Catch::Contains("(2, 0, 1)") && Catch::Contains("must be finite"));
  }
  SECTION("non-finite eta") {
    DenseGrid bad = eta;
    bad.at(1, 1, 1) = std::numeric_limits<float>::infinity();
    write({grid_spec("density", ok), grid_spec("eta", bad)});
    CHECK_THAT(volume_load_error(d), Catch::Contains("grid 'eta' voxel (1, 1, 1): eta must be finite (got inf)"));
  }
  SECTION("empty density") {
    write({grid_spec("density", DenseGrid(4, 4, 4, 0.0f))});
    CHECK_THAT(volume_load_error(desc_for(d.file)), Catch::Contains("no active voxels"));
  }
  SECTION("wrong grid type for eta names the type") {
    VdbGridSpec e = grid_spec("eta", eta);
    e.type = VdbGridSpec::Type::Double;
    write({grid_spec("density", ok), e});
    CHECK_THAT(volume_load_error(d), Catch::Contains("/media/m/eta_grid") && Catch::Contains("double") &&
                                  Catch::Contains("FloatGrid"));
  }
  SECTION("dense box above 2^30 cells") {
    // Two single voxels far apart: the union of the active boxes is 2001 x 2001 x 1001 cells.
    const DenseGrid one(1, 1, 1, 1.5f);
    VdbGridSpec e = grid_spec("eta", one);
    e.index_offset = {2000, 2000, 1000};
    e.origin_mm = e.index_offset;  // same transform as the density grid (voxel 1 mm)
    write({grid_spec("density", DenseGrid(1, 1, 1, 1.0f)), e});
    d.storage = VdbMediumDesc::Storage::Dense;  // the dense limit (auto keeps this sparse)
    CHECK_THAT(volume_load_error(d), Catch::Contains("2001 x 2001 x 1001") && Catch::Contains("2^30"));
  }
  SECTION("dense grids above the memory left by --max-memory") {
    const DenseGrid one(1, 1, 1, 0.5f), eta_one(1, 1, 1, 1.5f);
    VdbGridSpec a = grid_spec("albedo", one), e = grid_spec("eta", eta_one);
    e.index_offset = e.origin_mm = {127, 127, 127};  // 128^3 cells x 3 grids x 4 bytes = 24 MiB
    write({grid_spec("density", one), a, e});
    d.albedo_grid = "albedo";
    d.max_dense_bytes = 16ull << 20;
    d.storage = VdbMediumDesc::Storage::Dense;  // the dense limit (auto keeps this sparse)
    CHECK_THAT(volume_load_error(d), Catch::Contains("128 x 128 x 128") && Catch::Contains("24 MiB") &&
                                  Catch::Contains("--max-memory"));
  }
  SECTION("unreadable path: a folder") {
    CHECK_THAT(volume_load_error(desc_for(fs::path(d.file).parent_path().string())),
               Catch::Contains("directory"));
  }
}

// Catches: wrong inactive-voxel rules (the eta background-0 convention, used backgrounds) and
// active tiles (pruned constant blocks) left out of the dense copy.
TEST_CASE("volume backgrounds, tiles and the dense box", "[vdb]") {
  // Density: one constant 8^3 block (stored as a tile), placed at VDB index (8, 16, 0).
  DenseGrid dens(8, 8, 8, 2.0f);
  DenseGrid eta(8, 8, 8, 1.25f), eta_zero_bg(8, 8, 8, 0.0f);
  eta.at(7, 7, 7) = 1.5f;
  eta_zero_bg.at(0, 0, 0) = 1.5f;
  VdbGridSpec ds = grid_spec("density", dens);
  ds.index_offset = ds.origin_mm = {8, 16, 0};
  const auto with_eta = [&](const DenseGrid& e, float bg) {
    VdbGridSpec es = grid_spec("eta", e, bg);
    es.index_offset = es.origin_mm = {8, 16, 0};
    const std::string f = vol_path("tiles.vdb");
    write_vdb(f, {ds, es});
    VdbMediumDesc d = desc_for(f);
    d.eta_grid = "eta";
    d.eta = 1.1;
    return load_volume(d, "scene.json", "/media/m");
  };
  SECTION("background >= 1 is used as is") {
    const VolumeData v = with_eta(eta, 1.25f);  // only (7,7,7) is active in the eta grid
    CHECK(v.active_voxels == 512);
    CHECK(v.index_min[0] == 8);
    CHECK(v.index_min[1] == 16);
    CHECK(v.density.min_value == 2.0f);
    CHECK(v.density.max_value == 2.0f);
    CHECK(v.eta.at(0, 0, 0) == 1.25f);
    CHECK(v.eta.at(7, 7, 7) == 1.5f);
    CHECK(v.memory_bytes() == 2 * 512 * sizeof(float));
    // The cell of VDB index (8,16,0) spans world [8,9] x [16,17] x [0,1].
    CHECK(v.world_bounds_min.x == Approx(8));
    CHECK(v.world_bounds_max.y == Approx(24));
  }
  SECTION("background 0 means the medium's constant eta") {
    const VolumeData v = with_eta(eta_zero_bg, 0.0f);
    CHECK(v.eta.at(0, 0, 0) == 1.5f);
    CHECK(v.eta.at(3, 4, 5) == 1.1f);
    CHECK(v.eta.min_value == 1.1f);
  }
}

// Catches: inverse and bounds computed for axis-aligned transforms only.
TEST_CASE("rotated volume: world_to_grid inverts grid_to_world; bounds and voxel size", "[vdb]") {
  DenseGrid dens(3, 5, 7, 1.0f);
  const std::string f = vol_path("rotated.vdb");
  write_volume(f, dens, nullptr, nullptr, 0.5, {-1, 0, 2});
  VdbMediumDesc d = desc_for(f);
  d.transform.scale = {2, 1, 3};
  d.transform.rotate_deg = {30, 45, 60};
  d.transform.translate = {5, -6, 7};
  const VolumeData v = load_volume(d, "scene.json", "/media/m");
  CHECK(v.voxel_size[0] == Approx(1.0));
  CHECK(v.voxel_size[1] == Approx(0.5));
  CHECK(v.voxel_size[2] == Approx(1.5));
  Vec3 lo(1e300), hi(-1e300);
  for (const Vec3 g : {Vec3(0, 0, 0), Vec3(3, 5, 7), Vec3(1.25, 4.5, 0.5), Vec3(3, 0, 7)}) {
    const Vec3 back = v.to_grid(v.to_world(g));
    CHECK(back.x == Approx(g.x).margin(1e-9));
    CHECK(back.y == Approx(g.y).margin(1e-9));
    CHECK(back.z == Approx(g.z).margin(1e-9));
  }
  for (int c = 0; c < 8; ++c) {
    const Vec3 w = v.to_world({(c & 1) ? 3.0 : 0.0, (c & 2) ? 5.0 : 0.0, (c & 4) ? 7.0 : 0.0});
    lo = vmin(lo, w);
    hi = vmax(hi, w);
  }
  CHECK(v.world_bounds_min.x == Approx(lo.x));
  CHECK(v.world_bounds_max.z == Approx(hi.z));
  // Without rotation the grid's corner is the file origin scaled, then translated.
  d.transform.rotate_deg = {0, 0, 0};
  const Vec3 c0 = load_volume(d, "scene.json", "/media/m").to_world({0, 0, 0});
  CHECK(c0.x == Approx(-1 * 2 + 5));
  CHECK(c0.y == Approx(0 * 1 - 6));
  CHECK(c0.z == Approx(2 * 3 + 7));
}

// Catches: example volumes that lose their described shape (zero border, inclusion position).
TEST_CASE("generated cloud and tissue have the documented structure", "[vdb]") {
  const int n = 32;
  const GeneratedVolume cloud = make_cloud(n, 1);
  CHECK(cloud.albedo.empty());
  CHECK(cloud.eta.empty());
  CHECK(cloud.density.max_value > 0.9f);
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j) {
      CHECK(cloud.density.at(0, j, k) == 0.0f);
      CHECK(cloud.density.at(n - 1, j, k) == 0.0f);
    }
  CHECK(cloud.density.at(n / 2, n / 2, n / 2) > 0.0f);

  const GeneratedVolume t = make_tissue(n, 1);
  CHECK(t.eta_background == 1.37f);
  // Inclusion centre: 0.25 half-widths above the centre along +y; a corner is plain tissue.
  const int ci = n / 2, cj = n / 2 + n / 8;
  CHECK(t.eta.at(ci, cj, ci) == 1.45f);
  CHECK(t.eta.at(0, 0, 0) == 1.37f);
  CHECK(t.density.at(ci, cj, ci) > 2.5f);
  CHECK(t.density.at(0, 0, 0) > 0.85f);
  CHECK(t.density.at(0, 0, 0) < 1.15f);
  CHECK(t.density.min_value > 0.85f);
  CHECK(t.density.max_value < 3.5f);
}

#ifndef FEMTO_BINARY
#error "FEMTO_BINARY (path of the femto executable) must be defined by the build"
#endif

namespace {
struct VolumeRun {
  int code = -1;
  std::string out, err;
};

std::string slurp_volume_file(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// Runs the femto binary with `args` (no shell quoting needed: the tests use plain paths).
VolumeRun femto_cli(const std::string& args) {
  const fs::path out = vol_path("cli_stdout.txt"), err = vol_path("cli_stderr.txt");
  const std::string cmd = std::string("'") + FEMTO_BINARY + "' " + args + " >'" + out.string() +
                          "' 2>'" + err.string() + "' </dev/null";
  const int status = std::system(cmd.c_str());
  VolumeRun r;
  if (status != -1 && WIFEXITED(status)) r.code = WEXITSTATUS(status);
  r.out = slurp_volume_file(out);
  r.err = slurp_volume_file(err);
  return r;
}

std::string volume_scene_with(const std::string& medium) {
  return R"({"camera": {"position": [0, 0, 50], "look_at": [0, 0, 0], "resolution": [8, 8]},
    "time": {"bin_width": 10, "bins": 4},
    "media": {"vol": )" + medium + R"(},
    "shapes": [{"type": "box", "min": [-6, -6, -6], "max": [6, 6, 6], "medium": "vol"}],
    "lights": [{"type": "point", "position": [0, 20, 0], "intensity": 1}]})";
}

void write_volume_text(const std::string& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}
}  // namespace

// Catches: make-volume output that differs from the generator, or info that misreports a volume.
TEST_CASE("femto make-volume and femto info", "[vdb]") {
  const std::string cloud = vol_path("cli_cloud.vdb"), tissue = vol_path("cli_tissue.vdb");
  VolumeRun r = femto_cli("make-volume cloud --out " + cloud + " --resolution 16 --seed 5 --quiet");
  REQUIRE(r.code == 0);
  CHECK(r.err.empty());
  CHECK(r.out.empty());
  // The file holds exactly the generator's grid (VDB index = generator cell, 2 mm voxels).
  const GeneratedVolume g = make_cloud(16, 5);
  const VolumeData v = load_volume(desc_for(cloud), "scene.json", "/media/m");
  uint64_t nonzero = 0;
  for (const float x : g.density.v) nonzero += x != 0.0f;
  CHECK(v.active_voxels == nonzero);
  for (int k = 0; k < v.density.nz; ++k)
    for (int j = 0; j < v.density.ny; ++j)
      for (int i = 0; i < v.density.nx; ++i)
        REQUIRE(v.density.at(i, j, k) ==
                g.density.at(i + v.index_min[0], j + v.index_min[1], k + v.index_min[2]));
  CHECK(v.voxel_size[0] == Approx(2.0));
  CHECK(v.world_bounds_min.x >= -16.0);
  CHECK(v.world_bounds_max.x <= 16.0);

  r = femto_cli("make-volume tissue --out " + tissue + " --resolution 12 --voxel 1 --seed 2");
  REQUIRE(r.code == 0);
  CHECK_THAT(r.err, Catch::Contains("12^3 voxels of 1 mm"));
  const std::string scene = vol_path("cli_scene.json");
  write_volume_text(scene, volume_scene_with(R"({"type": "vdb", "file": "cli_tissue.vdb", "sigma_t_scale": 2,
      "albedo_grid": "albedo", "eta_grid": "eta", "eta": 1.37, "g": 0.8})"));
  r = femto_cli("info " + scene);
  REQUIRE(r.code == 0);
  CHECK_THAT(r.out, Catch::Contains("'vol': vdb") &&
                        Catch::Contains("density 'density', albedo 'albedo', eta 'eta'") &&
                        Catch::Contains("[-6, -6, -6] to [6, 6, 6] mm") &&
                        Catch::Contains("12 x 12 x 12 cells") &&
                        Catch::Contains("active voxels:   1728") &&
                        Catch::Contains("1.37 to 1.45 (grid)") && Catch::Contains("memory:") &&
                        Catch::Contains("time: 4 bins of 10 ps") && Catch::Contains("lights: 1"));

  // A bad voxel: exit 2 with one line naming the scene, the medium's key, the grid and the voxel.
  DenseGrid bad(2, 2, 2, 1.0f);
  bad.at(1, 0, 1) = -3.0f;
  write_volume(vol_path("cli_bad.vdb"), bad, nullptr, nullptr, 1.0, {0, 0, 0});
  write_volume_text(scene, volume_scene_with(R"({"type": "vdb", "file": "cli_bad.vdb", "sigma_t_scale": 1})"));
  r = femto_cli("info " + scene);
  CHECK(r.code == 2);
  CHECK(r.out.empty());
  CHECK_THAT(r.err, Catch::Contains("cli_scene.json: /media/vol/density_grid: ") &&
                        Catch::Contains("grid 'density' voxel (1, 0, 1): density must be >= 0 (got -3)"));
  CHECK(std::count(r.err.begin(), r.err.end(), '\n') == 1);
}

// Catches: flags that are silently ignored or errors that exit with the wrong code.
TEST_CASE("femto make-volume and femto info: help and bad input", "[vdb]") {
  VolumeRun r = femto_cli("make-volume --help");
  CHECK(r.code == 0);
  CHECK_THAT(r.out, Catch::Contains("cloud") && Catch::Contains("tissue") &&
                        Catch::Contains("--resolution") && Catch::Contains("--voxel") &&
                        Catch::Contains("--seed") && Catch::Contains("eta 1.45"));
  r = femto_cli("info --help");
  CHECK(r.code == 0);
  CHECK_THAT(r.out, Catch::Contains("SCENE.json"));
  const std::string out = vol_path("never.vdb");
  for (const std::string& args : std::vector<std::string>{
           "make-volume smoke --out " + out, "make-volume cloud", "make-volume --out " + out,
        "make-volume cloud --out " + out + " --resolution 2",
        "make-volume cloud --out " + out + " --voxel -1",
        "make-volume cloud --out " + vol_path("no/such/dir/x.vdb"), "make-volume cloud --bogus",
        "info", "info " + vol_path("missing.json"), "info a.json b.json"}) {
    INFO(args);
    r = femto_cli(args);
    CHECK(r.code == 2);
    CHECK_THAT(r.err, Catch::StartsWith("femto: error: "));
  }
  CHECK_FALSE(fs::exists(out));
}
