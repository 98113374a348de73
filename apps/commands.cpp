// The registry of subcommands (apps/commands.h), apart from main() so that other programs (the
// flag fuzzer in fuzz/) can link the commands.
#include "apps/commands.h"

#include <algorithm>

namespace femto {

std::vector<Command>& commands() {
  static std::vector<Command> list;
  return list;
}

CommandRegistrar::CommandRegistrar(const char* name, const char* summary, CommandFn fn) {
  auto& list = commands();
  list.push_back({name, summary, fn});
  std::sort(list.begin(), list.end(),
            [](const Command& a, const Command& b) { return std::string(a.name) < b.name; });
}

}  // namespace femto
