// `femto info`: validates a scene (including its VDB volumes) and prints what it contains.
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "apps/cli.h"
#include "apps/commands.h"
#include "apps/info_format.h"
#include "apps/tissue_info.h"
#include "core/error.h"
#include "core/mitsuba/mitsuba_xml.h"
#include "core/render.h"
#include "core/scene_loader.h"
#include "core/tissue/scene.h"
#include "media/volume_data.h"

namespace femto {
namespace {

const char* kInfoHelp =
    "Usage: femto info SCENE.json\n"
    "\n"
    "Loads and validates SCENE.json and every VDB volume it uses (without rendering), then\n"
    "prints a summary: camera, time axis in ps and in optical path length (mm), shapes, lights\n"
    "and, for each medium, its type and coefficients. For a \"vdb\" medium also: file, grids\n"
    "used, world bounding box, voxel size, box resolution, active voxels, value ranges\n"
    "(density, sigma_t = sigma_t_scale * density, albedo, eta), the storage (dense, or sparse\n"
    "with its leaf and tile counts) and its memory.\n"
    "A .xml scene is read as Mitsuba 3 / mitransient XML (a subset, docs/mitsuba.md).\n"
    "A tissue-optics scene (docs/tissue.md) is summarised instead: volume, labels or voxel\n"
    "medium with their optics, boundary, source, gates, tallies and the memory a run needs.\n"
    "Exit code 2 with a one-line message naming the file, key and value on bad input.\n"
    "\n"
    "Options:\n"
    "  -D NAME=VALUE   Mitsuba XML scenes: the value of $NAME, over the file's <default>\n"
    "                  (repeatable; also --define NAME=VALUE)\n"
    "  --help          this help\n";

using info::g6;
using info::range;
using info::vec;
std::string rgb(const RGB& c) {
  return c.r == c.g && c.g == c.b ? g6(c.r) : "[" + g6(c.r) + ", " + g6(c.g) + ", " + g6(c.b) + "]";
}

std::string pulse(const PulseDesc& p) {
  if (p.fwhm_ps == 0 && p.offset_ps == 0) return "delta pulse at 0 ps";
  return (p.fwhm_ps > 0 ? "Gaussian pulse, fwhm " + g6(p.fwhm_ps) + " ps"
                        : std::string("delta pulse")) +
         " at " + g6(p.offset_ps) + " ps";
}

std::string sampling(const MediumDesc& m) {
  switch (m.sampling) {
    case DistanceSampling::Mfp:
      return "mfp";
    case DistanceSampling::TimeUniform:
      return "time_uniform, rate " + (m.time_uniform_rate > 0 ? g6(m.time_uniform_rate) + " /mm OPL"
                                                              : std::string("automatic"));
    case DistanceSampling::Mixture:
      return "mixture (one-sample MIS of mfp and time_uniform per segment), time-uniform rate " +
             (m.time_uniform_rate > 0 ? g6(m.time_uniform_rate) + " /mm OPL"
                                      : std::string("automatic"));
    case DistanceSampling::Mis:
      return std::string("mis (") +
             (m.mis_heuristic == MisHeuristic::Balance ? "balance" : "power") +
             " heuristic), time-uniform rate " +
             (m.time_uniform_rate > 0 ? g6(m.time_uniform_rate) + " /mm OPL"
                                      : std::string("automatic"));
  }
  return "";
}

void print_vdb(const VdbMediumDesc& d, const VolumeData& v) {
  const TransformDesc& t = d.transform;
  std::printf("    file:            %s\n", clip(d.file, 200).c_str());
  std::printf("    grids:           density '%s'%s%s\n", clip(d.density_grid).c_str(),
              d.albedo_grid.empty() ? "" : (", albedo '" + clip(d.albedo_grid) + "'").c_str(),
              d.eta_grid.empty() ? "" : (", eta '" + clip(d.eta_grid) + "'").c_str());
  std::printf("    interpolation:   %s\n",
              d.interpolation == VdbMediumDesc::Interpolation::Nearest ? "nearest" : "trilinear");
  std::printf("    transform:       scale %s, rotate %s deg, translate %s mm\n",
              vec(t.scale).c_str(), vec(t.rotate_deg).c_str(), vec(t.translate).c_str());
  std::printf("    world bounds:    %s to %s mm\n", vec(v.world_bounds_min).c_str(),
              vec(v.world_bounds_max).c_str());
  std::printf("    voxel size:      %s mm\n",
              vec({v.voxel_size[0], v.voxel_size[1], v.voxel_size[2]}).c_str());
  const DenseGrid& g = v.density;
  // 64-bit: a box touching INT_MAX would overflow index_min + n - 1 in int.
  const auto last = [&](int a, int n) { return static_cast<long long>(v.index_min[a]) + n - 1; };
  const uint64_t cells = uint64_t(g.nx) * uint64_t(g.ny) * uint64_t(g.nz);
  std::printf(
      "    %s      %d x %d x %d cells (%llu), VDB index box (%d, %d, %d) to (%lld, %lld, %lld)\n",
      v.sparse ? "box:       " : "dense grid:", g.nx, g.ny, g.nz,
      static_cast<unsigned long long>(cells), v.index_min[0], v.index_min[1], v.index_min[2],
      last(0, g.nx), last(1, g.ny), last(2, g.nz));
  std::printf("    active voxels:   %llu (%.3g%% of the box)\n",
              static_cast<unsigned long long>(v.active_voxels),
              100.0 * static_cast<double>(v.active_voxels) / static_cast<double>(cells));
  std::printf("    density:         %s\n", range(g.min_value, g.max_value).c_str());
  std::printf("    sigma_t:         %s /mm (sigma_t_scale %s)\n",
              range(d.sigma_t_scale * g.min_value, d.sigma_t_scale * g.max_value).c_str(),
              g6(d.sigma_t_scale).c_str());
  std::printf("    albedo:          %s\n",
              d.albedo_grid.empty()
                  ? (g6(d.albedo) + " (constant)").c_str()
                  : (range(v.albedo.min_value, v.albedo.max_value) + " (grid)").c_str());
  std::printf("    eta:             %s; %s outside the grid box\n",
              d.eta_grid.empty() ? (g6(d.eta) + " (constant)").c_str()
                                 : (range(v.eta.min_value, v.eta.max_value) + " (grid)").c_str(),
              g6(d.eta).c_str());
  if (v.sparse) {
    const SparseField& f = *v.sparse;
    std::printf(
        "    storage:         sparse (%s): %llu leaves, %llu active tiles over all grids used\n",
        d.storage == VdbMediumDesc::Storage::Sparse ? "storage \"sparse\"" : "chosen automatically",
        static_cast<unsigned long long>(f.leaf_count),
        static_cast<unsigned long long>(f.tile_count));
    std::printf("    memory:          %s (OpenVDB trees %s, index and bounds %s)\n",
                cli::format_bytes(v.memory_bytes()).c_str(),
                cli::format_bytes(f.tree_bytes).c_str(),
                cli::format_bytes(f.index_bytes()).c_str());
  } else {
    std::printf("    storage:         dense (%s)\n", d.storage == VdbMediumDesc::Storage::Dense
                                                         ? "storage \"dense\""
                                                         : "chosen automatically");
    std::printf("    memory:          %s (dense float grids)\n",
                cli::format_bytes(v.memory_bytes()).c_str());
  }
}

int cmd_info(const std::vector<std::string>& argv, const std::string&) {
  cli::Args args("femto info", argv);
  std::string path;
  XmlDefines xml_defines;  // -D NAME=VALUE for Mitsuba XML scenes
  while (!args.done()) {
    const std::string a = args.next();
    if (a == "--help" || a == "-h") {
      std::fputs(kInfoHelp, stdout);
      return 0;
    } else if (a == "-D" || a == "--define") {
      const std::string d = args.value();
      if (!add_xml_define(d, xml_defines)) args.fail("expects NAME=VALUE", d);
    } else if (!a.empty() && a[0] == '-') {
      args.fail("unknown option (see femto info --help)", a);
    } else if (path.empty()) {
      path = a;
    } else {
      args.fail("only one scene file may be given", a);
    }
  }
  if (path.empty()) throw InputError("femto info: missing SCENE.json (see femto info --help)");
  if (!xml_defines.empty() && !is_mitsuba_xml_path(path))
    throw InputError("femto info: -D " + clip(xml_defines.begin()->first) +
                     ": applies to Mitsuba XML scenes (.xml) only");
  if (!is_mitsuba_xml_path(path)) {
    const std::string text = read_scene_text(path);
    if (tissue::is_tissue_scene(text)) {
      print_tissue_info(text, path);
      return 0;
    }
  }
  const SceneDesc s =
      is_mitsuba_xml_path(path)
          ? load_mitsuba_xml(read_scene_text(path), path,
                             std::filesystem::path(path).parent_path().string(), xml_defines)
                .desc
          : load_scene_file(path);
  for (const std::string& w : s.warnings) std::fprintf(stderr, "femto: warning: %s\n", w.c_str());
  // Every volume is loaded (and validated) before anything is printed.
  std::vector<VolumeData> volumes(s.media.size());
  for (size_t i = 0; i < s.media.size(); ++i)
    if (s.media[i].type == MediumDesc::Type::Vdb)
      volumes[i] = load_volume(s.media[i].vdb, s.source, medium_where(s.media[i].name));

  const CameraDesc& c = s.camera;
  std::printf("scene: %s\n", clip(s.source, 200).c_str());
  if (c.type == CameraDesc::Type::Perspective)
    std::printf("camera: perspective, %d x %d pixels, fov %s deg, at %s looking at %s\n", c.width,
                c.height, g6(c.fov_deg).c_str(), vec(c.position).c_str(), vec(c.look_at).c_str());
  else
    std::printf("camera: orthographic, %d x %d pixels, %s mm wide, at %s looking at %s\n", c.width,
                c.height, g6(c.ortho_width).c_str(), vec(c.position).c_str(),
                vec(c.look_at).c_str());
  const TimeAxis& t = s.time;
  std::printf("time: %d bins of %s ps, %s to %s ps (OPL %s mm, %s to %s mm), mode %s\n", t.bins,
              g6(t.bin_width_ps).c_str(), g6(t.t_start_ps).c_str(), g6(t.t_end_ps()).c_str(),
              g6(TimeAxis::opl_of_time(t.bin_width_ps)).c_str(),
              g6(TimeAxis::opl_of_time(t.t_start_ps)).c_str(),
              g6(TimeAxis::opl_of_time(t.t_end_ps())).c_str(),
              s.time_mode == TimeMode::Camera ? "camera" : "unwarp");
  std::printf("render: %d spp, max_depth %d, seed %llu\n", s.integrator.spp, s.integrator.max_depth,
              static_cast<unsigned long long>(s.integrator.seed));
  std::string why;
  const IntegratorKind kind = resolve_integrator(s, s.integrator.kind, why);
  std::printf("integrator: %s (%s)\n", integrator_name(kind), why.c_str());

  int count[4] = {0, 0, 0, 0}, emissive = 0;
  for (const ShapeDesc& sh : s.shapes) {
    ++count[static_cast<int>(sh.type)];
    emissive += sh.emissive;
  }
  std::printf("shapes: %zu (%d spheres, %d quads, %d boxes, %d meshes; %d emissive)\n",
              s.shapes.size(), count[0], count[1], count[2], count[3], emissive);
  std::printf("lights: %zu\n", s.lights.size());
  for (const LightDesc& l : s.lights) {
    if (l.type == LightDesc::Type::Point)
      std::printf("  %s: point at %s, intensity %s W/sr, %s\n", l.where.c_str(),
                  vec(l.position).c_str(), rgb(l.intensity).c_str(), pulse(l.pulse).c_str());
    else if (l.type == LightDesc::Type::Spot)
      std::printf("  %s: spot at %s, direction %s, cone %s deg, intensity %s W/sr, %s\n",
                  l.where.c_str(), vec(l.position).c_str(), vec(l.direction).c_str(),
                  g6(l.cone_angle_deg).c_str(), rgb(l.intensity).c_str(), pulse(l.pulse).c_str());
    else
      std::printf("  %s: laser at %s, direction %s, radius %s mm, power %s W, %s\n",
                  l.where.c_str(), vec(l.position).c_str(), vec(l.direction).c_str(),
                  g6(l.radius).c_str(), rgb(l.power).c_str(), pulse(l.pulse).c_str());
  }

  std::printf("media: %zu; around everything: %s\n", s.media.size(),
              s.global_medium < 0
                  ? "vacuum"
                  : ("'" + clip(s.media[static_cast<size_t>(s.global_medium)].name) + "'").c_str());
  for (size_t i = 0; i < s.media.size(); ++i) {
    const MediumDesc& m = s.media[i];
    int inside = 0;
    for (const ShapeDesc& sh : s.shapes) inside += sh.interior_medium == static_cast<int>(i);
    const std::string use =
        (static_cast<int>(i) == s.global_medium ? std::string("global") : "") +
        (inside ? std::string(static_cast<int>(i) == s.global_medium ? ", " : "") + "inside " +
                      std::to_string(inside) + " shape(s)"
                : "");
    std::printf("  '%s': %s%s\n", clip(m.name).c_str(),
                m.type == MediumDesc::Type::Vdb ? "vdb" : "homogeneous",
                use.empty() ? " (unused)" : (" (" + use + ")").c_str());
    if (m.type == MediumDesc::Type::Homogeneous) {
      const HomogeneousMedium& h = m.medium;
      std::printf("    sigma_a %s, sigma_s %s, sigma_t %s /mm; albedo %s; mean free path %s mm\n",
                  g6(h.sigma_a).c_str(), g6(h.sigma_s).c_str(), g6(h.sigma_t()).c_str(),
                  g6(h.albedo()).c_str(), h.sigma_t() > 0 ? g6(1 / h.sigma_t()).c_str() : "inf");
      std::printf("    g %s, eta %s\n", g6(h.g).c_str(), g6(h.eta).c_str());
    } else {
      std::printf("    g %s\n", g6(m.medium.g).c_str());
      print_vdb(m.vdb, volumes[i]);
    }
    std::printf("    distance sampling: %s\n", sampling(m).c_str());
    std::printf("    connection sampling: %s, directions: %s\n",
                connection_sampling_name(m.connection),
                m.direction == DirectionSampling::Angular ? "angular" : "phase");
  }
  return 0;
}

}  // namespace

FEMTO_COMMAND("info", "validate a scene and its volumes, and print a summary", cmd_info);

}  // namespace femto
