// Surface materials: diffuse, mirror, (rough) dielectric and rough conductor.
#include "core/error.h"
#include "core/scene_json/loader.h"

namespace femto::scene_json {

MaterialDesc Loader::material(const Json& v, const std::string& p) const {
  const Json& o = object(v, p);
  const Keys types = {"diffuse", "mirror", "dielectric", "rough_dielectric", "rough_conductor"};
  const Keys specific = {"albedo", "reflectance", "eta", "roughness"};
  const std::string type = type_of(o, p, types, join({"type"}, specific));
  MaterialDesc m;
  // GGX alpha: 0 would be a smooth surface (use "dielectric" or "mirror"), above 1 is unphysical.
  const auto roughness = [&] {
    if (const Json* r = find(o, "roughness"))
      m.roughness = number(*r, at(p, "roughness"), within(0, 1, true, false));
  };
  if (type == "diffuse") {
    check_keys(o, p, {"type", "albedo"}, "a diffuse material", specific);
    m.type = MaterialDesc::Type::Diffuse;
    m.albedo = rgb(require(o, p, "albedo"), at(p, "albedo"), 1.0);
  } else if (type == "mirror") {
    check_keys(o, p, {"type", "reflectance"}, "a mirror material", specific);
    m.type = MaterialDesc::Type::Mirror;
    if (const Json* r = find(o, "reflectance")) m.reflectance = rgb(*r, at(p, "reflectance"), 1.0);
  } else if (type == "rough_conductor") {
    check_keys(o, p, {"type", "reflectance", "roughness"}, "a rough conductor material", specific);
    m.type = MaterialDesc::Type::RoughConductor;
    if (const Json* r = find(o, "reflectance")) m.reflectance = rgb(*r, at(p, "reflectance"), 1.0);
    roughness();
  } else {
    const bool rough = type == "rough_dielectric";
    check_keys(o, p, rough ? Keys{"type", "eta", "roughness"} : Keys{"type", "eta"},
               rough ? "a rough dielectric material" : "a dielectric material", specific);
    m.type = rough ? MaterialDesc::Type::RoughDielectric : MaterialDesc::Type::Dielectric;
    if (const Json* e = find(o, "eta")) m.eta = number(*e, at(p, "eta"), at_least(1));
    if (rough) roughness();
  }
  return m;
}

}  // namespace femto::scene_json
