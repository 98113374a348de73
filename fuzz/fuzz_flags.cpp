// libFuzzer target: command-line flags. The input is one argument per line (NUL also separates:
// argv strings cannot contain it). The first line picks what parses the rest:
//   - a command name (render, diffusion, uniformity, info, make-volume): the command's own flag
//     loop, with two "--help" appended. Every flag takes at most one value, so one of the two is
//     read as a flag and the command prints its help (to /dev/null) and returns without loading,
//     rendering or writing anything; or a flag is refused first with an InputError.
//   - anything else: cli::Args parsers directly, picked by flag name (--int, --count, --size, ...)
//     with wider ranges than the commands use, and their results checked against those ranges.
// Bad input must be an InputError; any other exception, a crash or a sanitizer report is a
// finding.
#include <unistd.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <fcntl.h>
#include <limits>
#include <string>
#include <vector>

#include "apps/cli.h"
#include "apps/commands.h"
#include "core/error.h"

namespace {

[[noreturn]] void finding(const std::string& what) {
  std::fprintf(stderr, "fuzz_flags: %s\n", what.c_str());
  std::abort();
}

void check(bool ok, const char* what) {
  if (!ok) finding(std::string("parser result out of its range: ") + what);
}

void parse_directly(femto::cli::Args& args) {
  while (!args.done()) {
    const std::string a = args.next();
    if (a == "--int") {
      const int64_t x = args.int_value(std::numeric_limits<int64_t>::min(), std::numeric_limits<int64_t>::max());
      (void)x;
    } else if (a == "--int-small") {
      const int64_t x = args.int_value(1, 10000000);
      check(x >= 1 && x <= 10000000, "--int-small");
    } else if (a == "--uint") {
      (void)args.uint_value();
    } else if (a == "--double") {
      const double x = args.double_value(1e-6, 1e6);
      check(x >= 1e-6 && x <= 1e6, "--double");
    } else if (a == "--number") {
      const double x = args.number_in(0.0, 1.0, true, false, "in (0, 1]");
      check(x > 0 && x <= 1, "--number");
    } else if (a == "--number-wide") {
      const double x = args.number_in(-std::numeric_limits<double>::max(), std::numeric_limits<double>::max(),
                                      false, false, "finite");
      check(std::isfinite(x), "--number-wide");
    } else if (a == "--xyz") {
      const femto::Vec3 v = args.xyz_value();
      check(std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z), "--xyz");
    } else if (a == "--dir") {
      const femto::Vec3 v = args.xyz_value(true);
      check(length(v) > 0, "--dir");
    } else if (a == "--count") {
      const uint64_t n = args.count_value(2, 1e12);
      check(n >= 2 && n <= 1000000000000ull, "--count");
    } else if (a == "--count-wide") {
      const uint64_t n = args.count_value(0, 1e19);
      check(n <= 10000000000000000000ull, "--count-wide");
    } else if (a == "--size") {
      const uint64_t n = args.size_value();
      check(n >= 1, "--size");
      check(!femto::cli::format_bytes(n).empty(), "--size format");
    } else if (a == "--value") {
      (void)args.value();
    } else if (a == "--fail") {
      args.fail("refused", args.value());
    }
    // anything else is a positional argument
  }
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  // Help texts go to stdout: keep the fuzzer's output readable.
  const int null = open("/dev/null", O_WRONLY);
  if (null >= 0) dup2(null, STDOUT_FILENO);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::vector<std::string> args(1);
  for (size_t i = 0; i < size; ++i) {
    const char c = static_cast<char>(data[i]);
    if (c == '\n' || c == '\0') args.emplace_back();
    else args.back() += c;
  }
  const std::string selector = args.front();
  args.erase(args.begin());
  try {
    for (const femto::Command& c : femto::commands()) {
      if (selector != c.name) continue;
      args.push_back("--help");
      args.push_back("--help");
      const int code = c.run(args, "femto " + selector);
      if (code != 0) finding("command returned " + std::to_string(code) + " while parsing flags");
      return 0;
    }
    femto::cli::Args parser("fuzz", args);
    parse_directly(parser);
  } catch (const femto::InputError&) {
    // expected for bad input
  } catch (const std::exception& e) {
    finding(std::string("bad input escaped as ") + e.what() + ", not InputError");
  }
  return 0;
}
