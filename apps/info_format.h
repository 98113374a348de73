#pragma once
// Number formats of `femto info` (camera and tissue scenes): six significant digits.
#include <cstdio>
#include <string>

#include "core/vec3.h"

namespace femto::info {

inline std::string g6(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}
inline std::string vec(const Vec3& v) {
  return "[" + g6(v.x) + ", " + g6(v.y) + ", " + g6(v.z) + "]";
}
/// "lo" when both are equal, else "lo to hi".
inline std::string range(double lo, double hi) {
  return lo == hi ? g6(lo) : g6(lo) + " to " + g6(hi);
}

}  // namespace femto::info
