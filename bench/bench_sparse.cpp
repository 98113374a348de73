// femto-bench-sparse: sparse voxel media (docs/volumes.md, "Dense or sparse").
//  cloud  random walks in the 256^3 benchmark cloud (femto-bench-media's), dense vs sparse
//         storage, nearest and trilinear: collision events per second.
//  plume  free-path samples along random lines through a thin plume in a mostly empty box:
//         sparse with hierarchical skipping vs the same walk cell by cell (and dense storage
//         with 8^3 block skipping when the box fits).
//  large  loads FILE.vdb (e.g. `femto make-volume sparse-cloud --resolution 2048`) sparse and
//         renders it: load time, OpenVDB's in-memory size, the index, and the process's peak
//         memory against OpenVDB's size.
// Usage: femto-bench-sparse [cloud|plume|large FILE.vdb] [--resolution N] [--walks N]
#include <unistd.h>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "bench/bench_util.h"
#include "core/constants.h"
#include "core/memory_usage.h"
#include "core/render.h"
#include "core/rng.h"
#include "core/sampling.h"
#include "core/scene.h"
#include "media/grid_medium.h"
#include "media/sparse_generators.h"
#include "media/volume_data.h"
#include "media/volume_generators.h"
#include "samplers/medium_distance.h"

using namespace femto;
using bench::now_s;
namespace fs = std::filesystem;

namespace {


std::string temp_file(const std::string& name) {
  return (fs::temp_directory_path() /
          ("femto_bench_sparse_" + std::to_string(getpid()) + "_" + name))
      .string();
}

// femto-bench-media's walk through a voxel medium.
double walk_rate(const GridMedium& grid, int walks, double half, uint64_t& events) {
  return bench::walk_rate(
      walks, half, [&](const Ray& r, double s) { return GridMedium::Walker(grid, r, s); }, events);
}

struct Loaded {
  VolumeData data;
  GridMedium grid;
};
Loaded load(const std::string& file, double scale, bool trilinear, VdbMediumDesc::Storage storage) {
  VdbMediumDesc d;
  d.file = file;
  d.sigma_t_scale = scale;
  d.interpolation =
      trilinear ? VdbMediumDesc::Interpolation::Trilinear : VdbMediumDesc::Interpolation::Nearest;
  d.storage = storage;
  VolumeData v = load_volume(d, "bench", "/media/m");
  GridMedium g(v, d);
  return {std::move(v), std::move(g)};
}

void cloud(int n, int walks) {
  const std::string file = temp_file("cloud.vdb");
  write_generated(file, make_cloud(n, 1), 1.0);
  std::printf(
      "cloud: %d^3 procedural cloud (make_cloud, seed 1), voxel 1 mm, sigma_t = 0.5 * density, %d "
      "walks\n",
      n, walks);
  for (bool trilinear : {false, true}) {
    const Loaded dense = load(file, 0.5, trilinear, VdbMediumDesc::Storage::Dense);
    const Loaded sparse = load(file, 0.5, trilinear, VdbMediumDesc::Storage::Sparse);
    uint64_t ev_d = 0, ev_s = 0;
    const double half = 0.5 * n;
    const double r_d = walk_rate(dense.grid, walks, half, ev_d);
    const double r_s = walk_rate(sparse.grid, walks, half, ev_s);
    std::printf(
        "  %-9s dense %.3g events/s (%llu), sparse %.3g events/s (%llu): sparse/dense %.2fx\n",
        trilinear ? "trilinear" : "nearest", r_d, static_cast<unsigned long long>(ev_d), r_s,
        static_cast<unsigned long long>(ev_s), r_s / r_d);
    std::printf("            memory: dense %.1f MiB, sparse %.1f MiB (OpenVDB %.1f + index %.1f)\n",
                double(dense.data.memory_bytes()) / (1 << 20),
                double(sparse.data.memory_bytes()) / (1 << 20),
                double(sparse.data.sparse->tree_bytes) / (1 << 20),
                double(sparse.data.sparse->index_bytes()) / (1 << 20));
  }
  fs::remove(file);
}

// Free-path samples along `rays` random lines from one z face of the world box to the other.
double line_rate(const GridMedium& grid, const VolumeData& v, int rays, double& mean_segments) {
  const DistanceStrategy mfp{DistanceSampling::Mfp, 0, MisHeuristic::Balance};
  const Vec3 lo = v.world_bounds_min, hi = v.world_bounds_max;
  Rng rng(3, 1);
  uint64_t segs = 0;
  const double t0 = now_s();
  for (int r = 0; r < rays; ++r) {
    const Vec3 a(lo.x + (hi.x - lo.x) * rng.uniform(), lo.y + (hi.y - lo.y) * rng.uniform(),
                 lo.z - 1);
    const Vec3 b(lo.x + (hi.x - lo.x) * rng.uniform(), lo.y + (hi.y - lo.y) * rng.uniform(),
                 hi.z + 1);
    const Ray ray{a, normalize(b - a)};
    GridMedium::Walker segments(grid, ray, length(b - a));
    (void)sample_distance(segments, mfp, rng.uniform());
    if (r < 200) {  // segments per line, on the first lines
      GridMedium::Walker w(grid, ray, length(b - a));
      MediumSegment s;
      while (w.next(s)) ++segs;
    }
  }
  const double rate = rays / (now_s() - t0);
  mean_segments = double(segs) / std::min(rays, 200);
  return rate;
}

void plume(int n, int rays) {
  const std::string file = temp_file("plume.vdb");
  const SparseVolumeInfo info = write_plume(file, n, 1, 1.0);
  std::printf(
      "plume: %d^3 box, %llu active voxels (%.3g%%), sigma_t = 0.05 * density, %d lines along z\n",
      n, static_cast<unsigned long long>(info.active_voxels),
      100.0 * double(info.active_voxels) / (double(n) * n * n), rays);
  Loaded sparse = load(file, 0.05, false, VdbMediumDesc::Storage::Sparse);
  double seg_h = 0, seg_c = 0;
  const double r_h = line_rate(sparse.grid, sparse.data, rays, seg_h);
  sparse.grid.set_empty_space_skipping(false);
  const double r_c = line_rate(sparse.grid, sparse.data, std::max(1, rays / 10), seg_c);
  std::printf("  sparse, hierarchical skipping  %.3g lines/s (%.0f segments per line)\n", r_h,
              seg_h);
  std::printf("  sparse, cell by cell           %.3g lines/s (%.0f segments per line)\n", r_c,
              seg_c);
  std::printf("  speed-up %.1fx\n", r_h / r_c);
  const DenseGrid& g = sparse.data.density;
  if (double(g.nx) * g.ny * g.nz <= 1073741824.0) {
    const Loaded dense = load(file, 0.05, false, VdbMediumDesc::Storage::Dense);
    double seg_d = 0;
    const double r_d = line_rate(dense.grid, dense.data, rays, seg_d);
    std::printf(
        "  dense, 8^3 block skipping      %.3g lines/s (%.0f segments per line); sparse/dense "
        "%.1fx\n",
        r_d, seg_d, r_h / r_d);
    std::printf("  memory: dense %.1f MiB, sparse %.1f MiB\n",
                double(dense.data.memory_bytes()) / (1 << 20),
                double(sparse.data.memory_bytes()) / (1 << 20));
  }
  fs::remove(file);
}

void large(const std::string& file, int spp) {
  const uint64_t rss0 = current_rss_bytes();
  const double t0 = now_s();
  SceneDesc d;
  d.source = "bench: large sparse cloud";
  MediumDesc m;
  m.name = "cloud";
  m.type = MediumDesc::Type::Vdb;
  m.vdb.file = file;
  m.vdb.sigma_t_scale = 0.5;
  m.vdb.albedo = 0.95;
  m.vdb.interpolation = VdbMediumDesc::Interpolation::Trilinear;
  m.vdb.storage = VdbMediumDesc::Storage::Sparse;
  m.medium.g = 0.6;
  d.media.push_back(m);
  d.global_medium = 0;
  // Volume loaded once for the report (the Scene loads its own copy below: report, then free).
  uint64_t tree_bytes = 0, index_bytes = 0, active = 0, leaves = 0;
  Vec3 lo, hi;
  {
    const VolumeData v = load_volume(m.vdb, "bench", "/media/cloud");
    tree_bytes = v.sparse->tree_bytes;
    index_bytes = v.sparse->index_bytes();
    active = v.active_voxels;
    leaves = v.sparse->leaf_count;
    lo = v.world_bounds_min;
    hi = v.world_bounds_max;
    std::printf("large: %s: box %d x %d x %d voxels, %llu active, %llu leaves; load %.1f s\n",
                file.c_str(), v.density.nx, v.density.ny, v.density.nz,
                static_cast<unsigned long long>(active), static_cast<unsigned long long>(leaves),
                now_s() - t0);
  }
  const Vec3 c = 0.5 * (lo + hi);
  const double size = length(hi - lo);
  d.camera.type = CameraDesc::Type::Perspective;
  d.camera.position = c + Vec3(0, 0, 1.5 * size);
  d.camera.look_at = c;
  d.camera.fov_deg = 40;
  d.camera.width = d.camera.height = 64;
  d.time.t_start_ps = 0;
  d.time.bin_width_ps = 3.0 * size / kSpeedOfLight / 32;
  d.time.bins = 64;
  LightDesc l;
  l.position = c + Vec3(size, size, size);
  l.intensity = RGB(1e6 * size * size);
  d.lights.push_back(l);
  const double t1 = now_s();
  const Scene scene(d);
  const double t_load = now_s() - t1;
  RenderOptions o;
  o.spp = spp;
  o.quiet = true;
  const RenderResult r = render(scene, o);
  const uint64_t peak = peak_rss_bytes();
  std::printf("  scene load %.1f s, render 64 x 64 x %d spp %.1f s\n", t_load, spp, r.wall_seconds);
  std::printf(
      "  OpenVDB in memory %.1f MiB, index and bounds %.1f MiB; process peak RSS %.1f MiB (%.1f "
      "MiB before)\n",
      double(tree_bytes) / (1 << 20), double(index_bytes) / (1 << 20), double(peak) / (1 << 20),
      double(rss0) / (1 << 20));
  std::printf("  peak / OpenVDB size %.2fx\n", double(peak) / double(tree_bytes));
}

}  // namespace

int main(int argc, char** argv) {
  const std::string what = argc > 1 ? argv[1] : "";
  std::string file;
  int first = 2;
  if (what == "large") {
    file = argc > 2 ? argv[2] : "";
    first = 3;
  }
  int n = what == "plume" ? 1024 : 256, walks = 4000, spp = 4;
  for (int i = first; i + 1 < argc; i += 2) {
    const std::string a = argv[i];
    if (a == "--resolution")
      n = std::atoi(argv[i + 1]);
    else if (a == "--walks")
      walks = std::atoi(argv[i + 1]);
    else if (a == "--spp")
      spp = std::atoi(argv[i + 1]);
  }
  if ((what != "cloud" && what != "plume" && what != "large") ||
      (what == "large" && file.empty()) || n < 16 || walks < 1 || spp < 1) {
    std::fprintf(stderr,
                 "usage: femto-bench-sparse cloud [--resolution N] [--walks N]\n"
                 "       femto-bench-sparse plume [--resolution N] [--walks LINES]\n"
                 "       femto-bench-sparse large FILE.vdb [--spp N]\n");
    return 2;
  }
  std::printf("CPU: %s\n", bench::cpu_model().c_str());
  if (what == "cloud") cloud(n, walks);
  if (what == "plume") plume(n, walks * 10);
  if (what == "large") large(file, spp);
  return 0;
}
