#pragma once
// Subcommands of the femto command. Each apps/cmd_*.cpp registers itself with
// FEMTO_COMMAND(name, summary, function); femto.cpp dispatches by name.
#include <string>
#include <vector>

namespace femto {

/// A subcommand: receives its arguments (without the command name) and the full command line
/// (for render.json-style records); returns the exit code. Throws InputError for bad input.
using CommandFn = int (*)(const std::vector<std::string>& args, const std::string& command_line);

struct Command {
  const char* name;
  const char* summary;  ///< one line for `femto --help`
  CommandFn run;
};

/// All registered commands, sorted by name.
std::vector<Command>& commands();

struct CommandRegistrar {
  CommandRegistrar(const char* name, const char* summary, CommandFn fn);
};

}  // namespace femto

#define FEMTO_COMMAND(NAME, SUMMARY, FN) \
  static const ::femto::CommandRegistrar femto_command_registrar_##FN(NAME, SUMMARY, FN)
