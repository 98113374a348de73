#pragma once
// Progress on stderr: a live bar with elapsed time, ETA and paths/s on a terminal, a plain line
// every few seconds otherwise, nothing when quiet.
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <string>
#include <thread>

namespace femto {

class Progress {
 public:
  /// total: work units (paths); label: shown before the bar.
  /// unit: what the rate counts ("paths", "passes", "photons").
  Progress(uint64_t total, std::string label, bool quiet, std::string unit = "paths");
  ~Progress();
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  /// Thread-safe, lock-free.
  void add(uint64_t done) { done_.fetch_add(done, std::memory_order_relaxed); }
  /// Prints the final line and stops the reporter thread.
  void finish();

 private:
  void run();
  void print(bool final_line);

  uint64_t total_;
  std::string label_, unit_;
  bool quiet_, tty_;
  std::atomic<uint64_t> done_{0};
  std::chrono::steady_clock::time_point start_;
  std::thread thread_;
  std::mutex mutex_;
  std::condition_variable cv_;
  bool stop_ = false;
  bool finished_ = false;
};

/// "1h02m03s" / "4m05s" / "6.7s".
std::string format_duration(double seconds);

}  // namespace femto
