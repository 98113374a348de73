// `femto uniformity`: histograms the times produced by the distance (mfp, time_uniform),
// line-to-point, angular and equiangular samplers in a canonical configuration and tests them
// for uniformity over the time window (docs/uniformity.md).
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>

#include "apps/cli.h"
#include "apps/commands.h"
#include "apps/uniformity_flags.h"
#include "core/constants.h"
#include "core/error.h"
#include "core/uniformity.h"

namespace femto {

namespace {
const char* kUniformityHelp =
    "Usage: femto uniformity [options]\n"
    "\n"
    "Draws samples with each strategy in a homogeneous medium around a sensor ray and a point\n"
    "light, histograms the time each sample produces over its valid range inside the window,\n"
    "and tests the histogram for uniformity (chi-square and Kolmogorov-Smirnov). Times:\n"
    "  mfp            one vertex at s ~ sigma_t exp(-sigma_t s) on the sensor ray; its\n"
    "                 connection time eta (s + |sensor + s dir - light|) / c\n"
    "  time_uniform   every vertex time of subpaths with segments exponential in optical path\n"
    "                 length (rate --lambda), run to t_end (seed 000 Supp. D.1)\n"
    "  line_to_point  one vertex on the sensor ray, sampled for a uniform connection time\n"
    "  equiangular    one vertex on the sensor ray, equiangular towards the light over the\n"
    "                 distances whose connection time is inside the window\n"
    "  angular        a segment of length --segment from the light, direction sampled for a\n"
    "                 uniform time light -> vertex -> sensor\n"
    "The valid range of a strategy is the window intersected with the times it can reach.\n"
    "\n"
    "Options (defaults in brackets):\n"
    "  --strategy S       mfp | time_uniform | line_to_point | angular | equiangular | all [all]\n"
    "  --sigma-t X        extinction, 1/mm, > 0 [0.1]\n"
    "  --eta X            refractive index, >= 1 [1]\n"
    "  --t-start T        window start, ps >= 0 [0]\n"
    "  --t-end T          window end, ps > t-start [1000, about 30 mean free times]\n"
    "  --sensor X,Y,Z     sensor position, mm [0,0,0]\n"
    "  --dir X,Y,Z        sensor ray direction (normalised) [0,0,1]\n"
    "  --light X,Y,Z      point light position, mm [20,0,10]\n"
    "  --segment R        angular: segment length from the light, mm >= 0 [10]\n"
    "  --lambda X         time_uniform rate per mm of optical path length [3.5 / (c t_end)]\n"
    "  --mfp-time M       connection (as above) or vertices (mfp subpaths in the Poisson view of\n"
    "                     time_uniform, where mfp is time-uniform too) [connection]\n"
    "  --samples N        samples (subpaths for time_uniform) per strategy, 1..1e7 [100000]\n"
    "  --seed S           random seed, integer >= 0 [1]\n"
    "  --bins N           histogram bins, 2..10000 [50]\n"
    "  --alpha A          significance of the tests, 0 < A < 1 [0.01]\n"
    "  --out DIR          output folder, created if missing [./femto-uniformity]\n"
    "  --expect uniform   exit 1 unless every chosen strategy passes\n"
    "  --quiet            no file list on stderr\n"
    "  --help             this help\n"
    "\n"
    "A strategy passes when both p-values are >= alpha. Prints a table; writes\n"
    "hist_<strategy>.csv, summary.json and histograms.png. Exit codes: 0 ran (with --expect\n"
    "uniform: and every strategy passed), 1 a strategy failed under --expect uniform or another\n"
    "failure, 2 bad flags (nothing written).\n";

int cmd_uniformity(const std::vector<std::string>& argv, const std::string& command_line) {
  const UniformityRequest request = parse_uniformity_args(argv, "femto uniformity");
  if (request.help) {
    std::fputs(kUniformityHelp, stdout);
    return 0;
  }
  const uniformity::Config& c = request.config;
  const std::vector<uniformity::Strategy>& chosen = request.strategies;
  const std::string& out_dir = request.out_dir;
  const bool quiet = request.quiet, expect_uniform = request.expect_uniform;
  std::vector<uniformity::Result> results;
  for (uniformity::Strategy s : chosen) results.push_back(uniformity::run(c, s));

  std::error_code ec;
  std::filesystem::create_directories(out_dir, ec);
  if (ec) throw RuntimeError("cannot create output folder '" + out_dir + "': " + ec.message());
  const std::vector<std::string> files =
      uniformity::write_report(out_dir, c, results, command_line);

  std::printf(
      "femto uniformity: sigma_t %g/mm (mean free time %.4g ps), eta %g, window [%g, %g] ps, "
      "%d bins, alpha %g\n",
      c.sigma_t, c.eta / (c.sigma_t * kSpeedOfLight), c.eta, c.t_start_ps, c.t_end_ps, c.bins,
      c.alpha);
  std::fputs(uniformity::format_table(results).c_str(), stdout);
  for (const auto& r : results)
    if (!r.note.empty())
      std::printf("  %s: %s\n", uniformity::strategy_name(r.strategy), r.note.c_str());
  if (!quiet) {
    std::string list;
    for (const auto& f : files) list += (list.empty() ? "" : ", ") + f;
    std::fprintf(stderr, "femto uniformity: results in %s/ (%s)\n", out_dir.c_str(), list.c_str());
  }
  if (!expect_uniform) return 0;
  for (const auto& r : results)
    if (!r.pass) return 1;
  return 0;
}
}  // namespace

FEMTO_COMMAND("uniformity", "time uniformity of the distance, line-to-point and angular samplers",
              cmd_uniformity);

}  // namespace femto
