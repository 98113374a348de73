// The camera, the time axis with its film size bound, and the temporal reconstruction.
#include <cstdint>

#include "core/error.h"
#include "core/scene_json/loader.h"

namespace femto::scene_json {

void Loader::camera(const Json& v, CameraDesc& c) const {
  const std::string p = "/camera";
  const Json& o = object(v, p);
  std::string type = "perspective";
  if (const Json* t = find(o, "type"))
    type = choice(*t, at(p, "type"), {"perspective", "orthographic"});
  const bool persp = type == "perspective";
  const Keys common = {"type", "position", "look_at", "up", "resolution"};
  check_keys(o, p, join(common, {persp ? "fov" : "width"}),
             persp ? "a perspective camera" : "an orthographic camera", {"fov", "width"});
  c.type = persp ? CameraDesc::Type::Perspective : CameraDesc::Type::Orthographic;

  c.position = vec3(require(o, p, "position"), at(p, "position"));
  const Json& look = require(o, p, "look_at");
  c.look_at = vec3(look, at(p, "look_at"));
  if (!(length(c.look_at - c.position) > 0))
    fail(at(p, "look_at"), "must differ from 'position'", look);
  if (const Json* u = find(o, "up")) {
    c.up = nonzero_vec3(*u, at(p, "up"));
    const Vec3 view = normalize(c.look_at - c.position);
    if (length(cross(view, normalize(c.up))) < 1e-6)
      fail(at(p, "up"), "must not be parallel to the view direction " + fmt(view), *u);
  } else if (length(cross(normalize(c.look_at - c.position), c.up)) < 1e-6) {
    fail(at(p, "up"), "the default up [0, 1, 0] is parallel to the view direction; give 'up'");
  }
  c.up = normalize(c.up);

  if (persp) {
    if (const Json* f = find(o, "fov"))
      c.fov_deg = number(*f, at(p, "fov"), within(0, 180, true, true));
  } else {
    const Json& w = require(o, p, "width");
    c.ortho_width = not_tiny(number(w, at(p, "width"), above(0)), kMinLength, at(p, "width"), w);
  }

  const std::string rp = at(p, "resolution");
  const Json& r = require(o, p, "resolution");
  if (!r.is_array() || r.size() != 2)
    fail(rp, "expected an array of 2 integers [width, height]", r);
  c.width = int_in(r[0], at(rp, 0), 1, 16384);
  c.height = int_in(r[1], at(rp, 1), 1, 16384);
}

void Loader::time(const Json& v, SceneDesc& scene) const {
  const std::string p = "/time";
  const Json& o = object(v, p);
  check_keys(
      o, p,
      {"t_start", "bin_width", "bins", "start_opl", "bin_width_opl", "mode", "reconstruction"});
  const Json* bw = find(o, "bin_width");
  const Json* bw_opl = find(o, "bin_width_opl");
  if (bw && bw_opl)
    fail(at(p, "bin_width_opl"), "give either 'bin_width' (ps) or 'bin_width_opl' (mm), not both",
         *bw_opl);
  if (!bw && !bw_opl)
    fail(at(p, "bin_width"), "missing required key 'bin_width' (or 'bin_width_opl' in mm)");
  // One unit per axis: a ps start with an mm width (or the reverse) is almost surely a mistake.
  if (const Json* s = find(o, "start_opl"); s && bw)
    fail(at(p, "start_opl"), "cannot mix 'start_opl' (mm) with 'bin_width' (ps); use 't_start'",
         *s);
  if (const Json* s = find(o, "t_start"); s && bw_opl)
    fail(at(p, "t_start"), "cannot mix 't_start' (ps) with 'bin_width_opl' (mm); use 'start_opl'",
         *s);

  TimeAxis& axis = scene.time;
  if (bw) {
    axis.bin_width_ps =
        not_tiny(number(*bw, at(p, "bin_width"), above(0)), kMinBinWidth, at(p, "bin_width"), *bw);
    if (const Json* s = find(o, "t_start")) axis.t_start_ps = number(*s, at(p, "t_start"));
  } else {
    axis.bin_width_ps =
        TimeAxis::time_of_opl(not_tiny(number(*bw_opl, at(p, "bin_width_opl"), above(0)),
                                       kMinBinWidth, at(p, "bin_width_opl"), *bw_opl));
    if (const Json* s = find(o, "start_opl"))
      axis.t_start_ps = TimeAxis::time_of_opl(number(*s, at(p, "start_opl")));
    else
      axis.t_start_ps = 0.0;
  }
  const Json& bins = require(o, p, "bins");
  axis.bins = int_in(bins, at(p, "bins"), 1, 100000);
  if (axis.t_end_ps() > kMaxWindowEnd)
    fail(at(p, "bins"),
         "the window ends at " + fmt(axis.t_end_ps()) + " ps, beyond the bound of " +
             fmt(kMaxWindowEnd) + " ps (docs/scene-format.md, Bounds)",
         bins);

  const std::uint64_t bytes = std::uint64_t(scene.camera.width) *
                              std::uint64_t(scene.camera.height) * std::uint64_t(axis.bins) * 3u *
                              4u;
  if (bytes > kMaxFilmBytes)
    fail(at(p, "bins"),
         "a " + std::to_string(scene.camera.width) + " x " + std::to_string(scene.camera.height) +
             " x " + std::to_string(axis.bins) + " film needs " +
             fmt(double(bytes) / double(1ull << 30)) +
             " GiB (3 float channels), above the 64 GiB limit; lower 'bins' or "
             "/camera/resolution",
         bins);

  if (const Json* m = find(o, "mode"))
    scene.time_mode = choice(*m, at(p, "mode"), {"camera", "unwarp"}) == "camera"
                          ? TimeMode::Camera
                          : TimeMode::Unwarp;
  if (const Json* r = find(o, "reconstruction"))
    reconstruction(*r, at(p, "reconstruction"), scene.reconstruction);
}

// "histogram", or {"type": "kernel", "kernel", "alpha", "k", "first_pass_spp", "bandwidth"}.
void Loader::reconstruction(const Json& v, const std::string& p, ReconstructionDesc& r) const {
  const Keys kernel_keys = {"kernel",         "alpha",     "k",
                            "first_pass_spp", "bandwidth", "onset_reflection"};
  if (v.is_string()) {
    r.type = choice(v, p, {"histogram", "kernel"}) == "kernel" ? TemporalFilter::Kind::Kernel
                                                               : TemporalFilter::Kind::Histogram;
    return;
  }
  const Json& o = object(v, p);
  const std::string type = type_of(o, p, {"histogram", "kernel"}, kernel_keys);
  if (type == "histogram") {
    check_keys(o, p, {"type"}, "the histogram reconstruction", kernel_keys);
    r.type = TemporalFilter::Kind::Histogram;
    return;
  }
  check_keys(o, p, join(Keys{"type"}, kernel_keys));
  r.type = TemporalFilter::Kind::Kernel;
  if (const Json* k = find(o, "kernel"))
    r.kernel = choice(*k, at(p, "kernel"), {"perlin", "epanechnikov"}) == "perlin"
                   ? TemporalKernel::Perlin
                   : TemporalKernel::Epanechnikov;
  if (const Json* a = find(o, "alpha"))
    r.alpha = number(*a, at(p, "alpha"), within(0, 1, true, false));
  if (const Json* k = find(o, "k")) r.knn = int_in(*k, at(p, "k"), 1, 100000);
  if (const Json* f = find(o, "first_pass_spp"))
    r.first_pass_spp = int_in(*f, at(p, "first_pass_spp"), 1, 1000000);
  if (const Json* b = find(o, "bandwidth"))
    r.bandwidth_ps = number(*b, at(p, "bandwidth"), above(0));
  if (const Json* f = find(o, "onset_reflection")) {
    if (!f->is_boolean()) fail(at(p, "onset_reflection"), "expected true or false", *f);
    r.onset_reflection = f->get<bool>();
  }
}

}  // namespace femto::scene_json
