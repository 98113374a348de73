// End-to-end tests of the femto command line: they run the built femto executable (FEMTO_BINARY)
// in a fresh temporary folder and check its exit code, its stderr and the files it writes.
#include <catch2/catch.hpp>

#include "cli_helpers.h"

#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <nlohmann/json.hpp>
#include <regex>
#include <set>
#include <string>
#include <vector>

#include "core/io/exr.h"
#include "core/io/npy.h"
#include "femto_version.h"

#ifndef FEMTO_SOURCE_DIR
#error "FEMTO_SOURCE_DIR must be defined by the build"
#endif

using namespace femto::test::cli;

// Catches: outputs missing, wrong npy shape or layout, steady image not the sum of the bins,
// NaN/inf in the film, inconsistent time axis (ps vs OPL), wrong path counter, noise with --quiet.
TEST_CASE("cli: default scene at 1 spp writes consistent outputs", "[cli]") {
  CliTempDir tmp;
  const fs::path out = tmp.dir / "out";
  const RunResult r = run_cli({"render", "--spp", "1", "--frames", "files", "--out", out.string(), "--quiet"},
                                tmp.dir, tmp.dir / "logs");
  INFO(r.command << "\nstderr: " << r.err);
  REQUIRE(r.code == 0);
  // Catches: --quiet still printing progress or a summary.
  CHECK(r.err.empty());

  for (const char* f : {"steady.exr", "peak_time.exr", "transient.npy", "steady.png", "frames.png",
                        "render.json", "before_window.exr", "after_window.exr"})
    CHECK(fs::is_regular_file(out / f));
  // Catches: --frames files also writing the multi-part file.
  CHECK_FALSE(fs::exists(out / "transient.exr"));

  // The expected dimensions come from the scene the binary embeds.
  const json scene = json::parse(read_cli_file(fs::path(FEMTO_SOURCE_DIR) / "data/scenes/default.json"));
  const int W = scene["camera"]["resolution"][0].get<int>();
  const int H = scene["camera"]["resolution"][1].get<int>();
  const int T = scene["time"]["bins"].get<int>();
  const double t_start = scene["time"]["t_start"].get<double>();
  const double bin_width = scene["time"]["bin_width"].get<double>();

  // Catches: a missing frame, or stray files in frames/.
  size_t exr_frames = 0, entries = 0;
  for (const auto& e : fs::directory_iterator(out / "frames")) {
    ++entries;
    if (e.is_regular_file() && e.path().extension() == ".exr") ++exr_frames;
  }
  CHECK(exr_frames == static_cast<size_t>(T));
  CHECK(entries == static_cast<size_t>(T));

  const json info = json::parse(read_cli_file(out / "render.json"));
  const std::vector<size_t> expected_shape = {size_t(H), size_t(W), size_t(T), 3};
  CHECK(info.at("film").at("npy_shape").get<std::vector<size_t>>() == expected_shape);
  CHECK(info.at("film").at("width").get<int>() == W);
  CHECK(info.at("film").at("height").get<int>() == H);
  CHECK(info.at("film").at("bins").get<int>() == T);

  std::vector<size_t> shape;
  std::vector<float> tr;
  femto::read_npy_float32((out / "transient.npy").string(), shape, tr);
  REQUIRE(shape == expected_shape);
  REQUIRE(tr.size() == size_t(H) * W * T * 3);

  // Catches: NaN or inf leaking into the film.
  size_t nonfinite = 0;
  for (float v : tr) nonfinite += !std::isfinite(v);
  CHECK(nonfinite == 0);

  // Catches: steady.exr that is not the per-pixel sum over the bins (e.g. layout (H,W,T,3)
  // transposed, a missing bin, or a different normalisation).
  int ew = 0, eh = 0;
  std::vector<float> steady;
  femto::read_exr_rgb((out / "steady.exr").string(), ew, eh, steady);
  REQUIRE(ew == W);
  REQUIRE(eh == H);
  REQUIRE(steady.size() == size_t(H) * W * 3);
  size_t mismatches = 0;
  double total = 0, worst = 0;
  for (size_t p = 0; p < size_t(H) * W; ++p) {
    for (int c = 0; c < 3; ++c) {
      double sum = 0;
      for (int t = 0; t < T; ++t) sum += tr[(p * T + t) * 3 + c];
      const double s = steady[p * 3 + c];
      total += s;
      const double err = std::abs(sum - s);
      worst = std::max(worst, err / std::max(std::abs(s), 1e-30));
      if (err > 1e-5 * std::max(std::abs(s), std::abs(sum)) + 1e-30) ++mismatches;
    }
  }
  INFO("worst relative difference " << worst);
  CHECK(mismatches == 0);
  CHECK(total > 0);  // the check above is vacuous on a black image

  // Catches: peak-time map with the wrong size or times outside the window.
  {
    int pw = 0, ph = 0;
    std::vector<float> peak;
    femto::read_exr_channel((out / "peak_time.exr").string(), 0, "Y", pw, ph, peak);
    CHECK(pw == W);
    CHECK(ph == H);
    size_t outside = 0;
    for (float v : peak)
      if (!std::isnan(v) && !(v >= t_start && v <= t_start + T * bin_width)) ++outside;
    CHECK(outside == 0);
  }

  // Catches: time axis keys missing, or OPL not c * t with c = 0.299792458 mm/ps.
  const json& ax = info.at("time_axis");
  const double c = 0.299792458;
  CHECK(ax.at("t_start_ps").get<double>() == Approx(t_start));
  CHECK(ax.at("bin_width_ps").get<double>() == Approx(bin_width));
  CHECK(ax.at("bins").get<int>() == T);
  CHECK(ax.at("t_end_ps").get<double>() == Approx(t_start + T * bin_width));
  CHECK(ax.at("start_opl_mm").get<double>() == Approx(ax.at("t_start_ps").get<double>() * c).epsilon(1e-12));
  CHECK(ax.at("bin_width_opl_mm").get<double>() == Approx(ax.at("bin_width_ps").get<double>() * c).epsilon(1e-12));
  CHECK(ax.at("end_opl_mm").get<double>() == Approx(ax.at("t_end_ps").get<double>() * c).epsilon(1e-12));

  // Catches: a miscounted number of camera paths (e.g. per-thread counters not merged).
  CHECK(info.at("settings").at("spp").get<int>() == 1);
  CHECK(info.at("counters").at("paths").get<uint64_t>() == uint64_t(W) * uint64_t(H) * 1u);
}

// Catches: --frames multipart not writing one part per bin, or also writing frames/; --frames
// none / --no-previews still writing frames or PNGs.
TEST_CASE("cli: --frames multipart and --frames none", "[cli]") {
  CliTempDir tmp;
  const json scene = cli_scene();
  const int T = scene["time"]["bins"].get<int>();
  write_cli_text(tmp.dir / "scene.json", scene.dump(2));

  SECTION("multipart") {
    // Catches: a multi-part transient.exr with a wrong part count, or a frames/ folder beside it.
    const fs::path out = tmp.dir / "out";
    const RunResult r = run_cli({"render", "scene.json", "--spp", "1", "--frames", "multipart",
                                   "--out", out.string(), "--quiet"},
                                  tmp.dir, tmp.dir / "logs");
    INFO(r.command << "\nstderr: " << r.err);
    REQUIRE(r.code == 0);
    CHECK(r.err.empty());
    REQUIRE(fs::is_regular_file(out / "transient.exr"));
    const std::vector<std::string> parts = femto::exr_part_names((out / "transient.exr").string());
    CHECK(parts.size() == static_cast<size_t>(T));
    CHECK(std::set<std::string>(parts.begin(), parts.end()).size() == parts.size());
    CHECK_FALSE(fs::exists(out / "frames"));
    CHECK(fs::is_regular_file(out / "transient.npy"));
  }
  SECTION("none, no previews") {
    // Catches: --frames none or --no-previews being ignored.
    const fs::path out = tmp.dir / "out";
    const RunResult r = run_cli({"render", "scene.json", "--spp", "1", "--frames=none",
                                   "--no-previews", "--out", out.string(), "--quiet"},
                                  tmp.dir, tmp.dir / "logs");
    INFO(r.command << "\nstderr: " << r.err);
    REQUIRE(r.code == 0);
    CHECK_FALSE(fs::exists(out / "frames"));
    CHECK_FALSE(fs::exists(out / "transient.exr"));
    CHECK_FALSE(fs::exists(out / "steady.png"));
    CHECK_FALSE(fs::exists(out / "frames.png"));
    CHECK(fs::is_regular_file(out / "transient.npy"));
    CHECK(fs::is_regular_file(out / "steady.exr"));
    CHECK(fs::is_regular_file(out / "render.json"));
  }
}

// Catches: render.json turning invalid JSON (a "<discarded>" value) when the scene file holds
// // comments, which the scene loader accepts.
TEST_CASE("cli: render.json stays valid JSON for scene files with comments", "[cli]") {
  CliTempDir tmp;
  std::string text = cli_scene().dump(2);
  text.insert(text.find('{') + 1, "\n  // a comment the loader skips\n");
  write_cli_text(tmp.dir / "commented.json", text);
  const fs::path out = tmp.dir / "out";
  const RunResult r = run_cli({"render", "commented.json", "--spp", "1", "--frames", "none", "--no-previews",
                                 "--out", out.string(), "--quiet"},
                                tmp.dir, tmp.dir / "logs");
  INFO(r.command << "\nstderr: " << r.err);
  REQUIRE(r.code == 0);
  const json info = json::parse(read_cli_file(out / "render.json"), nullptr, false);
  REQUIRE_FALSE(info.is_discarded());
  CHECK(info["scene"]["json"]["time"]["bins"] == cli_scene()["time"]["bins"]);
}

// Catches: the kernel film's scene keys or flags being ignored, render.json not recording them,
// kernel_bandwidth.exr missing or holding nonsense, and the kernel film losing energy against the
// histogram film rendered from the same paths.
TEST_CASE("cli: --reconstruction kernel records its settings and keeps the histogram's energy",
          "[cli]") {
  CliTempDir tmp;
  json scene = cli_scene();
  scene["time"]["reconstruction"] = {{"type", "kernel"}, {"kernel", "perlin"}, {"k", 12}};
  write_cli_text(tmp.dir / "scene.json", scene.dump(2));
  const fs::path kout = tmp.dir / "kernel", hout = tmp.dir / "histogram";
  const RunResult k =
      run_cli({"render", "scene.json", "--spp", "6", "--kernel", "epanechnikov", "--alpha", "0.7",
               "--frames", "none", "--no-previews", "--out", kout.string(), "--quiet"},
              tmp.dir, tmp.dir / "logs_k");
  INFO(k.command << "\nstderr: " << k.err);
  REQUIRE(k.code == 0);
  const RunResult h =
      run_cli({"render", "scene.json", "--spp", "6", "--reconstruction", "histogram", "--frames",
               "none", "--no-previews", "--out", hout.string(), "--quiet"},
              tmp.dir, tmp.dir / "logs_h");
  INFO(h.command << "\nstderr: " << h.err);
  REQUIRE(h.code == 0);

  const json kj = json::parse(read_cli_file(kout / "render.json"));
  const json& rec = kj["settings"]["reconstruction"];
  CHECK(rec["type"] == "kernel");
  CHECK(rec["kernel"] == "epanechnikov");  // the flag overrides the scene
  CHECK(rec["alpha"].get<double>() == 0.7);
  CHECK(rec["k"].get<int>() == 12);        // the scene's key survives
  CHECK(rec["first_pass_spp"].get<int>() == 160);
  CHECK(rec["onset_reflection"].get<bool>());
  CHECK(json::parse(read_cli_file(hout / "render.json"))["settings"]["reconstruction"]["type"] == "histogram");
  CHECK_FALSE(fs::exists(hout / "kernel_bandwidth.exr"));

  int w = 0, hgt = 0;
  std::vector<float> T;
  femto::read_exr_channel((kout / "kernel_bandwidth.exr").string(), 0, "Y", w, hgt, T);
  REQUIRE(T.size() == 40u * 24u);
  const double window = 50.0 * 24;
  for (float t : T) CHECK((t >= 0.0f && t <= window));

  // Same seed, same paths: bins + before + after agree pixel by pixel (float storage).
  auto totals = [](const fs::path& dir) {
    std::vector<size_t> shape;
    std::vector<float> film;
    femto::read_npy_float32((dir / "transient.npy").string(), shape, film);
    int ww = 0, hh = 0;
    std::vector<float> before, after;
    femto::read_exr_rgb((dir / "before_window.exr").string(), ww, hh, before);
    femto::read_exr_rgb((dir / "after_window.exr").string(), ww, hh, after);
    std::vector<double> sum(before.size(), 0.0);
    const size_t bins = shape[2];
    for (size_t p = 0; p < sum.size() / 3; ++p)
      for (size_t c = 0; c < 3; ++c) {
        double s = double(before[3 * p + c]) + double(after[3 * p + c]);
        for (size_t i = 0; i < bins; ++i) s += film[(p * bins + i) * 3 + c];
        sum[3 * p + c] = s;
      }
    return sum;
  };
  const std::vector<double> ks = totals(kout), hs = totals(hout);
  REQUIRE(ks.size() == hs.size());
  double total = 0;
  for (size_t i = 0; i < ks.size(); ++i) {
    CHECK(std::abs(ks[i] - hs[i]) <= 1e-5 * std::max(1e-30, hs[i]));
    total += hs[i];
  }
  CHECK(total > 0);
}

// Catches: --version/--help failing or printing the wrong version, and the render help going out
// of sync with the options cmd_render.cpp actually parses.
TEST_CASE("cli: --version and --help", "[cli]") {
  CliTempDir tmp;
  SECTION("--version") {
    // Catches: a version string that differs from the project version, or a non-zero exit.
    const RunResult r = run_cli({"--version"}, tmp.dir, tmp.dir / "logs");
    INFO(r.out << r.err);
    CHECK(r.code == 0);
    CHECK(r.out.rfind(std::string("femto ") + FEMTO_VERSION, 0) == 0);
    CHECK(std::regex_search(r.out, std::regex(R"(^femto [0-9]+\.[0-9]+\.[0-9]+)")));
    CHECK(count_lines(r.out) == 1);
    CHECK(r.err.empty());
    // The instruction set decides the last bits of every output: a bug report needs it.
    CHECK(cli_contains(r.out, std::string("instruction set ") + FEMTO_INSTRUCTION_SET + ")"));
  }
  SECTION("--help") {
    // Catches: top-level help exiting non-zero or not mentioning the render command.
    const RunResult r = run_cli({"--help"}, tmp.dir, tmp.dir / "logs");
    CHECK(r.code == 0);
    CHECK(cli_contains(r.out, "render"));
    CHECK(cli_contains(r.out, "--version"));
    CHECK(r.err.empty());
  }
  SECTION("render --help lists every parsed option") {
    // Catches: an option added to cmd_render.cpp without documenting it in its --help.
    const std::string src = read_cli_file(fs::path(FEMTO_SOURCE_DIR) / "apps/cmd_render.cpp");
    const std::regex opt_re(R"re(a == "(--[A-Za-z0-9-]+)")re");
    std::set<std::string> options;
    for (auto it = std::sregex_iterator(src.begin(), src.end(), opt_re); it != std::sregex_iterator(); ++it)
      options.insert((*it)[1].str());
    REQUIRE(options.size() >= 8);  // guards against the regex silently matching nothing
    const RunResult r = run_cli({"render", "--help"}, tmp.dir, tmp.dir / "logs");
    CHECK(r.code == 0);
    CHECK(r.err.empty());
    for (const auto& o : options) {
      INFO("option " << o);
      CHECK(std::regex_search(r.out, std::regex("(^|[^A-Za-z0-9-])" + o + "([^A-Za-z0-9-]|$)")));
    }
    // --help must not have rendered anything.
    CHECK_FALSE(fs::exists(tmp.dir / "femto-out"));
  }
}

// Catches: bad input that is accepted, crashes, exits with the wrong code, gives a vague or
// multi-line message, or leaves a partial output folder behind.
TEST_CASE("cli: bad input exits 2 with a one-line message and writes nothing", "[cli]") {
  CliTempDir tmp;
  const fs::path work = tmp.dir / "work";  // femto's cwd and the scene folder
  fs::create_directories(work);
  const std::string out = (tmp.dir / "out").string();

  auto scene_with = [&](const std::string& name, const std::function<void(json&)>& edit) {
    json s = cli_scene();
    edit(s);
    write_cli_text(work / name, s.dump(2));
    return name;
  };
  const std::string good = scene_with("good.json", [](json&) {});

  struct Case {
    const char* what;  // the bug this case would catch
    std::vector<std::string> args;
    std::vector<std::string> expect;  // substrings the message must contain
  };
  std::vector<Case> cases = {
      {"unknown flags silently ignored",
       {"render", good, "--bogus-flag", "--out", out}, {"--bogus-flag"}},
      {"--spp 0 accepted (division by zero in the film)",
       {"render", good, "--spp", "0", "--out", out}, {"--spp", "'0'"}},
      {"non-numeric --spp parsed as 0 or a prefix (atoi)",
       {"render", good, "--spp", "abc", "--out", out}, {"--spp", "abc"}},
      {"negative --threads accepted",
       {"render", good, "--threads", "-1", "--out", out}, {"--threads", "-1"}},
      {"unknown --frames mode falling back to a default",
       {"render", good, "--frames", "bogus", "--out", out}, {"--frames", "bogus"}},
      {"--max-memory not enforced, or enforced after the output folder is created",
       {"render", good, "--max-memory", "1K", "--out", out}, {"--max-memory", "1.0 KiB"}},
      {"a missing scene file crashing or treated as a failure (1) rather than bad input",
       {"render", "no_such_scene.json", "--out", out}, {"no_such_scene.json"}},
      {"two scene files: the second silently ignored",
       {"render", good, "other.json", "--out", out}, {"other.json"}},
      {"unknown --connection-sampling accepted",
       {"render", good, "--connection-sampling", "line-to-point", "--out", out},
       {"--connection-sampling", "line-to-point"}},
      {"unknown --direction-sampling accepted",
       {"render", good, "--direction-sampling", "angle", "--out", out}, {"--direction-sampling", "angle"}},
      {"unknown --reconstruction falling back to the histogram",
       {"render", good, "--reconstruction", "kde", "--out", out}, {"--reconstruction", "kde"}},
      {"kernel settings silently ignored by a histogram render",
       {"render", good, "--alpha", "0.5", "--out", out}, {"--alpha", "--reconstruction kernel"}},
      {"alpha = 0 accepted (the bandwidth would collapse after one sample)",
       {"render", good, "--reconstruction", "kernel", "--alpha", "0", "--out", out}, {"--alpha", "0"}},
      {"a zero bandwidth accepted",
       {"render", good, "--reconstruction", "kernel", "--bandwidth", "0", "--out", out}, {"--bandwidth"}},
      {"unknown kernel names accepted",
       {"render", good, "--reconstruction", "kernel", "--kernel", "gauss", "--out", out}, {"--kernel", "gauss"}},
  };

  // Scene-file errors: each scene is the valid small scene with one defect.
  auto bad_scene = [&](const char* what, const std::string& file, std::vector<std::string> expect) {
    cases.push_back({what, {"render", file, "--out", out}, std::move(expect)});
  };
  {
    // JSON syntax error: the comma before "lights" removed.
    std::string text = cli_scene().dump(2);
    const size_t k = text.find("\"lights\"");
    REQUIRE(k != std::string::npos);
    text.erase(text.rfind(',', k), 1);
    write_cli_text(work / "syntax.json", text);
  }
  bad_scene("a JSON syntax error reported without file and position", "syntax.json",
            {"syntax.json", "line"});
  bad_scene("unknown (misspelt) keys silently ignored",
            scene_with("unknown_key.json", [](json& s) { s["camera"]["fvo"] = 40; }),
            {"/camera/fvo"});
  bad_scene("negative absorption accepted",
            scene_with("neg_sigma_a.json", [](json& s) { s["media"]["fog"]["sigma_a"] = -0.5; }),
            {"/media/fog/sigma_a", "-0.5"});
  bad_scene("a medium eta < 1 accepted",
            scene_with("eta.json", [](json& s) { s["media"]["fog"]["eta"] = 0.5; }),
            {"/media/fog/eta", "0.5"});
  bad_scene("|g| >= 1 accepted (singular Henyey-Greenstein phase function)",
            scene_with("g.json", [](json& s) { s["media"]["fog"]["g"] = -1.0; }),
            {"/media/fog/g", "-1"});
  bad_scene("g = 1 accepted (the upper bound of |g| < 1)",
            scene_with("g1.json", [](json& s) { s["media"]["fog"]["g"] = 1.0; }),
            {"/media/fog/g", "1"});
  bad_scene("zero bins accepted (empty film)",
            scene_with("bins.json", [](json& s) { s["time"]["bins"] = 0; }),
            {"/time/bins", "0"});
  bad_scene("a kernel alpha above 1 accepted (a growing bandwidth: inconsistent)",
            scene_with("alpha.json",
                       [](json& s) { s["time"]["reconstruction"] = {{"type", "kernel"}, {"alpha", 1.5}}; }),
            {"/time/reconstruction/alpha", "1.5"});
  bad_scene("an unknown connection sampling accepted",
            scene_with("conn.json", [](json& s) { s["media"]["fog"]["connection_sampling"] = "ltp"; }),
            {"/media/fog/connection_sampling", "ltp"});
  bad_scene("a misspelt reconstruction accepted",
            scene_with("recon.json", [](json& s) { s["time"]["reconstruction"] = "kernal"; }),
            {"/time/reconstruction", "kernal"});
  bad_scene(
      "a missing mesh file reported late or vaguely",
      scene_with("mesh.json",
                 [](json& s) {
                   s["shapes"].push_back({{"type", "mesh"},
                                          {"file", "missing_mesh.obj"},
                                          {"material", {{"type", "diffuse"}, {"albedo", 0.5}}}});
                 }),
      {"/shapes/1/file", "missing_mesh.obj"});

  const std::set<std::string> before = cli_listing(work);
  int index = 0;
  for (const auto& c : cases) {
    // Each case: bug it would catch is c.what.
    const RunResult r = run_cli(c.args, work, tmp.dir / ("logs" + std::to_string(index++)));
    INFO("case: " << c.what << "\ncommand: " << r.command << "\nstderr: " << r.err);
    CHECK(r.code == 2);
    CHECK(count_lines(r.err) == 1);
    for (const auto& e : c.expect) {
      INFO("message should contain '" << e << "'");
      CHECK(cli_contains(r.err, e));
    }
    CHECK_FALSE(fs::exists(out));
    CHECK(cli_listing(work) == before);  // no femto-out or other stray file either
    std::error_code ec;
    fs::remove_all(out, ec);  // so one failure does not cascade into the next cases
  }
}

// Catches: results that depend on the thread count (shared RNG streams, unordered sums), and a
// --seed that is ignored.
TEST_CASE("cli: same seed gives identical bytes for any thread count", "[cli]") {
  CliTempDir tmp;
  write_cli_text(tmp.dir / "scene.json", cli_scene().dump(2));
  auto render = [&](const std::string& name, const std::string& seed, const std::string& threads) {
    const fs::path out = tmp.dir / name;
    const RunResult r = run_cli({"render", "scene.json", "--seed", seed, "--threads", threads,
                                   "--frames", "none", "--no-previews", "--out", out.string(), "--quiet"},
                                  tmp.dir, tmp.dir / ("logs_" + name));
    INFO(r.command << "\nstderr: " << r.err);
    REQUIRE(r.code == 0);
    const json info = json::parse(read_cli_file(out / "render.json"));
    CHECK(info.at("settings").at("seed").get<uint64_t>() == std::stoull(seed));
    CHECK(info.at("settings").at("threads_requested").get<int>() == std::stoi(threads));
    return read_bytes(out / "transient.npy");
  };
  const std::vector<char> a = render("a", "7", "1");
  const std::vector<char> b = render("b", "7", "2");
  const std::vector<char> c = render("c", "8", "2");
  REQUIRE(a.size() > 128);
  CHECK(a.size() == b.size());
  CHECK(a == b);
  CHECK(a.size() == c.size());
  CHECK(a != c);
}

// Catches: an unknown subcommand (or none at all) treated as success.
TEST_CASE("cli: unknown subcommand exits 2", "[cli]") {
  CliTempDir tmp;
  const RunResult r = run_cli({"rendr", "--out", (tmp.dir / "out").string()}, tmp.dir, tmp.dir / "logs");
  INFO(r.err);
  CHECK(r.code == 2);
  CHECK(cli_contains(r.err, "rendr"));
  CHECK(count_lines(r.err) == 1);
  CHECK_FALSE(fs::exists(tmp.dir / "out"));
  // Catches: bare `femto` exiting 0, so scripts would not notice a missing command.
  const RunResult none = run_cli({}, tmp.dir, tmp.dir / "logs_none");
  CHECK(none.code == 2);
}
