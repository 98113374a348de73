#pragma once
// Small helpers for parsing subcommand flags with errors that name the flag and the value.
#include <cstdint>
#include <string>
#include <vector>

#include "core/vec3.h"

namespace femto::cli {

/// Walks argv-style arguments; `value()` takes the next one as the current flag's value,
/// accepting both "--flag value" and "--flag=value".
class Args {
 public:
  Args(std::string command, std::vector<std::string> args);
  bool done() const { return i_ >= args_.size(); }
  /// Next argument; for "--flag=value" returns "--flag" and keeps the value for value().
  std::string next();
  std::string value();
  const std::string& command() const { return command_; }
  const std::string& flag() const { return flag_; }

  int64_t int_value(int64_t lo, int64_t hi);
  uint64_t uint_value();
  double double_value(double lo, double hi);
  /// A number between lo and hi (each end open or closed); `range` completes "must be ...".
  double number_in(double lo, double hi, bool lo_open, bool hi_open, const std::string& range);
  /// "X,Y,Z" in mm; `nonzero` rejects the zero vector (directions).
  Vec3 xyz_value(bool nonzero = false);
  /// A whole count in [lo, hi], also written like 1e6.
  uint64_t count_value(double lo, double hi);
  /// Sizes like 512M, 4G, 1.5GiB or plain bytes; 2^64 bytes or more means no limit.
  uint64_t size_value();
  /// Throws InputError "<command>: <flag>: <problem> (got '<value>')".
  [[noreturn]] void fail(const std::string& problem, const std::string& got) const;

 private:
  std::string command_;
  std::vector<std::string> args_;
  size_t i_ = 0;
  std::string flag_;
  std::string pending_;
  bool has_pending_ = false;
};

std::string format_bytes(uint64_t bytes);
/// Current UTC time as ISO 8601, e.g. "2026-11-22T04:30:00Z" (for run records).
std::string utc_now();
uint64_t physical_memory_bytes();

}  // namespace femto::cli
