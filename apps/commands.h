#pragma once
// Subcommands of the femto command; each returns the process exit code.
#include <string>
#include <vector>

namespace femto {
int cmd_render(const std::vector<std::string>& args, const std::string& command_line);
}  // namespace femto
