// `femto tissue SCENE`: time-resolved tissue optics on a labelled volume (docs/tissue.md). The same
// run happens for `femto render SCENE` when the scene has a "tissue" section.
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "apps/cli.h"
#include "apps/commands.h"
#include "apps/tissue_run.h"
#include "core/distributed/comm.h"
#include "core/error.h"
#include "core/output_folder.h"
#include "core/progress.h"
#include "core/scene_loader.h"
#include "core/tissue/outputs.h"
#include "core/tissue/scene.h"
#include "core/tissue/simulate.h"
#include "femto_version.h"

namespace femto {

namespace {
const char* kTissueHelp =
    "Usage: femto tissue SCENE.json [options]   (or: femto render SCENE.json [options])\n"
    "\n"
    "Time-resolved tissue optics: photons from a pulsed source (pencil, gaussian, disk or\n"
    "isotropic) walk a labelled voxel volume with per-label mu_a, mu_s, g, n and Fresnel\n"
    "interfaces; tallies the time-gated fluence (X,Y,Z,T), absorbed energy per label, detector\n"
    "TPSFs, detected photons' partial path lengths and face exitance images. The scene is a\n"
    "\"tissue\" section (docs/scene-format.md, docs/tissue.md).\n"
    "\n"
    "Options (override the scene):\n"
    "  --photons N        photons launched, 1..1e12 (e.g. 1e6)\n"
    "  --seed S           random seed, integer >= 0; the same seed gives bit-identical output for\n"
    "                     any thread count\n"
    "  --threads N        worker threads, 0 = all cores (default 0)\n"
    "  --out DIR          output folder, replaced as a whole at the end (default ./femto-out)\n"
    "  --max-memory SIZE  refuse to run when the tallies need more than SIZE (e.g. 2G); default\n"
    "                     75% of physical memory\n"
    "  --quiet            no progress or summary on stderr\n"
    "  --help             this help\n"
    "\n"
    "mpirun -np N femto tissue ...: N ranks share the photons; rank 0 writes outputs\n"
    "bit-identical to one process's (docs/mpi.md).\n"
    "\n"
    "Outputs: fluence.npy (X,Y,Z,T float32, 1/mm^2 per gate per unit launched energy),\n"
    "fluence_rate.npy (1/(mm^2 ps)), fluence.nii, fluence_stderr.npy (on request), tpsf.npy and\n"
    "tpsf.csv (1/(mm^2 ps)), detected_photons.npy, detected_ppath.npy, detected_exit.npy,\n"
    "exitance_*.npy (faces),\n"
    "summary.json (energy balance, absorbed fraction) and render.json.\n";

int cmd_tissue(const std::vector<std::string>& argv, const std::string& command_line) {
  cli::Args args("femto tissue", argv);
  TissueRunOptions opt;
  std::string scene_path;
  while (!args.done()) {
    const std::string a = args.next();
    if (a == "--help" || a == "-h") {
      std::fputs(kTissueHelp, stdout);
      return 0;
    } else if (a == "--photons") {
      opt.photons = args.count_value(1, 1e12);
    } else if (a == "--seed") {
      opt.seed = args.uint_value();
    } else if (a == "--threads") {
      opt.threads = static_cast<int>(args.int_value(0, 4096));
    } else if (a == "--out") {
      opt.out = args.value();
      if (opt.out.empty()) args.fail("expects a folder", "");
    } else if (a == "--max-memory") {
      opt.max_memory = args.size_value();
    } else if (a == "--quiet" || a == "-q") {
      opt.quiet = true;
    } else if (!a.empty() && a[0] == '-') {
      args.fail("unknown option (see femto tissue --help)", a);
    } else if (scene_path.empty()) {
      scene_path = a;
    } else {
      args.fail("only one scene file may be given", a);
    }
  }
  if (scene_path.empty())
    throw InputError("femto tissue: a scene file is required (see femto tissue --help)");
  const std::string text = read_scene_text(scene_path);
  if (!tissue::is_tissue_scene(text))
    throw InputError(scene_path +
                     ": /tissue: required by femto tissue (a scene with a \"tissue\" section)");
  return run_tissue_scene(text, scene_path, opt, command_line);
}
}  // namespace

int run_tissue_scene(const std::string& text, const std::string& path, const TissueRunOptions& opt,
                     const std::string& command_line) {
  tissue::Setup s =
      tissue::load_tissue_scene(text, path, std::filesystem::path(path).parent_path().string());
  if (opt.photons) s.photons = *opt.photons;
  if (opt.seed) s.seed = *opt.seed;
  s.threads = opt.threads;
  // Under mpirun (docs/mpi.md) every rank checks the same input and traces its chunks; rank 0
  // reports and writes.
  const distributed::Comm& comm = distributed::world();
  const bool quiet = opt.quiet || !comm.root();
  s.quiet = quiet;
  if (!comm.single()) s.comm = &comm;
  const int threads = tissue::threads_for(s);
  const uint64_t max_memory =
      opt.max_memory ? opt.max_memory : cli::physical_memory_bytes() / 4 * 3;
  const uint64_t need = tissue::memory_bytes(s, threads);
  const uint64_t fluence_bytes = tissue::fluence_bytes_per_thread(s);
  if (need > max_memory)
    throw InputError(
        path + ": the run needs " + cli::format_bytes(need) + " (fluence volume " +
        std::to_string(s.fluence_grid.n[0]) + " x " + std::to_string(s.fluence_grid.n[1]) + " x " +
        std::to_string(s.fluence_grid.n[2]) + " x " + std::to_string(s.time.bins) +
        " gates, summed per thread, and the tissue volume), more than --max-memory " +
        cli::format_bytes(max_memory) +
        ": lower /tissue/fluence/resolution or /tissue/time/bins, or raise --max-memory");
  // The output folder is checked before the run (a foreign folder is bad input).
  {
    std::error_code ec;
    if (std::filesystem::exists(opt.out, ec)) {
      if (!std::filesystem::is_directory(opt.out, ec))
        throw InputError("--out " + clip(opt.out, 200) + ": exists and is not a folder");
      bool is_femto = false;
      const std::string foreign = foreign_entry(opt.out, is_femto);
      if (!foreign.empty())
        throw InputError("--out " + clip(opt.out, 200) + ": the folder holds '" + clip(foreign) +
                         "', which is not part of a femto run; give an empty or new folder");
    }
  }
  if (!quiet)
    std::fprintf(
        stderr,
        "femto tissue: %s: %d x %d x %d voxels of %g mm, %s, %s boundary; %llu photons, "
        "%d gates of %g ps; memory: fluence volume %s x %d threads + sums, tissue volume %s, "
        "total %s\n",
        path.c_str(), s.volume.n[0], s.volume.n[1], s.volume.n[2], s.volume.voxel,
        s.volume.voxel_optics.empty()
            ? (std::to_string(s.volume.optics.size() - 1) + " labels").c_str()
            : "optics per voxel",
        s.fresnel ? "Fresnel" : "index-matched",
        static_cast<unsigned long long>(s.photons), s.time.bins, s.time.bin_width_ps,
        cli::format_bytes(fluence_bytes).c_str(), threads,
        cli::format_bytes(s.volume.memory_bytes()).c_str(), cli::format_bytes(need).c_str());
  if (!comm.root()) {
    tissue::simulate(s);
    return 0;
  }
  OutputFolder folder(opt.out, false);
  const tissue::Result r = tissue::simulate(s);
  nlohmann::json record = {
      {"femto_version", FEMTO_VERSION},
      {"femto_build", FEMTO_GIT_DESCRIBE},
      {"femto_instruction_set", FEMTO_INSTRUCTION_SET},
      {"command", command_line},
      {"date_utc", cli::utc_now()},
      {"mode", "tissue"},
      {"scene", {{"source", path}, {"json", nlohmann::json::parse(text, nullptr, false, true)}}},
      {"seed", s.seed},
      {"threads", r.threads},
      {"mpi_ranks", comm.size()},
      {"memory_bytes_estimate", need}};
  const std::vector<std::string> files = tissue::write_outputs(folder.staging(), s, r, record);
  folder.commit();
  if (!quiet) {
    const double N = static_cast<double>(r.photons);
    std::fprintf(stderr,
                 "femto tissue: %llu photons in %s (%d threads, %.1f photons/ms); absorbed %.6f, "
                 "escaped %.6f, "
                 "alive at window end %.6f, balance residual %.2e\n",
                 static_cast<unsigned long long>(r.photons), format_duration(r.seconds).c_str(),
                 r.threads, N / (r.seconds * 1e3), r.balance.absorbed / N, r.balance.escaped() / N,
                 r.balance.alive / N, r.balance.residual() / N);
    std::fprintf(stderr, "femto tissue: results in %s/ (%zu files)\n", opt.out.c_str(),
                 files.size());
  }
  return 0;
}

FEMTO_COMMAND("tissue", "time-resolved tissue optics on a labelled volume (fluence, TPSFs)",
              cmd_tissue);

}  // namespace femto
