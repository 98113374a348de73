// BSDFs: diffuse, (rough) dielectric, (rough) conductor, null, twosided; Mitsuba's ior names.
#include "core/error.h"
#include "core/mitsuba/importer.h"

namespace femto::mitsuba {

namespace {

// Mitsuba's named refractive indices (its ior table) for int_ior and ext_ior given as strings.
bool named_ior(const std::string& name, double& eta) {
  static const std::map<std::string, double> kIor = {
      {"vacuum", 1.0},      {"helium", 1.000036},        {"hydrogen", 1.000132},
      {"air", 1.000277},    {"carbon dioxide", 1.00045}, {"water", 1.3330},
      {"acetone", 1.36},    {"ethanol", 1.361},          {"carbon tetrachloride", 1.461},
      {"glycerol", 1.4729}, {"benzene", 1.501},          {"silicone oil", 1.52045},
      {"bromine", 1.661},   {"water ice", 1.31},         {"fused quartz", 1.458},
      {"pyrex", 1.470},     {"acrylic glass", 1.49},     {"polypropylene", 1.49},
      {"bk7", 1.5046},      {"sodium chloride", 1.544},  {"amber", 1.55},
      {"pet", 1.5750},      {"diamond", 2.419}};
  const auto it = kIor.find(name);
  if (it == kIor.end()) return false;
  eta = it->second;
  return true;
}

}  // namespace

double Importer::ior(Props& p, const std::string& name, double fallback) const {
  const Node n = take(p, name);
  if (!n) return fallback;
  expect_tag(n, {"float", "string"});
  check_attributes(n, {"name", "value"});
  const std::string v = attr(n, "value");
  double eta = 0;
  if (std::string(n.name()) == "string") {
    if (!named_ior(v, eta))
      fail(n, "unknown refractive index name \"" + clip(v) + "\" (Mitsuba's table)");
  } else {
    eta = number(n, "value", v);
  }
  if (!(eta >= 1.0)) fail(n, name + " must be >= 1 (got " + fmt(eta) + ")");
  return eta;
}

double Importer::roughness(Props& p, Node n) const {
  const std::string dist = get_string(p, "distribution", "beckmann");
  if (dist != "ggx")
    fail(n,
         "femto's rough surfaces use the GGX distribution: add <string name=\"distribution\" "
         "value=\"ggx\"/> (got \"" +
             clip(dist) + "\"" + (p.by_name.count("distribution") ? "" : ", Mitsuba's default") +
             ")");
  double alpha = get_float(p, "alpha", 0.1);
  if (p.by_name.count("alpha_u") || p.by_name.count("alpha_v")) {
    const double au = get_float(p, "alpha_u", 0.1), av = get_float(p, "alpha_v", 0.1);
    if (au != av) fail(n, "anisotropic roughness (alpha_u != alpha_v) is not supported");
    alpha = au;
  }
  if (!(alpha > 0 && alpha <= 1)) fail(n, "alpha must be in (0, 1] (got " + fmt(alpha) + ")");
  take(p, "sample_visible");
  return alpha;
}

Importer::Material Importer::bsdf(Node ref, int depth) const {
  const Node n = resolve(ref, depth);
  if (std::string(n.name()) != "bsdf")
    fail(ref, "expected a <bsdf> (the id names a <" + clip(n.name()) + ">)");
  const std::string type = plugin_type(n);
  Props p = props(n);
  Material m;
  if (type == "twosided") {
    // femto's diffuse and conductor surfaces reflect on both sides already.
    check_all_used(p);
    if (p.objects.size() != 1)
      fail(n, "a twosided wrapper with different front and back BSDFs is not supported");
    m = bsdf(p.objects.front(), depth + 1);
    if (m.null || m.transmissive) fail(n, "twosided applies to opaque BSDFs (diffuse, conductors)");
    return m;
  }
  if (!p.objects.empty()) {
    const Node o = p.objects.front();
    fail(o, std::string(o.name()) == "texture" ||
                    (std::string(o.name()) == "ref" && ref_tag(o) == "texture")
                ? "textures are not supported (docs/mitsuba.md)"
                : "unexpected element inside " + describe(n));
  }
  if (type == "diffuse") {
    const Node rn = p.by_name.count("reflectance") ? p.by_name.at("reflectance") : Node();
    const RGB r = get_rgb(p, "reflectance", RGB(0.5));
    if (rn && !(r.r >= 0 && r.g >= 0 && r.b >= 0 && r.r <= 1 && r.g <= 1 && r.b <= 1))
      fail(rn, "reflectance must be in [0, 1]");
    m.json = {{"type", "diffuse"}, {"albedo", Json::array({r.r, r.g, r.b})}};
  } else if (type == "dielectric" || type == "roughdielectric") {
    const double int_ior = ior(p, "int_ior", 1.5046), ext_ior = ior(p, "ext_ior", 1.000277);
    m.eta = int_ior / ext_ior;  // Mitsuba refracts (and mitransient times) with the ratio
    if (!(m.eta >= 1.0))
      fail(n, "int_ior / ext_ior = " + fmt(m.eta) + " < 1: femto needs the denser side inside");
    for (const char* s : {"specular_reflectance", "specular_transmittance"})
      if (p.by_name.count(s)) {
        const Node sn = p.by_name.at(s);
        const RGB c = get_rgb(p, s, RGB(1.0));
        if (!(c.r == 1 && c.g == 1 && c.b == 1))
          fail(sn, std::string(s) + " other than 1 is not supported");
      }
    m.transmissive = true;
    if (type == "dielectric") {
      m.json = {{"type", "dielectric"}, {"eta", m.eta}};
    } else {
      const double alpha = roughness(p, n);
      m.json = {{"type", "rough_dielectric"}, {"eta", m.eta}, {"roughness", alpha}};
    }
  } else if (type == "conductor" || type == "roughconductor") {
    const std::string material = get_string(p, "material", "none");
    if (material != "none" || p.by_name.count("eta") || p.by_name.count("k"))
      fail(n,
           "conductors with a material or eta/k are not supported; femto reflects a constant "
           "colour: use <rgb name=\"specular_reflectance\"> with material \"none\"");
    const Node sn =
        p.by_name.count("specular_reflectance") ? p.by_name.at("specular_reflectance") : Node();
    const RGB r = get_rgb(p, "specular_reflectance", RGB(1.0));
    if (sn && !(r.r >= 0 && r.g >= 0 && r.b >= 0 && r.r <= 1 && r.g <= 1 && r.b <= 1))
      fail(sn, "specular_reflectance must be in [0, 1]");
    const Json refl = Json::array({r.r, r.g, r.b});
    if (type == "conductor") {
      m.json = {{"type", "mirror"}, {"reflectance", refl}};
    } else {
      const double alpha = roughness(p, n);
      m.json = {{"type", "rough_conductor"}, {"reflectance", refl}, {"roughness", alpha}};
    }
  } else if (type == "null") {
    m.null = true;
  } else {
    fail(n, "unsupported bsdf \"" + clip(type) +
                "\" (diffuse, dielectric, roughdielectric, conductor, roughconductor, null and "
                "twosided are)");
  }
  check_all_used(p);
  return m;
}

}  // namespace femto::mitsuba
