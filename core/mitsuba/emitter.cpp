// Emitters outside shapes: point and spot lights; constant ones are left out with a warning.
#include "core/error.h"
#include "core/mitsuba/importer.h"

namespace femto::mitsuba {

void Importer::light(Node n) {
  const std::string type = plugin_type(n);
  const std::string path = "/lights/" + std::to_string(out_["lights"].size());
  origin(path, n);
  if (type == "area") fail(n, "an area emitter belongs inside a <shape>");
  if (type == "constant") {
    // mitransient stamps light from infinity with an infinite path length (the escaped ray's
    // distance), so it never lands in a time bin: leaving it out keeps the transient the same.
    Props p = props(n);
    const RGB L = get_rgb(p, "radiance", RGB(1.0));
    (void)L;
    check_all_used(p);
    if (!p.objects.empty()) fail(p.objects.front(), "unexpected element inside <emitter>");
    warn(n,
         "left out: its light arrives at infinite path length, after every time bin, as in "
         "mitransient's transient film (docs/mitsuba.md)");
    infinite_emitters_ = true;
    return;
  }
  if (type == "envmap" || type == "directional")
    fail(n, "unsupported emitter \"" + type +
                "\": femto has no light at infinity (point, spot and "
                "area emitters are; constant is accepted and left out)");
  if (type != "point" && type != "spot")
    fail(n, "unsupported emitter \"" + clip(type) + "\" (point, spot and area are)");
  Props p = props(n);
  for (Node c : p.objects) {
    const std::string tag = std::string(c.name()) == "ref" ? ref_tag(c) : std::string(c.name());
    if (tag != "medium") fail(c, "unsupported element inside <emitter> (a medium is)");
    if (resolve(c, 0) != global_medium_)
      fail(c,
           "an emitter's medium must be the sensor's medium (lights sit in femto's global "
           "medium)");
  }
  // Point and spot intensities are per steradian, but the irradiance they give falls with the
  // squared distance: scaling lengths by femto_unit_mm needs unit^2 on the intensity.
  const RGB I = get_rgb(p, "intensity", RGB(1.0)) * (unit_mm_ * unit_mm_);
  Json l = Json::object();
  l["type"] = type;
  const bool has_position = p.by_name.count("position") > 0;
  const Vec3 position = get_point(p, "position", Vec3(0, 0, 0)) * unit_mm_;
  const Placement place = get_transform(p, "to_world");
  if (has_position && p.by_name.count("to_world"))
    fail(p.by_name.at("position"), "give either 'position' or 'to_world', not both");
  if (type == "point") {
    l["position"] = vec_json(has_position ? position : place.m.point(Vec3(0, 0, 0)));
  } else {
    const double cutoff = get_float(p, "cutoff_angle", 20.0);
    const double beam = get_float(p, "beam_width", cutoff * 0.75);
    if (!(cutoff > 0 && cutoff <= 90))
      fail(p.by_name.count("cutoff_angle") ? p.by_name.at("cutoff_angle") : n,
           "cutoff_angle must be in (0, 90] degrees (got " + fmt(cutoff) + ")");
    if (!(beam >= 0 && beam <= cutoff))
      fail(p.by_name.count("beam_width") ? p.by_name.at("beam_width") : n,
           "beam_width must be in [0, cutoff_angle] (got " + fmt(beam) + ")");
    if (has_position) fail(p.by_name.at("position"), "a spot is placed by to_world");
    if (place.single_lookat) {
      l["position"] = vec_json(place.origin);
      l["look_at"] = vec_json(place.target);
    } else {
      l["position"] = vec_json(place.m.point(Vec3(0, 0, 0)));
      l["direction"] = vec_json(place.m.vector(Vec3(0, 0, 1)));
    }
    l["cone_angle"] = cutoff;
    l["falloff_start"] = beam;
  }
  l["intensity"] = Json::array({I.r, I.g, I.b});
  check_all_used(p);
  out_["lights"].push_back(l);
}

}  // namespace femto::mitsuba
