// Homogeneous media and their phase functions, as femto media named per (medium, eta).
#include "core/error.h"
#include "core/mitsuba/importer.h"

namespace femto::mitsuba {

void Importer::medium_check(Node n) const {
  if (std::string(n.name()) != "medium")
    fail(n, "expected a <medium> (the id names a <" + clip(n.name()) + ">)");
}

Json Importer::medium_json(Node n) const {
  const std::string type = plugin_type(n);
  if (type != "homogeneous")
    fail(n, "unsupported medium \"" + clip(type) +
                "\" (femto reads \"homogeneous\"; voxel media: "
                "use a femto JSON scene with a .vdb file)");
  Props p = props(n);
  const bool st = p.by_name.count("sigma_t") || p.by_name.count("albedo");
  const bool as = p.by_name.count("sigma_a") || p.by_name.count("sigma_s");
  if (st && as) fail(n, "give sigma_t and albedo, or sigma_a and sigma_s, not both pairs");
  const double scale = get_float(p, "scale", 1.0);
  if (!(scale >= 0)) fail(p.by_name.at("scale"), "scale must be >= 0 (got " + fmt(scale) + ")");
  double sigma_a, sigma_s;
  if (as) {
    sigma_a = get_grey(p, "sigma_a", 0.0);
    sigma_s = get_grey(p, "sigma_s", 0.0);
    if (!(sigma_a >= 0 && sigma_s >= 0)) fail(n, "sigma_a and sigma_s must be >= 0");
  } else {
    const double sigma_t = get_grey(p, "sigma_t", 1.0);  // Mitsuba's defaults
    const double albedo = get_grey(p, "albedo", 0.75);
    if (!(sigma_t >= 0))
      fail(p.by_name.at("sigma_t"), "sigma_t must be >= 0 (got " + fmt(sigma_t) + ")");
    if (!(albedo >= 0 && albedo <= 1))
      fail(p.by_name.at("albedo"), "albedo must be in [0, 1] (got " + fmt(albedo) + ")");
    sigma_s = albedo * sigma_t;
    sigma_a = sigma_t - sigma_s;
  }
  for (const char* unused : {"sample_emitters", "has_spectral_extinction"})
    (void)take(p, unused);  // sampling hints of Mitsuba's integrators; nothing to map
  check_all_used(p);
  double g = 0.0;
  for (Node c : p.objects) {
    if (std::string(c.name()) != "phase")
      fail(c, "unsupported element inside <medium> (a <phase> is)");
    const std::string pt = plugin_type(c);
    Props pp = props(c);
    if (pt == "hg") {
      g = get_float(pp, "g", 0.8);  // Mitsuba's default
      if (!(g > -1 && g < 1)) fail(pp.by_name.at("g"), "g must be in (-1, 1) (got " + fmt(g) + ")");
    } else if (pt != "isotropic") {
      fail(c, "unsupported phase function \"" + clip(pt) + "\" (\"isotropic\" and \"hg\" are)");
    }
    check_all_used(pp);
    if (!pp.objects.empty()) fail(pp.objects.front(), "unexpected element inside <phase>");
  }
  // Coefficients are per scene unit; femto's are per mm.
  Json m = Json::object();
  m["type"] = "homogeneous";
  m["sigma_a"] = sigma_a * scale / unit_mm_;
  m["sigma_s"] = sigma_s * scale / unit_mm_;
  m["g"] = g;
  return m;
}

/// The femto medium for a Mitsuba medium with refractive index eta (a dielectric's interior
/// medium carries the dielectric's index in femto).
std::string Importer::medium_name(Node n, double eta) {
  for (const Medium& m : media_)
    if (m.node == n && m.eta == eta) return m.name;
  Medium m;
  m.node = n;
  m.eta = eta;
  std::string base =
      n.attribute("id") ? attr(n, "id") : "medium (line " + std::to_string(line_of(n)) + ")";
  m.name = eta == 1.0 ? base : base + " (eta " + fmt(eta) + ")";
  for (const Medium& other : media_)
    if (other.name == m.name) m.name += " #" + std::to_string(media_.size());
  m.json = medium_json(n);
  if (eta != 1.0) m.json["eta"] = eta;
  origin("/media/" + escape(m.name), n);
  media_.push_back(m);
  return m.name;
}

std::string Importer::escape(const std::string& key) {
  std::string out;
  for (char ch : clip(key, 40))
    out += ch == '~' ? std::string("~0") : ch == '/' ? std::string("~1") : std::string(1, ch);
  return out;
}

}  // namespace femto::mitsuba
