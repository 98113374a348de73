// femto-bench-tissue: speed of the tissue-optics Monte Carlo on the classic 60 mm cube
// (data/scenes/cube60.json: mu_a 0.005/mm, mu_s 1/mm, g 0.01, n 1.37, 50 gates of 0.1 ns,
// 60^3 fluence voxels, four detectors), with 1 and 2 threads, and a check that both give the
// same bits. Usage: femto-bench-tissue [SCENE.json] [photons] [--fluence-only] (default
// data/scenes/cube60.json, 1e6). --fluence-only drops the scene's face images and detectors:
// the classic tally (fluence volume and absorbed fraction) that the other tissue codes compute
// in bench/reference/run.sh.
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "bench/bench_util.h"
#include "core/scene_loader.h"
#include "core/tissue/scene.h"
#include "core/tissue/simulate.h"

using namespace femto;
using femto::bench::cpu_model;

int main(int argc, char** argv) {
  bool fluence_only = false;
  std::vector<std::string> args;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--fluence-only")
      fluence_only = true;
    else
      args.push_back(a);
  }
  const std::string path = args.size() > 0 ? args[0] : "data/scenes/cube60.json";
  const uint64_t photons =
      args.size() > 1 ? static_cast<uint64_t>(std::atof(args[1].c_str())) : 1000000;
  tissue::Setup s = tissue::load_tissue_scene(read_scene_text(path), path,
                                              std::filesystem::path(path).parent_path().string());
  s.photons = photons;
  if (fluence_only) {
    s.faces = false;
    s.detectors.clear();
  }
  std::printf("femto-bench-tissue: %s%s, %llu photons; CPU: %s\n", path.c_str(),
              fluence_only ? " (fluence only)" : "", static_cast<unsigned long long>(photons),
              cpu_model().c_str());
  // CPU time as well as wall time: on a shared machine, photons per CPU-ms per thread is the
  // figure that does not depend on what else runs.
  std::printf(
      "threads  photons/ms  photons/ms/thread  scatterings/s  (tracing only)  wall s  "
      "photons/cpu-ms  absorbed\n");
  tissue::Result first;
  for (int threads : {1, 2}) {
    s.threads = threads;
    const std::clock_t c0 = std::clock();
    const tissue::Result r = tissue::simulate(s);
    const double cpu_ms = 1e3 * static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC;
    const double N = static_cast<double>(r.photons);
    std::printf("%7d  %10.1f  %17.1f  %13.3g  (%.1f photons/ms)  %6.2f  %14.1f  %.6f\n", r.threads,
                N / (r.seconds * 1e3), N / (r.seconds * 1e3) / r.threads,
                static_cast<double>(r.scatterings) / r.seconds, N / (r.trace_seconds * 1e3),
                r.seconds, N / cpu_ms, r.balance.absorbed / N);
    if (threads == 1) {
      first = r;
    } else {
      const bool same = first.fluence == r.fluence && first.tpsf == r.tpsf &&
                        first.balance.absorbed == r.balance.absorbed &&
                        first.detected.weight == r.detected.weight;
      std::printf("1 and 2 threads give %s outputs\n", same ? "bit-identical" : "DIFFERENT");
      if (!same) return 1;
    }
  }
  return 0;
}
