// femto-bench: throughput of the transient path tracer on a homogeneous fog scene.
// Measures paths/s and medium scattering events/s for 1 and 2 threads, and the cost of a
// T-bin transient film against a one-bin film over the same window at equal samples. Runs the
// configurations interleaved and reports medians, so ratios come from one run on one machine.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "core/render.h"
#include "core/scene_desc.h"

using namespace femto;

namespace {

ShapeDesc quad(const Vec3& c, const Vec3& e1, const Vec3& e2, double albedo) {
  ShapeDesc s;
  s.type = ShapeDesc::Type::Quad;
  s.vertices = {c, c + e1, c + e1 + e2, c + e2};
  s.triangles = {{0, 1, 2}, {0, 2, 3}};
  s.material.type = MaterialDesc::Type::Diffuse;
  s.material.albedo = RGB(albedo);
  return s;
}

// A 400 mm room of diffuse walls filled with fog (mean free path 100 mm), lit by a point light.
SceneDesc fog_room(int bins, int width, int height) {
  SceneDesc d;
  d.source = "bench: fog room";
  d.camera.position = {0, 0, 190};
  d.camera.look_at = {0, 0, 0};
  d.camera.fov_deg = 60;
  d.camera.width = width;
  d.camera.height = height;
  d.time.t_start_ps = 0;
  d.time.bin_width_ps = 8000.0 / bins;
  d.time.bins = bins;
  MediumDesc fog;
  fog.name = "fog";
  fog.medium = HomogeneousMedium{0.001, 0.01, 0.5, 1.0};
  d.media.push_back(fog);
  d.global_medium = 0;
  const double a = 200;
  d.shapes.push_back(quad({-a, -a, -a}, {2 * a, 0, 0}, {0, 2 * a, 0}, 0.6));
  d.shapes.push_back(quad({-a, -a, -a}, {0, 0, 2 * a}, {2 * a, 0, 0}, 0.6));
  d.shapes.push_back(quad({-a, a, -a}, {2 * a, 0, 0}, {0, 0, 2 * a}, 0.6));
  d.shapes.push_back(quad({-a, -a, -a}, {0, 2 * a, 0}, {0, 0, 2 * a}, 0.6));
  d.shapes.push_back(quad({a, -a, -a}, {0, 0, 2 * a}, {0, 2 * a, 0}, 0.6));
  LightDesc l;
  l.position = {0, 150, -50};
  l.intensity = RGB(1e5);
  d.lights.push_back(l);
  return d;
}

struct Run {
  double seconds;
  PathStats stats;
};

Run run(const Scene& scene, int spp, int threads) {
  RenderOptions opt;
  opt.spp = spp;
  opt.threads = threads;
  opt.quiet = true;
  const RenderResult r = render(scene, opt);
  return {r.wall_seconds, r.stats};
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
  int spp = 16, reps = 3, bins = 256;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string a = argv[i];
    if (a == "--spp") spp = std::atoi(argv[i + 1]);
    else if (a == "--reps") reps = std::atoi(argv[i + 1]);
    else if (a == "--bins") bins = std::atoi(argv[i + 1]);
    else {
      std::fprintf(stderr, "usage: femto-bench [--spp N] [--reps N] [--bins T]\n");
      return 2;
    }
  }
  if (spp < 1 || reps < 1 || bins < 1) {
    std::fprintf(stderr, "femto-bench: --spp, --reps and --bins must be positive\n");
    return 2;
  }
  const int W = 128, H = 96;
  const Scene transient(fog_room(bins, W, H));
  const Scene one_bin(fog_room(1, W, H));
  std::vector<double> t1, t2, tt, to;
  PathStats s1;
  for (int r = 0; r < reps; ++r) {
    const Run a = run(transient, spp, 1);
    const Run b = run(transient, spp, 2);
    const Run c = run(one_bin, spp, 2);
    t1.push_back(a.seconds);
    t2.push_back(b.seconds);
    tt.push_back(b.seconds);
    to.push_back(c.seconds);
    s1 = a.stats;
  }
  const double paths = static_cast<double>(s1.paths);
  const double events = static_cast<double>(s1.medium_events);
  const double m1 = median(t1), m2 = median(t2), mt = median(tt), mo = median(to);
  std::printf("femto-bench: fog room %dx%d, %d spp, %d bins over 8000 ps, medians of %d runs\n", W, H,
              spp, bins, reps);
  std::printf("paths per render          %.0f (%.2f medium scattering events per path)\n", paths,
              events / paths);
  std::printf("1 thread                  %.3f s  %.3g paths/s  %.3g medium events/s\n", m1, paths / m1,
              events / m1);
  std::printf("2 threads                 %.3f s  %.3g paths/s  %.3g medium events/s\n", m2, paths / m2,
              events / m2);
  std::printf("speed-up 2 vs 1 threads   %.2fx\n", m1 / m2);
  std::printf("one-bin film (2 threads)  %.3f s\n", mo);
  std::printf("transient / one-bin cost  %.3fx\n", mt / mo);
  return 0;
}
