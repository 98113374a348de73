#pragma once
// Small helpers shared by the benchmark programs: the machine they ran on, medians, a clock and
// the random walk that the medium benchmarks time.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <ctime>
#include <fstream>
#include <string>
#include <vector>

#include "core/rng.h"
#include "core/sampling.h"
#include "samplers/medium_distance.h"

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

/// Seconds on a steady clock.
inline double now_s() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

/// CPU seconds used by this process's threads: unlike wall time, not lengthened while another
/// program (a second benchmark, a build) holds the core.
inline double process_cpu_s() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// Random walk of `walks` photons from the centre until they leave the box [-half, half]^3:
// returns collision events per second. Segments come from `make_segments(ray, s_exit)`.
template <class MakeSegments>
inline double walk_rate(int walks, double half, MakeSegments make_segments, uint64_t& events) {
  events = 0;
  const DistanceStrategy mfp{DistanceSampling::Mfp, 0, MisHeuristic::Balance};
  const double t0 = now_s();
  for (int w = 0; w < walks; ++w) {
    Rng rng(7, static_cast<uint64_t>(w));
    Vec3 x(0, 0, 0);
    for (int step = 0; step < 100000; ++step) {
      const Vec3 d = sample_uniform_sphere(rng.uniform(), rng.uniform());
      // Distance to the box boundary, without branches on the signs of d: they are random, and
      // their mispredictions cost more than the direction sample. d[a] = +-0 gives +inf.
      double s_exit = 1e30;
      for (int a = 0; a < 3; ++a) {
        const double s_a = (std::copysign(half, d[a]) - x[a]) / d[a];
        s_exit = s_a < s_exit ? s_a : s_exit;
      }
      auto segments = make_segments(Ray{x, d}, s_exit);
      const DistanceEvent ev = sample_distance(segments, mfp, rng.uniform());
      if (!ev.collided) break;
      ++events;
      x = x + d * ev.s;
    }
  }
  return static_cast<double>(events) / (now_s() - t0);
}

}  // namespace femto::bench
