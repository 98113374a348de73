// Voxel media as tissues (docs/tissue.md, "Voxel media"): OpenVDB density/albedo/eta media walked
// voxel by voxel with their own optics, checked against the labelled-volume walk and the loader.
#include <catch2/catch.hpp>

#include <filesystem>

#include "core/tissue/scene.h"
#include "core/tissue/simulate.h"
#include "media/volume_data.h"
#include "run_femto.h"
#include "temp_dir.h"
#include "tissue_setups.h"

using namespace femto;
using namespace femto::tissue;
namespace fs = std::filesystem;

namespace {
// Voxel (i, j, k)'s optics: a smooth variation of mu_s and n with a few repeated values, so that
// some neighbouring voxels share their optics (crossed inside a step) and others do not.
VoxelOptics optics_of_voxel(int i, int j, int k, int palette) {
  const int q = (3 * i + 5 * j + 7 * k) % palette;
  VoxelOptics o;
  o.mu_a = static_cast<float>(0.01 + 0.02 * (q % 3));
  o.mu_s = static_cast<float>(1.0 + 0.7 * q);
  o.n = static_cast<float>(q % 4 == 0 ? 1.33 : 1.37 + 0.01 * (q % 5));
  return o;
}

// The same tissue twice: as a voxel medium, and as a labelled volume with one label per distinct
// voxel optics (the labelled walk stops at exactly the faces where the optics change).
void voxel_and_labelled(int palette, Setup& voxel, Setup& labelled) {
  const double g = 0.7;
  voxel = test::tissue_box(10, 9, 8, 0.5, TissueOptics{0, 1, g, 1.33});
  LabelVolume& v = voxel.volume;
  v.voxel_optics.resize(v.cells());
  labelled = voxel;
  LabelVolume& l = labelled.volume;
  l.voxel_optics.clear();
  l.optics.resize(1);
  std::vector<VoxelOptics> seen;
  for (int i = 0; i < v.n[0]; ++i)
    for (int j = 0; j < v.n[1]; ++j)
      for (int k = 0; k < v.n[2]; ++k) {
        const VoxelOptics o = optics_of_voxel(i, j, k, palette);
        v.voxel_optics[v.index(i, j, k)] = o;
        size_t label = 0;
        while (label < seen.size() && seen[label] != o) ++label;
        if (label == seen.size()) {
          seen.push_back(o);
          l.optics.push_back(TissueOptics{0, 0, g, 0});
        }
        l.labels[l.index(i, j, k)] = static_cast<uint16_t>(label + 1);
      }
  // The labels' coefficients from the stored floats, in a loop of their own: GCC 12's SLP
  // vectoriser (-O2 and up) drops the float rounding when a value just converted to float is
  // read back as a double in the same block.
  for (size_t label = 0; label < seen.size(); ++label) {
    TissueOptics& o = l.optics[label + 1];
    o.mu_a = seen[label].mu_a, o.mu_s = seen[label].mu_s, o.n = seen[label].n;
  }
  for (Setup* s : {&voxel, &labelled}) {
    s->fresnel = true;
    s->source.type = Source::Type::Gaussian;
    s->source.waist = 1.0;
    s->source.direction = normalize(Vec3(0.2, -0.1, 1));
    s->source.position = {2.4, 2.3, -3};
    s->source.specular = true;
    s->time = TimeAxis{0, 15, 10};
    s->detectors = {{{2.5, 3.5, 0}, 1.0, 0.0}, {{2.5, 2.2, 4}, 1.5, 0.4}};
    s->faces = true;
    s->photons = 6000;
    s->seed = 11;
  }
}
}  // namespace

// Catches a voxel walk that reads the wrong voxel's optics, stops at the wrong faces, or
// reflects/refracts with the wrong indices: with one label per distinct voxel optics the labelled
// walk (checked against physics in test_tissue*.cpp) takes the same steps, so every output must
// be bit-identical. Both a few repeated values (faces crossed inside a step) and all-distinct ones.
TEST_CASE("a voxel medium walks exactly as the equivalent labelled volume", "[tissue]") {
  for (int palette : {4, 37}) {
    INFO("palette " << palette);
    Setup voxel, labelled;
    voxel_and_labelled(palette, voxel, labelled);
    REQUIRE(labelled.volume.optics.size() > 3);
    const Result a = simulate(voxel), b = simulate(labelled);
    test::check_same_outputs(a, b);
    CHECK(std::abs(a.balance.residual()) < 1e-9);
    // Label 1 names the whole medium: its absorbed energy is the total.
    REQUIRE(a.absorbed_per_label.size() == 2);
    CHECK(a.absorbed_per_label[1] == Approx(b.balance.absorbed).epsilon(1e-12));
    REQUIRE(a.detected.size() > 20);
  }
}

// Catches grids read into the wrong voxels (OpenVDB is x fastest, the walk z fastest), coefficients
// built wrongly from density, albedo and eta, a misplaced grid, and inactive eta voxels that do not
// take the constant eta.
TEST_CASE("voxel media load from OpenVDB density, albedo and eta grids", "[tissue]") {
  test::TempDir tmp("femto_tissue_vdb_medium");
  DenseGrid density(4, 3, 2), albedo(4, 3, 2), eta(4, 3, 2);
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 4; ++i) {
        density.at(i, j, k) = static_cast<float>(0.5 + i + 0.25 * j + 2 * k);
        albedo.at(i, j, k) = static_cast<float>(0.5 + 0.1 * i);
        eta.at(i, j, k) = i == 2 && j == 1 ? 0.0f : static_cast<float>(1.3 + 0.05 * k);
      }
  for (DenseGrid* d : {&density, &albedo, &eta}) d->update_range();
  write_volume((tmp.dir / "m.vdb").string(), density, &albedo, &eta, 0.5, Vec3(1, 2, 3));
  const std::string rest =
      R"("source": {"type": "pencil", "position": [2, 2.7, 2], "direction": [0, 0, 1]},)"
      R"("time": {"bin_width": 10, "bins": 3}, "photons": 200}})";
  const std::string medium =
      R"("medium": {"type": "vdb", "file": "m.vdb", "sigma_t_scale": 2, "albedo_grid": "albedo",)"
      R"("eta_grid": "eta", "eta": 1.45, "g": 0.6}, "outside_n": 1.1,)";
  const Setup s = load_tissue_scene(R"({"tissue": {)" + medium + rest, "t.json", tmp.dir.string());
  const LabelVolume& v = s.volume;
  CHECK(v.n[0] == 4);
  CHECK(v.n[1] == 3);
  CHECK(v.n[2] == 2);
  CHECK(v.voxel == Approx(0.5));
  CHECK(v.origin.x == Approx(1));
  CHECK(v.origin.y == Approx(2));
  CHECK(v.origin.z == Approx(3));
  REQUIRE(v.optics.size() == 2);
  CHECK(v.optics[0].n == 1.1);
  CHECK(v.optics[1].g == 0.6);
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 4; ++i) {
        INFO(i << ", " << j << ", " << k);
        const VoxelOptics& o = v.voxel_optics[v.index(i, j, k)];
        const double mu_t = 2.0 * density.at(i, j, k), a = albedo.at(i, j, k);
        CHECK(o.mu_s == static_cast<float>(a * mu_t));
        CHECK(o.mu_a == Approx(mu_t * (1 - a)).epsilon(1e-6));
        CHECK(o.n == (i == 2 && j == 1 ? 1.45f : eta.at(i, j, k)));
        CHECK(v.label_at(i, j, k) == 1);
      }
  // It runs, with the energy balanced.
  const Result r = simulate(s);
  CHECK(std::abs(r.balance.residual()) < 1e-9 * static_cast<double>(r.photons));
  CHECK(r.balance.absorbed > 0);
}

// Catches voxel-medium scenes that run although femto cannot walk them as given: exit 2 with one
// message naming the file, the key and the value, and no output folder.
TEST_CASE("femto render refuses bad voxel-medium tissue scenes", "[tissue][cli]") {
  test::TempDir tmp("femto_tissue_vdb_bad");
  DenseGrid density(3, 3, 3, 1.0f);
  density.update_range();
  write_volume((tmp.dir / "m.vdb").string(), density, nullptr, nullptr, 1.0, Vec3(0, 0, 0));
  VdbGridSpec flat;
  flat.name = "density";
  flat.values = &density;
  flat.voxel_mm = {1, 1, 2};
  write_vdb((tmp.dir / "flat.vdb").string(), {flat});
  const std::string rest =
      R"("source": {"type": "pencil", "position": [1.5, 1.5, -1], "direction": [0, 0, 1]},)"
      R"("time": {"bin_width": 10, "bins": 3}, "photons": 100}})";
  const std::string good_medium = R"("medium": {"file": "m.vdb", "sigma_t_scale": 1})";
  struct Case {
    std::string tissue, message;
  };
  const std::vector<Case> cases = {
      {R"("medium": {"file": "m.vdb", "sigma_t_scale": 1, "interpolation": "trilinear"},)",
       "bad.json: /tissue/medium/interpolation: tissue volumes are voxel-constant"},
      {good_medium + R"(, "volume": {"shape": [2, 2, 2], "fill": 1, "voxel": 1},)",
       "bad.json: /tissue/volume: a tissue is either \"medium\""},
      {R"("medium": {"file": "m.vdb"},)", "bad.json: /tissue/medium/sigma_t_scale: required"},
      {R"("medium": {"file": "none.vdb", "sigma_t_scale": 1},)", "none.vdb"},
      {R"("medium": {"file": "flat.vdb", "sigma_t_scale": 1},)", "bad.json: /tissue/medium/file"},
      {R"("medium": {"file": "m.vdb", "sigma_t_scale": 1, "albedo": 1.5},)",
       "bad.json: /tissue/medium/albedo: must be in [0, 1] (got 1.5)"},
  };
  for (const Case& c : cases) {
    test::write_file(tmp.dir / "bad.json", R"({"tissue": {)" + c.tissue + rest);
    const auto run = test::run_femto({"render", "bad.json", "--out", "out"}, tmp.dir);
    INFO(c.tissue << "\n" << run.err);
    CHECK(run.code == 2);
    CHECK(run.err.find(c.message) != std::string::npos);
    CHECK(!fs::exists(tmp.dir / "out"));
  }
  // The good one runs and writes its summary.
  test::write_file(tmp.dir / "good.json", R"({"tissue": {)" + good_medium + "," + rest);
  const auto run = test::run_femto({"render", "good.json", "--out", "out"}, tmp.dir);
  INFO(run.err);
  CHECK(run.code == 0);
  CHECK(fs::exists(tmp.dir / "out" / "summary.json"));
}

// Catches `femto info` refusing tissue scenes or describing them wrongly (labels, voxel media),
// and bad tissue scenes that it accepts.
TEST_CASE("femto info summarises tissue scenes", "[tissue][cli]") {
  const fs::path scenes = fs::path(FEMTO_SOURCE_DIR) / "data" / "scenes";
  const auto cube = test::run_femto({"info", (scenes / "cube60.json").string()}, scenes);
  INFO(cube.err);
  CHECK(cube.code == 0);
  CHECK(cube.out.find("volume: 60 x 60 x 60 voxels of 1 mm") != std::string::npos);
  CHECK(cube.out.find("label 1: mu_a 0.005 /mm, mu_s 1 /mm, g 0.01, n 1.37; 216000 voxels") !=
        std::string::npos);
  CHECK(cube.out.find("time: 50 gates of 100 ps") != std::string::npos);
  const auto vdb = test::run_femto({"info", (scenes / "tissue_vdb.json").string()}, scenes);
  INFO(vdb.err);
  CHECK(vdb.code == 0);
  CHECK(vdb.out.find("medium: optics per voxel") != std::string::npos);
  CHECK(vdb.out.find("n 1.37 to 1.45, g 0.8") != std::string::npos);
  test::TempDir tmp("femto_tissue_info_bad");
  std::string text = test::read_file(scenes / "cube60.json");
  const std::string g = R"("g": 0.01)";
  text.replace(text.find(g), g.size(), R"("g": 1.5)");
  test::write_file(tmp.dir / "bad.json", text);
  const auto bad = test::run_femto({"info", "bad.json"}, tmp.dir);
  CHECK(bad.code == 2);
  CHECK(bad.err.find("bad.json: /tissue/labels/0/g: must be in (-1, 1)") != std::string::npos);
}
