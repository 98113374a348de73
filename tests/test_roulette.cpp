// Russian roulette on camera paths (core/integrators/volpath.h, docs/scene-format.md
// "render/russian_roulette"): the same film with and without it, that it ends paths, the scene
// key and the flag, and what render.json records. Fixed seeds; tolerances are 4 combined
// standard errors of per-seed batches.
#include <catch2/catch.hpp>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "agreement.h"
#include "core/error.h"
#include "core/render.h"
#include "core/scene_loader.h"
#include "run_femto.h"
#include "temp_dir.h"

using namespace femto;
using Catch::Matchers::Contains;
using femto::test::run_femto;
using femto::test::TempDir;
using femto::test::write_file;
using nlohmann::json;

namespace {

// Grey fog (albedo 0.8, mean free path 2 mm) over a diffuse floor, a point light above it:
// paths scatter many times and their throughput falls, so the roulette plays on most of them.
const char* kFog = R"({
  "camera": { "position": [0, 30, 90], "look_at": [0, 5, 0], "fov": 30, "resolution": [16, 16] },
  "time": { "t_start": 250, "bin_width": 25, "bins": 16 },
  "media": { "fog": { "type": "homogeneous", "sigma_a": 0.1, "sigma_s": 0.4, "g": 0.3 } },
  "shapes": [
    { "type": "box", "min": [-15, 0.5, -15], "max": [15, 20, 15], "medium": "fog" },
    { "type": "quad", "corner": [-30, 0, 30], "edge1": [60, 0, 0], "edge2": [0, 0, -60],
      "material": { "type": "diffuse", "albedo": 0.7 } }
  ],
  "lights": [ { "type": "point", "position": [3, 35, -2], "intensity": 2000 } ]
})";

std::vector<TransientFilm> renders(const Scene& scene, const RouletteDesc& roulette, int n,
                                   uint64_t seed0, PathStats* stats = nullptr) {
  std::vector<TransientFilm> films;
  for (int b = 0; b < n; ++b) {
    RenderOptions opt;
    opt.integrator = IntegratorKind::Path;
    opt.spp = 32;
    opt.seed = seed0 + static_cast<uint64_t>(b);
    opt.threads = 2;
    opt.quiet = true;
    opt.roulette = roulette;
    RenderResult r = render(scene, opt);
    if (stats) *stats += r.stats;
    films.push_back(std::move(r.film));
  }
  return films;
}

json render_json(const std::filesystem::path& out) {
  return json::parse(femto::test::read_file(out / "render.json"));
}

}  // namespace

// Catches a survivor not divided by its probability (the film falls short wherever paths are
// long: light scattered many times, late bins) or a roulette that plays before its depth.
TEST_CASE("Russian roulette leaves the film unbiased: the strongest roulette against none") {
  const Scene scene(load_scene_string(kFog, "fog.json", "."));
  PathStats with, without;
  // Threshold 1 from the first vertex: every path with throughput below 1 plays.
  const auto rr = test::cells(renders(scene, {1, 1.0}, 24, 100, &with), 4, 2);
  const auto plain = test::cells(renders(scene, {0, 1.0}, 24, 200, &without), 4, 2);
  test::require_agreement(rr, plain, 20);
  // It plays, and the paths get shorter.
  CHECK(with.roulette_ends > with.paths / 4);
  CHECK(without.roulette_ends == 0);
  const double events_with = static_cast<double>(with.medium_events + with.surface_events) /
                             static_cast<double>(with.paths);
  const double events_without =
      static_cast<double>(without.medium_events + without.surface_events) /
      static_cast<double>(without.paths);
  INFO("vertices per path " << events_with << " with the roulette, " << events_without
                            << " without");
  CHECK(events_with < 0.6 * events_without);
}

TEST_CASE("the roulette's depth and threshold: none before the depth, none above the threshold") {
  const Scene scene(load_scene_string(kFog, "fog.json", "."));
  PathStats deep, high;
  renders(scene, {1000, 1.0}, 1, 7, &deep);  // deeper than any path here goes
  CHECK(deep.roulette_ends == 0);
  renders(scene, {1, 1e-9}, 1, 7, &high);  // no path's throughput gets that low
  CHECK(high.roulette_ends == 0);
  PathStats d3, d1;
  renders(scene, {3, 1.0}, 1, 7, &d3);
  renders(scene, {1, 1.0}, 1, 7, &d1);
  CHECK(d3.roulette_ends > 0);
  CHECK(d1.roulette_ends > d3.roulette_ends);
}

TEST_CASE("the russian_roulette scene key") {
  auto with = [](const std::string& value) {
    std::string s = kFog;
    s.insert(s.rfind('}'), R"(, "render": { "russian_roulette": )" + value + " }");
    return load_scene_string(s, "fog.json", ".").integrator.roulette;
  };
  const RouletteDesc by_default = load_scene_string(kFog, "fog.json", ".").integrator.roulette;
  CHECK(by_default.depth == 3);
  CHECK(by_default.threshold == 0.2);
  CHECK(with("false").depth == 0);
  CHECK(with("true").depth == 3);
  CHECK(with(R"({"depth": 5})").depth == 5);
  CHECK(with(R"({"depth": 5})").threshold == 0.2);
  CHECK(with(R"({"threshold": 1})").threshold == 1.0);
  auto error = [&](const std::string& value) {
    try {
      with(value);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  CHECK_THAT(error(R"({"depth": 0})"),
             Contains("fog.json") && Contains("/render/russian_roulette/depth") && Contains("0"));
  CHECK_THAT(error(R"({"threshold": 0})"), Contains("/render/russian_roulette/threshold"));
  CHECK_THAT(error(R"({"threshold": 1.5})"),
             Contains("/render/russian_roulette/threshold") && Contains("1.5"));
  CHECK_THAT(error(R"("yes")"),
             Contains("/render/russian_roulette") && Contains("expected true, false or an object"));
  CHECK_THAT(error(R"({"dept": 2})"), Contains("dept"));
}

TEST_CASE("cli: --russian-roulette, and what render.json records") {
  TempDir tmp("femto_roulette");
  write_file(tmp.dir / "fog.json", kFog);
  const std::vector<std::string> quiet = {"--spp",         "2",      "--frames", "none",
                                          "--no-previews", "--quiet"};
  auto run = [&](std::vector<std::string> args) {
    args.insert(args.begin(), {"render", "fog.json"});
    args.insert(args.end(), quiet.begin(), quiet.end());
    return run_femto(args, tmp.dir);
  };
  {
    const auto r = run({"--out", "default"});
    INFO(r.err);
    REQUIRE(r.code == 0);
    const json info = render_json(tmp.dir / "default");
    CHECK(info.at("settings").at("russian_roulette") == json({{"depth", 3}, {"threshold", 0.2}}));
    CHECK(info.at("counters").at("roulette_terminations").get<long>() > 0);
  }
  {
    const auto r = run({"--out", "off", "--russian-roulette", "off"});
    REQUIRE(r.code == 0);
    const json info = render_json(tmp.dir / "off");
    CHECK(info.at("settings").at("russian_roulette") == false);
    CHECK(info.at("counters").at("roulette_terminations") == 0);
  }
  {
    const auto r = run({"--out", "chosen", "--russian-roulette", "1,0.5"});
    REQUIRE(r.code == 0);
    CHECK(render_json(tmp.dir / "chosen").at("settings").at("russian_roulette") ==
          json({{"depth", 1}, {"threshold", 0.5}}));
  }
  for (const char* bad : {"0,0.5", "2,0", "2,1.5", "2", "x,0.5", "2,0.5x", "maybe"}) {
    const auto r = run({"--out", "bad", "--russian-roulette", bad});
    INFO(bad << ": " << r.err);
    CHECK(r.code == 2);
    CHECK_THAT(r.err, Contains("--russian-roulette") && Contains(bad));
    CHECK_FALSE(std::filesystem::exists(tmp.dir / "bad"));
  }
}
