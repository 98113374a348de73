// Passes, checkpoints and resume (core/render.h, core/checkpoint.h); SHA-256; the output folder
// swap, interruption by SIGINT/SIGTERM and the memory estimate, end to end.
#include <catch2/catch.hpp>

#include <signal.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <set>
#include <nlohmann/json.hpp>

#include "cli_helpers.h"
#include "core/checkpoint.h"
#include "core/error.h"
#include "core/io/sha256.h"
#include "core/render.h"
#include "core/rng.h"
#include "core/scene_loader.h"
#include "run_femto.h"
#include "spawn_femto.h"
#include "temp_dir.h"

using namespace femto;
using namespace femto::test;
namespace fs = std::filesystem;
using json = nlohmann::json;

namespace {

// The command-line tests' scene (cli::cli_scene) with its own seed and time bins.
std::string scene_text(int w = 24, int h = 20, int bins = 12, bool glass = false) {
  json s = cli::cli_scene();
  s["time"]["bin_width"] = 60;
  s["render"]["seed"] = 3;
  s["camera"]["resolution"] = {w, h};
  s["time"]["bins"] = bins;
  if (glass)
    s["shapes"].push_back(
        {{"type", "sphere"}, {"center", {0, 10, 25}}, {"radius", 12}, {"material", {{"type", "dielectric"}, {"eta", 1.5}}}});
  return s.dump();
}

std::vector<float> film_of(const RenderResult& r) {
  const TransientFilm& f = r.film;
  const size_t n = static_cast<size_t>(f.width()) * f.height() * (f.bins() + 2) * 3;
  std::vector<float> v(f.transient(), f.transient() + static_cast<size_t>(f.width()) * f.height() * f.bins() * 3);
  v.insert(v.end(), f.before(), f.before() + static_cast<size_t>(f.width()) * f.height() * 3);
  v.insert(v.end(), f.after(), f.after() + static_cast<size_t>(f.width()) * f.height() * 3);
  REQUIRE(v.size() == n);
  return v;
}

bool same_bits(const std::vector<float>& a, const std::vector<float>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
}

// Renders in one go, then again stopped after `stop_after` passes of `units` units, the state
// written to a checkpoint file and read back, and resumed with another thread count.
void check_resume(const Scene& scene, RenderOptions opt, int64_t units, int stop_after, const fs::path& dir) {
  opt.quiet = true;
  opt.threads = 2;
  const RenderResult whole = render(scene, opt);
  REQUIRE(whole.complete);

  std::atomic<bool> stop{false};
  int passes = 0;
  const json fp = {{"test", 1}};
  const std::string ck = (dir / "checkpoint.bin").string();
  RenderOptions a = opt;
  a.threads = 1;
  a.units_per_pass = units;
  a.stop = &stop;
  a.after_pass = [&](const RenderState& s, bool last) {
    if (++passes == stop_after) stop = true;
    if (last) write_checkpoint(ck, fp, s);
  };
  const RenderResult partial = render(scene, a);
  CHECK_FALSE(partial.complete);
  CHECK(partial.units_done > 0);
  CHECK(partial.units_done < partial.units_total);

  Checkpoint c = read_checkpoint(ck);
  CHECK(fingerprint_difference(c.fingerprint, fp).empty());
  RenderOptions b = opt;
  b.threads = 2;
  b.resume = &c.state;
  const RenderResult resumed = render(scene, b);
  CHECK(resumed.complete);
  CHECK(resumed.sessions == 2);
  CHECK(same_bits(film_of(resumed), film_of(whole)));
  CHECK(resumed.stats.paths == whole.stats.paths);
  CHECK(resumed.final_bandwidth_ps == whole.final_bandwidth_ps);
}

json read_json(const fs::path& p) { return json::parse(read_file(p)); }

std::set<std::string> tree(const fs::path& dir) {
  std::set<std::string> names;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file()) names.insert(fs::relative(e.path(), dir).string());
  return names;
}

// No staging, old or temporary files anywhere under `dir`.
void check_no_temporaries(const fs::path& dir) {
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    const std::string n = e.path().filename().string();
    INFO(e.path().string());
    CHECK(n.find(".tmp.") == std::string::npos);
    CHECK(n.find(".femto-tmp.") == std::string::npos);
    CHECK(n.find(".femto-old.") == std::string::npos);
  }
}

}  // namespace

// Catches: a wrong SHA-256 (padding, length encoding, blocks split across updates).
TEST_CASE("sha256 matches the FIPS 180-4 test vectors", "[resume]") {
  CHECK(sha256_hex("") == "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  CHECK(sha256_hex("abc") == "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  CHECK(sha256_hex("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq") ==
        "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
  Sha256 h;  // one million 'a', in uneven pieces
  const std::string piece(997, 'a');
  size_t left = 1000000;
  while (left > 0) {
    const size_t n = std::min(left, piece.size());
    h.update(piece.data(), n);
    left -= n;
  }
  CHECK(h.hex() == "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
}

// Catches: the CPU's SHA instructions (used when present) and the portable code disagreeing, e.g.
// a wrong state layout, message schedule or byte order in either, for any length and any split
// of the input into updates; and the portable code failing the FIPS vectors where the machine
// running the tests takes the hardware path.
TEST_CASE("sha256: the hardware and portable paths give the same digests", "[resume]") {
  INFO("SHA instructions on this CPU: " << sha256_hardware_available());
  Sha256 portable(false);
  portable.update("abc", 3);
  CHECK(portable.hex() == "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  Rng rng(2026, 12);
  std::string bytes(5000, '\0');
  for (char& c : bytes)  // via unsigned char: a double above 127 does not fit a char
    c = static_cast<char>(static_cast<unsigned char>(rng.uniform() * 256.0));
  for (size_t len : {0u, 1u, 55u, 56u, 63u, 64u, 65u, 127u, 128u, 1000u, 4099u, 5000u}) {
    Sha256 a(true), b(false);
    size_t at = 0;
    while (at < len) {  // pieces of 1 to 200 bytes
      const size_t n = std::min(len - at, size_t{1} + static_cast<size_t>(rng.uniform() * 200.0));
      a.update(bytes.data() + at, n);
      b.update(bytes.data() + at, n);
      at += n;
    }
    INFO("length " << len);
    CHECK(a.hex() == b.hex());
  }
}

// Catches: passes that change the per-pixel summation order (different bits), state that is
// not carried over (kernel bandwidths, photon schedule, light batches, counters), and
// checkpoints that lose or reorder data.
TEST_CASE("a render stopped after any pass and resumed from its checkpoint has the same bits", "[resume]") {
  TempDir tmp("femto_resume");
  SECTION("camera paths, histogram film") {
    const Scene scene(load_scene_string(scene_text(), "s.json", "."));
    RenderOptions opt;
    opt.spp = 7;
    check_resume(scene, opt, 2, 1, tmp.dir);
    check_resume(scene, opt, 1, 5, tmp.dir);
  }
  SECTION("camera paths, kernel film") {
    SceneDesc d = load_scene_string(scene_text(24, 40), "s.json", ".");
    d.reconstruction.type = TemporalFilter::Kind::Kernel;
    d.reconstruction.first_pass_spp = 3;
    d.reconstruction.knn = 4;
    const Scene scene(std::move(d));
    RenderOptions opt;
    opt.spp = 6;
    check_resume(scene, opt, 1, 1, tmp.dir);  // 3 tile rows: stop after the first
  }
  SECTION("light tracing") {
    const Scene scene(load_scene_string(scene_text(), "s.json", "."));
    RenderOptions opt;
    opt.integrator = IntegratorKind::Light;
    opt.light_paths = 3 * 65536 + 100;  // 4 batches, the last one short
    check_resume(scene, opt, 1, 2, tmp.dir);
  }
  SECTION("photons") {
    const Scene scene(load_scene_string(scene_text(24, 20, 12, true), "s.json", "."));
    RenderOptions opt;
    opt.integrator = IntegratorKind::Photons;
    opt.photons.per_pass = 2000;
    opt.spp = 5;
    check_resume(scene, opt, 1, 2, tmp.dir);
  }
}

// Catches: corrupt or truncated checkpoints being used, and vague fingerprint mismatches.
TEST_CASE("checkpoints are verified before use", "[resume]") {
  TempDir tmp("femto_resume");
  RenderState s;
  s.units_total = 4;
  s.units_done = 2;
  s.stride = 6;
  s.sums = {1, 2, 3, 4, 5, 6};
  const std::string path = (tmp.dir / "c.bin").string();
  write_checkpoint(path, {{"a", 1}}, s);
  const Checkpoint c = read_checkpoint(path);
  CHECK(c.state.sums == s.sums);
  CHECK(c.state.units_done == 2);
  std::string bytes = read_file(path);
  SECTION("a flipped byte") {
    bytes[bytes.size() - 50] ^= 1;  // inside the last double
    write_file(path, bytes);
    CHECK_THROWS_WITH(read_checkpoint(path), Catch::Contains("SHA-256"));
  }
  SECTION("truncated") {
    write_file(path, bytes.substr(0, bytes.size() / 2));
    CHECK_THROWS_AS(read_checkpoint(path), InputError);
  }
  SECTION("not a checkpoint") {
    write_file(path, "hello, this is not a checkpoint at all, really not");
    CHECK_THROWS_WITH(read_checkpoint(path), Catch::Contains("FEMTOCKP"));
  }
  CHECK(fingerprint_difference({{"settings", {{"spp", 4}}}}, {{"settings", {{"spp", 8}}}}) ==
        "/settings/spp: checkpoint has 4, this run has 8");
}

// Catches: frames of an earlier render left beside new ones, render.json not listing every file
// or with wrong sizes or hashes, and temporary files or folders left behind.
TEST_CASE("cli: a rerun replaces the whole output folder; render.json lists every file with its SHA-256",
          "[resume]") {
  TempDir tmp("femto_resume_cli");
  write_file(tmp.dir / "a.json", scene_text(16, 12, 40));
  write_file(tmp.dir / "b.json", scene_text(16, 12, 4));
  REQUIRE(run_femto({"render", "a.json", "--spp", "1", "--out", "out", "--quiet"}, tmp.dir).code == 0);
  CHECK(tree(tmp.dir / "out").size() == 40 + 9);  // frames + 9 other files (peak_time.png included)
  const auto r = run_femto({"render", "b.json", "--spp", "1", "--out", "out", "--quiet"}, tmp.dir);
  REQUIRE(r.code == 0);
  const json info = read_json(tmp.dir / "out" / "render.json");
  CHECK(info["complete"] == true);
  std::set<std::string> listed = {"render.json"};
  for (const auto& f : info["files"]) {
    const std::string name = f["name"];
    listed.insert(name);
    INFO(name);
    CHECK(f["bytes"].get<uint64_t>() == fs::file_size(tmp.dir / "out" / name));
    CHECK(f["sha256"] == sha256_file((tmp.dir / "out" / name).string()));
  }
  CHECK(tree(tmp.dir / "out") == listed);  // exactly the new files: 4 frames, not 40
  CHECK(listed.size() == 4 + 9);
  check_no_temporaries(tmp.dir);
}

// Catches: femto deleting a user's files, or starting a render it cannot write.
TEST_CASE("cli: --out is refused when it holds other files or cannot be written", "[resume]") {
  TempDir tmp("femto_resume_cli");
  write_file(tmp.dir / "s.json", scene_text(8, 6, 4));
  fs::create_directories(tmp.dir / "mine");
  write_file(tmp.dir / "mine" / "thesis.tex", "precious");
  auto r = run_femto({"render", "s.json", "--spp", "1", "--out", "mine"}, tmp.dir);
  CHECK(r.code == 2);
  CHECK_THAT(r.err, Catch::Contains("thesis.tex") && Catch::Contains("not part of a femto render"));
  CHECK(read_file(tmp.dir / "mine" / "thesis.tex") == "precious");
  CHECK(tree(tmp.dir / "mine").size() == 1);

  // A file added to a femto render folder is not femto's either.
  REQUIRE(run_femto({"render", "s.json", "--spp", "1", "--out", "done", "--quiet"}, tmp.dir).code == 0);
  write_file(tmp.dir / "done" / "notes.txt", "mine");
  r = run_femto({"render", "s.json", "--spp", "1", "--out", "done"}, tmp.dir);
  CHECK(r.code == 2);
  CHECK_THAT(r.err, Catch::Contains("notes.txt"));

  fs::create_directories(tmp.dir / "empty");
  CHECK(run_femto({"render", "s.json", "--spp", "1", "--out", "empty", "--quiet"}, tmp.dir).code == 0);

  r = run_femto({"render", "s.json", "--spp", "1", "--out", "s.json/out"}, tmp.dir);  // under a file
  CHECK(r.code == 2);
  CHECK_THAT(r.err, Catch::Contains("--out"));
  r = run_femto({"render", "s.json", "--spp", "1", "--out", "s.json"}, tmp.dir);
  CHECK(r.code == 2);
  CHECK_THAT(r.err, Catch::Contains("not a folder"));
  check_no_temporaries(tmp.dir);
}

// Catches: a stop that leaves half-written or inconsistent outputs, wrong exit codes, a
// checkpoint that does not resume to the uninterrupted bits, resumes with other settings, and a
// second signal that leaves temporary files or damages the previous output.
TEST_CASE("cli: SIGINT and SIGTERM stop after a pass; --resume gives the uninterrupted bits", "[resume]") {
  TempDir tmp("femto_resume_cli");
  write_file(tmp.dir / "s.json", scene_text(48, 40, 16));
  const std::vector<std::string> base = {"render", "s.json", "--spp", "160", "--quiet"};
  auto with = [&](std::vector<std::string> extra) {
    std::vector<std::string> a = base;
    a.insert(a.end(), extra.begin(), extra.end());
    return a;
  };
  REQUIRE(run_femto(with({"--out", "whole"}), tmp.dir).code == 0);

  for (const int sig : {SIGINT, SIGTERM}) {
    const std::string out = sig == SIGINT ? "int" : "term";
    INFO(out);
    const pid_t pid = spawn_femto(with({"--out", out, "--checkpoint-every", "0", "--threads", "1"}), tmp.dir);
    REQUIRE(pid > 0);
    REQUIRE(wait_for_file(tmp.dir / out / "checkpoint.bin", 20));  // a pass is done
    ::kill(pid, sig);
    const int code = wait_femto(pid);
    INFO(read_file(tmp.dir / "bg_stderr.txt"));
    REQUIRE(code == 128 + sig);
    const json info = read_json(tmp.dir / out / "render.json");
    CHECK(info["complete"] == false);
    CHECK(info["progress"]["spp_done"].get<int>() > 0);
    CHECK(info["progress"]["spp_done"].get<int>() < 160);
    CHECK(info["checkpoint"]["file"] == "checkpoint.bin");
    CHECK(fs::exists(tmp.dir / out / "transient.npy"));
    check_no_temporaries(tmp.dir);

    // Other settings are refused, naming the difference.
    auto bad = run_femto({"render", "s.json", "--spp", "100", "--resume", out}, tmp.dir);
    CHECK(bad.code == 2);
    CHECK_THAT(bad.err, Catch::Contains("/settings/spp") && Catch::Contains("160"));
    // The roulette decides the bits too.
    auto bad_rr = run_femto(
        {"render", "s.json", "--spp", "160", "--russian-roulette", "off", "--resume", out}, tmp.dir);
    CHECK(bad_rr.code == 2);
    CHECK_THAT(bad_rr.err, Catch::Contains("/settings/russian_roulette"));

    const auto r = run_femto(with({"--resume", out, "--threads", "2"}), tmp.dir);
    INFO(r.err);
    REQUIRE(r.code == 0);
    const json done = read_json(tmp.dir / out / "render.json");
    CHECK(done["complete"] == true);
    CHECK(done["progress"]["sessions"] == 2);
    CHECK_FALSE(fs::exists(tmp.dir / out / "checkpoint.bin"));
    CHECK(read_file(tmp.dir / out / "transient.npy") == read_file(tmp.dir / "whole" / "transient.npy"));
    // Counters carry over the sessions, the roulette's included.
    const json whole = read_json(tmp.dir / "whole" / "render.json");
    CHECK(done["counters"]["roulette_terminations"] == whole["counters"]["roulette_terminations"]);
    CHECK(done["counters"]["paths"] == whole["counters"]["paths"]);
  }

  // A second signal aborts at once: the previous output stays as it was, nothing else is left.
  const std::string before = read_file(tmp.dir / "whole" / "render.json");
  std::vector<std::string> loud = with({"--out", "whole", "--checkpoint-every", "0", "--threads", "1"});
  loud.erase(std::find(loud.begin(), loud.end(), "--quiet"));
  const pid_t pid = spawn_femto(loud, tmp.dir);
  REQUIRE(pid > 0);
  REQUIRE(wait_for_file(tmp.dir / "whole" / "checkpoint.bin", 20));
  ::kill(pid, SIGINT);
  // Signals of one kind are not queued: send the second once the first has been taken.
  for (int i = 0; i < 2000 && read_file(tmp.dir / "bg_stderr.txt").find("finishing the current pass") == std::string::npos; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  ::kill(pid, SIGINT);
  const int code = wait_femto(pid);
  INFO(read_file(tmp.dir / "bg_stderr.txt"));  // whether the first signal was taken in time
  CHECK(code == 130);
  CHECK(read_file(tmp.dir / "whole" / "render.json") == before);
  check_no_temporaries(tmp.dir);
}

// Catches: a memory estimate that misses a buffer (film, double sums, per-thread buffers).
// [no-sanitizer]: under ASan the resident memory also holds its shadow memory and quarantine.
TEST_CASE("cli: the memory estimate is within 10% of the measured peak", "[resume][no-sanitizer]") {
  TempDir tmp("femto_resume_cli");
  json s = json::parse(scene_text(256, 256, 64));
  s["render"]["max_depth"] = 2;
  write_file(tmp.dir / "s.json", s.dump());
  const auto r = run_femto({"render", "s.json", "--spp", "1", "--out", "out", "--quiet", "--frames", "none",
                            "--no-previews", "--integrator", "path"},
                           tmp.dir);
  REQUIRE(r.code == 0);
  const json m = read_json(tmp.dir / "out" / "render.json")["memory"];
  const double estimate = m["estimate_bytes"].get<double>(), peak = m["peak_rss_bytes"].get<double>();
  INFO("estimate " << estimate << " peak " << peak);
  CHECK(m["breakdown"]["sums"].get<double>() == 256.0 * 256 * 66 * 3 * 8);
  CHECK(peak > 0.9 * estimate);
  CHECK(peak < 1.1 * estimate);
}

// Catches: femto diffusion ignoring SIGTERM (killed without outputs) or exiting with 130.
TEST_CASE("cli: diffusion stops cleanly on SIGTERM with exit code 143", "[resume]") {
  TempDir tmp("femto_resume_cli");
  const pid_t pid = spawn_femto({"diffusion", "--photons", "1e12", "--threads", "1", "--out", "d"}, tmp.dir);
  REQUIRE(pid > 0);
  // Its estimate of the run time is printed once the first batches are traced.
  for (int i = 0; i < 5000 && read_file(tmp.dir / "bg_stderr.txt").find("photons") == std::string::npos; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  ::kill(pid, SIGTERM);
  CHECK(wait_femto(pid) == 143);
  const json run = read_json(tmp.dir / "d" / "summary.json");
  CHECK(run.at("stopped_early") == "SIGTERM");
  CHECK(run.at("photons_traced").get<double>() < 1e12);
}
