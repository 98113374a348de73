// End-to-end regression tests of the femto command on hostile input and of run records that
// used to mislead (docs/RELIABILITY.md). Each runs the built executable in a fresh folder.
#include <catch2/catch.hpp>

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fcntl.h>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>
#include <vector>

#include "run_femto.h"
#include "temp_dir.h"

#ifndef FEMTO_SOURCE_DIR
#error "FEMTO_SOURCE_DIR must be defined by the build"
#endif

using femto::test::run_femto;
using femto::test::TempDir;
using femto::test::write_file;
using Catch::Matchers::Contains;
using nlohmann::json;
namespace fs = std::filesystem;

namespace {

json bad_cli_scene() {
  return json::parse(R"({
    "camera": {"position": [0, 0, 100], "look_at": [0, 0, 0], "resolution": [16, 8]},
    "time": {"bin_width": 50, "bins": 8},
    "media": {"fog": {"type": "homogeneous", "sigma_a": 0.001, "sigma_s": 0.01}},
    "medium": "fog",
    "shapes": [{"type": "quad", "corner": [-60, -60, 0], "edge1": [120, 0, 0], "edge2": [0, 120, 0],
                "material": {"type": "diffuse", "albedo": 0.7}}],
    "lights": [{"type": "point", "position": [10, 20, 50], "intensity": 1000}],
    "render": {"spp": 2}
  })");
}

// Exit 2, one short error line on stderr, and no output folder.
void check_refused(const femto::test::Run& r, const fs::path& out) {
  INFO("stderr: " << r.err);
  CHECK(r.code == 2);
  const size_t at = r.err.find("femto: error: ");
  REQUIRE(at != std::string::npos);
  const size_t end = r.err.find('\n', at);
  CHECK(end == r.err.size() - 1);  // the error is the last line, and the only one
  CHECK(end - at < 1000);
  CHECK_FALSE(fs::exists(out));
}

json bad_cli_render_json(const fs::path& out) {
  return json::parse(femto::test::read_file(out / "render.json"));
}

}  // namespace

// Was: SIGSEGV (stack overflow) printing the deep value in the error message.
TEST_CASE("cli: 100,000 nested brackets exit 2", "[robust]") {
  TempDir tmp("femto_bad_cli");
  write_file(tmp.dir / "deep.json", std::string(100000, '[') + std::string(100000, ']'));
  const auto r = run_femto({"info", "deep.json"}, tmp.dir);
  check_refused(r, tmp.dir / "none");
  CHECK_THAT(r.err, Contains("deep.json: /0/0/0") && Contains("nested more than 64 levels"));
}

// Was: femto render /dev/zero read forever.
TEST_CASE("cli: an endless scene file exits 2", "[robust]") {
  TempDir tmp("femto_bad_cli");
  const auto r = run_femto({"render", "/dev/zero", "--out", "out"}, tmp.dir);
  check_refused(r, tmp.dir / "out");
  CHECK_THAT(r.err, Contains("/dev/zero: scene file is larger than the 64 MiB limit"));
}

// Was: exit 0 with inf in transient.npy.
TEST_CASE("cli: emission 1e308 exits 2 and writes nothing", "[robust]") {
  TempDir tmp("femto_bad_cli");
  json j = bad_cli_scene();
  j["shapes"][0]["emission"] = 1e308;
  write_file(tmp.dir / "scene.json", j.dump());
  check_refused(run_femto({"render", "scene.json", "--out", "out"}, tmp.dir), tmp.dir / "out");
}

// Was: --max-memory 1e30 became 0 B (an out-of-range double to integer cast).
TEST_CASE("cli: --max-memory beyond 2^64 bytes means no limit", "[robust]") {
  TempDir tmp("femto_bad_cli");
  write_file(tmp.dir / "scene.json", bad_cli_scene().dump());
  const auto ok = run_femto({"render", "scene.json", "--max-memory", "1e30", "--out", "a", "--quiet",
                             "--frames", "none", "--no-previews"},
                            tmp.dir);
  CHECK(ok.code == 0);
  const auto tiny = run_femto({"render", "scene.json", "--max-memory", "0.5", "--out", "b"}, tmp.dir);
  check_refused(tiny, tmp.dir / "b");
  CHECK_THAT(tiny.err, Contains("--max-memory: must be at least 1 byte"));
}

// Was: the memory guard ignored volumes.
TEST_CASE("cli: --max-memory also bounds the dense volumes", "[robust]") {
  TempDir tmp("femto_bad_cli");
  const std::string vdb = std::string(FEMTO_SOURCE_DIR) + "/data/volumes/cloud.vdb";  // 48 x 47 x 48 dense cells: 424 KiB
  write_file(tmp.dir / "scene.json", R"({
    "camera": {"position": [0, 0, 400], "look_at": [0, 0, 0], "resolution": [4, 4]},
    "time": {"bin_width": 10, "bins": 4},
    "media": {"cloud": {"type": "vdb", "file": ")" + vdb + R"(", "sigma_t_scale": 0.08}},
    "medium": "cloud",
    "lights": [{"type": "point", "position": [0, 0, 300], "intensity": 10}]})");
  const auto r = run_femto({"render", "scene.json", "--max-memory", "400K", "--out", "out"}, tmp.dir);
  check_refused(r, tmp.dir / "out");
  CHECK_THAT(r.err, Contains("cloud.vdb") && Contains("left by --max-memory"));
}

// Was: signed overflow in grid indices when paths live for a 1e12 ps pulse. The widest pulse
// allowed now (1e9 ps) renders with finite output.
TEST_CASE("cli: the widest allowed pulse in the cloud scene renders cleanly", "[robust]") {
  TempDir tmp("femto_bad_cli");
  const std::string vdb = std::string(FEMTO_SOURCE_DIR) + "/data/volumes/cloud.vdb";
  write_file(tmp.dir / "scene.json", R"({
    "camera": {"position": [0, 0, 400], "look_at": [0, 0, 0], "fov": 26, "resolution": [8, 8]},
    "time": {"start_opl": 560, "bin_width_opl": 4, "bins": 20},
    "media": {"cloud": {"type": "vdb", "file": ")" + vdb + R"(", "sigma_t_scale": 0.08,
              "albedo": 0.95, "g": 0.6, "interpolation": "trilinear"}},
    "medium": "cloud",
    "lights": [{"type": "spot", "position": [150, 150, 150], "look_at": [0, 0, 0],
                "intensity": 2e5, "cone_angle": 25, "pulse": {"fwhm": 1e9}}],
    "render": {"spp": 2, "max_depth": 50}})");
  const auto r = run_femto({"render", "scene.json", "--out", "out", "--quiet", "--frames", "none",
                            "--no-previews"},
                           tmp.dir);
  INFO(r.err);
  REQUIRE(r.code == 0);
  CHECK(bad_cli_render_json(tmp.dir / "out").at("counters").at("nonfinite_film_values_zeroed") == 0);
  std::string far = femto::test::read_file(tmp.dir / "scene.json");
  far.replace(far.find("1e9"), 3, "1e12");  // beyond the bound: refused by the loader
  write_file(tmp.dir / "far.json", far);
  check_refused(run_femto({"render", "far.json", "--out", "far"}, tmp.dir), tmp.dir / "far");
}

// Was: --threads 3 on 2 cores recorded as 3; files listed that were not written; a chosen
// --max-depth 1 (single scattering) reported as a warning.
TEST_CASE("cli: render.json and stderr describe what actually happened", "[robust]") {
  TempDir tmp("femto_bad_cli");
  write_file(tmp.dir / "scene.json", bad_cli_scene().dump());
  const auto r = run_femto({"render", "scene.json", "--threads", "4096", "--max-depth", "1",
                            "--frames", "none", "--no-previews", "--out", "out"},
                           tmp.dir);
  INFO(r.err);
  REQUIRE(r.code == 0);
  const json info = bad_cli_render_json(tmp.dir / "out");
  const int hw = static_cast<int>(std::thread::hardware_concurrency());
  CHECK(info.at("settings").at("threads_requested") == 4096);
  CHECK(info.at("settings").at("threads").get<int>() <= std::max(hw, 1));
  CHECK(info.at("settings").at("max_depth_source") == "--max-depth");
  CHECK(info.at("counters").at("max_depth_terminations").get<int>() > 0);
  CHECK_THAT(r.err, !Contains("warning") && Contains("ended at the chosen max_depth 1"));
  CHECK_THAT(r.err, Contains("results in out/ (steady.exr,") && !Contains("steady.png") &&
                        !Contains("frames/") && !Contains("frames.png"));
  for (const auto& f : info.at("outputs")) CHECK(fs::exists(tmp.dir / "out" / f.get<std::string>()));
}

// Was: every strategy aborted "fewer than two usable cells", exit 1, no output.
TEST_CASE("cli: uniformity with fewer than 5 x bins samples still tests and writes", "[robust]") {
  TempDir tmp("femto_bad_cli");
  const auto r = run_femto({"uniformity", "--samples", "249", "--out", "u", "--quiet"}, tmp.dir);
  INFO(r.err);
  CHECK(r.code == 0);
  CHECK_THAT(r.out, Contains("adjacent bins merged"));
  const json summary = json::parse(femto::test::read_file(tmp.dir / "u" / "summary.json"));
  for (const auto& s : summary.at("strategies")) CHECK(s.at("chi2_dof").get<int>() >= 1);
}

// Was: exit 0 with inf/nan in the CSVs.
TEST_CASE("cli: diffusion refuses a window too short for finite tallies", "[robust]") {
  TempDir tmp("femto_bad_cli");
  const auto r = run_femto({"diffusion", "--t-end", "1e-300", "--out", "d"}, tmp.dir);
  check_refused(r, tmp.dir / "d");
  CHECK_THAT(r.err, Contains("--t-end") && Contains("1e-300"));
}

// Was: --photons 1e12 ran with no estimate and no clean way to stop.
TEST_CASE("cli: diffusion estimates its run time and stops cleanly", "[robust]") {
  TempDir tmp("femto_bad_cli");
  const auto r = run_femto(
      {"diffusion", "--photons", "1e12", "--max-seconds", "0.5", "--threads", "1", "--out", "d"},
      tmp.dir);
  INFO(r.err);
  CHECK(r.code == 0);
  CHECK_THAT(r.err, Contains("for 1000000000000 photons") && Contains("stopped early"));
  const json run = json::parse(femto::test::read_file(tmp.dir / "d" / "summary.json"));
  CHECK(run.at("stopped_early") == "--max-seconds");
  CHECK(run.at("photons_traced").get<double>() < 1e12);

  // Ctrl-C: the photons so far are written and the exit code is 130.
  const pid_t pid = fork();
  REQUIRE(pid >= 0);
  if (pid == 0) {
    if (chdir(tmp.dir.c_str()) != 0) _exit(99);
    const int null = open("/dev/null", O_WRONLY);
    dup2(null, 1);
    dup2(null, 2);
    execl(FEMTO_BINARY, FEMTO_BINARY, "diffusion", "--photons", "1e12", "--threads", "1", "--out",
          "i", static_cast<char*>(nullptr));
    _exit(98);
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(1500));
  kill(pid, SIGINT);
  int status = 0;
  waitpid(pid, &status, 0);
  REQUIRE(WIFEXITED(status));
  CHECK(WEXITSTATUS(status) == 130);
  const json irun = json::parse(femto::test::read_file(tmp.dir / "i" / "summary.json"));
  CHECK(irun.at("stopped_early") == "interrupted (Ctrl-C)");
}
