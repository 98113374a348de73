#pragma once
// Comparing two estimators of the same film: per-batch sums over blocks of pixels and groups of
// bins, then cell by cell within 4 combined standard errors, a chi-square over the cells, and a
// stated resolution. Shared by the light-path and photon-beam tests.
#include <catch2/catch.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <vector>

#include <filesystem>
#include <string>

#include "core/film.h"
#include "media/volume_data.h"
#include "samplers/stats.h"
#include "scene_builders.h"

namespace femto::test {

/// Writes dir/graded.vdb: 12^3 voxels of 5 mm from (-30, 0, -30), density 0.01 + 0.004 (x + y) and
/// eta 1 + 0.05 z per voxel index; returns a voxel medium of it (albedo 0.85, g 0.2, eta 1
/// outside).
inline MediumDesc graded_voxel_medium(const std::filesystem::path& dir) {
  const int n = 12;
  DenseGrid density(n, n, n, 0.0f), eta(n, n, n, 1.0f);
  for (int z = 0; z < n; ++z)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) {
        const size_t i =
            (static_cast<size_t>(z) * n + static_cast<size_t>(y)) * n + static_cast<size_t>(x);
        density.v[i] = 0.01f + 0.004f * static_cast<float>(x + y);
        eta.v[i] = 1.0f + 0.05f * static_cast<float>(z);
      }
  density.update_range();
  eta.update_range();
  const std::string file = (dir / "graded.vdb").string();
  write_volume(file, density, nullptr, &eta, 5.0, {-30, 0, -30});
  MediumDesc m = vdb_medium("vdb", file, 0.85, 0.2);
  m.vdb.eta = 1.0;
  m.vdb.eta_grid = "eta";
  return m;
}

/// Progressive photon (or beam) settings of the tests: per pass, first radius (mm) and first
/// bandwidth (ps); the rest as the scene's defaults.
inline PhotonDesc progressive(int64_t per_pass, double radius_mm, double bandwidth_ps) {
  PhotonDesc pd;
  pd.per_pass = per_pass;
  pd.radius = radius_mm;
  pd.bandwidth_ps = bandwidth_ps;
  return pd;
}

/// Wall and process CPU time spent on one side of a comparison, summed over `run` calls;
/// FEMTO_AGREEMENT_LOG=1 has `log` print it, to balance a test's budget between its two sides.
struct SideTime {
  double wall = 0, cpu = 0;
  template <class F>
  auto run(F&& f) {
    const auto start = std::chrono::steady_clock::now();
    const std::clock_t cpu_start = std::clock();
    auto result = f();
    wall += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    cpu += static_cast<double>(std::clock() - cpu_start) / CLOCKS_PER_SEC;
    return result;
  }
  void log(const std::string& what) const {
    if (std::getenv("FEMTO_AGREEMENT_LOG"))
      std::fprintf(stderr, "%s: %.2f s (CPU %.2f s)\n", what.c_str(), wall, cpu);
  }
};

/// One film per seed (seed0, seed0 + 1, ...) with the given integrator; `work` is spp (passes) or,
/// for light tracing, light paths.
inline std::vector<TransientFilm> batches(const Scene& scene, IntegratorKind kind, int64_t work,
                                          int n, uint64_t seed0, const PhotonDesc& photons = {}) {
  std::vector<TransientFilm> films;
  SideTime elapsed;
  for (int b = 0; b < n; ++b) {
    RenderOptions opt;
    opt.integrator = kind;
    opt.spp = kind == IntegratorKind::Light ? 1 : static_cast<int>(work);
    opt.light_paths = kind == IntegratorKind::Light ? work : 0;
    opt.photons = photons;
    opt.seed = seed0 + static_cast<uint64_t>(b);
    opt.threads = 2;
    opt.quiet = true;
    films.push_back(elapsed.run([&] { return render(scene, opt).film; }));
  }
  elapsed.log("batches: integrator " + std::to_string(static_cast<int>(kind)) + ", " +
              std::to_string(work) + " x " + std::to_string(n));
  return films;
}

/// Per-batch sums of the three channels over blocks of `block` x `block` pixels and groups of
/// `group` bins: cells[c][b] for cell c of batch b.
inline std::vector<std::vector<double>> cells(const std::vector<TransientFilm>& films, int block,
                                              int group) {
  const TransientFilm& f0 = films.front();
  const int bx = (f0.width() + block - 1) / block, by = (f0.height() + block - 1) / block;
  const int bt = (f0.bins() + group - 1) / group;
  std::vector<std::vector<double>> out(static_cast<size_t>(bx * by * bt),
                                       std::vector<double>(films.size(), 0.0));
  for (size_t b = 0; b < films.size(); ++b) {
    const float* v = films[b].transient();
    for (int y = 0; y < f0.height(); ++y)
      for (int x = 0; x < f0.width(); ++x)
        for (int t = 0; t < f0.bins(); ++t) {
          const size_t i =
              ((static_cast<size_t>(y) * static_cast<size_t>(f0.width()) + static_cast<size_t>(x)) *
                   static_cast<size_t>(f0.bins()) +
               static_cast<size_t>(t)) *
              3;
          const size_t c = static_cast<size_t>(((y / block) * bx + x / block) * bt + t / group);
          out[c][b] += static_cast<double>(v[i]) + v[i + 1] + v[i + 2];
        }
  }
  return out;
}

/// Cells a and b agree: every cell whose signal is at least 2% of the largest within 4 combined
/// standard errors; the sum of z^2 over them (a small bias shared by many cells that no single
/// cell shows) with p > 1e-3; the totals within 4 combined standard errors (of the per-batch
/// totals); and the resolution: an error of 4 x `resolution` in the total would be 4 combined
/// standard errors.
/// Cells with `skip[c]` set are left out.
inline void require_agreement(const std::vector<std::vector<double>>& a,
                              const std::vector<std::vector<double>>& b, int min_cells,
                              double resolution = 0.02, const std::vector<bool>& skip = {}) {
  double peak = 0;
  for (size_t c = 0; c < a.size(); ++c)
    if (!(c < skip.size() && skip[c])) peak = std::max(peak, mean_se(a[c]).mean);
  int compared = 0;
  double chi2 = 0, max_z = 0, total = 0, var_a = 0, var_b = 0;
  for (size_t c = 0; c < a.size(); ++c) {
    if (c < skip.size() && skip[c]) continue;
    const MeanSE x = mean_se(a[c]), y = mean_se(b[c]);
    total += x.mean;
    var_a += x.se * x.se;
    var_b += y.se * y.se;
    const double se = std::sqrt(x.se * x.se + y.se * y.se);
    if (std::max(x.mean, y.mean) < 0.02 * peak || !(se > 0)) continue;
    const double z = (x.mean - y.mean) / se;
    chi2 += z * z;
    max_z = std::max(max_z, std::abs(z));
    ++compared;
  }
  // The totals per batch (cells of one batch are correlated, so their SEs do not add): a scale
  // error shared by all cells, which heavy-tailed cells can hide from the per-cell tests.
  std::vector<double> total_a(a.front().size(), 0.0), total_b(b.front().size(), 0.0);
  for (size_t c = 0; c < a.size(); ++c) {
    if (c < skip.size() && skip[c]) continue;
    for (size_t k = 0; k < total_a.size(); ++k) total_a[k] += a[c][k];
    for (size_t k = 0; k < total_b.size(); ++k) total_b[k] += b[c][k];
  }
  const MeanSE ta = mean_se(total_a), tb = mean_se(total_b);
  INFO("cells " << compared << ", max |z| " << max_z << ", chi2 " << chi2
                << ", relative SE of the total " << std::sqrt(var_a) / total << " and "
                << std::sqrt(var_b) / total << "; totals " << ta.mean << " +- " << ta.se << " and "
                << tb.mean << " +- " << tb.se);
  // FEMTO_AGREEMENT_LOG=1 prints the figures of every comparison, passed or not (the measured
  // catches that the tests' comments quote).
  if (std::getenv("FEMTO_AGREEMENT_LOG"))
    std::fprintf(stderr, "agreement: cells %d, max |z| %.2f, chi2 %.1f, relative SE %.4f / %.4f\n",
                 compared, max_z, chi2, std::sqrt(var_a) / total, std::sqrt(var_b) / total);
  REQUIRE(compared >= min_cells);
  CHECK(max_z < 4.0);
  CHECK(stats::chi2_survival(chi2, compared) > 1e-3);
  CHECK(std::sqrt(var_a + var_b) / total < resolution);
  CHECK(std::abs(ta.mean - tb.mean) < 4.0 * std::sqrt(ta.se * ta.se + tb.se * tb.se));
}

}  // namespace femto::test
