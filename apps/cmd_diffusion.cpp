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
#include "core/diffusion/models.h"
#include "core/diffusion/report.h"
#include "core/error.h"
#include "core/distributed/comm.h"
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

// The smallest time bin and shell: their widths divide the tallies (a 1e-300 ps window would
// give infinite densities).
constexpr double kMinBinPs = 1e-9, kMinShellMm = 1e-9;

int cmd_diffusion(const std::vector<std::string>& argv_in, const std::string& command_line) {
  std::vector<std::string> argv = argv_in;
  for (auto& a : argv)  // --sigma_s and --sigma-s are the same flag
    if (a.rfind("--", 0) == 0)
      for (size_t i = 2; i < a.size() && a[i] != '='; ++i)
        if (a[i] == '_') a[i] = '-';
  cli::Args args("femto diffusion", argv);
  diffusion::DiffusionSetup setup;
  setup.medium.sigma_s = 4.1;
  double t_start = 0, threshold = 0.05;
  std::optional<double> t_end, r_max;
  int t_bins = 200, r_bins = 120;
  std::string out_dir = "femto-diffusion", plot_text;
  std::vector<double> plot_times;
  bool quiet = false, absorption_given = false;
  std::string scene_path, medium_name;
  std::optional<Vec3> at;
  while (!args.done()) {
    const std::string a = args.next();
    if (a == "--help" || a == "-h") {
      std::fputs(kDiffusionHelp, stdout);
      return 0;
    } else if (a == "--sigma-s") {
      setup.medium.sigma_s = args.number_in(0, 1e6, false, false, "in [0, 1e6] (1/mm)");
    } else if (a == "--sigma-a") {
      setup.medium.sigma_a = args.number_in(0, 1e6, false, false, "in [0, 1e6] (1/mm)");
    } else if (a == "--g") {
      setup.medium.g = args.number_in(-1, 1, true, true, "in (-1, 1)");
    } else if (a == "--eta") {
      setup.medium.eta = args.number_in(1, 100, false, false, "in [1, 100]");
    } else if (a == "--scene") {
      scene_path = args.value();
    } else if (a == "--medium") {
      medium_name = args.value();
    } else if (a == "--at") {
      at = args.xyz_value();
    } else if (a == "--absorption") {
      absorption_given = true;
      const std::string v = args.value();
      if (v == "weighted")
        setup.absorption = diffusion::Absorption::Weighted;
      else if (v == "analog")
        setup.absorption = diffusion::Absorption::Analog;
      else
        args.fail("expected weighted or analog", v);
    } else if (a == "--t-start") {
      t_start = args.number_in(0, 1e9, false, false, "in [0, 1e9] ps");
    } else if (a == "--t-end") {
      t_end = args.number_in(0, 1e9, true, false, "in (0, 1e9] ps");
    } else if (a == "--t-bins") {
      t_bins = static_cast<int>(args.int_value(1, 100000));
    } else if (a == "--r-max") {
      r_max = args.number_in(0, 1e9, true, false, "in (0, 1e9] mm");
    } else if (a == "--r-bins") {
      r_bins = static_cast<int>(args.int_value(1, 100000));
    } else if (a == "--threshold") {
      threshold = args.number_in(0, 1, true, true, "in (0, 1)");
    } else if (a == "--plot-times") {
      plot_text = args.value();
      plot_times.clear();
      std::stringstream ss(plot_text);
      for (std::string item; std::getline(ss, item, ',');) {
        char* end = nullptr;
        const double t = std::strtod(item.c_str(), &end);
        if (item.empty() || *end != '\0' || !std::isfinite(t))
          args.fail("expected comma-separated times in ps", plot_text);
        plot_times.push_back(t);
      }
      if (plot_times.empty() || plot_times.size() > 6)
        args.fail("expected 1 to 6 times", plot_text);
    } else if (a == "--photons") {
      setup.photons = args.count_value(2, 1e12);
    } else if (a == "--max-seconds") {
      setup.max_seconds = args.number_in(0, 1e9, true, false, "in (0, 1e9] s");
    } else if (a == "--seed") {
      setup.seed = args.uint_value();
    } else if (a == "--batches") {
      setup.batches = static_cast<int>(args.int_value(2, 1000));
    } else if (a == "--threads") {
      setup.threads = static_cast<int>(args.int_value(0, 4096));
    } else if (a == "--out") {
      out_dir = args.value();
      if (out_dir.empty()) args.fail("expects a folder", "");
    } else if (a == "--quiet" || a == "-q") {
      quiet = true;
    } else {
      args.fail("unknown option (see femto diffusion --help)", a);
    }
  }

  // A source inside a scene's medium: a homogeneous medium is used as an infinite one, a voxel
  // medium through VoxelTransport around the source point.
  std::unique_ptr<GridMedium> grid;
  std::unique_ptr<diffusion::PhotonTransport> transport;
  nlohmann::json source = {{"kind", "infinite homogeneous medium"}};
  if (!scene_path.empty() || at || !medium_name.empty()) {
    if (scene_path.empty()) throw InputError("femto diffusion: --at and --medium need --scene");
    if (!at) throw InputError("femto diffusion: --at: required with --scene (the source position)");
    const SceneDesc scene = load_scene_file(scene_path);
    int mi = scene.global_medium;
    if (!medium_name.empty()) {
      mi = -1;
      for (size_t i = 0; i < scene.media.size(); ++i)
        if (scene.media[i].name == medium_name) mi = static_cast<int>(i);
      if (mi < 0)
        throw InputError("femto diffusion: --medium: no medium named '" + clip(medium_name) +
                         "' in " + clip(scene_path, 200));
    }
    if (mi < 0)
      throw InputError("femto diffusion: --medium: " + clip(scene_path, 200) + " has no \"medium\" around everything; name one");
    const MediumDesc& md = scene.media[static_cast<size_t>(mi)];
    source = {{"kind", "scene medium"}, {"scene", scene_path}, {"medium", md.name},
              {"position_mm", {at->x, at->y, at->z}}, {"shapes", "ignored: the medium fills space"}};
    if (md.type == MediumDesc::Type::Homogeneous) {
      setup.medium = md.medium;
    } else {
      if (absorption_given && setup.absorption == diffusion::Absorption::Weighted)
        throw InputError("femto diffusion: --absorption: 'weighted' needs a homogeneous medium; voxel media use analog (got 'weighted')");
      const VolumeData data = load_volume(md.vdb, scene_path, medium_where(md.name));
      grid = std::make_unique<GridMedium>(data, md.vdb);
      transport = std::make_unique<diffusion::VoxelTransport>(*grid, md.medium.g, *at);
      setup.absorption = diffusion::Absorption::Analog;
      setup.normalise_by_energy = true;
      // The models and the default window use the medium at the source point.
      const double st = grid->sigma_t_at(*at), albedo = grid->albedo_at(*at);
      setup.medium = HomogeneousMedium{(1 - albedo) * st, albedo * st, md.medium.g, grid->eta_at(*at)};
      source["local_coefficients"] = {{"sigma_a", setup.medium.sigma_a}, {"sigma_s", setup.medium.sigma_s},
                                      {"g", setup.medium.g}, {"eta", setup.medium.eta}};
    }
  }

  // Cross-flag checks, all before anything is written.
  const diffusion::Scales sc = diffusion::scales_of(setup.medium);
  auto fail = [](const std::string& flag, const std::string& problem, double got) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%g", got);
    throw InputError("femto diffusion: " + flag + ": " + problem + " (got '" + buf + "')");
  };
  if (!t_end) {
    if (!(sc.sigma_t > 0))  // no mean free time to scale the default window with
      throw InputError(
          "femto diffusion: --t-end: required in a clear medium (sigma_s = sigma_a = 0)");
    t_end = t_start + 40 * sc.mean_free_time;
  }
  if (!(*t_end > t_start)) fail("--t-end", "must be greater than --t-start", *t_end);
  if (!r_max) r_max = sc.v * *t_end;
  if ((*t_end - t_start) / t_bins < kMinBinPs)
    fail("--t-end", "time bins of (--t-end - --t-start) / --t-bins must be at least 1e-9 ps wide",
         *t_end);
  if (*r_max / r_bins < kMinShellMm)
    fail("--r-max", "shells of --r-max / --r-bins (default r-max: (c / eta) t_end) must be at "
                    "least 1e-9 mm thick",
         *r_max);
  if (static_cast<double>(t_bins) * r_bins > 2e6)
    fail("--r-bins", "shells x time bins must be at most 2e6 (lower --r-bins or --t-bins)", r_bins);
  for (double t : plot_times)
    if (t < t_start || t > *t_end)
      fail("--plot-times", "each time must lie inside [--t-start, --t-end]", t);
  if (plot_times.empty())
    for (double k : {1.0, 3.0, 10.0, 30.0})
      if (std::isfinite(sc.mean_free_time) && k * sc.mean_free_time > t_start &&
          k * sc.mean_free_time < *t_end)
        plot_times.push_back(k * sc.mean_free_time);
  setup.grid.time = TimeAxis{t_start, (*t_end - t_start) / t_bins, t_bins};
  setup.grid.shells = r_bins;
  setup.grid.dr = *r_max / r_bins;
  // Under mpirun (docs/mpi.md) every rank checks the same input and traces its share; rank 0
  // reports and writes.
  const distributed::Comm& comm = distributed::world();
  if (!comm.root()) quiet = true;
  if (!comm.single()) setup.comm = &comm;
  setup.quiet = quiet;
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
                 static_cast<unsigned long long>(setup.photons), t_bins, *t_end, r_bins, *r_max,
                 setup.medium.sigma_s * sc.v * *t_end);

  g_interrupted.store(false);
  setup.stop = &g_interrupted;
  const auto previous = std::signal(SIGINT, on_interrupt);
  const auto previous_term = std::signal(SIGTERM, on_interrupt);
  const diffusion::DiffusionResult result =
      transport ? diffusion::simulate(setup, *transport) : diffusion::simulate(setup);
  std::signal(SIGINT, previous);
  std::signal(SIGTERM, previous_term);
  const bool interrupted = result.stopped_early && g_interrupted.load();
  const diffusion::Analysis analysis = diffusion::analyse(setup, result, threshold);
  diffusion::ReportOptions opt;
  opt.dir = out_dir;
  opt.plot_times = plot_times;
  opt.run = {{"femto_version", FEMTO_VERSION},
             {"femto_build", FEMTO_GIT_DESCRIBE},
             {"command", command_line},
             {"date_utc", cli::utc_now()},
             {"source", source},
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
          t.t_ps, t.t_ps / sc.mean_free_time, t.t_ps * sc.v * sc.sigma_tr, 100 * threshold,
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
                   100 * threshold);
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
