// Lights: point, spot and laser, aimed by direction or look_at, and emission pulses.
#include "core/error.h"
#include "core/scene_json/loader.h"

namespace femto::scene_json {

PulseDesc Loader::pulse(const Json& v, const std::string& p) const {
  const Json& o = object(v, p);
  check_keys(o, p, {"fwhm", "offset"});
  PulseDesc d;
  if (const Json* f = find(o, "fwhm")) d.fwhm_ps = number(*f, at(p, "fwhm"), at_least(0));
  if (const Json* f = find(o, "offset")) d.offset_ps = number(*f, at(p, "offset"));
  return d;
}

Vec3 Loader::aim(const Json& o, const std::string& p, const Vec3& position) const {
  const Json* d = find(o, "direction");
  const Json* l = find(o, "look_at");
  if (d && l) fail(at(p, "look_at"), "give either 'direction' or 'look_at', not both", *l);
  if (!d && !l) fail(at(p, "direction"), "missing required key 'direction' (or 'look_at')");
  if (d) return normalize(nonzero_vec3(*d, at(p, "direction")));
  const Vec3 target = vec3(*l, at(p, "look_at"));
  if (!(length(target - position) > 0)) fail(at(p, "look_at"), "must differ from 'position'", *l);
  return normalize(target - position);
}

void Loader::lights(const Json& v, SceneDesc& scene) const {
  if (!v.is_array()) fail("/lights", "expected an array of lights", v);
  const Keys types = {"point", "spot", "laser"};
  const Keys specific = {"intensity",     "direction", "look_at", "cone_angle",
                         "falloff_start", "radius",    "power"};
  for (std::size_t i = 0; i < v.size(); ++i) {
    const std::string p = at("/lights", i);
    const Json& o = object(v[i], p);
    const std::string type = type_of(o, p, types, join({"type", "position", "pulse"}, specific));
    LightDesc l;
    l.where = p;
    if (type == "point") {
      check_keys(o, p, {"type", "position", "intensity", "pulse"}, "a point light", specific);
      l.type = LightDesc::Type::Point;
    } else if (type == "spot") {
      check_keys(o, p,
                 {"type", "position", "direction", "look_at", "intensity", "cone_angle",
                  "falloff_start", "pulse"},
                 "a spot light", specific);
      l.type = LightDesc::Type::Spot;
    } else {
      check_keys(o, p, {"type", "position", "direction", "look_at", "radius", "power", "pulse"},
                 "a laser", specific);
      l.type = LightDesc::Type::Laser;
    }
    l.position = vec3(require(o, p, "position"), at(p, "position"));
    if (l.type != LightDesc::Type::Point) l.direction = aim(o, p, l.position);
    if (l.type == LightDesc::Type::Laser) {
      const Json& jr = require(o, p, "radius");
      l.radius = not_tiny(number(jr, at(p, "radius"), above(0)), kMinLength, at(p, "radius"), jr);
      l.power = bright_rgb(require(o, p, "power"), at(p, "power"));
    } else {
      l.intensity = bright_rgb(require(o, p, "intensity"), at(p, "intensity"));
    }
    if (l.type == LightDesc::Type::Spot) {
      l.cone_angle_deg =
          number(require(o, p, "cone_angle"), at(p, "cone_angle"), within(0, 90, true, false));
      l.falloff_deg = 0.8 * l.cone_angle_deg;
      if (const Json* f = find(o, "falloff_start")) {
        l.falloff_deg = number(*f, at(p, "falloff_start"));
        if (!within(0, l.cone_angle_deg).contains(l.falloff_deg))
          fail(at(p, "falloff_start"), within(0, l.cone_angle_deg).text() + " (0 to cone_angle)",
               *f);
      }
    }
    if (const Json* pl = find(o, "pulse")) l.pulse = pulse(*pl, at(p, "pulse"));
    scene.lights.push_back(l);
  }
}

}  // namespace femto::scene_json
