// femto-bench-sampling: which sampling strategy pays, scene by scene. A matrix of scenes (thin
// fog, dense fog, a voxel cloud, tissue) x sampling configurations (distance, connection), each
// render repeated with independent seeds and the configurations interleaved. Per configuration:
// paths/s and the equal-time efficiency against `mfp + collision` (plain path tracing with
// next-event estimation): the median over pixel-bin cells (typical pixels), the median over the
// late cells (last third of the window), the median over blocks of 4 x 4 pixels x 5 bins (the
// same question where single cells are too noisy to answer it), and the whole film's (summed
// squared errors: what the rare large errors, the tail, dominate). Each scene also prints how
// noisy one `mfp + collision` render is per cell and per block: where that is near 1, a render
// that leaves out most of the light scores well on the medians. The default configuration is
// marked; it plays the scene's default Russian roulette, which every other configuration leaves off
// ("default, no roulette" is the same sampling without it; `--roulette D,T` adds the same sampling
// with other roulettes; `--max-depth N` renders scattering orders up to N only, to see which
// order a configuration wins or loses on).
//
// Error measure: per cell (pixel x bin, channels summed), the mean squared error of one render
// against a long reference render (32x the samples, seeds of its own, so uncorrelated with every
// configuration), times the 1-thread render time (the process's CPU time; `--wall-time`: the
// wall clock, which also counts time the core spent on other programs; the default's median over
// seeds, and each other configuration's as a median of per-seed ratios to it: time_of). A
// squared error, not a variance: an estimator whose rare large values most runs miss shows up as
// a shortfall in every run.
//
// "default vs it" is that product's ratio cell by cell (median over cells / blocks); "at equal
// paths" is the squared errors' ratio alone. The latter depends only on the seeds, so two builds
// compare on it exactly; the render times still move with the host's load.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "bench/bench_util.h"
#include "core/render.h"
#include "core/scene_loader.h"

using namespace femto;
using femto::bench::cpu_model;
using femto::bench::median;
using femto::bench::process_cpu_s;

namespace {

struct BenchScene {
  const char* name;
  std::string json;
  int spp;  ///< per render, so that a render takes a fraction of a second
  /// Cells count when the reference exceeds this fraction of the film's peak (0: every
  /// cell with light, for scenes whose late frames are many decades dimmer than the first).
  double min_signal = 0.01;
  /// Errors are measured against one long reference render (`mfp + mis`, this many times the
  /// spp, seeds of its own): independent of every configuration measured, and free of the rare
  /// huge weights of time-uniform distances, which made a mean of the configurations fall short
  /// in dense media.
  int reference_factor = 32;
};

/// A box of homogeneous medium (half-width `half`) with a point light at (0.2, 0.3, light_z) x
/// half, seen from 6 half-widths away along +z; the window opens when light can first come back
/// from the front face. light_z < 1: the light is inside the medium; > 1: outside, in front of
/// the face the camera sees (a source shining into the medium, as in a reflectance measurement).
std::string box_scene(double half, double sigma_a, double sigma_s, double g, double eta,
                      double bin_ps, double light_z = 0.1) {
  const double t_start = 5.0 * half / 0.299792458;
  char light[256];
  std::snprintf(light, sizeof(light),
                R"({ "type": "point", "position": [%g, %g, %g], "intensity": 100 })", 0.2 * half,
                0.3 * half, light_z * half);
  char buf[1024];
  std::snprintf(buf, sizeof(buf), R"({
    "camera": { "type": "perspective", "position": [0, 0, %g], "look_at": [0, 0, 0], "fov": 30,
                "resolution": [32, 32] },
    "time": { "t_start": %g, "bin_width": %g, "bins": 150 },
    "media": { "m": { "type": "homogeneous", "sigma_a": %g, "sigma_s": %g, "g": %g, "eta": %g } },
    "shapes": [ { "type": "box", "min": [%g, %g, %g], "max": [%g, %g, %g], "medium": "m" } ],
    "lights": [ %s ]
  })",
                6 * half, t_start, bin_ps, sigma_a, sigma_s, g, eta, -half, -half, -half, half,
                half, half, light);
  return buf;
}

/// The time-uniform regime: a 2 m long corridor of thin fog (extinction sigma_t, given albedo,
/// g 0.3, square section of half-width `half`) seen down its length by a camera whose field of
/// view stays inside it, a point light beside the camera outside the fog, a 12 ns window. A frame
/// at time t sees light scattered about c t / 2 down the corridor, so the last third of the
/// window lies 1200-1800 mm away (4.8-7.2 mean free paths at sigma_t = 0.004/mm), where
/// mean-free-path sampling rarely puts a vertex; light that leaves the corridor's side does not
/// come back. Every cell with light counts (the late frames are many decades dimmer).
std::string corridor_scene(double sigma_t, double albedo, double half) {
  const double fov = 2.0 * std::atan(0.8 * half / 2050.0) * 180.0 / 3.14159265358979;
  char buf[1024];
  std::snprintf(buf, sizeof(buf), R"({
    "camera": { "type": "perspective", "position": [0, 0, 50], "look_at": [0, 0, -1000],
                "fov": %g, "resolution": [8, 8] },
    "time": { "t_start": 0, "bin_width": 80, "bins": 150 },
    "media": { "fog": { "type": "homogeneous", "sigma_a": %g, "sigma_s": %g, "g": 0.3 } },
    "shapes": [ { "type": "box", "min": [%g, %g, -2000], "max": [%g, %g, 0], "medium": "fog" } ],
    "lights": [ { "type": "point", "position": [0, %g, 30], "intensity": 1000 } ]
  })",
                fov, (1 - albedo) * sigma_t, albedo * sigma_t, -half, -half, half, half,
                0.75 * half);
  return buf;
}

struct Config {
  std::string name;
  DistanceSampling distance;
  ConnectionSampling connection;
  bool is_default;
  RouletteDesc roulette{0, 1.0};  ///< off, except where the scene's default is measured
};

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[static_cast<size_t>(q * static_cast<double>(v.size() - 1))];
}

/// Options that shape a scene's run.
struct RunOptions {
  int reps = 8;
  double spp_scale = 1.0;
  bool all_cells = false;
  bool deciles = false;  ///< also "default vs it" per tenth of the window
  std::vector<RouletteDesc> roulettes;  ///< extra configurations: the default with these
  int max_depth = 1000;  ///< scattering orders rendered (1: single scattering), reference too
  bool wall_time = false;  ///< time renders by the wall clock instead of the process's CPU time
};

void run_scene(const BenchScene& bs, const RunOptions& ro) {
  const int reps = ro.reps;
  const double spp_scale = ro.spp_scale;
  const bool all_cells = ro.all_cells;
  SceneDesc base;
  try {
    base = load_scene_string(bs.json, bs.name, ".");
  } catch (const std::exception& e) {
    std::printf("\n%s: skipped (%s)\n", bs.name, e.what());
    return;
  }
  const MediumDesc& m0 = base.media[0];
  std::vector<Config> configs = {
      {"default (mfp + auto, roulette)", m0.sampling, m0.connection, true,
       base.integrator.roulette},
      {"default, no roulette", m0.sampling, m0.connection, false},
      {"mis + mis", DistanceSampling::Mis, ConnectionSampling::Mis, false},
      {"mfp + equiangular", DistanceSampling::Mfp, ConnectionSampling::Equiangular, false},
      {"mfp + line_to_point", DistanceSampling::Mfp, ConnectionSampling::LineToPoint, false},
      {"mfp + mis", DistanceSampling::Mfp, ConnectionSampling::Mis, false},
      {"mis + collision", DistanceSampling::Mis, ConnectionSampling::Collision, false},
      {"mis + auto", DistanceSampling::Mis, ConnectionSampling::Auto, false},
      {"time_uniform + collision", DistanceSampling::TimeUniform, ConnectionSampling::Collision,
       false},
      {"mixture + collision", DistanceSampling::Mixture, ConnectionSampling::Collision, false},
      {"mfp + collision", DistanceSampling::Mfp, ConnectionSampling::Collision, false},
  };
  // --roulette D,T: the default's sampling with another Russian roulette.
  for (const RouletteDesc& r : ro.roulettes) {
    char name[64];
    std::snprintf(name, sizeof(name), "default, roulette %d,%g", r.depth, r.threshold);
    configs.push_back({name, m0.sampling, m0.connection, false, r});
  }
  const int n = static_cast<int>(configs.size());
  std::vector<std::unique_ptr<Scene>> scenes;
  for (const Config& c : configs) {
    SceneDesc d = base;
    for (MediumDesc& m : d.media) {
      m.sampling = c.distance;
      m.connection = c.connection;
      m.direction = DirectionSampling::Phase;
    }
    scenes.push_back(std::make_unique<Scene>(d));
  }
  const int spp = std::max(1, static_cast<int>(bs.spp * spp_scale));
  std::vector<std::vector<double>> secs(static_cast<size_t>(n));
  std::vector<PathStats> stats(static_cast<size_t>(n));
  std::vector<std::vector<std::vector<float>>> films(static_cast<size_t>(n));
  int width = 0, height = 0, bins = 0;
  for (int r = 0; r < reps; ++r)
    for (int k = 0; k < n; ++k) {
      RenderOptions opt;
      opt.spp = spp;
      opt.threads = 1;
      opt.quiet = true;
      opt.seed = 1 + static_cast<uint64_t>(r);
      opt.roulette = configs[k].roulette;
      opt.max_depth = ro.max_depth;
      const double cpu0 = process_cpu_s();
      const RenderResult res = render(*scenes[static_cast<size_t>(k)], opt);
      secs[static_cast<size_t>(k)].push_back(ro.wall_time ? res.wall_seconds
                                                          : process_cpu_s() - cpu0);
      stats[static_cast<size_t>(k)] = res.stats;
      const TransientFilm& f = res.film;
      width = f.width(), height = f.height(), bins = f.bins();
      const size_t cells = static_cast<size_t>(f.width() * f.height() * f.bins());
      std::vector<float> c(cells);
      for (size_t i = 0; i < cells; ++i)
        c[i] = f.transient()[3 * i] + f.transient()[3 * i + 1] + f.transient()[3 * i + 2];
      films[static_cast<size_t>(k)].push_back(std::move(c));
    }
  const size_t cells = films[0][0].size();
  RenderOptions ref_opt;
  ref_opt.spp = spp * bs.reference_factor;
  ref_opt.threads = 0;
  ref_opt.quiet = true;
  ref_opt.seed = 1000003;
  ref_opt.max_depth = ro.max_depth;
  int c_mis = 0;
  while (configs[c_mis].name != "mfp + mis") ++c_mis;
  const RenderResult ref_res = render(*scenes[static_cast<size_t>(c_mis)], ref_opt);
  std::vector<double> ref(cells);
  for (size_t i = 0; i < cells; ++i)
    ref[i] = static_cast<double>(ref_res.film.transient()[3 * i]) +
             ref_res.film.transient()[3 * i + 1] + ref_res.film.transient()[3 * i + 2];
  // Blocks of kBlockPx x kBlockPx pixels x kBlockBins bins: where a single cell's error is of
  // the order of its value (tissue, the cloud at 16 spp), the median of 16 squared errors per
  // cell is decided by whether a cell's rare large contributions came up at all, and an
  // estimator that misses most light can look best; a block pools enough paths for its squared
  // error to stand for its variance.
  constexpr int kBlockPx = 4, kBlockBins = 5;
  const int bw = (width + kBlockPx - 1) / kBlockPx, bh = (height + kBlockPx - 1) / kBlockPx;
  const int bb = (bins + kBlockBins - 1) / kBlockBins;
  auto block_of = [&](size_t i) {
    const int b = static_cast<int>(i % static_cast<size_t>(bins));
    const int px = static_cast<int>(i / static_cast<size_t>(bins));
    const int x = px % width, y = px / width;
    return (static_cast<size_t>(y / kBlockPx) * static_cast<size_t>(bw) +
            static_cast<size_t>(x / kBlockPx)) *
               static_cast<size_t>(bb) +
           static_cast<size_t>(b / kBlockBins);
  };
  const size_t blocks = static_cast<size_t>(bw) * static_cast<size_t>(bh) * static_cast<size_t>(bb);
  auto pool = [&](const auto& v) {  // cell values (float or double) summed per block
    std::vector<double> out(blocks, 0.0);
    for (size_t i = 0; i < cells; ++i) out[block_of(i)] += v[i];
    return out;
  };
  const std::vector<double> ref_block = pool(ref);
  // Cells (blocks) count above this fraction of the reference's peak cell (block).
  const double min_signal = all_cells ? 0.0 : bs.min_signal;
  const double peak = percentile(ref, 0.999);
  const double peak_block = percentile(ref_block, 0.999);
  auto mse_of = [&](int k) {
    std::vector<double> mse(cells, 0.0);
    for (size_t i = 0; i < cells; ++i)
      for (const auto& f : films[static_cast<size_t>(k)])
        mse[i] += (f[i] - ref[i]) * (f[i] - ref[i]) / reps;
    return mse;
  };
  auto mse_block_of = [&](int k) {
    std::vector<double> mse(blocks, 0.0);
    for (const auto& f : films[static_cast<size_t>(k)]) {
      const std::vector<double> sum = pool(f);
      for (size_t j = 0; j < blocks; ++j)
        mse[j] += (sum[j] - ref_block[j]) * (sum[j] - ref_block[j]) / reps;
    }
    return mse;
  };
  int c_ref = 0;  // mfp + collision: the baseline
  while (configs[c_ref].name != "mfp + collision") ++c_ref;
  int c_def = 0;
  while (!configs[c_def].is_default) ++c_def;
  // A configuration's time per render: the default's median times the median over seeds of its
  // time over the default's in the same round. Renders of one round run back to back, so a
  // change in the host's load between rounds (another program starting or ending) cancels.
  const std::vector<double>& secs_def = secs[static_cast<size_t>(c_def)];
  auto time_of = [&](int k) {
    std::vector<double> ratio;
    for (size_t r = 0; r < secs_def.size(); ++r)
      ratio.push_back(secs[static_cast<size_t>(k)][r] / secs_def[r]);
    return median(secs_def) * median(ratio);
  };
  const std::vector<double> mse_c = mse_of(c_ref);
  const std::vector<double> mse_block_c = mse_block_of(c_ref);
  const double time_c = time_of(c_ref);
  double ref_total = 0;
  for (size_t i = 0; i < cells; ++i) ref_total += ref[i];
  // How noisy one baseline render is where it counts: the median relative RMS error of its
  // cells and of its blocks. Near 1 or above, a render that leaves out most of the light scores
  // well on the median, and only the pooled figures (block, film) mean something.
  std::vector<double> rel_cell, rel_block;
  for (size_t i = 0; i < cells; ++i)
    if (ref[i] > min_signal * peak) rel_cell.push_back(std::sqrt(mse_c[i]) / ref[i]);
  for (size_t j = 0; j < blocks; ++j)
    if (ref_block[j] > min_signal * peak_block)
      rel_block.push_back(std::sqrt(mse_block_c[j]) / ref_block[j]);
  const std::string depth_note =
      ro.max_depth < 1000 ? ", up to " + std::to_string(ro.max_depth) + " scattering vertices"
                          : std::string();
  std::printf(
      "\n%s: %d x %d px, %d bins, %d spp x %d seeds, %.2f medium events per path%s\n"
      "  mfp + collision, one render: median relative RMS error %.2f per cell (%zu cells), "
      "%.2f per block of %d x %d px x %d bins (%zu blocks)\n",
      bs.name, width, height, bins, spp, reps,
      static_cast<double>(stats[static_cast<size_t>(c_ref)].medium_events) /
          static_cast<double>(stats[static_cast<size_t>(c_ref)].paths),
      depth_note.c_str(), rel_cell.empty() ? 0.0 : median(rel_cell), rel_cell.size(),
      rel_block.empty() ? 0.0 : median(rel_block), kBlockPx, kBlockPx, kBlockBins,
      rel_block.size());
  std::printf("  %-31s %10s %12s %12s %12s %12s %18s %19s %17s\n", "configuration", "paths/s",
              "median eff.", "late eff.", "block eff.", "film eff.", "total vs reference",
              "default vs it", "at equal paths");
  // The default against each configuration directly: the median over cells (blocks) of the
  // configuration's MSE x time over the default's. A ratio of two medians against the baseline
  // (the eff. columns) can differ from it, since different cells decide each median.
  const std::vector<double> mse_def = mse_of(c_def), mse_block_def = mse_block_of(c_def);
  const double time_def = time_of(c_def);
  for (int k = 0; k < n; ++k) {
    const double t = time_of(k);
    const std::vector<double> mse = mse_of(k);
    std::vector<double> vs_def, vs_def_block;
    std::vector<std::vector<double>> by_tenth(10);  // vs_def per tenth of the window
    std::vector<double> all, late;
    double sum_mse = 0, sum_mse_c = 0;
    for (size_t i = 0; i < cells; ++i) {
      sum_mse += mse[i];
      sum_mse_c += mse_c[i];
      if (ref[i] > min_signal * peak && mse[i] > 0 && mse_def[i] > 0) {
        vs_def.push_back((mse[i] * t) / (mse_def[i] * time_def));
        by_tenth[static_cast<size_t>(static_cast<int>(i % static_cast<size_t>(bins)) * 10 / bins)]
            .push_back(vs_def.back());
      }
      if (!(ref[i] > min_signal * peak && mse[i] > 0 && mse_c[i] > 0)) continue;
      const double e = (mse_c[i] * time_c) / (mse[i] * t);
      all.push_back(e);
      if (static_cast<int>(i % static_cast<size_t>(bins)) >= 2 * bins / 3) late.push_back(e);
    }
    const std::vector<double> mse_block = mse_block_of(k);
    std::vector<double> block_eff;
    for (size_t j = 0; j < blocks; ++j) {
      if (ref_block[j] > min_signal * peak_block && mse_block[j] > 0 && mse_block_def[j] > 0)
        vs_def_block.push_back((mse_block[j] * t) / (mse_block_def[j] * time_def));
      if (ref_block[j] > min_signal * peak_block && mse_block[j] > 0 && mse_block_c[j] > 0)
        block_eff.push_back((mse_block_c[j] * time_c) / (mse_block[j] * t));
    }
    std::vector<double> totals;
    for (const auto& f : films[static_cast<size_t>(k)]) {
      double sum = 0;
      for (size_t i = 0; i < cells; ++i) sum += f[i];
      totals.push_back(sum / ref_total);
    }
    double tm = 0, tv = 0;
    for (double x : totals) tm += x / reps;
    for (double x : totals) tv += (x - tm) * (x - tm) / (reps - 1);
    char late_text[32] = "           -";  // no late cell with signal
    if (!late.empty()) std::snprintf(late_text, sizeof(late_text), "%11.2fx", median(late));
    // The same at equal paths (every configuration renders the same spp): the squared errors'
    // ratio alone, which depends on the seeds only, not on how busy the host was.
    const double vs_def_cells = vs_def.empty() ? 0.0 : median(vs_def);
    const double vs_def_blocks = vs_def_block.empty() ? 0.0 : median(vs_def_block);
    std::printf(
        "%s %-31s %10.3g %11.2fx %s %11.2fx %11.3fx %10.3f +- %.3f %8.2fx / %5.2fx %7.2fx / "
        "%5.2fx\n",
        configs[k].is_default ? "*" : " ", configs[k].name.c_str(),
        static_cast<double>(stats[static_cast<size_t>(k)].paths) / t, median(all), late_text,
        block_eff.empty() ? 0.0 : median(block_eff),
        sum_mse > 0 ? (sum_mse_c * time_c) / (sum_mse * t) : 0.0, tm, std::sqrt(tv / reps),
        vs_def_cells, vs_def_blocks, vs_def_cells * time_def / t, vs_def_blocks * time_def / t);
    if (ro.deciles && k != c_def) {
      // Where in the window the default wins or loses against this configuration: the same
      // cell-by-cell median, per tenth of the bins.
      std::printf("    default vs it by tenth of the window:");
      for (const std::vector<double>& v : by_tenth)
        if (v.empty())
          std::printf("     -");
        else
          std::printf(" %5.2f", median(v));
      std::printf("\n");
    }
    std::fflush(stdout);
  }
}

}  // namespace

int main(int argc, char** argv) {
  RunOptions ro;
  std::string only;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--reps" && i + 1 < argc) {
      ro.reps = std::atoi(argv[++i]);
    } else if (a == "--spp-scale" && i + 1 < argc) {
      ro.spp_scale = std::atof(argv[++i]);
    } else if (a == "--scene" && i + 1 < argc) {
      only = argv[++i];
    } else if (a == "--all-cells") {
      ro.all_cells = true;  // every cell with light counts, as in the corridors
    } else if (a == "--deciles") {
      ro.deciles = true;
    } else if (a == "--wall-time") {
      ro.wall_time = true;
    } else if (a == "--roulette" && i + 1 < argc) {
      // DEPTH,THRESHOLD as in `femto render --russian-roulette`, except that a threshold above 1
      // is allowed here (a cut of about 1 - 1/T at vertex DEPTH, for studies)
      RouletteDesc r;
      char comma = 0;
      int used = 0;
      const std::string v = argv[++i];
      if (std::sscanf(v.c_str(), "%d%c%lf%n", &r.depth, &comma, &r.threshold, &used) != 3 ||
          comma != ',' || used != static_cast<int>(v.size()) || r.depth < 1 || !(r.threshold > 0) ||
          !std::isfinite(r.threshold)) {
        std::fprintf(stderr,
                     "femto-bench-sampling: --roulette \"%s\": expected DEPTH,THRESHOLD with "
                     "DEPTH >= 1 and THRESHOLD > 0, e.g. 8,2\n",
                     v.c_str());
        return 2;
      }
      ro.roulettes.push_back(r);
    } else if (a == "--max-depth" && i + 1 < argc) {
      // Scattering orders up to N (1: single scattering): which order a configuration wins on.
      const std::string v = argv[++i];
      char* end = nullptr;
      const long n = std::strtol(v.c_str(), &end, 10);
      if (v.empty() || *end != '\0' || n < 1 || n > 1000000) {
        std::fprintf(stderr,
                     "femto-bench-sampling: --max-depth \"%s\": expected an integer in "
                     "[1, 1000000]\n",
                     v.c_str());
        return 2;
      }
      ro.max_depth = static_cast<int>(n);
    } else {
      std::fprintf(stderr,
                   "usage: femto-bench-sampling [--reps N (seeds, >= 3)] [--spp-scale X] "
                   "[--scene NAME] [--all-cells] [--deciles] [--roulette D,T]... [--max-depth N] "
                   "[--wall-time]  (run from the repository root: the cloud reads "
                   "data/volumes/cloud.vdb)\n");
      return 2;
    }
  }
  if (ro.reps < 3 || !(ro.spp_scale > 0)) {
    std::fprintf(stderr, "femto-bench-sampling: --reps must be >= 3 and --spp-scale > 0\n");
    return 2;
  }
  std::vector<BenchScene> list = {
      // 200 mm box, mean free path 100 mm (2 mean free paths across), a 2 ns window.
      {"thin fog", box_scene(100, 0.001, 0.009, 0.3, 1.0, 2000.0 / 150), 64},
      // 20 mm box, mean free path 1 mm, 300 ps.
      {"dense fog", box_scene(10, 0.2, 0.8, 0.3, 1.0, 2.0), 64},
      // 20 mm block of tissue: mu_s = 10/mm, g = 0.9 (mu_s' = 1/mm), mu_a = 0.01/mm, n = 1.37,
      // 150 ps; the source 2 mm in front of the face the camera sees (time-domain diffuse
      // reflectance). A source inside would give collision next-event estimation infinite
      // variance (1/r^2 at the light), and every total would be meaningless. 128 spp: at 16 a
      // block of cells still had a relative error near 1 in one render, and the medians
      // rewarded estimators whose rare large contributions most renders miss.
      {"tissue", box_scene(10, 0.01, 10.0, 0.9, 1.37, 1.0, 1.2), 128},
      // A closed 400 mm room of grey walls (albedo 0.8) in very thin fog (mean free path 2 m),
      // a point light, the camera inside; a 12 ns window: the late frames are light that has
      // bounced and scattered many times (the regime where time-uniform sampling should pay).
      {"thin fog room, long window", R"({
        "camera": { "type": "perspective", "position": [0, 0, 150], "look_at": [0, 0, 0],
                    "fov": 60, "resolution": [32, 32] },
        "time": { "t_start": 0, "bin_width": 80, "bins": 150 },
        "media": { "fog": { "type": "homogeneous", "sigma_a": 0.00005, "sigma_s": 0.00045,
                            "g": 0.3 } },
        "medium": "fog",
        "shapes": [ { "type": "box", "min": [-200, -200, -200], "max": [200, 200, 200],
                      "material": { "type": "diffuse", "albedo": 0.8 } } ],
        "lights": [ { "type": "point", "position": [40, 60, -30], "intensity": 1000 } ]
      })",
       16},
      // The time-uniform regime (corridor_scene): a narrow corridor of grey fog (albedo 0.5),
      // and a wide one of brighter fog (albedo 0.8) whose multiply scattered light also reaches
      // the late frames.
      {"fog corridor, long window", corridor_scene(0.004, 0.5, 5), 2048, 0.0},
      {"wide fog corridor, long window", corridor_scene(0.004, 0.8, 20), 2048, 0.0},
  };
  const std::string cloud = "data/volumes/cloud.vdb";
  if (std::filesystem::exists(cloud)) {
    list.push_back({"voxel cloud",
                    R"({
      "camera": { "type": "perspective", "position": [0, 0, 400], "look_at": [0, 0, 0], "fov": 26,
                  "resolution": [32, 32] },
      "time": { "start_opl": 360, "bin_width_opl": 4, "bins": 150 },
      "media": { "cloud": { "type": "vdb", "file": ")" +
                        cloud + R"(", "density_grid": "density",
                            "sigma_t_scale": 0.08, "albedo": 0.95, "g": 0.6 } },
      "medium": "cloud",
      "lights": [ { "type": "point", "position": [20, 30, 10], "intensity": 1000 } ]
    })",
                    128});
  } else {
    std::printf("(no %s here: run from the repository root for the voxel cloud)\n", cloud.c_str());
  }
  if (!only.empty() && std::none_of(list.begin(), list.end(),
                                    [&](const BenchScene& bs) { return bs.name == only; })) {
    std::string names;
    for (const BenchScene& bs : list)
      names += std::string(names.empty() ? "\"" : ", \"") + bs.name + "\"";
    std::fprintf(stderr, "femto-bench-sampling: --scene \"%s\": no such scene (scenes: %s)\n",
                 only.c_str(), names.c_str());
    return 2;
  }
  std::printf(
      "femto-bench-sampling: CPU %s; 1 thread; time: %s; efficiency = (MSE x time) of mfp + "
      "collision over the configuration's, per pixel-bin cell (> 1: better); * = default\n",
      cpu_model().c_str(), ro.wall_time ? "wall clock" : "the process's CPU time");
  for (const BenchScene& bs : list)
    if (only.empty() || only == bs.name) run_scene(bs, ro);
  return 0;
}
