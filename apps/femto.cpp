// The femto command: dispatches to subcommands and maps errors to exit codes
// (2: bad input, 1: other failures).
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include "apps/commands.h"
#include "core/error.h"
#include "femto_version.h"

namespace {
void print_usage() {
  std::printf("femto %s - transient (time-resolved) light transport in participating media\n\n",
              FEMTO_VERSION);
  std::printf("Usage: femto COMMAND [options]     (femto COMMAND --help for its options)\n\n");
  std::printf("Commands:\n");
  for (const auto& c : femto::commands()) std::printf("  %-12s %s\n", c.name, c.summary);
  std::printf("\n  --version    print the version\n  --help       this help\n\n");
  std::printf("Units: millimetres and picoseconds. Exit codes: 0 ok, 1 failure, 2 bad input.\n");
  std::printf("Documentation: README.md and docs/ (scene-format.md, outputs.md).\n");
}
}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> args(argv + 1, argv + argc);
  std::string command_line = "femto";
  for (const auto& a : args) command_line += " " + a;
  if (args.empty() || args[0] == "--help" || args[0] == "-h" || args[0] == "help") {
    print_usage();
    return args.empty() ? 2 : 0;
  }
  if (args[0] == "--version" || args[0] == "-V") {
    std::printf("femto %s (%s)\n", FEMTO_VERSION, FEMTO_GIT_DESCRIBE);
    return 0;
  }
  const std::string name = args[0];
  args.erase(args.begin());
  for (const auto& c : femto::commands()) {
    if (name != c.name) continue;
    try {
      return c.run(args, command_line);
    } catch (const femto::InputError& e) {
      std::fprintf(stderr, "femto: error: %s\n", e.what());
      return 2;
    } catch (const std::exception& e) {
      std::fprintf(stderr, "femto: failure: %s\n", e.what());
      return 1;
    }
  }
  std::fprintf(stderr, "femto: unknown command '%s' (try femto --help)\n",
               femto::clip(name).c_str());
  return 2;
}
