#pragma once
// Runs the built femto executable (FEMTO_BINARY) for end-to-end tests: exit code, stdout, stderr.
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#ifndef FEMTO_BINARY
#error "FEMTO_BINARY (path of the femto executable) must be defined by the build"
#endif

namespace femto::test {

inline std::string read_file(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

inline void write_file(const std::filesystem::path& p, const std::string& text) {
  std::ofstream out(p, std::ios::binary);
  out << text;
}

inline std::string quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

struct Run {
  int code = -1;  ///< exit code, or -1 when femto did not exit normally (a crash)
  std::string out, err;
};

/// femto `args` run in `cwd`; its output is captured in files under `cwd`.
inline Run run_femto(const std::vector<std::string>& args, const std::filesystem::path& cwd) {
  std::string cmd = "cd " + quote(cwd.string()) + " && " + quote(FEMTO_BINARY);
  for (const auto& a : args) cmd += " " + quote(a);
  const auto out = cwd / "run_stdout.txt", err = cwd / "run_stderr.txt";
  cmd += " >" + quote(out.string()) + " 2>" + quote(err.string()) + " </dev/null";
  Run r;
  const int status = std::system(cmd.c_str());
  if (status != -1 && WIFEXITED(status)) r.code = WEXITSTATUS(status);
  r.out = read_file(out);
  r.err = read_file(err);
  std::filesystem::remove(out);
  std::filesystem::remove(err);
  return r;
}

}  // namespace femto::test
