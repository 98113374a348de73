// femto-bench-media: voxel-medium performance and distance-sampling efficiency.
//  tracking   random walks in a 256^3 procedural cloud vs a homogeneous box with the same mean
//             sigma_t, with and without empty-space skipping; memory of the block structure.
//  strategies seed 000 Fig. 7 in spirit: a sphere of scattering medium lit by a pulsed point
//             light, seen by one pixel; relative RMS error per time bin of mfp, time-uniform and MIS at equal
//             samples against a high-sample reference; equal-error sample ratios at late times.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "bench/bench_util.h"
#include "core/render.h"
#include "core/rng.h"
#include "core/sampling.h"
#include "media/grid_medium.h"
#include "media/volume_generators.h"
#include "samplers/medium_distance.h"

using namespace femto;
using bench::now_s;
using bench::walk_rate;

namespace {

VolumeData volume_from(const GeneratedVolume& g, double voxel) {
  VolumeData v{};
  v.density = g.density;
  const double half = 0.5 * voxel * g.density.nx;
  const double g2w[12] = {voxel, 0, 0, -half, 0, voxel, 0, -half, 0, 0, voxel, -half};
  const double w2g[12] = {1 / voxel, 0, 0, half / voxel, 0, 1 / voxel, 0, half / voxel, 0, 0, 1 / voxel, half / voxel};
  std::copy(g2w, g2w + 12, v.grid_to_world);
  std::copy(w2g, w2g + 12, v.world_to_grid);
  return v;
}


void tracking(int n) {
  const double voxel = 1.0, half = 0.5 * n * voxel;
  const GeneratedVolume cloud = make_cloud(n, 1);
  const VolumeData data = volume_from(cloud, voxel);
  VdbMediumDesc desc;
  desc.sigma_t_scale = 0.5;  // 1/mm per unit density
  GridMedium grid(data, desc);
  const double mean = grid.mean_sigma_t();
  std::printf("tracking: %d^3 cloud, voxel %.1f mm, sigma_t = %.2f * density (max %.3f, mean %.4f /mm)\n", n,
              voxel, desc.sigma_t_scale, grid.max_sigma_t(), mean);
  std::printf("  CPU: %s\n", bench::cpu_model().c_str());
  std::printf("  dense fields %.1f MiB, block structure (%d^3-cell blocks: max sigma_t, index) %.1f KiB\n",
              static_cast<double>(grid.field_memory_bytes()) / (1 << 20), GridMedium::kBlock,
              static_cast<double>(grid.block_memory_bytes()) / 1024);
  const int walks = 4000;
  uint64_t ev_h = 0, ev_s = 0, ev_n = 0;
  // The homogeneous walks take ~15 ms: the median of 15 repetitions, so that the figure is not
  // one time slice of a shared machine.
  std::vector<double> rates_h;
  for (int rep = 0; rep < 15; ++rep)
    rates_h.push_back(
        walk_rate(walks, half, [&](const Ray&, double s) { return ConstantSegments(mean, 1.0, s); }, ev_h));
  const double r_h = bench::median(rates_h);
  grid.set_empty_space_skipping(true);
  const double r_s = walk_rate(walks, half, [&](const Ray& r, double s) { return GridMedium::Walker(grid, r, s); }, ev_s);
  grid.set_empty_space_skipping(false);
  const double r_n = walk_rate(walks, half, [&](const Ray& r, double s) { return GridMedium::Walker(grid, r, s); }, ev_n);
  std::printf("  homogeneous box (same mean sigma_t)   %.3g events/s (%llu events, median of 15 runs)\n", r_h,
              static_cast<unsigned long long>(ev_h));
  std::printf("  voxel cloud, empty-space skipping     %.3g events/s (%llu events)\n", r_s,
              static_cast<unsigned long long>(ev_s));
  std::printf("  voxel cloud, cell-by-cell             %.3g events/s (%llu events)\n", r_n,
              static_cast<unsigned long long>(ev_n));
  std::printf("  ratios: homogeneous / skipping %.2fx, skipping speed-up %.2fx\n", r_h / r_s, r_s / r_n);
}

// A sphere of medium (radius 10 mm, index-matched boundary) seen through its centre by one
// pixel, lit by a pulsed point light 10 mm outside it (outside: no 1/r^2 singularity in the
// medium, so every estimator has finite variance).
SceneDesc fig7_scene(double sigma_s, DistanceSampling sampling) {
  SceneDesc d;
  d.source = "bench: medium sphere";
  d.camera.type = CameraDesc::Type::Orthographic;
  d.camera.position = {0, 0, -30};
  d.camera.look_at = {0, 0, 0};
  d.camera.ortho_width = 1e-3;
  d.camera.width = d.camera.height = 1;
  d.time.t_start_ps = 130;  // the first light arrives after 40 mm of travel (133 ps)
  d.time.bin_width_ps = 10;
  d.time.bins = 40;  // 400 ps: 120 mm of light travel, 36-192 mean free paths
  MediumDesc m;
  m.name = "m";
  m.medium = HomogeneousMedium{0.1, sigma_s, 0.0, 1.0};
  m.sampling = sampling;
  d.media.push_back(m);
  ShapeDesc ball;
  ball.type = ShapeDesc::Type::Sphere;
  ball.radius = 10;
  ball.interior_medium = 0;
  d.shapes.push_back(ball);
  LightDesc l;
  l.position = {0, 20, 0};
  l.intensity = RGB(1.0);
  d.lights.push_back(l);
  return d;
}

std::vector<double> bins_of(const TransientFilm& f) {
  std::vector<double> v;
  for (int i = 0; i < f.bins(); ++i) v.push_back(f.transient()[3 * i]);
  return v;
}

void strategies(int spp, int runs, int ref_spp) {
  const char* names[] = {"mfp", "time_uniform", "mis"};
  const DistanceSampling kinds[] = {DistanceSampling::Mfp, DistanceSampling::TimeUniform, DistanceSampling::Mis};
  for (double sigma_s : {0.2, 0.9, 1.5}) {
    RenderOptions ro;
    ro.spp = ref_spp;
    ro.quiet = true;
    ro.seed = 99999;
    const Scene ref_scene(fig7_scene(sigma_s, DistanceSampling::Mis));
    const std::vector<double> ref = bins_of(render(ref_scene, ro).film);
    std::printf("strategies: sigma_s %.1f /mm, sigma_a 0.1 /mm, %d spp x %d runs, reference %d spp (mis)\n",
                sigma_s, spp, runs, ref_spp);
    std::vector<std::vector<double>> rel(3);
    std::vector<double> secs(3, 0.0);
    for (int k = 0; k < 3; ++k) {
      const Scene scene(fig7_scene(sigma_s, kinds[k]));
      std::vector<double> sq(ref.size(), 0.0);
      for (int r = 0; r < runs; ++r) {
        RenderOptions o;
        o.spp = spp;
        o.quiet = true;
        o.seed = static_cast<uint64_t>(r + 1);
        const RenderResult res = render(scene, o);
        secs[k] += res.wall_seconds;
        const std::vector<double> est = bins_of(res.film);
        for (size_t i = 0; i < ref.size(); ++i) sq[i] += (est[i] - ref[i]) * (est[i] - ref[i]);
      }
      for (size_t i = 0; i < ref.size(); ++i)
        rel[k].push_back(ref[i] > 0 ? std::sqrt(sq[i] / runs) / ref[i] : 0.0);
    }
    std::printf("  bin  t_ps    rel.err mfp   time_unif   mis\n");
    for (size_t i = 0; i < ref.size(); i += 3)
      std::printf("  %3zu %6.0f   %9.4f   %9.4f   %9.4f\n", i, 130.0 + (static_cast<double>(i) + 0.5) * 10.0, rel[0][i], rel[1][i], rel[2][i]);
    // Late times: the last third of the window; equal-error sample ratio = (err_a / err_b)^2.
    double late[3] = {0, 0, 0};
    const size_t from = ref.size() * 2 / 3;
    for (int k = 0; k < 3; ++k) {
      for (size_t i = from; i < ref.size(); ++i) late[k] += rel[k][i] * rel[k][i];
      late[k] = std::sqrt(late[k] / static_cast<double>(ref.size() - from));
    }
    std::printf("  late-time rel. RMS error: mfp %.4f, time_uniform %.4f, mis %.4f\n", late[0], late[1], late[2]);
    std::printf("  equal-error spp ratio vs mfp (late): time_uniform %.2fx, mis %.2fx; time per run: %s %.3fs %s %.3fs %s %.3fs\n",
                std::pow(late[0] / late[1], 2), std::pow(late[0] / late[2], 2), names[0], secs[0] / runs, names[1],
                secs[1] / runs, names[2], secs[2] / runs);
  }
}

}  // namespace

int main(int argc, char** argv) {
  std::string what = argc > 1 ? argv[1] : "all";
  int n = 256, spp = 4096, runs = 16, ref_spp = 1 << 20;
  for (int i = 2; i + 1 < argc; i += 2) {
    const std::string a = argv[i];
    if (a == "--resolution") n = std::atoi(argv[i + 1]);
    else if (a == "--spp") spp = std::atoi(argv[i + 1]);
    else if (a == "--runs") runs = std::atoi(argv[i + 1]);
    else if (a == "--ref-spp") ref_spp = std::atoi(argv[i + 1]);
  }
  if ((what != "all" && what != "tracking" && what != "strategies") || n < 8 || spp < 1 || runs < 2 || ref_spp < 1) {
    std::fprintf(stderr, "usage: femto-bench-media [all|tracking|strategies] [--resolution N] [--spp N] [--runs N] [--ref-spp N]\n");
    return 2;
  }
  if (what != "strategies") tracking(n);
  if (what != "tracking") strategies(spp, runs, ref_spp);
  return 0;
}
