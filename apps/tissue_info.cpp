#include "apps/tissue_info.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <vector>

#include "apps/cli.h"
#include "apps/info_format.h"
#include "core/error.h"
#include "core/tissue/scene.h"
#include "core/tissue/simulate.h"

namespace femto {

namespace {
using info::g6;
using info::range;
using info::vec;

const char* source_name(tissue::Source::Type t) {
  using T = tissue::Source::Type;
  return t == T::Pencil     ? "pencil"
         : t == T::Gaussian ? "gaussian"
         : t == T::Disk     ? "disk"
         : t == T::Spot     ? "spot"
         : t == T::Sphere   ? "sphere"
         : t == T::Quad     ? "quad"
         : t == T::Box      ? "box"
         : t == T::Mesh     ? "mesh"
                            : "isotropic";
}
}  // namespace

void print_tissue_info(const std::string& text, const std::string& path) {
  const tissue::Setup s =
      tissue::load_tissue_scene(text, path, std::filesystem::path(path).parent_path().string());
  const LabelVolume& v = s.volume;
  std::printf("scene: %s (tissue optics, docs/tissue.md)\n", clip(path, 200).c_str());
  std::printf("volume: %d x %d x %d voxels of %s mm, from %s to %s mm\n", v.n[0], v.n[1], v.n[2],
              g6(v.voxel).c_str(), vec(v.origin).c_str(), vec(v.upper()).c_str());
  if (!v.voxel_optics.empty()) {
    float lo[3] = {1e30f, 1e30f, 1e30f}, hi[3] = {-1e30f, -1e30f, -1e30f};
    for (const VoxelOptics& o : v.voxel_optics) {
      const float x[3] = {o.mu_a, o.mu_s, o.n};
      for (int i = 0; i < 3; ++i) lo[i] = std::min(lo[i], x[i]), hi[i] = std::max(hi[i], x[i]);
    }
    std::printf("medium: optics per voxel: mu_a %s /mm, mu_s %s /mm, n %s, g %s\n",
                range(lo[0], hi[0]).c_str(), range(lo[1], hi[1]).c_str(),
                range(lo[2], hi[2]).c_str(), g6(v.optics[1].g).c_str());
  } else {
    std::vector<uint64_t> count(v.optics.size(), 0);
    for (uint16_t l : v.labels) ++count[l];
    std::printf("labels: %zu\n", v.optics.size() - 1);
    for (size_t l = 1; l < v.optics.size(); ++l) {
      const TissueOptics& o = v.optics[l];
      if (count[l] == 0 && o.n == 1 && o.mu_s == 0 && o.mu_a == 0) continue;  // not in the table
      std::printf("  label %zu: mu_a %s /mm, mu_s %s /mm, g %s, n %s; %llu voxels\n", l,
                  g6(o.mu_a).c_str(), g6(o.mu_s).c_str(), g6(o.g).c_str(), g6(o.n).c_str(),
                  static_cast<unsigned long long>(count[l]));
    }
    if (count[0] > 0)
      std::printf("  label 0 (outside): %llu voxels inside the grid\n",
                  static_cast<unsigned long long>(count[0]));
  }
  std::printf("outside: n %s; boundary %s; absorption %s\n", g6(v.optics[0].n).c_str(),
              s.fresnel ? "fresnel" : "matched",
              s.absorption == Absorption::Weighted ? "weighted" : "analog");
  const tissue::Source& src = s.source;
  using ST = tissue::Source::Type;
  std::printf("source: %s", source_name(src.type));
  if (src.type == ST::Box)
    std::printf(" from %s to %s mm", vec(src.box_min).c_str(), vec(src.box_max).c_str());
  else if (src.type == ST::Mesh)
    std::printf(" of %zu triangles", src.mesh_triangles.size());
  else
    std::printf(" at %s", vec(src.position).c_str());
  if (src.type == ST::Sphere) std::printf(", radius %s mm", g6(src.radius).c_str());
  if (src.type == ST::Quad)
    std::printf(", edges %s and %s mm", vec(src.edge1).c_str(), vec(src.edge2).c_str());
  if (src.type != ST::Isotropic && !tissue::is_surface(src.type))
    std::printf(", direction %s", vec(src.direction).c_str());
  if (src.fwhm_ps > 0)
    std::printf(", Gaussian pulse of FWHM %s ps at %s ps\n", g6(src.fwhm_ps).c_str(),
                g6(src.offset_ps).c_str());
  else
    std::printf(", delta pulse at %s ps\n", g6(src.offset_ps).c_str());
  std::printf("time: %d gates of %s ps, %s to %s ps\n", s.time.bins,
              g6(s.time.bin_width_ps).c_str(), g6(s.time.t_start_ps).c_str(),
              g6(s.time.t_end_ps()).c_str());
  if (s.fluence)
    std::printf("fluence: %d x %d x %d cells from %s, size %s mm%s\n", s.fluence_grid.n[0],
                s.fluence_grid.n[1], s.fluence_grid.n[2], vec(s.fluence_grid.origin).c_str(),
                vec(s.fluence_grid.size).c_str(), s.fluence_stderr ? ", with standard errors" : "");
  else
    std::printf("fluence: off\n");
  std::printf("detectors: %zu%s; face images: %s\n", s.detectors.size(),
              s.detectors.empty() ? "" : (s.save_detected ? ", detected photons saved" : ""),
              s.faces ? "on" : "off");
  std::printf("photons: %llu in %d batches, seed %llu\n",
              static_cast<unsigned long long>(s.photons), s.batches,
              static_cast<unsigned long long>(s.seed));
  const int threads = tissue::threads_for(s);
  std::printf("memory: %s with %d threads (fluence sums %s per thread, tissue volume %s)\n",
              cli::format_bytes(tissue::memory_bytes(s, threads)).c_str(), threads,
              cli::format_bytes(tissue::fluence_bytes_per_thread(s)).c_str(),
              cli::format_bytes(v.memory_bytes()).c_str());
}

}  // namespace femto
