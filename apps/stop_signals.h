#pragma once
// SIGINT and SIGTERM for long commands: they are blocked in every thread and taken by one
// waiting thread, so no code runs inside a signal handler. The first signal asks the command to
// stop (it finishes its current pass and writes what it has); a second aborts at once, after
// `on_abort` has removed temporary files, with exit code 128 + signal.
#include <atomic>
#include <functional>

namespace femto::stop_signals {

/// Starts the waiting thread; call first thing, before any other thread exists. While
/// `immediate` (the default) the first signal already aborts.
void start();
/// The stop request (set by the first signal).
const std::atomic<bool>& requested();
/// The signal that asked to stop (SIGINT, SIGTERM) or 0.
int signal_number();
/// From now on the first signal only requests a stop (and prints `message` unless empty).
void defer(const char* message);
/// Called (on the signal thread) before an abort exits; replaced by each call.
void on_abort(std::function<void()> f);

}  // namespace femto::stop_signals
