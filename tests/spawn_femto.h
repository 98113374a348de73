#pragma once
// Starts the femto executable in the background (for signal tests): its pid, then wait for it.
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

extern char** environ;

namespace femto::test {

/// Starts femto `args` in `cwd` with stdout and stderr into cwd/bg_stdout.txt, cwd/bg_stderr.txt.
inline pid_t spawn_femto(const std::vector<std::string>& args, const std::filesystem::path& cwd) {
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  const std::string out = (cwd / "bg_stdout.txt").string(), err = (cwd / "bg_stderr.txt").string();
  posix_spawn_file_actions_addopen(&fa, 0, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&fa, 1, out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_addopen(&fa, 2, err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  // posix_spawn has no chdir action in glibc 2.36's portable API: run through the shell's cd.
  std::string cmd = "cd '" + cwd.string() + "' && exec '" FEMTO_BINARY "'";
  for (const auto& a : args) cmd += " '" + a + "'";
  std::vector<std::string> argv_s = {"/bin/sh", "-c", cmd};
  std::vector<char*> argv;
  for (auto& s : argv_s) argv.push_back(s.data());
  argv.push_back(nullptr);
  // Signals blocked in this (test) process must not be inherited by femto.
  posix_spawnattr_t attr;
  posix_spawnattr_init(&attr);
  sigset_t none;
  sigemptyset(&none);
  posix_spawnattr_setsigmask(&attr, &none);
  sigset_t defaults;
  sigemptyset(&defaults);
  sigaddset(&defaults, SIGINT);
  sigaddset(&defaults, SIGTERM);
  posix_spawnattr_setsigdefault(&attr, &defaults);
  posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETSIGMASK | POSIX_SPAWN_SETSIGDEF);
  pid_t pid = -1;
  if (posix_spawn(&pid, "/bin/sh", &fa, &attr, argv.data(), environ) != 0) pid = -1;
  posix_spawn_file_actions_destroy(&fa);
  posix_spawnattr_destroy(&attr);
  return pid;
}

/// Exit code of `pid`, or -1 if it did not exit normally (e.g. killed by a signal).
inline int wait_femto(pid_t pid) {
  int status = 0;
  if (waitpid(pid, &status, 0) != pid) return -1;
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

/// Waits until `path` exists (or `seconds` pass); true if it appeared.
inline bool wait_for_file(const std::filesystem::path& path, double seconds) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (std::chrono::steady_clock::now() < end) {
    if (std::filesystem::exists(path)) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return false;
}

}  // namespace femto::test
