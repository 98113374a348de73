// `femto diffusion`: Monte Carlo of a pulsed isotropic point source in an infinite homogeneous
// medium, compared with diffusion theory, Paasschens' solution and the exact <r^2>(t); reports
// when the wavefront becomes Gaussian (docs/diffusion.md).
#include <atomic>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <memory>
#include <optional>
#include <sstream>

#include "apps/cli.h"
#include "apps/commands.h"
#include "apps/diffusion_flags.h"
#include "core/diffusion/models.h"
#include "core/diffusion/report.h"
#include "core/distributed/comm.h"
#include "core/error.h"
#include "core/progress.h"
#include "core/scene_loader.h"
#include "media/grid_medium.h"
#include "media/volume_data.h"
#include "femto_version.h"

namespace femto {

namespace {
const char* kDiffusionHelp =
    "Usage: femto diffusion [options]\n"
    "\n"
    "Monte Carlo of an isotropic delta pulse (unit energy, t = 0) at the origin of an infinite\n"
    "homogeneous medium. Tallies the energy density u(r, t) in radial shells per time bin, the\n"
    "energy, <r^2>, <r^4> and the unscattered and singly scattered fractions, with standard\n"
    "errors; compares them with diffusion theory, Paasschens (1997) and the exact <r^2>(t) of the\n"
    "persistent random walk, and reports t*, the time after which the radial profile stays within\n"
    "a distance threshold of the Gaussian of the same <r^2>. See docs/diffusion.md.\n"
    "\n"
    "Medium (defaults: the seed paper's Fig. 12 medium, isotropic):\n"
    "  --sigma-s X        scattering coefficient, 1/mm, >= 0 (default 4.1)\n"
    "  --sigma-a X        absorption coefficient, 1/mm, >= 0 (default 0)\n"
    "  --g X              Henyey-Greenstein asymmetry, -1 < g < 1 (default 0)\n"
    "  --eta X            refractive index, >= 1; light travels at c / eta (default 1)\n"
    "  --absorption MODE  weighted (default: weight exp(-sigma_a v t), energy exact by\n"
    "                     construction) or analog (absorbing collisions end photons)\n"
    "Source inside a scene's medium (instead of the flags above):\n"
    "  --scene FILE       a scene file; its shapes are ignored, the medium fills space\n"
    "  --medium NAME      the medium to use (default: the scene's \"medium\", around everything)\n"
    "  --at X,Y,Z         source position in the scene, mm (required with --scene). Voxel (vdb)\n"
    "                     media use analog absorption and the measured energy to normalise\n"
    "                     the moments; the models use the coefficients at the source point\n"
    "Tallies:\n"
    "  --t-start T        window start, ps >= 0 (default 0)\n"
    "  --t-end T          window end, ps (default 40 mean free times)\n"
    "  --t-bins N         time bins, 1..100000 (default 200)\n"
    "  --r-max R          outer radius of the shells, mm (default (c / eta) t_end: all the light)\n"
    "  --r-bins N         radial shells, 1..100000 (default 120); shells x bins <= 2e6\n"
    "Analysis and plots:\n"
    "  --threshold D      distance threshold for t*, 0 < D < 1 (default 0.05)\n"
    "  --plot-times LIST  comma-separated times (ps) for fluence.png, 1 to 6 of them\n"
    "                     (default 1, 3, 10, 30 mean free times inside the window)\n"
    "Run:\n"
    "  --photons N        photons, 2..1e12, e.g. 1e6 (default 1e6); the run time estimated after\n"
    "                     the first batches is printed\n"
    "  --max-seconds S    stop after about S seconds and write the photons traced so far;\n"
    "                     Ctrl-C or SIGTERM does the same (exit code 130 or 143), a second\n"
    "                     signal aborts\n"
    "  --seed S           random seed, integer >= 0; the same seed gives bit-identical output for\n"
    "                     any thread count (default 1)\n"
    "  --batches N        independent batches for the jackknife interval of t*, 2..1000\n"
    "                     (default 10)\n"
    "  --threads N        worker threads, 0 = all cores (default 0)\n"
    "  --out DIR          output folder, created if missing (default ./femto-diffusion)\n"
    "  --quiet            no progress or summary on stderr\n"
    "  --help             this help\n"
    "\n"
    "mpirun -np N femto diffusion ...: N ranks share the photons; rank 0 writes outputs\n"
    "bit-identical to one process's (docs/mpi.md).\n"
    "\n"
    "Outputs: fluence.csv, moments.csv, models.csv, fluence_models.csv, summary.json,\n"
    "fluence.png and distance.png (see docs/diffusion.md).\n";


// Ctrl-C or SIGTERM ends the run after the current round of photons; the results so far are
// written and the exit code is 130 (SIGINT) or 143 (SIGTERM).
std::atomic<bool> g_interrupted{false};
std::atomic<int> g_signal{0};
extern "C" void on_interrupt(int sig) {
  g_signal.store(sig);
  g_interrupted.store(true);
  std::signal(SIGINT, SIG_DFL);  // a second signal aborts at once
  std::signal(SIGTERM, SIG_DFL);
}


int cmd_diffusion(const std::vector<std::string>& argv_in, const std::string& command_line) {
  DiffusionRequest request = parse_diffusion_args(argv_in, "femto diffusion");
  if (request.help) {
    std::fputs(kDiffusionHelp, stdout);
    return 0;
  }
  diffusion::DiffusionSetup& setup = request.setup;
  // Under mpirun (docs/mpi.md) every rank checks the same input and traces its share; rank 0
  // reports and writes.
  const distributed::Comm& comm = distributed::world();
  if (!comm.root()) request.quiet = true;
  if (!comm.single()) setup.comm = &comm;
  setup.quiet = request.quiet;
  const bool quiet = request.quiet;
  const std::string& out_dir = request.out_dir;
  const diffusion::Scales sc = diffusion::scales_of(setup.medium);
  const int t_bins = setup.grid.time.bins, r_bins = setup.grid.shells;
  const double t_end = setup.grid.time.t_end_ps(), r_max = setup.grid.r_max();
  const std::unique_ptr<diffusion::PhotonTransport>& transport = request.transport;
  if (!comm.root()) {
    if (transport) diffusion::simulate(setup, *transport);
    else diffusion::simulate(setup);
    return 0;
  }

  std::error_code ec;
  std::filesystem::create_directories(out_dir, ec);
  if (ec) throw RuntimeError("cannot create output folder '" + out_dir + "': " + ec.message());
  if (!quiet)
    std::fprintf(stderr,
                 "femto diffusion: sigma_s %g/mm, sigma_a %g/mm, g %g, eta %g (%s absorption); "
                 "%llu photons, "
                 "%d bins to %.4g ps, %d shells to %.4g mm; ~%.3g scatterings per photon\n",
                 setup.medium.sigma_s, setup.medium.sigma_a, setup.medium.g, setup.medium.eta,
                 setup.absorption == diffusion::Absorption::Analog ? "analog" : "weighted",
                 static_cast<unsigned long long>(setup.photons), t_bins, t_end, r_bins, r_max,
                 setup.medium.sigma_s * sc.v * t_end);

  g_interrupted.store(false);
  setup.stop = &g_interrupted;
  const auto previous = std::signal(SIGINT, on_interrupt);
  const auto previous_term = std::signal(SIGTERM, on_interrupt);
  const diffusion::DiffusionResult result =
      transport ? diffusion::simulate(setup, *transport) : diffusion::simulate(setup);
  std::signal(SIGINT, previous);
  std::signal(SIGTERM, previous_term);
  const bool interrupted = result.stopped_early && g_interrupted.load();
  const diffusion::Analysis analysis = diffusion::analyse(setup, result, request.threshold);
  diffusion::ReportOptions opt;
  opt.dir = out_dir;
  opt.plot_times = request.plot_times;
  opt.run = {{"femto_version", FEMTO_VERSION},
             {"femto_build", FEMTO_GIT_DESCRIBE},
             {"femto_instruction_set", FEMTO_INSTRUCTION_SET},
             {"command", command_line},
             {"date_utc", cli::utc_now()},
             {"source", request.source},
             {"mpi_ranks", comm.size()},
             {"photons_requested", setup.photons},
             {"photons_traced", result.photons},
             {"stopped_early", !result.stopped_early ? nlohmann::json(nullptr)
                               : interrupted         ? nlohmann::json(g_signal.load() == SIGTERM ? "SIGTERM" : "interrupted (Ctrl-C)")
                                                     : nlohmann::json("--max-seconds")}};
  const std::vector<std::string> files = diffusion::write_report(setup, result, analysis, opt);

  if (!quiet) {
    std::fprintf(stderr, "femto diffusion: %llu photons, %llu segments in %s (%d threads)\n",
                 static_cast<unsigned long long>(result.photons),
                 static_cast<unsigned long long>(result.segments),
                 format_duration(result.seconds).c_str(), result.threads);
    const diffusion::Transition& t = analysis.gaussian;
    const diffusion::TransitionConfidence c = diffusion::transition_confidence(setup, result, analysis);
    if (t.reached) {
      std::fprintf(
          stderr,
          "femto diffusion: t* = %.4g ps = %.3g mean free times = %.3g transport mean free paths "
          "(distance to the Gaussian of the same <r^2> stays below %g%%)%s\n",
          t.t_ps, t.t_ps / sc.mean_free_time, t.t_ps * sc.v * sc.sigma_tr, 100 * request.threshold,
          t.from_start ? " from the window start" : "");
      if (std::isfinite(c.se_ps))
        std::fprintf(stderr, "femto diffusion: t* 95%% interval [%.4g, %.4g] ps = [%.3g, %.3g] mean free times (jackknife over %d batches)\n",
                     c.ci_lo_ps, c.ci_hi_ps, c.ci_lo_ps / sc.mean_free_time, c.ci_hi_ps / sc.mean_free_time, c.batches);
      if (c.noise_limited)
        std::fprintf(stderr,
                     "femto diffusion: warning: t* is decided by Monte Carlo noise (noise floor %.3g%% at t*, "
                     "t* with the floor subtracted %.4g ps): not a property of the medium; use more photons or a "
                     "larger --threshold\n",
                     100 * c.noise_at_t_star, c.floor_subtracted.t_ps);
    }
    else
      std::fprintf(stderr,
                   "femto diffusion: the profile does not stay within %g%% of a Gaussian inside "
                   "the window\n",
                   100 * request.threshold);
    std::string list;
    for (const auto& f : files) list += (list.empty() ? "" : ", ") + f;
    std::fprintf(stderr, "femto diffusion: results in %s/ (%s)\n", out_dir.c_str(), list.c_str());
    if (result.stopped_early)
      std::fprintf(stderr, "femto diffusion: stopped early (%s): %llu of %llu photons traced\n",
                   interrupted ? "interrupted" : "--max-seconds",
                   static_cast<unsigned long long>(result.photons),
                   static_cast<unsigned long long>(setup.photons));
  }
  return interrupted ? 128 + (g_signal.load() == SIGTERM ? SIGTERM : SIGINT) : 0;
}
}  // namespace

FEMTO_COMMAND("diffusion", "pulse in a medium: when does the wavefront become Gaussian?",
              cmd_diffusion);

}  // namespace femto
