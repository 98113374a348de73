// Tests of `femto uniformity`: the library (core/uniformity.h) on fixed seeds, and the command
// end to end through the built femto executable (FEMTO_BINARY): outputs, --expect uniform exit
// codes and bad flags.
#include <catch2/catch.hpp>

#include "temp_dir.h"

#include <sys/wait.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

#include "core/constants.h"
#include "core/uniformity.h"

#ifndef FEMTO_BINARY
#error "FEMTO_BINARY (path of the femto executable) must be defined by the build"
#endif

namespace fs = std::filesystem;
namespace un = femto::uniformity;
using nlohmann::json;

namespace {

un::Config small_config() {
  un::Config c;  // the canonical configuration, fewer samples
  c.samples = 20000;
  c.seed = 3;
  return c;
}

std::string read_uniformity_file(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

std::string shell_quote(const std::string& s) {
  std::string q = "'";
  for (char ch : s) q += ch == '\'' ? std::string("'\\''") : std::string(1, ch);
  return q + "'";
}

struct UniformityRun {
  int code = -1;
  std::string out, err;
};

// Runs femto uniformity with `args` from folder `cwd`; output captured under `logs`.
UniformityRun run_uniformity(const std::vector<std::string>& args, const fs::path& cwd,
                             const fs::path& logs) {
  fs::create_directories(logs);
  std::string cmd = shell_quote(FEMTO_BINARY) + " uniformity";
  for (const auto& a : args) cmd += " " + shell_quote(a);
  const fs::path out = logs / "stdout.txt", err = logs / "stderr.txt";
  const std::string full = "cd " + shell_quote(cwd.string()) + " && " + cmd + " >" +
                           shell_quote(out.string()) + " 2>" + shell_quote(err.string()) +
                           " </dev/null";
  const int status = std::system(full.c_str());
  UniformityRun r;
  if (status != -1 && WIFEXITED(status)) r.code = WEXITSTATUS(status);
  r.out = read_uniformity_file(out);
  r.err = read_uniformity_file(err);
  return r;
}

std::set<std::string> uniformity_listing(const fs::path& dir) {
  std::set<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.insert(e.path().filename().string());
  return names;
}

bool listing_contains(const std::string& s, const std::string& part) {
  return s.find(part) != std::string::npos;
}

}  // namespace

// Catches a time-targeted strategy that is not uniform in the canonical configuration, and a
// test without power: mfp and equiangular over a window ~30 mean free times long must fail.
TEST_CASE("uniformity: time-targeted strategies pass, mfp and equiangular fail", "[uniformity]") {
  const un::Config c = small_config();
  for (un::Strategy s : un::all_strategies()) {
    const un::Result r = un::run(c, s);
    INFO(un::strategy_name(s) << ": in range " << r.in_range << "  chi2 p = " << r.chi2.p_value
                              << "  KS p = " << r.ks_p);
    REQUIRE(r.valid);
    const bool targeted = s == un::Strategy::TimeUniform || s == un::Strategy::LineToPoint ||
                          s == un::Strategy::Angular;
    if (targeted) {
      CHECK(r.pass);
      CHECK(r.min_p() >= c.alpha);
    } else {
      CHECK_FALSE(r.pass);
      CHECK(r.chi2.p_value < 1e-6);
      CHECK(r.ks_p < 1e-6);
    }
  }
}

// Catches a rigged comparison: in the Poisson view of Supp. D.1 any exponential rate gives
// uniform vertex times, so mfp subpaths must pass there too (the difference is cost).
TEST_CASE("uniformity: mfp vertex times (Poisson view) are uniform too", "[uniformity]") {
  un::Config c = small_config();
  c.samples = 2000;  // ~30 vertices per subpath
  c.mfp_time = un::MfpTime::Vertices;
  const un::Result r = un::run(c, un::Strategy::Mfp);
  INFO("in range " << r.in_range << "  chi2 p = " << r.chi2.p_value << "  KS p = " << r.ks_p);
  CHECK(r.pass);
  CHECK(static_cast<double>(r.in_range) ==
        Approx(un::expected_vertices(c, un::Strategy::Mfp) * static_cast<double>(c.samples))
            .epsilon(0.05));
}

// Catches bookkeeping errors: counts not summing to the times in range, a wrong expected count
// or dof, a range not clipped to the reachable times, or results depending on anything but the
// seed.
TEST_CASE("uniformity: histogram bookkeeping, ranges and determinism", "[uniformity]") {
  un::Config c = small_config();
  c.bins = 20;
  for (un::Strategy s : un::all_strategies()) {
    INFO(un::strategy_name(s));
    const un::Result r = un::run(c, s);
    double sum = 0;
    for (double k : r.counts) sum += k;
    CHECK(r.counts.size() == 20);
    CHECK(sum == static_cast<double>(r.in_range));
    CHECK(r.expected_per_bin == Approx(sum / 20));
    CHECK(r.chi2.dof == 19);
    CHECK(r.range_lo_ps >= c.t_start_ps);
    CHECK(r.range_hi_ps <= c.t_end_ps);
    CHECK(un::run(c, s).counts == r.counts);
  }
  // The direct light-sensor time is |(20, 0, 10)| / c = 74.6 ps: connection ranges start there.
  CHECK(un::run(c, un::Strategy::LineToPoint).range_lo_ps ==
        Approx(std::sqrt(500.0) / femto::kSpeedOfLight).epsilon(1e-12));
}

// Catches a window that misses every reachable time being reported as a pass (or crashing).
TEST_CASE("uniformity: an unreachable window is reported invalid", "[uniformity]") {
  un::Config c = small_config();
  c.t_start_ps = 0;
  c.t_end_ps = 50;  // before the direct connection time (74.6 ps)
  for (un::Strategy s :
       {un::Strategy::LineToPoint, un::Strategy::Equiangular, un::Strategy::Angular}) {
    const un::Result r = un::run(c, s);
    INFO(un::strategy_name(s));
    CHECK_FALSE(r.valid);
    CHECK_FALSE(r.pass);
    CHECK_FALSE(r.note.empty());
  }
}

// Catches missing or malformed outputs, a table without every strategy, and a wrong exit code
// when no expectation is given.
TEST_CASE("uniformity cli: default run writes the table, CSVs, JSON and PNG", "[uniformity][cli]") {
  femto::test::TempDir tmp("femto_test_uniformity");
  const fs::path out = tmp.dir / "out";
  const UniformityRun r = run_uniformity({"--samples", "20000", "--bins", "40", "--out", out.string()},
                               tmp.dir, tmp.dir / "logs");
  INFO(r.err);
  REQUIRE(r.code == 0);
  for (un::Strategy s : un::all_strategies()) {
    const std::string name = un::strategy_name(s);
    CHECK(listing_contains(r.out, name));
    const std::string csv = read_uniformity_file(out / ("hist_" + name + ".csv"));
    CHECK(std::count(csv.begin(), csv.end(), '\n') == 41);  // header + 40 bins
  }
  const json j = json::parse(read_uniformity_file(out / "summary.json"));
  REQUIRE(j["strategies"].size() == 5);
  for (const auto& s : j["strategies"]) {
    CHECK(s["in_range"].get<double>() > 0);
    CHECK(s["chi2_dof"].get<int>() == 39);
    const bool targeted = s["strategy"] != "mfp" && s["strategy"] != "equiangular";
    CHECK(s["uniform"].get<bool>() == targeted);
  }
  CHECK(fs::file_size(out / "histograms.png") > 1000);
  for (const auto& e : fs::directory_iterator(out))  // atomic writes leave no temporaries
    CHECK_FALSE(listing_contains(e.path().filename().string(), ".tmp"));
}

// Catches --expect uniform ignoring failures (or failing passing strategies).
TEST_CASE("uniformity cli: --expect uniform exit codes", "[uniformity][cli]") {
  femto::test::TempDir tmp("femto_test_uniformity");
  struct Case {
    const char* strategy;
    int code;
  };
  int k = 0;
  for (const Case c : {Case{"line_to_point", 0}, Case{"angular", 0}, Case{"time_uniform", 0},
                       Case{"mfp", 1}, Case{"equiangular", 1}, Case{"all", 1}}) {
    const fs::path out = tmp.dir / ("out" + std::to_string(k));
    const UniformityRun r = run_uniformity({"--strategy", c.strategy, "--samples", "20000", "--expect",
                                  "uniform", "--quiet", "--out", out.string()},
                                 tmp.dir, tmp.dir / ("logs" + std::to_string(k)));
    ++k;
    INFO(c.strategy << ": " << r.out << r.err);
    CHECK(r.code == c.code);
    CHECK(fs::exists(out / "summary.json"));  // a failed expectation still writes the results
  }
}

// Catches bad flags accepted, reported vaguely, reported as failures (1) or leaving files.
TEST_CASE("uniformity cli: bad flags exit 2 with one message and write nothing",
          "[uniformity][cli]") {
  femto::test::TempDir tmp("femto_test_uniformity");
  const fs::path work = tmp.dir / "work";
  fs::create_directories(work);
  const std::string out = (tmp.dir / "out").string();
  struct Case {
    const char* what;  // the bug the case would catch
    std::vector<std::string> args;
    std::vector<std::string> expect;
  };
  const std::vector<Case> cases = {
      {"an empty window accepted", {"--t-start", "500", "--t-end", "400"}, {"--t-end", "'400'"}},
      {"t_end == t_start accepted", {"--t-start", "100", "--t-end", "100"}, {"--t-end", "'100'"}},
      {"sigma_t = 0 accepted", {"--sigma-t", "0"}, {"--sigma-t", "'0'"}},
      {"negative sigma_t accepted", {"--sigma-t", "-1"}, {"--sigma-t", "'-1'"}},
      {"eta < 1 accepted", {"--eta", "0.9"}, {"--eta", "'0.9'"}},
      {"zero samples accepted", {"--samples", "0"}, {"--samples", "'0'"}},
      {"an unknown strategy falling back to all",
       {"--strategy", "uniform"},
       {"--strategy", "'uniform'"}},
      {"a vector with two components", {"--light", "1,2"}, {"--light", "'1,2'"}},
      {"a vector with junk", {"--sensor", "1,x,3"}, {"--sensor", "'1,x,3'"}},
      {"a trailing comma", {"--dir", "0,0,1,"}, {"--dir", "'0,0,1,'"}},
      {"a zero direction", {"--dir", "0,0,0"}, {"--dir", "'0,0,0'"}},
      {"alpha = 1 accepted", {"--alpha", "1"}, {"--alpha", "'1'"}},
      {"one bin accepted (no test possible)", {"--bins", "1"}, {"--bins", "'1'"}},
      {"an unknown --expect value", {"--expect", "gaussian"}, {"--expect", "'gaussian'"}},
      {"an unknown flag", {"--bogus"}, {"--bogus"}},
      {"a non-numeric number", {"--t-end", "abc"}, {"--t-end", "'abc'"}},
  };
  const std::set<std::string> before = uniformity_listing(work);
  int index = 0;
  for (const auto& c : cases) {
    std::vector<std::string> args = c.args;
    args.push_back("--out");
    args.push_back(out);
    const UniformityRun r = run_uniformity(args, work, tmp.dir / ("logs" + std::to_string(index++)));
    INFO("case: " << c.what << "\nstderr: " << r.err);
    CHECK(r.code == 2);
    CHECK(std::count(r.err.begin(), r.err.end(), '\n') == 1);
    for (const auto& e : c.expect) {
      INFO("message should contain " << e);
      CHECK(listing_contains(r.err, e));
    }
    CHECK(r.out.empty());
    CHECK_FALSE(fs::exists(out));
    CHECK(uniformity_listing(work) == before);
  }
}
