// The femto command: dispatches to subcommands and maps errors to exit codes
// (2: bad input, 1: other failures).
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include "apps/commands.h"
#include "apps/stop_signals.h"
#include "core/distributed/comm.h"
#include "core/distributed/job.h"
#include "core/error.h"
#include "core/memory_usage.h"
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
  std::printf(
      "Across processes or machines: mpirun -np N femto render|tissue|diffusion ... "
      "(docs/mpi.md)%s.\n",
      femto::distributed::mpi_built() ? "" : "; this build has no MPI");
}
}  // namespace

namespace {
// A command's exit code; under MPI a failing rank ends the whole job with it (docs/mpi.md).
int leave(int code) {
  if (code != 0 && !femto::distributed::world().single()) femto::distributed::abort_job(code);
  femto::distributed::finish();
  return code;
}
// "femto: error: ..." with the rank under MPI.
void report(const char* kind, const char* what) {
  const std::string rank = femto::distributed::rank_label();
  std::fprintf(stderr, "femto: %s%s%s: %s\n", kind, rank.empty() ? "" : " on ", rank.c_str(), what);
}
}  // namespace

int main(int argc, char** argv) {
  femto::reuse_freed_memory();  // per-pass lists reuse their pages (page faults are costly)
  // Under mpirun: signals go to femto's waiting thread (blocked before MPI starts its threads),
  // then the process joins the job.
  if (femto::distributed::launched_by_mpi()) femto::stop_signals::start();
  femto::distributed::start(argc, argv);
  std::vector<std::string> args(argv + 1, argv + argc);
  std::string command_line = "femto";
  for (const auto& a : args) command_line += " " + a;
  if (args.empty() || args[0] == "--help" || args[0] == "-h" || args[0] == "help") {
    if (femto::distributed::world().root()) print_usage();
    return leave(args.empty() ? 2 : 0);
  }
  if (args[0] == "--version" || args[0] == "-V") {
    std::printf("femto %s (%s%s, instruction set %s)\n", FEMTO_VERSION, FEMTO_GIT_DESCRIBE,
                femto::distributed::mpi_built() ? ", MPI" : "", FEMTO_INSTRUCTION_SET);
    return leave(0);
  }
  const std::string name = args[0];
  args.erase(args.begin());
  for (const auto& c : femto::commands()) {
    if (name != c.name) continue;
    // Only these split their work over ranks; N copies of another command would repeat it.
    const bool distributed = name == "render" || name == "tissue" || name == "diffusion";
    if (!distributed && !femto::distributed::world().single()) {
      if (femto::distributed::world().root())
        std::fprintf(stderr,
                     "femto: error: femto %s does not run across MPI ranks; run it as one process "
                     "(mpirun runs render, tissue and diffusion: docs/mpi.md)\n",
                     c.name);
      return leave(2);
    }
    int code = 0;
    try {
      code = c.run(args, command_line);
    } catch (const femto::InputError& e) {
      report("error", e.what());
      code = 2;
    } catch (const std::exception& e) {
      report("failure", e.what());
      code = 1;
    }
    return leave(code);
  }
  std::fprintf(stderr, "femto: unknown command '%s' (try femto --help)\n",
               femto::clip(name).c_str());
  return leave(2);
}
