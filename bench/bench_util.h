#pragma once
// Small helpers shared by the benchmark programs: the machine they ran on, and medians.
#include <algorithm>
#include <fstream>
#include <string>
#include <vector>

namespace femto::bench {

/// The CPU model from /proc/cpuinfo, so that printed figures say which machine made them.
inline std::string cpu_model() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("model name", 0) == 0) return line.substr(line.find(':') + 2);
  return "unknown";
}

/// Median of the values (the upper one of the middle two for an even count); 0 when empty.
inline double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

}  // namespace femto::bench
