// End-to-end tests of `femto render`'s integrator choice: what render.json records for each
// integrator, the hybrid without a diffuse surface, and bad integrator input. The other
// command-line tests: tests/test_cli.cpp.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "cli_helpers.h"

using namespace femto::test::cli;

// Catches: --integrator ignored, render.json not saying which integrator ran and why, the
// automatic choice not picking photons and beams (hybrid) for a delta light behind glass in fog,
// or photon settings lost.
TEST_CASE("cli: --integrator choices are recorded in render.json", "[cli]") {
  CliTempDir tmp;
  json s = cli_scene();
  s["shapes"].push_back(json::parse(R"({ "type": "sphere", "center": [0, 0, 20], "radius": 10,
                                          "material": { "type": "dielectric", "eta": 1.5 } })"));
  write_cli_text(tmp.dir / "glass.json", s.dump(2));
  struct Case {
    std::vector<std::string> flags;
    std::string type, why_part;
  };
  const std::vector<Case> cases = {
      {{}, "hybrid", "auto"},
      {{"--integrator", "path"}, "path", "chosen"},
      {{"--integrator", "light", "--light-paths", "2e4"}, "light", "chosen"},  // counts as 1e5 too
      {{"--integrator", "photons", "--photons", "3000", "--photon-radius", "2",
        "--photon-bandwidth", "20"},
       "photons",
       "chosen"},
      {{"--integrator", "beams", "--photons", "5e2"}, "beams", "chosen"},
  };
  for (size_t i = 0; i < cases.size(); ++i) {
    const fs::path out = tmp.dir / ("out" + std::to_string(i));
    std::vector<std::string> args = {"render",  (tmp.dir / "glass.json").string(),
                                     "--spp",   "2",
                                     "--out",   out.string(),
                                     "--quiet", "--frames",
                                     "none",    "--no-previews"};
    args.insert(args.end(), cases[i].flags.begin(), cases[i].flags.end());
    const RunResult r = run_cli(args, tmp.dir, tmp.dir / ("logs" + std::to_string(i)));
    INFO(r.command << "\nstderr: " << r.err);
    REQUIRE(r.code == 0);
    const json info = json::parse(read_cli_file(out / "render.json"));
    const json& integ = info["settings"]["integrator"];
    CHECK(integ["type"] == cases[i].type);
    CHECK(cli_contains(integ["why"].get<std::string>(), cases[i].why_part));
    if (cases[i].type == "photons" || cases[i].type == "hybrid") {
      CHECK(integ["passes"] == 2);
      // The hybrid's default is one photon per two pixels, at least 10000 (40 x 24 pixels here),
      // times the share of the light's emission aimed at the glass (docs/outputs.md); a chosen
      // count stays as it is.
      const double scale = integ["aim"]["paths_per_pass_scale"].get<double>();
      CHECK(scale == (cases[i].flags.empty()
                          ? integ["aim"]["lights"][0]["solid_angle_share"].get<double>()
                          : 1.0));
      CHECK(integ["photons_per_pass"].get<int64_t>() ==
            (cases[i].flags.empty() ? std::max<int64_t>(100, std::llround(10000 * scale)) : 3000));
      CHECK(integ["photon_memory_bytes_peak"].get<uint64_t>() > 0);
      if (!cases[i].flags.empty()) {
        CHECK(integ["radius_mm"]["first_pass"].get<double>() == 2.0);
        CHECK(integ["bandwidth_ps"]["first_pass"].get<double>() == 20.0);
        // Second pass: R^2 and T shrink by ((1 + alpha) / 2)^(beta) with alpha = 4/7.
        const double ratio = (1.0 + 4.0 / 7.0) / 2.0;
        CHECK(integ["radius_mm"]["last_pass"].get<double>() ==
              Approx(2.0 * std::sqrt(std::pow(ratio, 2.0 / 3.0))));
        CHECK(integ["bandwidth_ps"]["last_pass"].get<double>() ==
              Approx(20.0 * std::pow(ratio, 1.0 / 3.0)));
      }
      CHECK(info["counters"]["light_paths"].get<uint64_t>() > 0);
    }
    if (cases[i].type == "light") CHECK(integ["light_paths"] == 20000);
    if (cases[i].type == "hybrid") {
      CHECK(integ["caustic_beams"]["alpha"].get<double>() == Approx(2.0 / 3.0));
      // One beam path per 128 pixels of the 40 x 24 film, raised to the floor of 500, times the
      // aimed share, raised to 100.
      CHECK(integ["caustic_beams"]["light_paths_per_pass"] ==
            std::max<int64_t>(
                100, std::llround(500 * integ["aim"]["paths_per_pass_scale"].get<double>())));
    }
    if (cases[i].type != "path" && cases[i].type != "light") {
      // Each part of a pass is timed where it runs (none where it does not), within the render.
      const json& ps = info["timing"]["pass_seconds"];
      const bool photons = cases[i].type != "beams", beams = cases[i].type != "photons";
      const bool light = cases[i].type == "hybrid";
      CHECK((ps["photons"].get<double>() > 0) == photons);
      CHECK((ps["beams"].get<double>() > 0) == beams);
      CHECK((ps["light_paths"].get<double>() > 0) == light);
      CHECK(ps["camera_paths"].get<double>() > 0);
      const double parts = ps["photons"].get<double>() + ps["beams"].get<double>() +
                           ps["light_paths"].get<double>() + ps["camera_paths"].get<double>();
      CHECK(parts <= info["timing"]["render_seconds"].get<double>() * 1.01 + 1e-3);
    }
    if (cases[i].type == "beams") {
      CHECK(integ["photons_per_pass"] == 500);
      CHECK(integ["alpha"].get<double>() == Approx(2.0 / 3.0));
      CHECK(info["counters"]["beams_stored"].get<uint64_t>() > 0);
    }
  }
}

// Catches: photons traced in every hybrid pass of a scene where nothing can store them (no
// diffuse surface: glass in fog), a share of each pass for nothing.
TEST_CASE("cli: the hybrid traces no photons without a diffuse surface", "[cli]") {
  CliTempDir tmp;
  json s = cli_scene();
  s["shapes"] = json::parse(R"([ { "type": "sphere", "center": [0, 0, 20], "radius": 10,
                                   "material": { "type": "dielectric", "eta": 1.5 } } ])");
  write_cli_text(tmp.dir / "glass.json", s.dump(2));
  const fs::path out = tmp.dir / "out";
  const RunResult r = run_cli(
      {"render", (tmp.dir / "glass.json").string(), "--spp", "2", "--integrator", "hybrid",
       "--photons", "500", "--out", out.string(), "--quiet", "--frames", "none", "--no-previews"},
      tmp.dir, tmp.dir / "logs");
  INFO(r.command << "\nstderr: " << r.err);
  REQUIRE(r.code == 0);
  const json info = json::parse(read_cli_file(out / "render.json"));
  CHECK(info["timing"]["pass_seconds"]["photons"].get<double>() == 0.0);
  CHECK(info["timing"]["pass_seconds"]["beams"].get<double>() > 0.0);
  // Per pass: 500 beam light paths and one indirect light path per four pixels (40 x 24), no
  // photons.
  CHECK(info["counters"]["light_paths"].get<uint64_t>() == 2u * (500u + 40u * 24u / 4u));
  CHECK(info["counters"]["photons_stored"].get<uint64_t>() == 0u);
}

// Catches: photon and light-path settings accepted where they mean nothing or with impossible
// values, and an integrator that cannot handle the scene's film, each with a clear exit-2
// message and nothing written.
TEST_CASE("cli: bad integrator input exits 2 naming the key and value", "[cli]") {
  CliTempDir tmp;
  const json s = cli_scene();
  write_cli_text(tmp.dir / "good.json", s.dump(2));
  auto with = [&](const std::string& name, const std::function<void(json&)>& edit) {
    json t = cli_scene();
    edit(t);
    write_cli_text(tmp.dir / name, t.dump(2));
    return (tmp.dir / name).string();
  };
  const std::string good = (tmp.dir / "good.json").string();
  const std::string out = (tmp.dir / "out").string();
  struct Case {
    std::vector<std::string> args;
    std::vector<std::string> expect;
  };
  const std::vector<Case> cases = {
      {{"render", good, "--integrator", "bidir"}, {"--integrator", "bidir"}},
      {{"render", good, "--integrator", "photons", "--photons", "-5"}, {"--photons", "-5"}},
      {{"render", good, "--integrator", "photons", "--photons", "0"}, {"--photons", "0"}},
      {{"render", good, "--integrator", "photons", "--photon-radius", "0"},
       {"--photon-radius", "0"}},
      {{"render", good, "--integrator", "photons", "--photon-bandwidth", "-1"},
       {"--photon-bandwidth", "-1"}},
      {{"render", good, "--integrator", "path", "--photons", "1000"},
       {"--photons", "photon mapping and photon beams only"}},
      {{"render", good, "--light-paths", "1000", "--integrator", "path"}, {"--light-paths"}},
      {{"render", good, "--integrator", "light", "--reconstruction", "kernel"},
       {"light", "kernel film"}},
      {{"render",
        with("nofog.json",
             [](json& t) {
               t.erase("media");
               t.erase("medium");
             }),
        "--integrator", "beams"},
       {"beams", "no scattering medium"}},
      {{"render", with("k1.json", [](json& t) { t["render"]["integrator"] = "photon"; })},
       {"/render/integrator", "photon"}},
      {{"render", with("k2.json",
                       [](json& t) {
                         t["render"]["photons"] = json{{"per_pass", -1}};
                       })},
       {"/render/photons/per_pass", "-1"}},
      {{"render", with("k3.json",
                       [](json& t) {
                         t["render"]["photons"] = json{{"radius", 0}};
                       })},
       {"/render/photons/radius", "0"}},
      {{"render", with("k4.json",
                       [](json& t) {
                         t["render"]["photons"] = json{{"alpha", 1.5}};
                       })},
       {"/render/photons/alpha", "1.5"}},
      {{"render", with("k5.json",
                       [](json& t) {
                         t["render"]["photons"] = json{{"radius_mm", 1}};
                       })},
       {"/render/photons", "radius_mm"}},
      {{"render", with("k6.json", [](json& t) { t["render"]["light_paths"] = 0; })},
       {"/render/light_paths", "0"}},
  };
  for (size_t i = 0; i < cases.size(); ++i) {
    std::vector<std::string> args = cases[i].args;
    args.insert(args.end(), {"--out", out, "--quiet"});
    const RunResult r = run_cli(args, tmp.dir, tmp.dir / ("logs" + std::to_string(i)));
    INFO(r.command << "\nstderr: " << r.err);
    CHECK(r.code == 2);
    CHECK(count_lines(r.err) == 1);
    for (const auto& part : cases[i].expect) CHECK(cli_contains(r.err, part));
    CHECK_FALSE(fs::exists(out));
  }
}
