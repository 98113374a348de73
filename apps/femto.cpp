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
const char* kUsage =
    "femto " FEMTO_VERSION " - transient (time-resolved) light transport in participating media\n"
    "\n"
    "Usage:\n"
    "  femto render [SCENE.json] [options]   render a scene (the built-in default scene without one)\n"
    "  femto --version                       print the version\n"
    "  femto --help | femto COMMAND --help   this help, or a command's options\n"
    "\n"
    "Units: millimetres and picoseconds. Exit codes: 0 ok, 1 failure, 2 bad input.\n"
    "Documentation: README.md, docs/scene-format.md, docs/outputs.md.\n";
}

int main(int argc, char** argv) {
  std::vector<std::string> args(argv + 1, argv + argc);
  std::string command_line = "femto";
  for (const auto& a : args) command_line += " " + a;
  if (args.empty() || args[0] == "--help" || args[0] == "-h" || args[0] == "help") {
    std::fputs(kUsage, stdout);
    return args.empty() ? 2 : 0;
  }
  if (args[0] == "--version" || args[0] == "-V") {
    std::printf("femto %s (%s)\n", FEMTO_VERSION, FEMTO_GIT_DESCRIBE);
    return 0;
  }
  const std::string cmd = args[0];
  args.erase(args.begin());
  try {
    if (cmd == "render") return femto::cmd_render(args, command_line);
    std::fprintf(stderr, "femto: unknown command '%s' (try femto --help)\n", cmd.c_str());
    return 2;
  } catch (const femto::InputError& e) {
    std::fprintf(stderr, "femto: error: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "femto: failure: %s\n", e.what());
    return 1;
  }
}
