// `femto render`: loads a scene (or the built-in one), renders it and writes the outputs.
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <optional>
#include <thread>
#include <nlohmann/json.hpp>

#include "apps/cli.h"
#include "apps/commands.h"
#include "apps/stop_signals.h"
#include "core/checkpoint.h"
#include "core/distributed/comm.h"
#include "core/io/sha256.h"
#include "core/mitsuba/mitsuba_xml.h"
#include "core/memory_usage.h"
#include "core/output_folder.h"
#include "apps/render_flags.h"
#include "apps/render_record.h"
#include "apps/tissue_run.h"
#include "core/tissue/scene.h"
#include "core/default_scene.h"
#include "core/error.h"
#include "core/outputs.h"
#include "core/progress.h"
#include "core/render.h"
#include "core/scene_loader.h"
#include "femto_version.h"

namespace femto {

namespace {
const char* kRenderHelp =
    "Usage: femto render [SCENE.json] [options]\n"
    "\n"
    "Renders a time-resolved image (H x W x T) of SCENE.json, or of the built-in default scene\n"
    "(a pulsed spot light in fog behind a glass sphere) when no scene is given. A .xml scene is\n"
    "read as Mitsuba 3 / mitransient XML (a subset, docs/mitsuba.md).\n"
    "\n"
    "Options (override the scene's \"render\" block):\n"
    "  --spp N            samples (camera paths) per pixel, 1..10^7 (scene default: 16)\n"
    "  --seed S           random seed, integer >= 0; the same seed gives bit-identical output\n"
    "                     for any thread count (scene default: 1)\n"
    "  --threads N        worker threads, 0 = all cores (default 0)\n"
    "  --distance-sampling S  collision-distance sampling in every medium, overriding the\n"
    "                     scene: mfp (mean free path), time_uniform (exponential in optical\n"
    "                     path length, uniform vertex times), mis (both, combined by MIS)\n"
    "                     or mixture (one of the two per segment, time-uniform more often\n"
    "                     when the remaining window spans many mean free paths; the path\n"
    "                     continues from it); scene default mfp\n"
    "  --connection-sampling C  direct light from point and spot lights along each ray\n"
    "                     segment in every medium: collision (next-event estimation at the\n"
    "                     collisions), equiangular, line_to_point (uniform in connection time),\n"
    "                     mis (line_to_point + equiangular) or auto (the scene default:\n"
    "                     collision, plus equiangular on segments that pass close to a\n"
    "                     light and for spot lights, and line_to_point by MIS with the\n"
    "                     collisions on camera segments that span 3-16 mean free paths\n"
    "                     with the light behind and on optically thin segments of a medium\n"
    "                     thinner than a mean free path lit from outside;\n"
    "                     docs/scene-format.md)\n"
    "  --direction-sampling D   next direction at medium collisions: phase, or angular\n"
    "                     (half phase, half angular sampling uniform in connection time)\n"
    "  --reconstruction R how path contributions become time bins: histogram (one bin per\n"
    "                     contribution) or kernel (progressive kernel density estimation:\n"
    "                     smooth, consistent frames; docs/outputs.md)\n"
    "  --kernel K         kernel film: perlin (default) or epanechnikov\n"
    "  --alpha A          kernel film: bandwidth shrinking, T_{j+1} = T_j (j + A) / (j + 1),\n"
    "                     0 < A <= 1 (default 0.8; 1 keeps the bandwidth fixed: biased)\n"
    "  --knn K            kernel film: k of the k-nearest-arrival initial bandwidth (default 40)\n"
    "  --first-pass-spp N kernel film: samples whose arrival times set the bandwidth (default\n"
    "                     160; all samples when spp is lower)\n"
    "  --bandwidth PS     kernel film: initial bandwidth T_1 in ps instead of the k-NN choice\n"
    "  --no-onset-reflection  kernel film: let kernels spill before the pixel's earliest\n"
    "                     first-pass arrival instead of reflecting them there\n"
    "  --integrator I     auto (default), path (camera paths only), light (light paths\n"
    "                     splatted to the camera), photons (camera paths + transient\n"
    "                     progressive photon mapping of caustics on surfaces), beams (camera\n"
    "                     paths + transient progressive photon beams for all light scattered\n"
    "                     in media) or hybrid (camera paths + surface photons + beams for\n"
    "                     caustics inside media + light paths for the caustic on the surface\n"
    "                     the camera sees and the light that reaches the fog the camera sees\n"
    "                     after scattering). auto: with point, spot or laser lights and\n"
    "                     non-diffuse surfaces, beams when a scattering medium lies behind\n"
    "                     specular surfaces only, else hybrid (with or without a medium);\n"
    "                     else path (femto info prints the choice and why)\n"
    "  --light-paths N    light tracing: light paths in all, e.g. 4e7 (default spp x pixels);\n"
    "                     hybrid: its light-traced share in all, spread over the spp passes\n"
    "                     (default one path per four pixels per pass)\n"
    "  --camera-ball MM   hybrid, camera in a scattering medium: radius of the ball around the\n"
    "                     pinhole whose medium light camera paths gather instead of light\n"
    "                     tracing (default 1% of the scene's diagonal, at most half the way to\n"
    "                     the nearest surface; 0: none)\n"
    "  --photons N        photons (or beam light paths) per pass (default 200000 photons;\n"
    "                     beam paths: half the pixels, 1000 to 20000; hybrid: one photon per\n"
    "                     two pixels, 10000 to 200000, and caustic beam paths one per 128\n"
    "                     pixels, 500 to 20000; its light-traced share: --light-paths);\n"
    "                     passes = spp\n"
    "  --photon-radius MM photons and beams: initial gather radius R_1 (default 0.5% of the\n"
    "                     bounding-box diagonal of the scene for photons, 1% for beams, one\n"
    "                     pixel's width at the look_at distance for the hybrid's caustic beams)\n"
    "  --photon-bandwidth PS  photons and beams: initial temporal bandwidth T_1 (default 1 bin)\n"
    "  --photon-aim on|off  photons and the hybrid's caustic beams: point and spot lights emit\n"
    "                     only towards mirrors, glass and rough surfaces (default on; unbiased);\n"
    "                     default --photons counts then shrink by the aimed share of emission\n"
    "  --max-depth N      scattering/bounce vertices per path: 1 = single scattering, 2 = up\n"
    "                     to double, ...; left at its default (1000) it is a safety bound and\n"
    "                     paths reaching it are reported as a warning (counted in render.json)\n"
    "  --russian-roulette on|off|D,T  camera paths: from vertex D on, a path whose\n"
    "                     throughput is below T goes on with probability throughput / T\n"
    "                     (unbiased; on = 3,0.2, the default)\n"
    "  --out DIR          output folder, created if missing (default ./femto-out)\n"
    "  --frames MODE      per-bin EXR frames: files (frames/*.exr, default), multipart\n"
    "                     (one transient.exr with a part per bin) or none\n"
    "  --no-previews      skip the PNG previews (steady.png, frames.png, peak_time.png)\n"
    "  --video            also write transient.mp4: H.264, one frame per time bin, each\n"
    "                     stamped with its start time (FFmpeg libraries, or the ffmpeg program)\n"
    "  --video-fps N      frames (time bins) per second of the video, 1..240 (default 24)\n"
    "  --video-encoder E  FFmpeg H.264 encoder (default libx264, else any H.264 encoder)\n"
    "  --tonemap M        how frames.png and transient.mp4 show the frames: global (one\n"
    "                     automatic exposure for all frames, the default), per-frame (each\n"
    "                     frame exposed on its own; the radiance shown as white is stamped\n"
    "                     on it and listed in render.json) or log (log10 of luminance over\n"
    "                     --log-decades below white: late, dim frames stay visible)\n"
    "  --exposure EV      brighten (or darken, EV < 0) the automatic exposure by 2^EV\n"
    "  --log-decades D    --tonemap log: decades from white to black, 0.5..12, or auto (the\n"
    "                     default: down to the dimmest frame's own exposure, plus one decade)\n"
    "  --max-memory SIZE  refuse to render when it needs more than SIZE (e.g. 2G): film,\n"
    "                     sums, buffers and volumes; default 75% of physical memory\n"
    "  --checkpoint       write DIR/checkpoint.bin (DIR = --out) every 60 s, atomically, and\n"
    "                     into the partial output when stopped, for --resume\n"
    "  --checkpoint-every S  seconds between checkpoints (0: after every pass); implies\n"
    "                     --checkpoint\n"
    "  --resume DIR       continue the render checkpointed in DIR (same scene and options,\n"
    "                     any --threads): the result has the same bits as an uninterrupted\n"
    "                     run; writes to DIR unless --out is given; keeps checkpointing\n"
    "  --quiet            no progress or summary on stderr\n"
    "  -D NAME=VALUE      Mitsuba XML scenes: the value of $NAME, over the file's <default>\n"
    "                     (repeatable; also --define NAME=VALUE; e.g. -D spp=64)\n"
    "  --help             this help\n"
    "\n"
    "Ctrl-C or SIGTERM: the current pass is finished and a complete result for the samples\n"
    "done is written (render.json: \"complete\": false), exit code 130 or 143; a second\n"
    "signal aborts at once and leaves the output folder as it was.\n"
    "\n"
    "mpirun -np N femto render ...: N ranks share the work; rank 0 writes outputs bit-identical\n"
    "to one process's (no --checkpoint/--resume; a signal aborts the job; docs/mpi.md).\n"
    "\n"
    "Outputs (see docs/outputs.md): steady.exr, frames/*.exr, peak_time.exr, transient.npy\n"
    "(float32, shape (H, W, T, 3)), before_window.exr, after_window.exr, steady.png,\n"
    "frames.png, peak_time.png (with a colour bar in ps), transient.mp4 (--video) and\n"
    "render.json (settings, time axis in ps and OPL mm, timings, counters).\n";

}  // namespace

namespace {
int cmd_render(const std::vector<std::string>& argv, const std::string& command_line) {
  // Before any thread exists: SIGINT/SIGTERM go to one waiting thread (apps/stop_signals.h).
  // Until the render starts, a signal aborts at once (nothing has been written yet).
  stop_signals::start();
  cli::Args args("femto render", argv);
  std::string scene_path;
  XmlDefines xml_defines;  // -D NAME=VALUE for Mitsuba XML scenes
  RenderOverrides overrides;
  OutputOptions out;
  bool out_given = false;
  bool checkpoint = false;
  double checkpoint_every = 60;
  std::string resume_dir;
  bool quiet = false;
  std::string video_flag, tonemap_flag, log_flag;  // the first of each given, for error messages
  uint64_t max_memory = cli::physical_memory_bytes() / 4 * 3;
  while (!args.done()) {
    const std::string a = args.next();
    if (a == "--help" || a == "-h") {
      std::fputs(kRenderHelp, stdout);
      return 0;
    } else if (parse_render_flag(args, a, overrides)) {
      // --spp, --seed, --threads and the sampling, film and integrator options
    } else if (a == "--out") {
      out.dir = args.value();
      if (out.dir.empty()) args.fail("expects a folder", "");
      out_given = true;
    } else if (a == "--checkpoint") {
      checkpoint = true;
    } else if (a == "--checkpoint-every") {
      checkpoint_every = args.number_in(0.0, 1e9, false, false, "in [0, 1e9] s");
      checkpoint = true;
    } else if (a == "--resume") {
      resume_dir = args.value();
      if (resume_dir.empty()) args.fail("expects the folder of the render to continue", "");
    } else if (a == "--frames") {
      const std::string v = args.value();
      if (v == "files") out.frames = OutputOptions::Frames::Files;
      else if (v == "multipart") out.frames = OutputOptions::Frames::Multipart;
      else if (v == "none") out.frames = OutputOptions::Frames::None;
      else args.fail("expected files, multipart or none", v);
    } else if (a == "--no-previews") {
      out.previews = false;
    } else if (a == "--video") {
      out.video = true;
    } else if (a == "--video-fps") {
      out.video_spec.fps = static_cast<int>(args.int_value(1, 240));
      if (video_flag.empty()) video_flag = a;
    } else if (a == "--video-encoder") {
      out.video_spec.encoder = args.value();
      if (out.video_spec.encoder.empty()) args.fail("expects an FFmpeg encoder name, e.g. libx264", "");
      if (video_flag.empty()) video_flag = a;
    } else if (a == "--tonemap") {
      const std::string v = args.value();
      if (!parse_tone_map(v, out.tonemap.mode)) args.fail("expected global, per-frame or log", v);
      if (tonemap_flag.empty()) tonemap_flag = a;
    } else if (a == "--exposure") {
      out.tonemap.exposure_stops = args.number_in(-30.0, 30.0, false, false, "in [-30, 30] stops");
      if (tonemap_flag.empty()) tonemap_flag = a;
    } else if (a == "--log-decades") {
      const std::string v = args.value();
      char* end = nullptr;
      const double d = std::strtod(v.c_str(), &end);
      if (v == "auto") out.tonemap.log_decades = 0;
      else if (v.empty() || *end != '\0' || !(d >= 0.5 && d <= 12)) args.fail("expected 0.5..12 or auto", v);
      else out.tonemap.log_decades = d;
      log_flag = a;
      if (tonemap_flag.empty()) tonemap_flag = a;
    } else if (a == "--max-memory") {
      max_memory = args.size_value();
    } else if (a == "--quiet" || a == "-q") {
      quiet = true;
    } else if (a == "-D" || a == "--define") {
      const std::string d = args.value();
      if (!add_xml_define(d, xml_defines)) args.fail("expects NAME=VALUE", d);
    } else if (!a.empty() && a[0] == '-') {
      args.fail("unknown option (see femto render --help)", a);
    } else if (scene_path.empty()) {
      scene_path = a;
    } else {
      args.fail("only one scene file may be given", a);
    }
  }

  if (!xml_defines.empty() && !is_mitsuba_xml_path(scene_path))
    throw InputError("femto render: -D " + clip(xml_defines.begin()->first) +
                     ": applies to Mitsuba XML scenes (.xml) only");
  // Picture options that would silently do nothing are errors.
  if (!video_flag.empty() && !out.video)
    throw InputError("femto render: " + video_flag + ": applies to the video only; add --video");
  if (!log_flag.empty() && out.tonemap.mode != ToneMapMode::Log)
    throw InputError("femto render: " + log_flag + ": applies to --tonemap log only");
  if (!tonemap_flag.empty() && !out.previews && !out.video)
    throw InputError("femto render: " + tonemap_flag +
                     ": tone mapping applies to frames.png and transient.mp4, but --no-previews is given "
                     "without --video");

  // Under mpirun (docs/mpi.md) every rank loads and checks the same input; rank 0 reports and
  // writes. Stopping early and checkpoints are for a single process.
  const distributed::Comm& comm = distributed::world();
  if (!comm.single() && (checkpoint || !resume_dir.empty()))
    throw InputError(std::string("femto render: ") + (checkpoint ? "--checkpoint" : "--resume") +
                     ": not available under mpirun (" + std::to_string(comm.size()) +
                     " ranks); run a single process to checkpoint or resume");
  if (!comm.root()) quiet = true;

  // Load and validate everything before anything is written.
  std::string scene_text;
  SceneDesc desc;
  if (scene_path.empty()) {
    scene_text = default_scene_json();
    desc = load_scene_string(scene_text, "<default scene>", ".");
  } else {
    scene_text = read_scene_text(scene_path);  // read once, size-limited
    if (tissue::is_tissue_scene(scene_text)) {  // tissue optics (docs/tissue.md)
      const char* camera_only = overrides.camera_only_flag() ? overrides.camera_only_flag()
                              : checkpoint ? "--checkpoint" : !resume_dir.empty() ? "--resume"
                              : !out.previews ? "--no-previews" : out.video ? "--video"
                              : !video_flag.empty() ? video_flag.c_str()
                              : !tonemap_flag.empty() ? tonemap_flag.c_str() : nullptr;
      if (camera_only)
        throw InputError(std::string("femto render: ") + camera_only + ": does not apply to the tissue scene " +
                         clip(scene_path, 200) + " (its options: --photons, --seed, --threads, --out, "
                         "--max-memory, --quiet)");
      TissueRunOptions t;
      if (overrides.photons_per_pass) t.photons = static_cast<uint64_t>(*overrides.photons_per_pass);
      t.seed = overrides.seed;
      t.threads = overrides.threads;
      if (out_given) t.out = out.dir;
      t.quiet = quiet;
      t.max_memory = max_memory;
      return run_tissue_scene(scene_text, scene_path, t, command_line);
    }
    const std::string base_dir = std::filesystem::path(scene_path).parent_path().string();
    if (is_mitsuba_xml_path(scene_path)) {
      MitsubaImport xml = load_mitsuba_xml(scene_text, scene_path, base_dir, xml_defines);
      scene_text = std::move(xml.femto_json);  // render.json records the translated scene
      desc = std::move(xml.desc);
    } else {
      desc = load_scene_string(scene_text, scene_path, base_dir);
    }
  }
  for (const std::string& w : desc.warnings) std::fprintf(stderr, "femto: warning: %s\n", w.c_str());
  const std::string where = scene_path.empty() ? "femto render" : scene_path;
  RenderSetup setup = apply_render_overrides(desc, overrides, args.command(), where);
  const IntegratorKind kind = setup.kind;
  RenderOptions& opt = setup.options;
  const ReconstructionDesc& rec = desc.reconstruction;
  opt.quiet = quiet;
  const CameraDesc& cam = desc.camera;
  const TimeAxis axis = desc.time;
  const bool kernel_film = rec.type == TemporalFilter::Kind::Kernel;
  const uint64_t film_bytes = TransientFilm::memory_bytes(cam.width, cam.height, axis.bins);
  if (film_bytes > max_memory)
    throw InputError("film needs " + cli::format_bytes(film_bytes) + " (" + std::to_string(cam.width) +
                     " x " + std::to_string(cam.height) + " pixels x " + std::to_string(axis.bins) +
                     " bins x RGB float32), more than --max-memory " + cli::format_bytes(max_memory) +
                     ": lower the resolution or the number of bins, or raise --max-memory");
  // Everything the render allocates beside the scene: the film, the per-pixel double sums kept
  // between passes, per-thread buffers, a photon pass or a light-splat batch, and the buffers of
  // writing the outputs (core/render.h, render_memory).
  const int hardware_threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  const int threads_used = opt.threads > 0 ? std::min(opt.threads, hardware_threads) : hardware_threads;
  const RenderMemory mem = render_memory(
      cam.width, cam.height, axis.bins, opt, threads_used, kernel_film, rec.first_pass_spp,
      out.frames == OutputOptions::Frames::Multipart, has_scattering_medium(desc));
  const uint64_t render_bytes = mem.peak();
  if (render_bytes > max_memory)
    throw InputError("render needs " + cli::format_bytes(render_bytes) + " (film " + cli::format_bytes(mem.film) +
                     ", double-precision sums " + cli::format_bytes(mem.sums) + ", integrator buffers " +
                     cli::format_bytes(mem.integrator + mem.per_thread) + "), more than --max-memory " +
                     cli::format_bytes(max_memory) +
                     ": lower the resolution, the number of bins or photons per pass, or raise --max-memory");
  // Volumes share --max-memory with the render; the renderer keeps a second copy of their grids.
  const uint64_t left_for_volumes = max_memory > render_bytes ? max_memory - render_bytes : 0;
  for (MediumDesc& m : desc.media) {
    m.vdb.max_dense_bytes = left_for_volumes / 2;
    m.vdb.max_sparse_bytes = left_for_volumes;  // sparse grids are shared, not copied
  }

  // Checkpoint and resume: the fingerprint holds everything that decides the bits.
  const nlohmann::json fingerprint = render_fingerprint(scene_text, desc, kind, opt);
  if (!resume_dir.empty() && !out_given) out.dir = resume_dir;
  if (!resume_dir.empty()) checkpoint = true;  // a resumed render stays resumable
  std::optional<Checkpoint> resumed;
  if (!resume_dir.empty()) {
    const std::string path = resume_dir + "/checkpoint.bin";
    std::error_code ec;
    if (!std::filesystem::exists(path, ec))
      throw InputError("--resume " + clip(resume_dir, 200) +
                       ": no checkpoint.bin there (the render finished, or ran without --checkpoint)");
    resumed = read_checkpoint(path);
    const std::string diff = fingerprint_difference(resumed->fingerprint, fingerprint);
    if (!diff.empty())
      throw InputError("--resume " + clip(resume_dir, 200) +
                       ": the checkpoint was made with different settings (" + diff +
                       "); resume with the same scene file and options");
  }
  // A missing H.264 encoder is found before rendering, not after.
  if (out.video) out.video_spec.encoder = check_h264_encoder(out.video_spec.encoder, out.video_backend);
  if (out.video && (cam.width > 16384 || cam.height > 16384))
    throw InputError("--video: the film is " + std::to_string(cam.width) + " x " + std::to_string(cam.height) +
                     " pixels; the video is limited to 16384 on each side (render without --video)");
  // The output folder is checked before the (possibly long) scene build: a foreign or
  // unwritable --out is bad input.
  {
    std::error_code ec;
    if (std::filesystem::exists(out.dir, ec)) {
      if (!std::filesystem::is_directory(out.dir, ec))
        throw InputError("--out " + clip(out.dir, 200) + ": exists and is not a folder");
      bool is_femto = false;
      const std::string foreign = foreign_entry(out.dir, is_femto);
      if (!foreign.empty())
        throw InputError("--out " + clip(out.dir, 200) + ": the folder holds '" + clip(foreign) +
                         "', which is not part of a femto render " +
                         (is_femto ? "there" : "(no render.json written by femto)") +
                         "; femto replaces the whole folder, so give an empty or new folder, or move the file away");
    }
  }
  if (!quiet)
    std::fprintf(stderr, "femto: %s: %d x %d pixels, %d bins of %.4g ps from %.4g ps, %d spp; film memory %s\n",
                 desc.source.c_str(), cam.width, cam.height, axis.bins, axis.bin_width_ps, axis.t_start_ps,
                 opt.spp, cli::format_bytes(film_bytes).c_str());

  const Scene scene(std::move(desc));
  // The estimate of the peak: what is resident now (program, scene, volumes; or the highest so
  // far, if loading peaked higher) plus what the render will allocate.
  const uint64_t baseline_rss = current_rss_bytes();
  const uint64_t estimate = std::max(peak_rss_bytes(), baseline_rss + render_bytes);
  if (estimate > max_memory && baseline_rss > 0)
    throw InputError("render needs about " + cli::format_bytes(estimate) + " (scene and program " +
                     cli::format_bytes(baseline_rss) + ", render " + cli::format_bytes(render_bytes) +
                     "), more than --max-memory " + cli::format_bytes(max_memory) +
                     ": lower the resolution, the number of bins or the volumes' size, or raise --max-memory");

  if (!comm.single()) {  // each rank renders its share; rank 0 receives the rest and writes
    opt.comm = &comm;
    if (!comm.root()) {
      render(scene, opt);
      return 0;
    }
  }
  // Outputs go to a staging folder beside --out, swapped in at the end (core/output_folder.h).
  OutputFolder folder(out.dir, checkpoint);
  stop_signals::on_abort([&folder] { folder.discard(); });
  struct AbortReset {
    ~AbortReset() { stop_signals::on_abort(nullptr); }
  } abort_reset;
  OutputOptions staged = out;
  staged.dir = folder.staging();
  staged.threads = opt.threads;

  if (comm.single()) opt.stop = &stop_signals::requested();  // across ranks a signal aborts
  if (resumed) opt.resume = &resumed->state;
  const auto start_time = std::chrono::steady_clock::now();
  auto last_checkpoint = start_time;
  bool wrote_final_checkpoint = false;
  opt.after_pass = [&](const RenderState& state, bool last) {
    const auto now = std::chrono::steady_clock::now();
    const bool stopping = last && state.units_done < state.units_total;
    if (!checkpoint) return;
    if (stopping) {  // into the partial output, beside the result it continues
      std::lock_guard<std::mutex> lock(folder.mutex());
      write_checkpoint(folder.staging() + "/checkpoint.bin", fingerprint, state);
      wrote_final_checkpoint = true;
    } else if (!last && std::chrono::duration<double>(now - last_checkpoint).count() >= checkpoint_every) {
      std::lock_guard<std::mutex> lock(folder.mutex());
      write_checkpoint(folder.checkpoint_path(), fingerprint, state);
      last_checkpoint = std::chrono::steady_clock::now();
    }
  };
  if (comm.single())
    stop_signals::defer(quiet ? "" : "finishing the current pass, then writing the results (again to abort)");
  RenderResult result = render(scene, opt);
  const PathStats& st = result.stats;
  const uint64_t film_nonfinite = result.film.zero_nonfinite();  // outputs stay finite
  const std::string depth_source = max_depth_source(overrides.max_depth.has_value(), scene.desc().integrator);

  const int stop_signal = stop_signals::signal_number();
  nlohmann::json info =
      render_info(scene, scene_text, setup, overrides.max_depth.has_value(), result, film_nonfinite,
                  result.complete ? nullptr : stop_signal == SIGTERM ? "SIGTERM" : "SIGINT");
  info["command"] = command_line;
  info["date_utc"] = cli::utc_now();
  info["checkpoint"] = {{"enabled", checkpoint},
                        {"every_seconds", checkpoint_every},
                        {"resumed_from", resume_dir.empty() ? nlohmann::json(nullptr) : nlohmann::json(resume_dir)},
                        {"file", wrote_final_checkpoint ? nlohmann::json("checkpoint.bin") : nlohmann::json(nullptr)}};
  info["memory"] = {{"estimate_bytes", estimate},
                    {"baseline_rss_bytes", baseline_rss},
                    {"render_bytes", render_bytes},
                    {"breakdown",
                     {{"film", mem.film},
                      {"sums", mem.sums},
                      {"per_thread", mem.per_thread},
                      {"integrator", mem.integrator},
                      {"outputs", mem.outputs}}},
                    {"max_memory_bytes", max_memory},
                    {"peak_rss_bytes", 0}};
  const std::vector<std::string> files = write_outputs(result.film, staged, info, result.final_bandwidth_ps);
  folder.commit();
  if (!quiet) {
    std::fprintf(stderr, "femto: %llu camera paths and %llu light paths (%s) in %s (%d threads)\n",
                 static_cast<unsigned long long>(st.paths), static_cast<unsigned long long>(st.light_paths),
                 integrator_name(kind), format_duration(result.wall_seconds).c_str(), result.threads);
    if (st.max_depth_hits > 0 && depth_source == "default")
      std::fprintf(stderr, "femto: warning: %llu paths reached the safety bound max_depth %d (counted in render.json)\n",
                   static_cast<unsigned long long>(st.max_depth_hits), opt.max_depth);
    else if (st.max_depth_hits > 0)
      std::fprintf(stderr, "femto: %llu paths ended at the chosen max_depth %d\n",
                   static_cast<unsigned long long>(st.max_depth_hits), opt.max_depth);
    if (st.nonfinite_dropped > 0)
      std::fprintf(stderr, "femto: warning: %llu non-finite contributions dropped\n",
                   static_cast<unsigned long long>(st.nonfinite_dropped));
    if (film_nonfinite > 0)
      std::fprintf(stderr, "femto: warning: %llu film values overflowed float32 and were set to 0\n",
                   static_cast<unsigned long long>(film_nonfinite));
    std::fprintf(stderr, "femto: results in %s/ (%s)\n", out.dir.c_str(), file_list(files).c_str());
    if (!result.complete)
      std::fprintf(stderr, "femto: stopped early: %lld of %lld %s done (render.json: \"complete\": false)%s\n",
                   static_cast<long long>(result.units_done), static_cast<long long>(result.units_total), result.unit,
                   wrote_final_checkpoint ? "; continue with --resume" : "");
  }
  if (!result.complete) return 128 + (stop_signal ? stop_signal : SIGINT);
  return 0;
}
}  // namespace

FEMTO_COMMAND("render", "render a scene (the built-in default scene without one)", cmd_render);

}  // namespace femto
