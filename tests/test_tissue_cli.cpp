// Tissue optics through the femto command line: bad scenes refused, the documented outputs of
// cube60 and cube60_fresnel, the memory statement before a run.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/io/nifti.h"
#include "core/io/npy.h"
#include "run_femto.h"
#include "temp_dir.h"

using namespace femto;
namespace fs = std::filesystem;

// Catches bad tissue scenes that run anyway or leave files behind: exit 2, one message naming the
// file, the key and the value, and no output folder.
TEST_CASE("femto render refuses bad tissue scenes with exit 2 and writes nothing",
          "[tissue][cli]") {
  femto::test::TempDir tmp("femto_tissue_cli");
  const std::string good =
      femto::test::read_file(fs::path(FEMTO_SOURCE_DIR) / "data/scenes/cube60.json");
  struct Case {
    std::string from, to, message;
  };
  const std::vector<Case> cases = {
      {R"("mu_s": 1.0)", R"("mu_s": -1)",
       "cube.json: /tissue/labels/0/mu_s: must be in [0, 1e+06] (got -1)"},
      {R"("boundary": "matched")", R"("boundary": "mirror")",
       "cube.json: /tissue/boundary: must be one of \"fresnel\", \"matched\" (got \"mirror\")"},
      {R"("bins": 50)", R"("bins": 50, "binz": 3)", "cube.json: /tissue/time/binz: unknown key"},
      {R"("fill": 1)", R"("fill": 7)",
       "cube.json: /tissue/labels: label 7 occurs in the volume but has no optical properties"},
      {R"("type": "pencil")", R"("type": "laser")",
       "cube.json: /tissue/source/type: must be one of"},
      {R"("type": "pencil")", R"("type": "sphere", "radius": 2)",
       "cube.json: /tissue/source/direction: a sphere source has no direction"},
      {R"("type": "pencil", "position": [30, 30, 0], "direction": [0, 0, 1])",
       R"("type": "quad", "position": [0, 0, -1], "edge1": [60, 0, 0], "edge2": [-6, 0, 0])",
       "cube.json: /tissue/source/edge2: parallel to edge1: the quad has no area (got [-6,0,0])"},
      {R"("type": "pencil", "position": [30, 30, 0], "direction": [0, 0, 1])",
       R"("type": "quad", "position": [0, 0, -1], "edge2": [0, 60, 0])",
       "cube.json: /tissue/source/edge1: required for a quad source"},
      {R"("type": "pencil", "position": [30, 30, 0], "direction": [0, 0, 1])",
       R"("type": "box", "min": [0, 0, -2], "max": [60, 60, -3])",
       "cube.json: /tissue/source/max: must exceed 'min' on every axis (got [60,60,-3])"},
      {R"("type": "pencil", "position": [30, 30, 0], "direction": [0, 0, 1])",
       R"("type": "mesh", "file": "missing.obj")",
       "cube.json: /tissue/source/file: mesh file not found"},
      {R"("type": "pencil", "position": [30, 30, 0], "direction": [0, 0, 1])",
       R"("type": "mesh", "position": [0, 0, 0], "file": "missing.obj")",
       "cube.json: /tissue/source/position: a mesh source has no position"},
      {R"("type": "pencil")", R"("type": "isotropic")",
       "cube.json: /tissue/source/direction: an isotropic source has no direction\n"},
  };
  for (const Case& c : cases) {
    std::string text = good;
    const size_t at = text.find(c.from);
    REQUIRE(at != std::string::npos);
    text.replace(at, c.from.size(), c.to);
    femto::test::write_file(tmp.dir / "cube.json", text);
    const auto run =
        femto::test::run_femto({"render", "cube.json", "--out", "out", "--photons", "10"}, tmp.dir);
    INFO(run.err);
    CHECK(run.code == 2);
    CHECK(run.err.find(c.message) != std::string::npos);
    CHECK(!fs::exists(tmp.dir / "out"));
  }
  // Memory beyond --max-memory is refused before anything is written.
  femto::test::write_file(tmp.dir / "cube.json", good);
  const auto big = femto::test::run_femto(
      {"render", "cube.json", "--out", "out", "--max-memory", "10M"}, tmp.dir);
  CHECK(big.code == 2);
  CHECK(big.err.find("more than --max-memory") != std::string::npos);
  CHECK(!fs::exists(tmp.dir / "out"));
  // Camera-only flags do not apply.
  const auto spp = femto::test::run_femto({"render", "cube.json", "--spp", "4"}, tmp.dir);
  CHECK(spp.code == 2);
  CHECK(spp.err.find("--spp: does not apply to the tissue scene") != std::string::npos);
}

// Catches outputs that are missing, mis-shaped or inconsistent with the summary: femto render on
// the cube60 scene with few photons; fluence.npy is (X,Y,Z,T) and integrates (times mu_a) to the
// absorbed fraction, since the fluence per gate times mu_a is the energy absorbed per mm^3.
TEST_CASE("femto render runs a tissue scene and writes the documented outputs", "[tissue][cli]") {
  femto::test::TempDir tmp("femto_tissue_run");
  const std::string scene = (fs::path(FEMTO_SOURCE_DIR) / "data/scenes/cube60.json").string();
  const auto run = femto::test::run_femto(
      {"render", scene, "--out", "out", "--photons", "2000", "--quiet"}, tmp.dir);
  INFO(run.err);
  REQUIRE(run.code == 0);
  for (const char* f : {"fluence.npy", "fluence_rate.npy", "fluence.nii", "tpsf.npy", "tpsf.csv",
                        "detected_photons.npy", "detected_ppath.npy", "detected_exit.npy",
                        "exitance_zmin.npy", "summary.json", "render.json"})
    CHECK(fs::exists(tmp.dir / "out" / f));
  std::vector<size_t> shape;
  std::vector<float> fl;
  read_npy_float32((tmp.dir / "out/fluence.npy").string(), shape, fl);
  CHECK(shape == std::vector<size_t>{60, 60, 60, 50});
  const nlohmann::json sum =
      nlohmann::json::parse(femto::test::read_file(tmp.dir / "out/summary.json"));
  double absorbed = 0;
  for (float x : fl) absorbed += x;
  absorbed *= 0.005;                      // mu_a times fluence (1/mm^2) times the 1 mm^3 voxel
  const double alive_absorbed_after = 0;  // photons stop at the window end: nothing after it
  CHECK(absorbed ==
        Approx(sum["absorbed_fraction"].get<double>() + alive_absorbed_after).epsilon(1e-4));
  CHECK(std::abs(sum["energy_balance"]["residual"].get<double>()) < 1e-12);
  for (const auto& det : sum["detectors"]) {  // a TPSF's Gaussian distance lies in [0, 1]
    if (det["pulse"].is_null()) continue;     // nothing detected in 2000 photons
    const auto& gd = det["pulse"]["gaussian_distance"];
    CHECK(gd["value"].get<double>() >= 0);
    CHECK(gd["value"].get<double>() <= 1);
    CHECK(gd["noise_floor"].get<double>() >= 0);
  }
  const NiftiVolume nv = read_nifti((tmp.dir / "out/fluence.nii").string());
  CHECK(nv.dim == std::array<int, 4>{60, 60, 60, 50});
  CHECK(nv.data[((7ul * 60 + 30) * 60 + 30) * 60 + 30] ==
        Approx(fl[((30ul * 60 + 30) * 60 + 30) * 50 + 7]));
}

// Catches a shipped Fresnel benchmark scene that no longer runs as documented: cube60_fresnel
// through plain femto render, its balance closed and more light kept inside than with matched
// boundaries (internal reflection: absorbed 0.273 against 0.177 at 10^6 photons, docs/tissue.md).
TEST_CASE("femto render runs cube60_fresnel", "[tissue][cli]") {
  femto::test::TempDir tmp("femto_tissue_fresnel");
  const std::string scene =
      (fs::path(FEMTO_SOURCE_DIR) / "data/scenes/cube60_fresnel.json").string();
  const auto run = femto::test::run_femto(
      {"render", scene, "--out", "out", "--photons", "4000", "--quiet"}, tmp.dir);
  INFO(run.err);
  REQUIRE(run.code == 0);
  const nlohmann::json sum =
      nlohmann::json::parse(femto::test::read_file(tmp.dir / "out/summary.json"));
  CHECK(std::abs(sum["energy_balance"]["residual"].get<double>()) < 1e-12);
  // Each photon's absorbed share lies in [0, 1]: its standard error is below 0.5 / sqrt(4000).
  CHECK(sum["absorbed_fraction"].get<double>() ==
        Approx(0.2729).margin(4 * 0.5 / std::sqrt(4000.0)));
  CHECK(fs::exists(tmp.dir / "out/fluence.npy"));
}

// Catches a run whose memory is not stated before it starts, or stated as something other than
// the estimate it is checked against (--max-memory) and records: the line on stderr names the
// fluence volume per thread and the total, and the total is render.json's estimate.
TEST_CASE("femto render states a tissue run's memory before it starts", "[tissue][cli]") {
  femto::test::TempDir tmp("femto_tissue_memory");
  const std::string scene = (fs::path(FEMTO_SOURCE_DIR) / "data/scenes/cube60.json").string();
  const auto run = femto::test::run_femto(
      {"render", scene, "--out", "out", "--photons", "500", "--threads", "2"}, tmp.dir);
  INFO(run.err);
  REQUIRE(run.code == 0);
  const nlohmann::json rec =
      nlohmann::json::parse(femto::test::read_file(tmp.dir / "out/render.json"));
  const uint64_t need = rec["memory_bytes_estimate"].get<uint64_t>();
  const size_t line = run.err.find("memory: fluence volume ");
  REQUIRE(line != std::string::npos);
  CHECK(run.err.find("x 2 threads", line) != std::string::npos);
  // "total 227.5 MiB": the estimate to the printed digit, before the run's end line.
  const size_t at = run.err.find("total ", line);
  REQUIRE(at != std::string::npos);
  REQUIRE(run.err.find("photons in", line) != std::string::npos);
  CHECK(at < run.err.find("photons in", line));
  double value = 0;
  char unit[8] = {};
  REQUIRE(std::sscanf(run.err.c_str() + at, "total %lf %7s", &value, unit) == 2);
  const double scale = std::string(unit) == "GiB"   ? 1073741824.0
                       : std::string(unit) == "MiB" ? 1048576.0
                       : std::string(unit) == "KiB" ? 1024.0
                                                    : 1.0;
  CHECK(std::abs(value * scale - static_cast<double>(need)) <= 0.05 * scale);
  // The fluence sums alone: 64-bit cells of 4^3 bricks over 60^3 voxels x 50 gates, 2 threads.
  CHECK(need > 2 * 60ull * 60 * 60 * 50 * 8);
}
