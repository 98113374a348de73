#include "apps/cli.h"

#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdint>
#include <cstdlib>
#include <ctime>

#include "core/error.h"

namespace femto::cli {

Args::Args(std::string command, std::vector<std::string> args)
    : command_(std::move(command)), args_(std::move(args)) {}

std::string Args::next() {
  std::string a = args_[i_++];
  has_pending_ = false;
  const auto eq = a.find('=');
  if (a.rfind("--", 0) == 0 && eq != std::string::npos) {
    pending_ = a.substr(eq + 1);
    has_pending_ = true;
    a = a.substr(0, eq);
  }
  flag_ = a;
  return a;
}

std::string Args::value() {
  if (has_pending_) {
    has_pending_ = false;
    return pending_;
  }
  if (i_ >= args_.size()) fail("expects a value", "");
  return args_[i_++];
}

void Args::fail(const std::string& problem, const std::string& got) const {
  std::string msg = command_ + ": " + flag_ + ": " + problem;
  if (!got.empty()) msg += " (got '" + clip(got, 200) + "')";
  throw InputError(msg);
}

int64_t Args::int_value(int64_t lo, int64_t hi) {
  const std::string v = value();
  char* end = nullptr;
  errno = 0;
  const long long x = std::strtoll(v.c_str(), &end, 10);
  if (v.empty() || *end != '\0' || errno == ERANGE)
    fail("expected an integer", v);
  if (x < lo || x > hi)
    fail("must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]", v);
  return x;
}

uint64_t Args::uint_value() {
  const std::string v = value();
  char* end = nullptr;
  errno = 0;
  if (v.empty() || v[0] == '-') fail("expected a non-negative integer", v);
  const unsigned long long x = std::strtoull(v.c_str(), &end, 10);
  if (*end != '\0' || errno == ERANGE) fail("expected a non-negative integer", v);
  return x;
}

double Args::double_value(double lo, double hi) {
  const std::string v = value();
  char* end = nullptr;
  const double x = std::strtod(v.c_str(), &end);
  if (v.empty() || *end != '\0' || !std::isfinite(x)) fail("expected a number", v);
  if (x < lo || x > hi) fail("out of range", v);
  return x;
}

double Args::number_in(double lo, double hi, bool lo_open, bool hi_open, const std::string& range) {
  const std::string v = value();
  char* end = nullptr;
  const double x = std::strtod(v.c_str(), &end);
  if (v.empty() || *end != '\0' || !std::isfinite(x)) fail("expected a number", v);
  if (x < lo || x > hi || (lo_open && x == lo) || (hi_open && x == hi)) fail("must be " + range, v);
  return x;
}

Vec3 Args::xyz_value(bool nonzero) {
  const std::string v = value();
  double xyz[3];
  size_t n = 0, start = 0;
  for (;;) {
    const size_t comma = v.find(',', start);
    const std::string item = v.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    char* end = nullptr;
    const double x = std::strtod(item.c_str(), &end);
    if (item.empty() || *end != '\0' || !std::isfinite(x) || n == 3) fail("expected X,Y,Z in mm", v);
    xyz[n++] = x;
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  if (n != 3) fail("expected X,Y,Z in mm", v);
  const Vec3 p(xyz[0], xyz[1], xyz[2]);
  if (nonzero && !(length(p) > 0)) fail("must be a non-zero direction", v);
  return p;
}

uint64_t Args::count_value(double lo, double hi) {
  const std::string v = value();
  char* end = nullptr;
  const double n = std::strtod(v.c_str(), &end);
  if (v.empty() || *end != '\0' || !(n >= lo && n <= hi) || n != std::floor(n)) {
    char range[96];
    std::snprintf(range, sizeof range, "expected an integer in [%.15g, %.15g], e.g. 1e5", lo, hi);
    fail(range, v);
  }
  return static_cast<uint64_t>(n);
}

uint64_t Args::size_value() {
  const std::string v = value();
  char* end = nullptr;
  const double x = std::strtod(v.c_str(), &end);
  if (v.empty() || end == v.c_str() || !std::isfinite(x) || x <= 0)
    fail("expected a positive size such as 512M or 4G", v);
  std::string unit(end);
  for (auto& c : unit) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  double mult = 1;
  if (unit.empty() || unit == "B") mult = 1;
  else if (unit == "K" || unit == "KB" || unit == "KIB") mult = 1024.0;
  else if (unit == "M" || unit == "MB" || unit == "MIB") mult = 1024.0 * 1024;
  else if (unit == "G" || unit == "GB" || unit == "GIB") mult = 1024.0 * 1024 * 1024;
  else if (unit == "T" || unit == "TB" || unit == "TIB") mult = 1024.0 * 1024 * 1024 * 1024;
  else fail("unknown size unit (use K, M, G or T)", v);
  const double bytes = x * mult;
  if (bytes < 1) fail("must be at least 1 byte", v);
  // A double at or above 2^64 has no uint64 value (the cast would be undefined): no limit.
  if (bytes >= 18446744073709551616.0) return UINT64_MAX;
  return static_cast<uint64_t>(bytes);
}

std::string format_bytes(uint64_t bytes) {
  char buf[64];
  const double b = static_cast<double>(bytes);
  if (b >= 1024.0 * 1024 * 1024) std::snprintf(buf, sizeof buf, "%.2f GiB", b / (1024.0 * 1024 * 1024));
  else if (b >= 1024.0 * 1024) std::snprintf(buf, sizeof buf, "%.1f MiB", b / (1024.0 * 1024));
  else if (b >= 1024.0) std::snprintf(buf, sizeof buf, "%.1f KiB", b / 1024.0);
  else std::snprintf(buf, sizeof buf, "%llu B", static_cast<unsigned long long>(bytes));
  return buf;
}

std::string utc_now() {
  const std::time_t now = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&now, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}

uint64_t physical_memory_bytes() {
  const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGE_SIZE);
  if (pages <= 0 || page <= 0) return 8ull << 30;
  return static_cast<uint64_t>(pages) * static_cast<uint64_t>(page);
}

}  // namespace femto::cli
