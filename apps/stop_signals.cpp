#include "apps/stop_signals.h"

#include <pthread.h>
#include <signal.h>
#include <unistd.h>

#include <cstdio>
#include <mutex>
#include <thread>

namespace femto::stop_signals {

namespace {
std::atomic<bool> g_requested{false};
std::atomic<int> g_signal{0};
std::atomic<bool> g_immediate{true};
const char* g_message = "";
std::mutex g_mutex;  // guards g_abort
std::function<void()> g_abort;

void abort_now(int sig) {
  std::function<void()> f;
  {
    std::lock_guard<std::mutex> lock(g_mutex);
    f = g_abort;
  }
  if (f) f();
  std::fprintf(stderr, "femto: aborted (%s)\n", sig == SIGTERM ? "SIGTERM" : "SIGINT");
  std::fflush(stderr);
  ::_exit(128 + sig);
}

void wait_loop(sigset_t set) {
  for (;;) {
    int sig = 0;
    if (::sigwait(&set, &sig) != 0) continue;
    if (g_requested.load() || g_immediate.load()) abort_now(sig);
    g_signal.store(sig);
    g_requested.store(true);
    if (g_message[0]) {
      std::fprintf(stderr, "\nfemto: %s: %s\n", sig == SIGTERM ? "SIGTERM" : "interrupted", g_message);
      std::fflush(stderr);
    }
  }
}
}  // namespace

void start() {
  static std::once_flag once;
  std::call_once(once, [] {
    sigset_t set;
    sigemptyset(&set);
    sigaddset(&set, SIGINT);
    sigaddset(&set, SIGTERM);
    pthread_sigmask(SIG_BLOCK, &set, nullptr);  // inherited by every thread created later
    std::thread(wait_loop, set).detach();
  });
}

const std::atomic<bool>& requested() { return g_requested; }
int signal_number() { return g_signal.load(); }

void defer(const char* message) {
  g_message = message ? message : "";
  g_immediate.store(false);
}

void on_abort(std::function<void()> f) {
  std::lock_guard<std::mutex> lock(g_mutex);
  g_abort = std::move(f);
}

}  // namespace femto::stop_signals
