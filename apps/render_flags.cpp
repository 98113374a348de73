#include "apps/render_flags.h"

#include <algorithm>
#include <sstream>
#include <stdexcept>
#include <string>

#include "core/error.h"
#include "core/integrators/camera_ball.h"

namespace femto {

const char* RenderOverrides::camera_only_flag() const {
  return spp                    ? "--spp"
         : max_depth            ? "--max-depth"
         : roulette             ? "--russian-roulette"
         : sampling             ? "--distance-sampling"
         : connection           ? "--connection-sampling"
         : direction            ? "--direction-sampling"
         : reconstruction       ? "--reconstruction"
         : !kernel_flag.empty() ? kernel_flag.c_str()
         : integrator           ? "--integrator"
         : light_paths          ? "--light-paths"
         : photon_radius        ? "--photon-radius"
         : photon_bandwidth     ? "--photon-bandwidth"
         : photon_aim           ? "--photon-aim"
                                : nullptr;
}

namespace {
// --russian-roulette on | off | DEPTH,THRESHOLD
RouletteDesc parse_roulette(cli::Args& args) {
  const std::string v = args.value();
  if (v == "on") return RouletteDesc{};
  if (v == "off") return RouletteDesc{0, 1.0};
  const size_t comma = v.find(',');
  const char* expected =
      "expected on, off or DEPTH,THRESHOLD (an integer >= 1, a number in (0, 1])";
  if (comma == std::string::npos) args.fail(expected, v);
  RouletteDesc r;
  try {
    size_t used = 0;
    const std::string d = v.substr(0, comma), t = v.substr(comma + 1);
    const long depth = std::stol(d, &used);
    if (used != d.size() || depth < 1 || depth > 1000000) args.fail(expected, v);
    const double threshold = std::stod(t, &used);
    if (used != t.size() || !(threshold > 0 && threshold <= 1)) args.fail(expected, v);
    r.depth = static_cast<int>(depth);
    r.threshold = threshold;
  } catch (const std::logic_error&) {  // stol / stod: no number, or out of range
    args.fail(expected, v);
  }
  return r;
}
}  // namespace

bool parse_render_flag(cli::Args& args, const std::string& a, RenderOverrides& o) {
  if (a == "--spp") {
    o.spp = static_cast<int>(args.int_value(1, 10000000));
  } else if (a == "--seed") {
    o.seed = args.uint_value();
  } else if (a == "--threads") {
    o.threads = static_cast<int>(args.int_value(0, 4096));
  } else if (a == "--distance-sampling") {
    const std::string v = args.value();
    if (v == "mfp")
      o.sampling = DistanceSampling::Mfp;
    else if (v == "time_uniform")
      o.sampling = DistanceSampling::TimeUniform;
    else if (v == "mis")
      o.sampling = DistanceSampling::Mis;
    else if (v == "mixture")
      o.sampling = DistanceSampling::Mixture;
    else
      args.fail("expected mfp, time_uniform, mis or mixture", v);
  } else if (a == "--connection-sampling") {
    const std::string v = args.value();
    if (v == "collision")
      o.connection = ConnectionSampling::Collision;
    else if (v == "equiangular")
      o.connection = ConnectionSampling::Equiangular;
    else if (v == "line_to_point")
      o.connection = ConnectionSampling::LineToPoint;
    else if (v == "mis")
      o.connection = ConnectionSampling::Mis;
    else if (v == "auto")
      o.connection = ConnectionSampling::Auto;
    else
      args.fail("expected collision, equiangular, line_to_point, mis or auto", v);
  } else if (a == "--direction-sampling") {
    const std::string v = args.value();
    if (v == "phase")
      o.direction = DirectionSampling::Phase;
    else if (v == "angular")
      o.direction = DirectionSampling::Angular;
    else
      args.fail("expected phase or angular", v);
  } else if (a == "--reconstruction") {
    const std::string v = args.value();
    if (v == "histogram")
      o.reconstruction = TemporalFilter::Kind::Histogram;
    else if (v == "kernel")
      o.reconstruction = TemporalFilter::Kind::Kernel;
    else
      args.fail("expected histogram or o.kernel", v);
  } else if (a == "--kernel") {
    const std::string v = args.value();
    if (v == "perlin")
      o.kernel = TemporalKernel::Perlin;
    else if (v == "epanechnikov")
      o.kernel = TemporalKernel::Epanechnikov;
    else
      args.fail("expected perlin or epanechnikov", v);
    if (o.kernel_flag.empty()) o.kernel_flag = a;
  } else if (a == "--alpha") {
    o.alpha = args.number_in(0.0, 1.0, true, false, "in (0, 1]");
    if (o.kernel_flag.empty()) o.kernel_flag = a;
  } else if (a == "--knn") {
    o.knn = static_cast<int>(args.int_value(1, 100000));
    if (o.kernel_flag.empty()) o.kernel_flag = a;
  } else if (a == "--first-pass-spp") {
    o.first_pass_spp = static_cast<int>(args.int_value(1, 1000000));
    if (o.kernel_flag.empty()) o.kernel_flag = a;
  } else if (a == "--bandwidth") {
    o.bandwidth = args.number_in(0.0, 1e12, true, false, "in (0, 1e12] ps");
    if (o.kernel_flag.empty()) o.kernel_flag = a;
  } else if (a == "--no-onset-reflection") {
    o.no_onset_reflection = true;
    if (o.kernel_flag.empty()) o.kernel_flag = a;
  } else if (a == "--integrator") {
    const std::string v = args.value();
    if (v == "auto")
      o.integrator = IntegratorKind::Auto;
    else if (v == "path")
      o.integrator = IntegratorKind::Path;
    else if (v == "light")
      o.integrator = IntegratorKind::Light;
    else if (v == "photons")
      o.integrator = IntegratorKind::Photons;
    else if (v == "beams")
      o.integrator = IntegratorKind::Beams;
    else if (v == "hybrid")
      o.integrator = IntegratorKind::Hybrid;
    else
      args.fail("expected auto, path, light, photons, beams or hybrid", v);
  } else if (a == "--light-paths") {
    o.light_paths = static_cast<int64_t>(args.count_value(1, 1e12));  // 4e7 as well as 40000000
  } else if (a == "--camera-ball") {
    o.camera_ball = args.number_in(0.0, 1e6, false, false, "in [0, 1e6] mm");
  } else if (a == "--photons") {
    o.photons_per_pass = static_cast<int64_t>(args.count_value(1, 1e9));
    if (o.photon_flag.empty()) o.photon_flag = a;
  } else if (a == "--photon-radius") {
    o.photon_radius = args.number_in(0.0, 1e9, true, false, "in (0, 1e9] mm");
    if (o.photon_flag.empty()) o.photon_flag = a;
  } else if (a == "--photon-bandwidth") {
    o.photon_bandwidth = args.number_in(0.0, 1e12, true, false, "in (0, 1e12] ps");
    if (o.photon_flag.empty()) o.photon_flag = a;
  } else if (a == "--photon-aim") {
    const std::string v = args.value();
    if (v != "on" && v != "off") args.fail("expected on or off", v);
    o.photon_aim = v == "on";
    if (o.photon_flag.empty()) o.photon_flag = a;
  } else if (a == "--max-depth") {
    o.max_depth = static_cast<int>(args.int_value(1, 1000000));
  } else if (a == "--russian-roulette") {
    o.roulette = parse_roulette(args);
  } else {
    return false;
  }
  return true;
}

RenderSetup apply_render_overrides(SceneDesc& desc, const RenderOverrides& o,
                                   const std::string& command, const std::string& where) {
  for (MediumDesc& m : desc.media) {
    if (o.sampling) m.sampling = *o.sampling;
    if (o.connection) m.connection = *o.connection;
    if (o.direction) m.direction = *o.direction;
  }
  ReconstructionDesc& rec = desc.reconstruction;
  if (o.reconstruction) rec.type = *o.reconstruction;
  if (!o.kernel_flag.empty() && rec.type != TemporalFilter::Kind::Kernel)
    throw InputError(command + ": " + o.kernel_flag +
                     ": applies to the kernel film only; add --reconstruction kernel (or set "
                     "/time/reconstruction in the scene)");
  if (o.kernel) rec.kernel = *o.kernel;
  if (o.alpha) rec.alpha = *o.alpha;
  if (o.knn) rec.knn = *o.knn;
  if (o.first_pass_spp) rec.first_pass_spp = *o.first_pass_spp;
  if (o.bandwidth) rec.bandwidth_ps = *o.bandwidth;
  if (o.no_onset_reflection) rec.onset_reflection = false;
  if (o.integrator) desc.integrator.kind = *o.integrator;
  if (o.light_paths) desc.integrator.light_paths = *o.light_paths;
  if (o.camera_ball) desc.integrator.camera_ball_mm = *o.camera_ball;
  PhotonDesc& pd = desc.integrator.photons;
  if (o.photons_per_pass) pd.per_pass = *o.photons_per_pass;
  if (o.photon_radius) pd.radius = *o.photon_radius;
  if (o.photon_bandwidth) pd.bandwidth_ps = *o.photon_bandwidth;
  if (o.photon_aim) pd.aim = *o.photon_aim;
  std::string integrator_why;
  const IntegratorKind kind = resolve_integrator(desc, desc.integrator.kind, integrator_why);
  if (kind != IntegratorKind::Path && rec.type == TemporalFilter::Kind::Kernel)
    throw InputError(
        where + ": integrator \"" + integrator_name(kind) +
        "\": the kernel film (/time/reconstruction kernel) works with camera paths only; use "
        "--integrator path or the histogram film");
  if (!o.photon_flag.empty() && kind != IntegratorKind::Photons && kind != IntegratorKind::Beams &&
      kind != IntegratorKind::Hybrid)
    throw InputError(command + ": " + o.photon_flag +
                     ": applies to photon mapping and photon beams only, but the integrator is \"" +
                     integrator_name(kind) + "\"; add --integrator photons or beams");
  const bool scattering = has_scattering_medium(desc);
  if (kind == IntegratorKind::Beams && !scattering)
    throw InputError(
        where +
        ": integrator \"beams\": the scene has no scattering medium, so there are no beams "
        "to gather; use --integrator path, light or photons");
  if (o.light_paths && kind != IntegratorKind::Light && kind != IntegratorKind::Hybrid)
    throw InputError(
        command +
        ": --light-paths: applies to --integrator light and hybrid only, but the integrator is \"" +
        integrator_name(kind) + "\"");
  if (o.camera_ball && kind != IntegratorKind::Hybrid)
    throw InputError(command +
                     ": --camera-ball: applies to --integrator hybrid only, but the "
                     "integrator is \"" +
                     integrator_name(kind) + "\"");
  // Without a scattering medium there is no ball (core/integrators/camera_ball.h).
  if (kind == IntegratorKind::Hybrid && scattering && desc.integrator.camera_ball_mm > 0) {
    // The ball must hold no surface: camera paths gather only the camera's medium inside it.
    const double nearest = nearest_surface_distance(desc, desc.camera.position);
    if (!(desc.integrator.camera_ball_mm < nearest)) {
      std::ostringstream msg;
      msg << (o.camera_ball ? command + ": --camera-ball " : where + ": /render/camera_ball ")
          << desc.integrator.camera_ball_mm
          << ": the ball around the camera would reach a surface (the nearest is " << nearest
          << " mm from the camera); use a smaller radius, or 0 for none";
      throw InputError(msg.str());
    }
  }
  RenderOptions opt;
  opt.integrator = kind;
  opt.light_paths = desc.integrator.light_paths;
  opt.camera_ball_mm = desc.integrator.camera_ball_mm;
  opt.photons = pd;
  opt.spp = o.spp.value_or(desc.integrator.spp);
  opt.seed = o.seed.value_or(desc.integrator.seed);
  opt.max_depth = o.max_depth.value_or(desc.integrator.max_depth);
  opt.roulette = o.roulette.value_or(desc.integrator.roulette);
  opt.threads = o.threads;
  return {kind, integrator_why, opt};
}

}  // namespace femto
