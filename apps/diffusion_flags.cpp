#include "apps/diffusion_flags.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <sstream>

#include "apps/cli.h"
#include "core/diffusion/models.h"
#include "core/error.h"
#include "core/scene_loader.h"
#include "media/volume_data.h"

namespace femto {

namespace {
// The smallest time bin and shell: their widths divide the tallies (a 1e-300 ps window would
// give infinite densities).
constexpr double kMinBinPs = 1e-9, kMinShellMm = 1e-9;
}  // namespace

DiffusionRequest parse_diffusion_args(const std::vector<std::string>& argv_in,
                                      const std::string& command) {
  DiffusionRequest r;
  std::vector<std::string> argv = argv_in;
  for (auto& a : argv)  // --sigma_s and --sigma-s are the same flag
    if (a.rfind("--", 0) == 0)
      for (size_t i = 2; i < a.size() && a[i] != '='; ++i)
        if (a[i] == '_') a[i] = '-';
  cli::Args args(command, argv);
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
      r.help = true;
      return r;
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
    if (scene_path.empty()) throw InputError(command + ": --at and --medium need --scene");
    if (!at) throw InputError(command + ": --at: required with --scene (the source position)");
    const SceneDesc scene = load_scene_file(scene_path);
    int mi = scene.global_medium;
    if (!medium_name.empty()) {
      mi = -1;
      for (size_t i = 0; i < scene.media.size(); ++i)
        if (scene.media[i].name == medium_name) mi = static_cast<int>(i);
      if (mi < 0)
        throw InputError(command + ": --medium: no medium named '" + clip(medium_name) + "' in " +
                         clip(scene_path, 200));
    }
    if (mi < 0)
      throw InputError(command + ": --medium: " + clip(scene_path, 200) +
                       " has no \"medium\" around everything; name one");
    const MediumDesc& md = scene.media[static_cast<size_t>(mi)];
    source = {{"kind", "scene medium"},
              {"scene", scene_path},
              {"medium", md.name},
              {"position_mm", {at->x, at->y, at->z}},
              {"shapes", "ignored: the medium fills space"}};
    if (md.type == MediumDesc::Type::Homogeneous) {
      setup.medium = md.medium;
    } else {
      if (absorption_given && setup.absorption == diffusion::Absorption::Weighted)
        throw InputError(command +
                         ": --absorption: 'weighted' needs a homogeneous medium; voxel media use "
                         "analog (got 'weighted')");
      const VolumeData data = load_volume(md.vdb, scene_path, medium_where(md.name));
      grid = std::make_unique<GridMedium>(data, md.vdb);
      transport = std::make_unique<diffusion::VoxelTransport>(*grid, md.medium.g, *at);
      setup.absorption = diffusion::Absorption::Analog;
      setup.normalise_by_energy = true;
      // The models and the default window use the medium at the source point.
      const double st = grid->sigma_t_at(*at), albedo = grid->albedo_at(*at);
      setup.medium =
          HomogeneousMedium{(1 - albedo) * st, albedo * st, md.medium.g, grid->eta_at(*at)};
      source["local_coefficients"] = {{"sigma_a", setup.medium.sigma_a},
                                      {"sigma_s", setup.medium.sigma_s},
                                      {"g", setup.medium.g},
                                      {"eta", setup.medium.eta}};
    }
  }

  // Cross-flag checks, all before anything is written.
  const diffusion::Scales sc = diffusion::scales_of(setup.medium);
  auto fail = [&command](const std::string& flag, const std::string& problem, double got) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%g", got);
    throw InputError(command + ": " + flag + ": " + problem + " (got '" + buf + "')");
  };
  if (!t_end) {
    if (!(sc.sigma_t > 0))  // no mean free time to scale the default window with
      throw InputError(command + ": --t-end: required in a clear medium (sigma_s = sigma_a = 0)");
    t_end = t_start + 40 * sc.mean_free_time;
  }
  if (!(*t_end > t_start)) fail("--t-end", "must be greater than --t-start", *t_end);
  if (!r_max) r_max = sc.v * *t_end;
  if ((*t_end - t_start) / t_bins < kMinBinPs)
    fail("--t-end", "time bins of (--t-end - --t-start) / --t-bins must be at least 1e-9 ps wide",
         *t_end);
  if (*r_max / r_bins < kMinShellMm)
    fail("--r-max",
         "shells of --r-max / --r-bins (default r-max: (c / eta) t_end) must be at "
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
  setup.quiet = quiet;
  r.setup = setup;
  r.threshold = threshold;
  r.plot_times = plot_times;
  r.out_dir = out_dir;
  r.quiet = quiet;
  r.source = source;
  r.grid = std::move(grid);
  r.transport = std::move(transport);
  return r;
}

}  // namespace femto
