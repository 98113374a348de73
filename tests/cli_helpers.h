#pragma once
// Helpers of the command-line tests (tests/test_cli.cpp, tests/test_cli_integrators.cpp): they run
// the built femto executable (FEMTO_BINARY) in a fresh temporary folder and read what it wrote.
#include <catch2/catch.hpp>

#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

#include "temp_dir.h"

#ifndef FEMTO_BINARY
#error "FEMTO_BINARY (path of the femto executable) must be defined by the build"
#endif

namespace femto::test::cli {

namespace fs = std::filesystem;
using nlohmann::json;

struct CliTempDir : femto::test::TempDir {
  CliTempDir() : femto::test::TempDir("femto_test_cli") {}
};

inline std::string read_cli_file(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

inline void write_cli_text(const fs::path& p, const std::string& text) {
  std::ofstream out(p, std::ios::binary);
  out << text;
  REQUIRE(out.good());
}

inline std::string shell_quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) {
    if (c == '\'')
      q += "'\\''";
    else
      q += c;
  }
  return q + "'";
}

struct RunResult {
  int code = -1;  ///< exit code, or -1 when femto did not exit normally (e.g. it crashed)
  std::string out, err;
  std::string command;
};

// Runs femto with `args` from folder `cwd` (so a stray default ./femto-out would land in the
// temp folder too); stdout and stderr are captured in files under `logs`, which is created.
inline RunResult run_cli(const std::vector<std::string>& args, const fs::path& cwd,
                         const fs::path& logs) {
  fs::create_directories(logs);
  RunResult r;
  std::string cmd = shell_quote(FEMTO_BINARY);
  for (const auto& a : args) cmd += " " + shell_quote(a);
  r.command = cmd;
  const fs::path out = logs / "stdout.txt", err = logs / "stderr.txt";
  const std::string full = "cd " + shell_quote(cwd.string()) + " && " + cmd + " >" +
                           shell_quote(out.string()) + " 2>" + shell_quote(err.string()) +
                           " </dev/null";
  const int status = std::system(full.c_str());
  if (status != -1 && WIFEXITED(status)) r.code = WEXITSTATUS(status);
  r.out = read_cli_file(out);
  r.err = read_cli_file(err);
  return r;
}

inline bool cli_contains(const std::string& s, const std::string& part) {
  return s.find(part) != std::string::npos;
}

inline std::vector<char> read_bytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::vector<char>(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// A small valid scene: a camera, a time axis, a foggy global medium, one diffuse quad and one
// point light. 40 x 24 pixels is several 16-pixel tiles, so --threads 2 really splits the work.
inline json cli_scene() {
  return json::parse(R"({
    "camera": { "type": "perspective", "position": [0, 0, 100], "look_at": [0, 0, 0],
                "fov": 40, "resolution": [40, 24] },
    "time": { "t_start": 0, "bin_width": 50, "bins": 24, "mode": "camera" },
    "media": { "fog": { "type": "homogeneous", "sigma_a": 0.001, "sigma_s": 0.01, "g": 0.3, "eta": 1.0 } },
    "medium": "fog",
    "shapes": [
      { "type": "quad", "corner": [-60, -60, 0], "edge1": [120, 0, 0], "edge2": [0, 120, 0],
        "material": { "type": "diffuse", "albedo": 0.7 } }
    ],
    "lights": [ { "type": "point", "position": [10, 20, 50], "intensity": 1000 } ],
    "render": { "spp": 4, "max_depth": 100, "seed": 1 }
  })");
}

// Sorted names of the entries directly inside `dir`.
inline std::set<std::string> cli_listing(const fs::path& dir) {
  std::set<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.insert(e.path().filename().string());
  return names;
}

inline size_t count_lines(const std::string& s) {
  size_t n = 0;
  for (char c : s) n += c == '\n';
  if (!s.empty() && s.back() != '\n') ++n;
  return n;
}

}  // namespace femto::test::cli
