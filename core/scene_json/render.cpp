// Render settings: samples, depth, seed, the integrator and its photon mapping parameters.
#include <climits>

#include "core/error.h"
#include "core/scene_json/loader.h"

namespace femto::scene_json {

// Transient progressive photon mapping: {"per_pass", "radius", "bandwidth", "alpha", "beta_t",
// "kernel"}.
void Loader::photons(const Json& v, const std::string& p, PhotonDesc& d) const {
  const Json& o = object(v, p);
  check_keys(o, p, {"per_pass", "radius", "bandwidth", "alpha", "beta_t", "kernel", "aim"});
  if (const Json* s = find(o, "per_pass"))
    d.per_pass = integer(*s, at(p, "per_pass"), 1, 1000000000LL);
  if (const Json* s = find(o, "radius")) d.radius = number(*s, at(p, "radius"), above(0));
  if (const Json* s = find(o, "bandwidth"))
    d.bandwidth_ps = number(*s, at(p, "bandwidth"), above(0));
  if (const Json* s = find(o, "alpha"))
    d.alpha = number(*s, at(p, "alpha"), within(0, 1, true, false));
  if (const Json* s = find(o, "beta_t")) d.beta_t = number(*s, at(p, "beta_t"), within(0, 1));
  if (const Json* k = find(o, "kernel"))
    d.kernel = choice(*k, at(p, "kernel"), {"perlin", "epanechnikov"}) == "perlin"
                   ? TemporalKernel::Perlin
                   : TemporalKernel::Epanechnikov;
  if (const Json* a = find(o, "aim")) {
    if (!a->is_boolean()) fail(at(p, "aim"), "expected true or false", *a);
    d.aim = a->get<bool>();
  }
}

// Russian roulette on camera paths: true (from vertex 3, throughput threshold 0.2), false, or
// {"depth", "threshold"}.
void Loader::roulette(const Json& v, const std::string& p, RouletteDesc& d) const {
  if (v.is_boolean()) {
    d = v.get<bool>() ? RouletteDesc{} : RouletteDesc{0, 1.0};
    return;
  }
  if (!v.is_object()) fail(p, "expected true, false or an object {\"depth\", \"threshold\"}", v);
  check_keys(v, p, {"depth", "threshold"});
  d = RouletteDesc{};
  if (const Json* s = find(v, "depth")) d.depth = int_in(*s, at(p, "depth"), 1, 1000000);
  if (const Json* s = find(v, "threshold"))
    d.threshold = number(*s, at(p, "threshold"), within(0, 1, true, false));
}

void Loader::render(const Json& v, IntegratorDesc& d) const {
  const std::string p = "/render";
  const Json& o = object(v, p);
  check_keys(o, p,
             {"spp", "max_depth", "seed", "integrator", "light_paths", "camera_ball", "photons",
              "russian_roulette"});
  if (const Json* s = find(o, "spp")) d.spp = int_in(*s, at(p, "spp"), 1, 10000000);
  if (const Json* s = find(o, "integrator")) {
    const std::string k =
        choice(*s, at(p, "integrator"), {"auto", "path", "light", "photons", "beams", "hybrid"});
    d.kind = k == "path"      ? IntegratorKind::Path
             : k == "light"   ? IntegratorKind::Light
             : k == "photons" ? IntegratorKind::Photons
             : k == "beams"   ? IntegratorKind::Beams
             : k == "hybrid"  ? IntegratorKind::Hybrid
                              : IntegratorKind::Auto;
  }
  if (const Json* s = find(o, "light_paths"))
    d.light_paths = integer(*s, at(p, "light_paths"), 1, 1000000000000LL);
  // Hybrid: the camera ball's radius, mm (0: none; core/integrators/camera_ball.h).
  if (const Json* s = find(o, "camera_ball"))
    d.camera_ball_mm = number(*s, at(p, "camera_ball"), within(0, 1e6));
  if (const Json* s = find(o, "photons")) photons(*s, at(p, "photons"), d.photons);
  if (const Json* s = find(o, "russian_roulette"))
    roulette(*s, at(p, "russian_roulette"), d.roulette);
  if (const Json* s = find(o, "max_depth")) {
    d.max_depth = int_in(*s, at(p, "max_depth"), 1, 1000000);
    d.max_depth_set = true;
  }
  if (const Json* s = find(o, "seed")) {
    // Seeds span the full uint64 range, beyond what integer() reads.
    if (s->is_number_unsigned())
      d.seed = s->get<std::uint64_t>();
    else
      d.seed = static_cast<std::uint64_t>(integer(*s, at(p, "seed"), 0, LLONG_MAX));
  }
}

}  // namespace femto::scene_json
