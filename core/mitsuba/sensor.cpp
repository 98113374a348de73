// Sensor, film, sampler and transient integrator: femto's camera, time axis and render settings.
#include <cmath>

#include "core/constants.h"
#include "core/error.h"
#include "core/mitsuba/importer.h"

namespace femto::mitsuba {

void Importer::sensor(Node n) {
  const std::string type = plugin_type(n);
  if (type != "perspective")
    fail(n, "unsupported sensor type \"" + clip(type) + "\" (femto supports \"perspective\")");
  Props p = props(n);
  origin("/camera", n);
  const Node fov_node = p.by_name.count("fov") ? p.by_name.at("fov") : Node();
  if (!fov_node)
    fail(n, "give the field of view as <float name=\"fov\" .../> (focal_length is not supported)");
  const double fov = get_float(p, "fov", 0);
  if (!(fov > 0 && fov < 180))
    fail(fov_node, "fov must be in (0, 180) degrees (got " + fmt(fov) + ")");
  const Node axis_node = p.by_name.count("fov_axis") ? p.by_name.at("fov_axis") : Node();
  const std::string fov_axis = get_string(p, "fov_axis", "x");
  const Placement place = get_transform(p, "to_world");
  for (const char* unused : {"near_clip", "far_clip", "focus_distance"})
    if (const Node u = take(p, unused)) warn(u, "not used (femto has no clipping planes or focus)");
  for (const char* must_be_zero : {"principal_point_offset_x", "principal_point_offset_y"})
    if (p.by_name.count(must_be_zero) && get_float(p, must_be_zero, 0) != 0)
      fail(p.by_name.at(must_be_zero), "a shifted principal point is not supported");
  check_all_used(p);

  Node film_node, sampler_node;
  for (Node c : p.objects) {
    const std::string tag = c.name();
    if (tag == "film") {
      if (film_node) fail(c, "a second <film>");
      film_node = c;
    } else if (tag == "sampler") {
      if (sampler_node) fail(c, "a second <sampler>");
      sampler_node = c;
    } else if (tag == "medium" || (tag == "ref" && ref_tag(c) == "medium")) {
      if (global_medium_) fail(c, "a second medium for the sensor");
      global_medium_ = resolve(c, 0);
      medium_check(global_medium_);
    } else {
      fail(c, "unsupported element inside <sensor> (film, sampler and a medium are)");
    }
  }
  if (!film_node)
    fail(n,
         "the sensor needs <film type=\"transient_hdr_film\"> (mitransient's time-resolved film)");
  Json camera = Json::object();
  camera["type"] = "perspective";
  if (place.single_lookat) {
    camera["position"] = vec_json(place.origin);
    camera["look_at"] = vec_json(place.target);
    camera["up"] = vec_json(place.up);
  } else {
    // A camera frame: rotation times a uniform scale, not mirrored (the image cannot flip).
    const Affine& m = place.m;
    const Vec3 x = m.column(0), y = m.column(1), z = m.column(2);
    const double s = length(z);
    const bool frame = s > 0 && std::abs(length(x) - s) <= 1e-9 * s &&
                       std::abs(length(y) - s) <= 1e-9 * s && std::abs(dot(x, y)) <= 1e-9 * s * s &&
                       std::abs(dot(x, z)) <= 1e-9 * s * s && std::abs(dot(y, z)) <= 1e-9 * s * s;
    if (!frame || !(m.det() > 0))
      fail(p.by_name.count("to_world") ? p.by_name.at("to_world") : n,
           "the camera's to_world must be a rotation and translation (no mirroring, shear or "
           "non-uniform scale)");
    const Vec3 pos = m.point(Vec3(0, 0, 0));
    camera["position"] = vec_json(pos);
    camera["look_at"] = vec_json(pos + z / s);
    camera["up"] = vec_json(y / s);
  }
  const auto [width, height] = film(film_node);
  // Mitsuba's fov spans the axis fov_axis names; femto's is vertical.
  const double t = std::tan(0.5 * fov * kPi / 180.0);
  const double w = static_cast<double>(width), h = static_cast<double>(height);
  double vertical = fov;
  if (fov_axis == "x")
    vertical = 2.0 * std::atan(t * h / w) * 180.0 / kPi;
  else if (fov_axis == "y")
    vertical = fov;
  else if (fov_axis == "diagonal")
    vertical = 2.0 * std::atan(t * h / std::sqrt(w * w + h * h)) * 180.0 / kPi;
  else if (fov_axis == "smaller")
    vertical = w < h ? 2.0 * std::atan(t * h / w) * 180.0 / kPi : fov;
  else if (fov_axis == "larger")
    vertical = w > h ? 2.0 * std::atan(t * h / w) * 180.0 / kPi : fov;
  else
    fail(axis_node,
         "fov_axis must be one of \"x\", \"y\", \"diagonal\", \"smaller\", \"larger\" (got \"" +
             clip(fov_axis) + "\")");
  camera["fov"] = vertical;
  camera["resolution"] = Json::array({width, height});
  out_["camera"] = camera;
  if (global_medium_) {
    out_["medium"] = medium_name(global_medium_, 1.0);
    origin("/medium", global_medium_);
  }
  sampler(sampler_node);
}

std::pair<long long, long long> Importer::film(Node n) {
  const std::string type = plugin_type(n);
  if (type != "transient_hdr_film")
    fail(n, "unsupported film \"" + clip(type) +
                "\": femto renders a time axis; use mitransient's \"transient_hdr_film\" with "
                "temporal_bins, start_opl and bin_width_opl");
  Props p = props(n);
  origin("/time", n);
  const auto int_in = [&](const char* name, long long fallback, long long lo, long long hi) {
    const Node node = p.by_name.count(name) ? p.by_name.at(name) : Node();
    const long long v = get_int(p, name, fallback);
    if (node && (v < lo || v > hi))
      fail(node, std::string(name) + " must be in [" + std::to_string(lo) + ", " +
                     std::to_string(hi) + "] (got " + std::to_string(v) + ")");
    return v;
  };
  const long long width = int_in("width", 768, 1, 16384);  // Mitsuba's film defaults
  const long long height = int_in("height", 576, 1, 16384);
  const long long bins = int_in("temporal_bins", 2048, 1, 100000);  // mitransient's defaults
  const Node bw_node = p.by_name.count("bin_width_opl") ? p.by_name.at("bin_width_opl") : Node();
  const double bin_width = get_float(p, "bin_width_opl", 0.003);
  if (!(bin_width > 0)) fail(bw_node, "bin_width_opl must be > 0 (got " + fmt(bin_width) + ")");
  const double start = get_float(p, "start_opl", 0.0);
  for (const char* unused : {"file_format", "pixel_format", "component_format", "banner"})
    if (const Node u = take(p, unused))
      warn(u, "not used (femto writes its own outputs, docs/outputs.md)");
  if (p.by_name.count("sample_border") && get_bool(p, "sample_border", false))
    fail(p.by_name.at("sample_border"), "sample_border is not supported");
  check_all_used(p);
  for (Node c : p.objects) {
    if (std::string(c.name()) != "rfilter")
      fail(c, "unsupported element inside <film> (an <rfilter> is)");
    if (plugin_type(c) != "box")
      warn(c, "not used: femto's pixel filter is a box (uniform over the pixel)");
    else
      check_all_used(props(c));
  }
  Json time = Json::object();
  time["start_opl"] = start * unit_mm_;
  time["bin_width_opl"] = bin_width * unit_mm_;
  time["bins"] = bins;
  out_["time"] = time;
  return {width, height};
}

void Importer::sampler(Node n) {
  long long spp = 4;  // Mitsuba's default sample_count
  Json render = out_.contains("render") ? out_["render"] : Json::object();
  if (n) {
    check_attributes(n, {"type", "id", "name"});
    origin("/render", n);
    const std::string type = attr(n, "type");
    static const std::set<std::string> kSamplers = {"independent", "stratified", "multijitter",
                                                    "orthogonal", "ldsampler"};
    if (!kSamplers.count(type)) fail(n, "unknown sampler \"" + clip(type) + "\"");
    if (type != "independent")
      warn(n,
           "femto draws its own independent random numbers; only sample_count and seed are used");
    Props p = props(n);
    const Node sc = p.by_name.count("sample_count") ? p.by_name.at("sample_count") : Node();
    spp = get_int(p, "sample_count", 4);
    if (sc && (spp < 1 || spp > 10000000))
      fail(sc, "sample_count must be in [1, 10000000] (got " + std::to_string(spp) + ")");
    if (p.by_name.count("seed")) {
      const Node sn = p.by_name.at("seed");
      const long long seed = get_int(p, "seed", 0);
      if (seed < 0) fail(sn, "seed must be >= 0");
      render["seed"] = seed;
    }
    for (const char* unused : {"jitter", "scramble_seed", "dimension", "strength"})
      if (const Node u = take(p, unused)) warn(u, "not used (femto's own sampler)");
    check_all_used(p);
    if (!p.objects.empty()) fail(p.objects.front(), "unexpected element inside <sampler>");
  }
  render["spp"] = spp;
  out_["render"] = render;
}

void Importer::integrator(Node n) {
  Json render = out_.contains("render") ? out_["render"] : Json::object();
  render["integrator"] = "path";  // mitransient's integrators trace camera paths only
  if (n) {
    const std::string type = plugin_type(n);
    static const std::set<std::string> kTransient = {"transient_path", "transientpath",
                                                     "transient_prbvolpath"};
    if (!kTransient.count(type))
      fail(n, "unsupported integrator \"" + clip(type) +
                  "\" (femto reads mitransient's \"transient_path\", \"transientpath\" and "
                  "\"transient_prbvolpath\")");
    Props p = props(n);
    const Node md = p.by_name.count("max_depth") ? p.by_name.at("max_depth") : Node();
    const long long max_depth = get_int(p, "max_depth", -1);
    if (md) {
      origin("/render/max_depth", md);
      // Mitsuba counts path segments (1: emitters seen directly, 2: direct light); femto counts
      // scattering and bounce vertices, one fewer.
      if (max_depth == -1) {
      } else if (max_depth < 2 || max_depth > 1000001) {
        fail(md,
             "max_depth must be -1 (no bound) or in [2, 1000001]: femto's bound counts "
             "scattering events, max_depth - 1, at least 1 (got " +
                 std::to_string(max_depth) + ")");
      } else {
        render["max_depth"] = max_depth - 1;
      }
    }
    if (const Node rr = take(p, "rr_depth"))
      warn(rr,
           "not used: femto plays its own Russian roulette on camera paths, by throughput "
           "(/render/russian_roulette in the translated scene)");
    for (const char* unused : {"temporal_filter", "gaussian_stddev", "block_size"})
      if (const Node u = take(p, unused)) warn(u, "not used");
    if (p.by_name.count("camera_unwarp")) {
      const Node cu = p.by_name.at("camera_unwarp");
      const bool unwarp = get_bool(p, "camera_unwarp", false);
      out_["time"]["mode"] = unwarp ? "unwarp" : "camera";
      origin("/time/mode", cu);
    }
    for (const char* must_be_false : {"discard_direct_light", "hide_emitters"})
      if (p.by_name.count(must_be_false) && get_bool(p, must_be_false, false))
        fail(p.by_name.at(must_be_false), std::string(must_be_false) + " is not supported");
    check_all_used(p);
    if (!p.objects.empty()) fail(p.objects.front(), "unexpected element inside <integrator>");
  }
  out_["render"] = render;
}

}  // namespace femto::mitsuba
