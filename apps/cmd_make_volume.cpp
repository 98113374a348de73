// `femto make-volume`: writes a procedural example volume (cloud or tissue) as an OpenVDB file.
#include <cstdio>
#include <filesystem>
#include <optional>

#include "apps/cli.h"
#include "apps/commands.h"
#include "core/error.h"
#include "media/sparse_generators.h"
#include "media/volume_generators.h"

namespace femto {
namespace {

const char* kMakeVolumeHelp =
    "Usage: femto make-volume KIND --out FILE.vdb [options]\n"
    "\n"
    "Writes a procedural example volume as an OpenVDB file, centred on the world origin,\n"
    "for a \"vdb\" medium (docs/volumes.md). The same options give the same grids.\n"
    "\n"
    "KIND:\n"
    "  cloud    a fog/smoke cloud: float grid 'density' (fog volume) in [0, 1], smooth\n"
    "           fractal value noise under a soft spherical falloff, exactly 0 (inactive) near\n"
    "           the faces of the grid. No albedo or eta grid: set them in the scene.\n"
    "           Defaults: --resolution 64, --voxel 2 (a 128 mm cube).\n"
    "  tissue   a block of tissue filling the grid: 'density' 1 +- 0.1 (mild noise),\n"
    "           'albedo' 0.9 +- 0.03, 'eta' 1.37 (the eta grid's background); a spherical\n"
    "           inclusion (radius 0.35 of the half-width, centred 0.25 of the half-width above\n"
    "           the centre, along +y) has 3x the density and eta 1.45 (its only active eta\n"
    "           voxels). Defaults: --resolution 48, --voxel 0.5 (a 24 mm cube).\n"
    "  sparse-cloud  a large sparse cloud of noisy puffs in a box of N x 0.68N x 1.22N voxels\n"
    "           (the proportions of the usual production test cloud; N = 2048 gives\n"
    "           2048 x 1393 x 2499), 'density' only, about 5-10% of the box active. Generated\n"
    "           leaf by leaf (never dense) and written uncompressed. Defaults: --resolution\n"
    "           256, --voxel 0.5. --resolution up to 4096.\n"
    "  plume    a thin smoke plume rising and drifting through an N^3 box, mostly empty space.\n"
    "           Defaults: --resolution 512, --voxel 0.25. --resolution up to 4096.\n"
    "\n"
    "Options:\n"
    "  --out FILE.vdb     output file (required); written atomically\n"
    "  --resolution N     voxels along each axis, 4..512 (sparse-cloud, plume: 16..4096)\n"
    "  --seed S           noise seed, integer >= 0 (default 1)\n"
    "  --voxel MM         voxel edge length in mm, > 0\n"
    "  --quiet            print nothing on success\n"
    "  --help             this help\n"
    "\n"
    "Inspect the result with `femto info SCENE.json` on a scene that uses it.\n";

int make_sparse(const std::string& kind, const std::string& out, std::optional<int> resolution,
                std::optional<double> voxel, uint64_t seed, bool quiet) {
  const bool cloud = kind == "sparse-cloud";
  const int n = resolution.value_or(cloud ? 256 : 512);
  if (n < 16)
    throw InputError("femto make-volume: --resolution: " + kind + " needs at least 16 (got " + std::to_string(n) + ")");
  const double mm = voxel.value_or(cloud ? 0.5 : 0.25);
  const SparseVolumeInfo v = cloud ? write_sparse_cloud(out, n, seed, mm) : write_plume(out, n, seed, mm);
  if (!quiet) {
    std::error_code ec;
    std::fprintf(stderr, "femto: wrote %s: %s in a %d x %d x %d voxel box of %g mm (centred on the origin), seed %llu\n",
                 out.c_str(), kind.c_str(), v.dims[0], v.dims[1], v.dims[2], mm, static_cast<unsigned long long>(seed));
    const double cells = double(v.dims[0]) * v.dims[1] * v.dims[2];
    std::fprintf(stderr, "femto:   grid 'density': %llu active voxels (%.3g%% of the box) in %llu leaves, values up to %g\n",
                 static_cast<unsigned long long>(v.active_voxels), 100.0 * double(v.active_voxels) / cells,
                 static_cast<unsigned long long>(v.leaves), v.max_density);
    std::fprintf(stderr, "femto:   OpenVDB in memory %s, file size %s\n", cli::format_bytes(v.memory_bytes).c_str(),
                 cli::format_bytes(std::filesystem::file_size(out, ec)).c_str());
  }
  return 0;
}

int cmd_make_volume(const std::vector<std::string>& argv, const std::string&) {
  cli::Args args("femto make-volume", argv);
  std::string kind, out;
  std::optional<int> resolution;
  std::optional<double> voxel;
  uint64_t seed = 1;
  bool quiet = false;
  while (!args.done()) {
    const std::string a = args.next();
    if (a == "--help" || a == "-h") {
      std::fputs(kMakeVolumeHelp, stdout);
      return 0;
    } else if (a == "--out") {
      out = args.value();
      if (out.empty()) args.fail("expects a file name", "");
    } else if (a == "--resolution") {
      resolution = static_cast<int>(args.int_value(4, 4096));
    } else if (a == "--seed") {
      seed = args.uint_value();
    } else if (a == "--voxel") {
      voxel = args.double_value(1e-6, 1e6);
    } else if (a == "--quiet" || a == "-q") {
      quiet = true;
    } else if (!a.empty() && a[0] == '-') {
      args.fail("unknown option (see femto make-volume --help)", a);
    } else if (kind.empty()) {
      if (a != "cloud" && a != "tissue" && a != "sparse-cloud" && a != "plume")
        args.fail("unknown volume kind: expected cloud, tissue, sparse-cloud or plume", a);
      kind = a;
    } else {
      args.fail("only one volume kind may be given", a);
    }
  }
  if (kind.empty())
    throw InputError("femto make-volume: missing KIND (cloud, tissue, sparse-cloud or plume); see --help");
  if (out.empty()) throw InputError("femto make-volume: --out: missing output file (FILE.vdb)");
  const std::filesystem::path parent = std::filesystem::path(out).parent_path();
  std::error_code ec;
  if (!parent.empty() && !std::filesystem::is_directory(parent, ec))
    throw InputError("femto make-volume: --out: folder does not exist: " + parent.string() +
                     " (got '" + out + "')");

  if (kind == "sparse-cloud" || kind == "plume") return make_sparse(kind, out, resolution, voxel, seed, quiet);
  if (resolution && *resolution > 512)
    throw InputError("femto make-volume: --resolution: " + kind + " is dense: at most 512 (got " +
                     std::to_string(*resolution) + "); sparse-cloud and plume go to 4096");
  const bool cloud = kind == "cloud";
  const int n = resolution.value_or(cloud ? 64 : 48);
  const double mm = voxel.value_or(cloud ? 2.0 : 0.5);
  const GeneratedVolume vol = cloud ? make_cloud(n, seed) : make_tissue(n, seed);
  write_generated(out, vol, mm);

  if (!quiet) {
    uint64_t active = 0;
    for (const float d : vol.density.v) active += d != 0.0f;
    std::fprintf(stderr, "femto: wrote %s: %s, %d^3 voxels of %g mm (a %g mm cube centred on the origin), seed %llu\n",
                 out.c_str(), kind.c_str(), n, mm, n * mm, static_cast<unsigned long long>(seed));
    std::fprintf(stderr, "femto:   grid 'density': %llu active voxels, values %g to %g\n",
                 static_cast<unsigned long long>(active), vol.density.min_value, vol.density.max_value);
    if (!vol.albedo.empty())
      std::fprintf(stderr, "femto:   grid 'albedo': values %g to %g\n", vol.albedo.min_value,
                   vol.albedo.max_value);
    if (!vol.eta.empty())
      std::fprintf(stderr, "femto:   grid 'eta': values %g to %g (background %g)\n", vol.eta.min_value,
                   vol.eta.max_value, vol.eta_background);
    std::fprintf(stderr, "femto:   file size %s\n",
                 cli::format_bytes(std::filesystem::file_size(out, ec)).c_str());
  }
  return 0;
}

}  // namespace

FEMTO_COMMAND("make-volume", "write a procedural example volume (cloud, tissue, sparse-cloud, plume) as a .vdb file",
              cmd_make_volume);

}  // namespace femto
